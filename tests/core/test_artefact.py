"""The compiled model as a frozen artefact (issue #22): the compiler's record
cannot be rebound and no run writes into it; the callbacks are a named
record that is still the positional tuple the solvers index; the layers
import downwards only and no module imports another's private names; the
hybrid loop has no branch on sensitivities (they are an observer)."""
import ast
import dataclasses
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from acausal import Model, ModelError, ParameterError, compile_model
from acausal.compiler.artefact import Artefact, Resolver
from acausal.compiler.codegen import Callbacks
from acausal.mechanics.translational import Damper, Fixed, Mass, Spring

PACKAGE = Path(__file__).resolve().parents[2] / "acausal"


def _oscillator():
    m = Model()
    m.ground = Fixed()
    m.mass = Mass(m=2.0, s=0.1, v=0.0)
    m.spring = Spring(c=50.0)
    m.damper = Damper(d=0.5)
    m.connect(m.ground.flange, m.spring.flange_a, m.damper.flange_a)
    m.connect(m.spring.flange_b, m.damper.flange_b, m.mass.flange)
    return m


@pytest.fixture(scope="module")
def cm():
    return compile_model(_oscillator(), cache=False)


def test_the_artefact_is_frozen_and_no_run_writes_into_it(cm):
    art = cm.artefact
    assert isinstance(art, Artefact)
    with pytest.raises(dataclasses.FrozenInstanceError):
        art.dae = None
    with pytest.raises(dataclasses.FrozenInstanceError):
        art.parameters.entries = ()
    with pytest.raises(AttributeError):
        cm.params = []                 # the wrapper's views are read-only
    fields = {f.name: getattr(art, f.name) for f in dataclasses.fields(art)}
    cm.simulate(t_end=0.2, sensitivities=["spring.c"])
    cm.simulate(t_end=0.2, params={"mass.v": 0.3}, backend="compiled")
    assert all(getattr(art, k) is v for k, v in fields.items())
    assert set(vars(cm)) == {"artefact"}


def test_the_resolver_rewrites_each_expression_once_with_the_same_answer():
    """The artefact's resolver is the code generator's: the expressions it
    rewrote there come back as the same objects; a fresh resolver of the
    same model gives equal ones; a name it cannot give fails every time."""
    art = compile_model(_oscillator(), cache=False).artefact
    e = sp.Symbol("spring.f") * sp.Symbol("mass.v") + sp.Symbol("damper.f")
    first = art.resolve(e)
    assert art.resolve(e) is first
    fresh = Resolver.of(art.reduced, art.dae, art.parameters.symbols,
                        [d.symbol for d in art.flat.discretes.values()])
    assert fresh(e) == first
    assert first.free_symbols <= fresh.known
    for _ in range(2):
        with pytest.raises(ModelError, match="not available"):
            art.resolve(sp.Symbol("mass.nothing"))


def test_damped_oscillator_against_its_closed_form(cm):
    """x'' + (d/m) x' + (c/m) x = 0 from x0 = 0.1 at rest."""
    res = cm.simulate(t_end=1.0, rtol=1e-10, atol=1e-12, output_step=0.01)
    zeta_w, w0 = 0.5 / (2 * 2.0), np.sqrt(50.0 / 2.0)
    wd = np.sqrt(w0 ** 2 - zeta_w ** 2)
    x = 0.1 * np.exp(-zeta_w * res.t) * (np.cos(wd * res.t) + zeta_w / wd * np.sin(wd * res.t))
    np.testing.assert_allclose(res["mass.s"], x, rtol=0, atol=1e-8)


def test_callbacks_are_a_named_record_still_indexed_by_position(cm):
    cb = cm.callbacks(cm.param_vector(), cm.discrete_start())
    assert isinstance(cb, Callbacks) and isinstance(cb, tuple)
    assert cb[0] is cb.res and cb[4] is cb.observe and cb[6] is cb.jac_csc
    assert cb.reinit is None and cb.init_newton is None      # Python: the runtime's own
    lin = cm.linear_solver("sparse")
    assert cb[lin.jac_index] is cb.jac_csc


def test_with_defaults_shares_the_code_and_leaves_the_original(cm):
    other = cm.with_defaults({"spring.c": 200.0})
    assert other.artefact.code is cm.artefact.code
    assert other.params[other.param_index("spring.c")].default == 200.0
    assert cm.params[cm.param_index("spring.c")].default == 50.0
    a = other.simulate(t_end=0.3)
    b = cm.simulate(t_end=0.3, params={"spring.c": 200.0})
    assert np.array_equal(a["mass.s"], b["mass.s"])
    with pytest.raises(ParameterError):
        cm.with_defaults({"spring.c": -1.0})
    with pytest.raises(ParameterError):
        cm.with_defaults({"spring.q": 1.0})


def _imports(path):
    """(module the import names, the names) of every import in ``path``,
    relative imports resolved against the package."""
    parts = list(path.relative_to(PACKAGE.parent).parts[:-1])    # the module's package
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = parts[:len(parts) - node.level + 1]
                mod = ".".join(base + ([node.module] if node.module else []))
            else:
                mod = node.module or ""
            yield mod, [a.name for a in node.names]
        elif isinstance(node, ast.Import):
            for a in node.names:
                yield a.name, []


def test_no_private_name_is_imported_from_another_module_of_the_lower_layers():
    hits = []
    for layer in ("compiler", "runtime", "infra"):
        for path in (PACKAGE / layer).rglob("*.py"):
            for mod, names in _imports(path):
                bad = [n for n in names if n.startswith("_") and not n.startswith("__")]
                if mod.startswith("acausal") and bad:
                    hits.append(f"{path.relative_to(PACKAGE)}: {mod} {bad}")
    assert not hits, hits


@pytest.mark.parametrize("layer,above", [("compiler", ("acausal.runtime", "acausal.studies",
                                                       "acausal.diagnose", "acausal.modelfile")),
                                         ("infra", ("acausal.lang", "acausal.compiler",
                                                    "acausal.runtime"))])
def test_no_arrow_runs_back_up(layer, above):
    hits = [f"{path.relative_to(PACKAGE)}: {mod}"
            for path in (PACKAGE / layer).rglob("*.py")
            for mod, _ in _imports(path) if mod.startswith(above)]
    assert not hits, hits


def test_the_hybrid_loop_has_no_branch_on_sensitivities():
    tree = ast.parse((PACKAGE / "runtime" / "hybrid.py").read_text())
    loop = {"_integrate", "_observers", "_handle", "_event_iteration", "_log_event",
            "_failure"}
    for fn in (n for n in ast.walk(tree) if isinstance(n, ast.FunctionDef) and n.name in loop):
        for node in ast.walk(fn):
            if isinstance(node, (ast.If, ast.IfExp)):
                text = ast.unparse(node.test)
                assert "sens" not in text, (fn.name, text)
