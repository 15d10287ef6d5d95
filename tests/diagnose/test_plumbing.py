"""The diagnosis's plumbing: one options record, a context, stages
``stage(ctx, state) -> state`` that leave their input alone, a typed
Diagnosis built by keyword, short parameter lists, no private imports, and
the old names still working (with a DeprecationWarning)."""
import ast
import dataclasses
import importlib
from pathlib import Path

import pytest

import acausal
from acausal.diagnose import run
from acausal.diagnose.options import DiagnosisOptions
from acausal.diagnose.problem import FitSettings, Problem
from acausal.diagnose.report.result import Diagnosis
from acausal.diagnose.stages.context import Clock, Context
from acausal.diagnose.stages.locate import Location
from acausal.diagnose.stages.state import State
from acausal.infra.executor import open_executor

PACKAGE = Path(acausal.__file__).parent
CHECKED = [PACKAGE / "diagnose", PACKAGE / "studies" / "calibrate.py",
           PACKAGE / "studies" / "residuals.py"]
MAX_PARAMS = 8


def _files():
    for root in CHECKED:
        yield from sorted(root.rglob("*.py")) if root.is_dir() else [root]


def test_no_function_takes_more_than_eight_parameters():
    long = []
    for path in _files():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                a = node.args
                names = [x.arg for x in a.posonlyargs + a.args + a.kwonlyargs
                         if x.arg not in ("self", "cls")]
                names += [x.arg for x in (a.vararg, a.kwarg) if x is not None]
                if len(names) > MAX_PARAMS:
                    long.append(f"{path.relative_to(PACKAGE)}:{node.lineno} {node.name} "
                                f"({len(names)})")
    assert long == []


def test_no_private_name_is_imported_from_another_module():
    private = []
    for path in _files():
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                private += [f"{path.relative_to(PACKAGE)}:{node.lineno} {a.name}"
                            for a in node.names if a.name.startswith("_")]
    assert private == []


@pytest.mark.parametrize("module, old, new", [
    ("acausal.data", "Experiment", "MeasuredExperiment"),
    ("acausal.data.records", "Experiment", "MeasuredExperiment"),
    ("acausal.diagnose.stages.chain", "Calibration", "NominalFit"),
    ("acausal.studies.profile", "Profile", "LikelihoodProfile"),
    ("acausal.diagnose.library.hypotheses", "Clearance", "ExtraClearance"),
])
def test_an_old_name_still_imports_with_a_deprecation_warning(module, old, new):
    mod = importlib.import_module(module)
    with pytest.warns(DeprecationWarning, match=new):
        got = getattr(mod, old)
    assert got is getattr(mod, new)
    with pytest.raises(AttributeError):
        getattr(mod, "NoSuchName")


def test_options_have_the_command_lines_defaults_and_take_keywords():
    o = DiagnosisOptions()
    assert (o.alpha, o.settings.lhs, o.settings.refine) == (0.01, 4, 2)   # acausal diagnose
    assert all((o.families, o.pairs, o.generic, o.profile, o.design, o.views, o.plots,
                o.exact_cv, o.progress))
    got = DiagnosisOptions.of(o, workers=3, pairs=False)
    assert (got.workers, got.pairs, o.workers, o.pairs) == (3, False, None, True)
    assert DiagnosisOptions.of(None, max_nfev=7).settings == FitSettings(max_nfev=7)
    kept = FitSettings(lhs=0)
    assert DiagnosisOptions.of(None, max_nfev=7, settings=kept).settings is kept
    assert DiagnosisOptions.of(None, settings=None).settings == FitSettings()
    with pytest.raises(TypeError, match="diagnose\\(\\) got an unexpected keyword argument "
                                        "'worker'"):
        DiagnosisOptions.of(None, worker=2)
    with pytest.raises(TypeError, match="unexpected keyword argument 'bogus'"):
        run.diagnose("m.py", "d", out_dir="o", bogus=1)


def test_the_checkpoint_key_leaves_out_where_and_how_the_diagnosis_runs():
    a = DiagnosisOptions(hypotheses=["coulomb_friction"])
    b = dataclasses.replace(a, workers=7, scheduler="serial", progress=False, plots=False)
    assert a.checkpoint_key() == b.checkpoint_key()
    assert a.checkpoint_key() == dict(
        hypotheses=["coulomb_friction"], locations=None, alpha=0.01, exact_cv=True,
        library=None, settings=repr(FitSettings()), generic=True, pairs=True, families=True)
    assert dataclasses.replace(a, alpha=0.05).checkpoint_key() != a.checkpoint_key()


def test_the_diagnosis_is_built_by_keyword_and_frozen():
    fields = {f.name: f for f in dataclasses.fields(Diagnosis)}
    assert "object" not in {str(f.type) for f in fields.values()}
    with pytest.raises(TypeError):
        Diagnosis(None, None, None, 0, None, None, None)      # noqa: positional
    d = Diagnosis(problem=None, dataset=None, calibration=None, n_candidates=0,
                  decision=None, cv=None, ranking=None)
    with pytest.raises(dataclasses.FrozenInstanceError):
        d.timing = {}


def _state(**options):
    problem = Problem("m.py", "d", "lib", ())
    return State(problem, None, DiagnosisOptions(**options), "out")


def test_a_stage_returns_a_new_state_and_leaves_its_input_alone():
    ctx = Context(None, False)
    s = _state(generic=False, families=False, profile=False)
    got = run.located(ctx, s)
    assert got is not s and s.location is None
    assert got.location == Location(skipped="not run (generic=False)")
    assert run.members_fitted(ctx, s) is s          # families=False: nothing to do
    assert run.profiled(ctx, s) is s
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.fits = ()


def _double(x):
    return 2 * x


class _Store:
    def __init__(self):
        self.kept = []

    def __call__(self, task, result):
        self.kept.append((task, result))


def test_the_context_runs_tasks_and_checkpoints_only_what_it_is_told():
    store = _Store()
    with open_executor("serial", None) as ex:
        ctx = Context(ex, False, store)
        assert ctx.run(_double, [1, 2, 3], "t") == [2, 4, 6]
        assert ctx.run(_double, [5], "t", checkpoint=False) == [10]
    assert sorted(store.kept) == [(1, 2), (2, 4), (3, 6)]      # not the unkept (5, 10)
    clock = Clock()
    with clock.timing("a_s"):
        pass
    with pytest.raises(ValueError):
        with clock.timing("b_s"):
            raise ValueError
    assert list(clock.times) == ["a_s"] and clock.elapsed() >= clock.times["a_s"]


OSCILLATOR = '''
from acausal import Experiment, Model
from acausal.mechanics.translational import Fixed, Mass, Spring

model = Model()
model.mass = Mass(m=1.0, s=0.1, v=0.0)
model.spring = Spring(c=100.0, s_rel0=0.0)
model.ground = Fixed()
model.connect(model.ground.flange, model.spring.flange_a)
model.connect(model.spring.flange_b, model.mass.flange)
experiment = Experiment(t_end=0.5, rtol=1e-8, atol=1e-10, output_step=1e-3)
free_parameters = {"spring.c": (50.0, 200.0)}
'''


def test_the_workers_fit_the_same_thinned_traces_the_diagnosis_loads(tmp_path):
    """A 5001-sample trace of a signal travelling 72 mm read in 1 mm steps
    (floor 0.29 mm) supports about 250 samples: the dataset the stages load
    and the one every worker task loads (dataset_of) are thinned alike
    (main had thinned only the first: the fits saw every sample), and the
    dataset's notes say so."""
    import numpy as np

    from acausal.data import Dataset, Instrument, MeasuredExperiment, Trace, write_dataset
    from acausal.diagnose.stages.chain import load_problem
    from acausal.diagnose.stages.tasks import dataset_of
    (tmp_path / "osc.py").write_text(OSCILLATOR)
    t = np.linspace(0.0, 0.5, 5001)
    x = np.round(0.1 * np.cos(10.0 * t) / 1e-3) * 1e-3
    write_dataset(tmp_path / "data", Dataset(None, [MeasuredExperiment(
        "a", {"mass.m": 1.0}, {}, Trace(t, {"mass.s": x}))],
        {"mass.s": Instrument("mass.s", resolution=1e-3)}))
    problem, ds = load_problem(str(tmp_path / "osc.py"), str(tmp_path / "data"))
    worker = dataset_of(problem)
    n = len(ds.experiments[0].trace.time)
    assert 200 < n < 5001 and len(ds.notes) == 1 and "5,001" in ds.notes[0]
    np.testing.assert_array_equal(worker.experiments[0].trace.time,
                                  ds.experiments[0].trace.time)
    assert worker.notes == ds.notes
