"""Large-model support: the generated sparse Jacobians (iteration matrix,
fixed-start rows), the linear solvers chosen from their structure, the fast
differentiation the compiler uses, and batched simulation. Checked against
sympy, finite differences and the exact solution of a linear chain
(matrix exponential), on mechanisms built here."""
import numpy as np
import pytest
import scipy.linalg
import sympy as sp

from acausal import Assertion, Model, Parameter, compile_model
from acausal.runtime.batch import BatchItemError
from acausal.lang.component import Component
from acausal.lang.connectors import Flange
from acausal.lang.fastdiff import diff
from acausal.mechanics.translational import Fixed, Mass, SpringDamper

M, C, D = 0.5, 3e3, 2.0


def chain(n, ds=0.01):
    """n masses M joined by spring-dampers (C, D), the first one to ground;
    the last mass starts displaced by ds."""
    m = Model()
    m.add("ground", Fixed())
    prev = m.ground.flange
    for k in range(n):
        mass = m.add(f"m{k}", Mass(m=M, s=ds if k == n - 1 else 0.0, v=0.0))
        spring = m.add(f"k{k}", SpringDamper(c=C, d=D))
        m.connect(prev, spring.flange_a)
        m.connect(spring.flange_b, mass.flange)
        prev = mass.flange
    return m


def exact_chain(n, t, ds=0.01):
    """Positions at time t: x'' = -(K x + D x')/M with tridiagonal K, D."""
    T = 2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1)
    T[-1, -1] = 1.0                              # the last mass has one spring
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-C / M * T, -D / M * T]])
    x0 = np.zeros(2 * n)
    x0[n - 1] = ds
    return scipy.linalg.expm(A * t) @ x0


@pytest.fixture(scope="module")
def cm12():
    return compile_model(chain(12), cache=False)


def test_fast_diff_equals_sympy():
    x, y, z = sp.symbols("x y z", real=True)
    exprs = [x * y * z + 3 * x ** 2 * y, (x + y) ** 2.5 * sp.sin(x * z), x / (1 + y * x),
             sp.Abs(x - y) * x, sp.Piecewise((x ** 1.5 * y, x > 0), (0, True)),
             sp.exp(-x * y) + sp.sqrt(x ** 2 + z ** 2), 2 * x * x * sp.cos(y) ** 3,
             sp.Piecewise((x ** 1.5 * y, z > 0), (y * sp.sin(x), True)),
             sp.Heaviside(x - y) * x, sp.tanh(x * y), sp.atan2(x, y)]
    for e in exprs:
        for s in (x, y, z):
            assert sp.simplify(diff(e, s) - sp.diff(e, s)) == 0, (e, s)


def test_iteration_matrix_pattern_and_storage(cm12):
    n = len(cm12.dae.y)
    p, d = cm12.param_vector(), cm12.discrete_start()
    cb = cm12.callbacks(p, d)
    rng = np.random.default_rng(0)
    y, yp, cj = rng.normal(size=n), rng.normal(size=n), 17.0
    J = np.zeros((n, n))
    cb[1](0.0, y, yp, np.zeros(n), cj, J)
    # the dense Jacobian against central differences of the residual
    def F(yy, yyp):
        r = np.zeros(n)
        cb[0](0.0, yy, yyp, r)
        return r
    h = 1e-6
    Jfd = np.column_stack([(F(y + h * e, yp + cj * h * e) - F(y - h * e, yp - cj * h * e))
                           / (2 * h) for e in np.eye(n)])
    assert np.allclose(J, Jfd, rtol=1e-7, atol=1e-6 * np.abs(J).max())
    # every non-zero is in the pattern; the CSC array holds the same values
    sp_ = cm12.sparsity
    pattern = np.zeros((n, n), bool)
    pattern[sp_.rows, sp_.cols] = True
    assert not np.any(J[~pattern])
    flat = np.zeros(sp_.nnz)
    cb[6](0.0, y, yp, np.zeros(n), cj, flat)
    assert np.array_equal(sp_.matrix().toarray() * 0 + _csc_dense(sp_, flat), J)
    rows, cols = np.nonzero(pattern)
    assert sp_.lband == max(rows - cols) and sp_.uband == max(cols - rows)
    assert sp_.lband + sp_.uband + 1 < n // 4          # a chain is narrow-banded
    assert cm12.linear_solver().kind == "dense"        # 24 unknowns: below the band size
    assert cm12.linear_solver("band").options["lband"] == sp_.lband


def _csc_dense(sp_, flat):
    import scipy.sparse as sps
    return sps.csc_matrix((flat, (sp_.rows, sp_.cols)), shape=(sp_.n, sp_.n)).toarray()


@pytest.mark.filterwarnings("ignore:Custom sparse Jacobian approximation")
@pytest.mark.parametrize("kind", ["dense", "band", "sparse"])
def test_linear_solvers_agree_with_exact_chain(cm12, kind):
    t_end = 0.05
    res = cm12.simulate(t_end=t_end, rtol=1e-10, atol=1e-13, linsolver=kind,
                        output_times=[t_end])
    exact = exact_chain(12, t_end)
    got = np.array([res.final()[f"m{k}.s"] for k in range(12)])
    assert np.max(np.abs(got - exact[:12])) < 1e-9


def test_fixed_start_rows_against_finite_differences():
    """A fixed start on an eliminated variable (a spring-damper force, an
    expression of two masses' positions and velocities) gives a row that is
    not a unit vector."""
    m = Model()
    m.ground = Fixed()
    m.a = Mass(m=M, s=0.01, v=0.0)
    m.b = Mass(m=M)
    m.k0 = SpringDamper(c=C, d=D)
    m.k1 = SpringDamper(c=C, d=D, f=5.0)
    m.connect(m.ground.flange, m.k0.flange_a)
    m.connect(m.k0.flange_b, m.a.flange, m.k1.flange_a)
    m.connect(m.k1.flange_b, m.b.flange)
    cm = compile_model(m, cache=False)
    n, ns = len(cm.dae.y), cm.dae.n_states
    p, d = cm.param_vector(), cm.discrete_start()
    cb = cm.callbacks(p, d)
    fixed = cm.fixed_starts(p)
    rng = np.random.default_rng(3)
    y, yp = rng.normal(size=n), rng.normal(size=n)
    F = cm.fixed_jacobian()(0.0, *y, *yp, *p, *d)
    assert F.shape == (len(fixed), n + ns)

    def obs(z):
        yy, yyp = z[:n], np.concatenate([z[n:], yp[ns:]])
        o = cb[4](0.0, yy, yyp)
        return np.array([o[k] for k, _, _ in fixed])
    z = np.concatenate([y, yp[:ns]])
    h = 1e-6
    Ffd = np.column_stack([(obs(z + h * e) - obs(z - h * e)) / (2 * h)
                           for e in np.eye(n + ns)])
    assert np.allclose(F, Ffd, atol=1e-8)
    row = F[[name for _, _, name in fixed].index("k1.f")]
    assert sorted(row[row != 0]) == [D, C]          # f = C s_rel + D der(s_rel)
    res = cm.simulate(t_end=1e-3, rtol=1e-10, atol=1e-12)
    assert abs(res["k1.f"][0] - 5.0) < 1e-9


class Limit(Component):
    """A flange that must stay below ``s_max`` (an assertion); no force."""
    flange = Flange("watched flange")
    s_max = Parameter(1.0, "m", "largest allowed position")

    def equations(self):
        return [self.flange.f]

    def assertions(self):
        return [Assertion(self.s_max - self.flange.s, "past the limit")]


def test_batch_matches_one_by_one_and_reports_failures():
    m = chain(3)
    m.add("limit", Limit(s_max=0.05))
    m.connect(m.limit.flange, m.m2.flange)
    cm = compile_model(m, cache=False)
    sets = [{"k0.c": c} for c in (1e3, 2e3, 4e3)] + [{"limit.s_max": 0.001}]
    kw = dict(t_end=0.05, rtol=1e-9, atol=1e-12, output_step=1e-3)
    out = cm.simulate_batch(sets, workers=2, errors="return", **kw)
    for p, res in zip(sets[:3], out[:3]):
        one = cm.simulate(params=p, **kw)
        assert np.array_equal(res.t, one.t) and np.array_equal(res["m0.s"], one["m0.s"])
    assert isinstance(out[3], BatchItemError) and out[3].index == 3
    assert "past the limit" in str(out[3])
    with pytest.raises(BatchItemError, match="parameter set 3"):
        cm.simulate_batch(sets, workers=2, **kw)
    finals = cm.simulate_batch(sets[:3], workers=2, reduce=lambda r: r.final()["m2.s"], **kw)
    assert finals == [r.final()["m2.s"] for r in out[:3]]


def test_sparse_initialisation_equals_the_dense_one(cm12, monkeypatch):
    """From SPARSE_MIN unknowns the initialisation assembles sparse
    Jacobians and solves them by sparse LU; forced on for two small models
    (a chain with every start fixed; a fixed start on an eliminated
    spring-damper force, a row that is not a unit vector, and a free mass
    whose start is a guess), it gives the dense path's point."""
    import acausal.runtime.initialize as ini
    m = Model()
    m.ground = Fixed()
    m.a = Mass(m=M, s=0.01, v=0.0)
    m.b = Mass(m=M)
    m.k0 = SpringDamper(c=C, d=D)
    m.k1 = SpringDamper(c=C, d=D, f=5.0)
    m.connect(m.ground.flange, m.k0.flange_a)
    m.connect(m.k0.flange_b, m.a.flange, m.k1.flange_a)
    m.connect(m.k1.flange_b, m.b.flange)
    for cm in (cm12, compile_model(m, cache=False)):
        p, d = cm.param_vector(), cm.discrete_start()
        cb = cm.callbacks(p, d)
        monkeypatch.setattr(ini, "SPARSE_MIN", 10 ** 9)
        y_dense, yp_dense = ini.initial_point(cm, p, d, cb, 0.0)
        monkeypatch.setattr(ini, "SPARSE_MIN", 0)
        y_sparse, yp_sparse = ini.initial_point(cm, p, d, cb, 0.0)
        scale = 1 + np.abs(y_dense)
        assert np.all(np.abs(y_sparse - y_dense) <= 1e-12 * scale)
        assert np.all(np.abs(yp_sparse - yp_dense) <= 1e-9 * (1 + np.abs(yp_dense)))
    assert abs(cb[4](0.0, y_sparse, yp_sparse)[cm.var_names.index("k1.f")] - 5.0) < 1e-9
