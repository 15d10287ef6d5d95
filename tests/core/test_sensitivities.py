"""Forward parameter sensitivities (``simulate(sensitivities=...)``,
:mod:`acausal.sensitivity`) against closed forms, central finite
differences and each other on the two backends.

The closed forms are derived here, independently of the library: the damped
oscillator's solution differentiated by sympy; the Hertz impact's contact
period ``T = 2.94328 delta_max / v0``, ``delta_max ~ (m / K)^(2/5)``, so
``dT/dK = -(2/5) T / K`` and ``dT/dm = (2/5) T / m``.
"""
import numpy as np
import pytest
import sympy as sp

from acausal import Model, time
from acausal.runtime.backends import compiled_available
from acausal.runtime.model import compile_model
from acausal.errors import ParameterError, UsageError
from acausal.mechanics.contact import Contact, contact_period
from acausal.lang import Eq, Parameter
from acausal.mechanics.partials import PartialCompliantWithRelativeStates
from acausal.mechanics.translational import Damper, Fixed, Force, Mass, Spring

# the compiled backend's cases build a C library each (about a second): slow tier
BACKENDS = ["sundae", pytest.param("compiled", marks=pytest.mark.slow)]


def _oscillator(m=1.0, c=100.0, d=2.0, x0=0.1, model=None):
    model = model or Model()
    model.mass = Mass(m=m, s=x0, v=0.0)
    model.spring = Spring(c=c, s_rel0=0.0)
    model.damper = Damper(d=d)
    model.ground = Fixed()
    model.connect(model.ground.flange, model.spring.flange_a)
    model.connect(model.spring.flange_b, model.mass.flange)
    model.connect(model.ground.flange, model.damper.flange_a)
    model.connect(model.damper.flange_b, model.mass.flange)
    return model


def _oscillator_exact(wrt, m=1.0, c=100.0, d=2.0, x0=0.1):
    """x(t) of m x'' + d x' + c x = 0, x(0) = x0, x'(0) = 0 (underdamped),
    and its derivative with respect to ``wrt`` (sympy, independently)."""
    t, M, C, D = sp.symbols("t M C D", positive=True)
    zw = D / (2 * M)
    wd = sp.sqrt(C / M - zw ** 2)
    x = x0 * sp.exp(-zw * t) * (sp.cos(wd * t) + zw / wd * sp.sin(wd * t))
    sym = {"mass.m": M, "spring.c": C, "damper.d": D}[wrt]
    vals = {M: m, C: c, D: d}
    return (sp.lambdify(t, x.subs(vals), "numpy"),
            sp.lambdify(t, sp.diff(x, sym).subs(vals), "numpy"))


@pytest.fixture(scope="module")
def oscillator():
    return compile_model(_oscillator())


@pytest.mark.parametrize("backend", BACKENDS)
def test_damped_oscillator_closed_form(oscillator, backend):
    names = ["spring.c", "damper.d", "mass.m"]
    res = oscillator.simulate(t_end=0.6, rtol=1e-11, atol=1e-14, output_step=1e-2,
                              sensitivities=names, backend=backend)
    if compiled_available() is None:
        assert res.stats["backend"] == backend
    x, _ = _oscillator_exact("spring.c")
    assert np.max(np.abs(res["mass.s"] - x(res.t))) < 1e-10
    for name in names:
        _, dx = _oscillator_exact(name)
        exact = dx(res.t)
        err = np.max(np.abs(res.sensitivity("mass.s", name) - exact)) / np.max(np.abs(exact))
        assert err < 1e-8, (name, err)
    # an observed variable (the spring force c*s): d/dc = s + c ds/dc
    f = res.sensitivity("spring.f", "spring.c")
    expect = -(res["mass.s"] + 100.0 * res.sensitivity("mass.s", "spring.c"))
    np.testing.assert_allclose(np.abs(f), np.abs(expect), rtol=0, atol=1e-9)


def test_sensitivity_of_a_fixed_start_parameter():
    """A start value that is a parameter: d x / d x0 = x(t) / x0 from t = 0
    (the initial sensitivity comes from the initial equations)."""
    model = Model()
    x0 = model.parameter("x0", 0.1, "m", "initial position")
    cm = compile_model(_oscillator(x0=x0, model=model))
    res = cm.simulate(t_end=0.5, rtol=1e-10, atol=1e-13, sensitivities=["x0"])
    s = res.sensitivity("mass.s", "x0")
    assert s[0] == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(s, res["mass.s"] / 0.1, rtol=0, atol=1e-8)


def _hertz(delta_tol=0.0):
    model = Model()
    model.mass = Mass(m=0.1, s=-1e-4, v=1.0)
    model.wall = Fixed(s0=0.0)
    model.contact = Contact(K=1e9, gamma=1.5, e=1.0, gap=0.0, delta_tol=delta_tol)
    model.connect(model.mass.flange, model.contact.flange_a)
    model.connect(model.contact.flange_b, model.wall.flange)
    return compile_model(model)


@pytest.mark.parametrize("backend", BACKENDS)
def test_hertz_contact_period_closed_form(backend):
    """dT/dK = -(2/5) T/K and dT/dm = (2/5) T/m through the onset and the
    release events (their times move with K and m)."""
    cm = _hertz()
    res = cm.simulate(t_end=5e-4, rtol=1e-10, atol=1e-14, output_step=1e-5,
                      sensitivities=["contact.K", "mass.m"], backend=backend)
    names = [n for _, n in res.events]
    on, off = names.index("contact.onset"), names.index("contact.release")
    T = res.events[off][0] - res.events[on][0]
    assert T == pytest.approx(0.321807e-3, rel=1e-5)
    for p, value, power in [("contact.K", 1e9, -0.4), ("mass.m", 0.1, 0.4)]:
        e = res.event_sensitivity(p)
        assert e[on] == pytest.approx(0.0, abs=1e-12 * T / value)   # free flight to the wall
        dT = e[off] - e[on]
        assert dT == pytest.approx(power * T / value, rel=1e-8), p
    # the same through the measure (a function of the result reading the
    # discrete values the contact's actions record at its events)
    dT = res.measure_sensitivity(lambda r: contact_period(r, "contact"), "contact.K")
    assert dT == pytest.approx(-0.4 * T / 1e9, rel=1e-8)
    assert res.sensitivity("contact.t_release", "contact.K")[-1] == pytest.approx(dT, rel=1e-8)
    # after the impact the mass leaves at -v0 whatever K: d v / dK = 0, and its
    # position lags by v0 * dT/dK
    v = res.sensitivity("mass.v", "contact.K")
    assert abs(v[-1]) < 1e-8 * 1.0 / 1e9
    s = res.sensitivity("mass.s", "contact.K")
    assert s[-1] == pytest.approx(1.0 * (-0.4) * T / 1e9, rel=1e-6)


def _bouncing():
    """A mass pushed against a damped Hertz contact: it bounces, each impact
    moving with every parameter (the impact velocity, a discrete value the
    law uses, too)."""
    model = Model()
    model.mass = Mass(m=0.1, s=-2e-3, v=0.0)
    model.push = Force(f=20.0)
    model.wall = Fixed(s0=0.0)
    model.contact = Contact(K=1e8, gamma=1.5, e=0.7, gap=0.0)
    model.connect(model.push.flange, model.mass.flange)
    model.connect(model.mass.flange, model.contact.flange_a)
    model.connect(model.contact.flange_b, model.wall.flange)
    return compile_model(model)


def _five_point(runs, get, h):
    """The five-point central difference (error O(h^4)) of ``get(run)`` from
    runs at p0 - 2h, p0 - h, p0 + h, p0 + 2h."""
    v = {k: np.asarray(get(r), float) for k, r in runs.items()}
    return (v[-2] - 8 * v[-1] + 8 * v[1] - v[2]) / (12 * h)


@pytest.mark.slow
def test_bouncing_contact_against_central_differences():
    """Event times and the trajectory over several impacts against five-point
    central differences (step 1e-3 of each parameter, rtol 1e-11). Measured:
    event times within 1.3e-6 of the largest (K) and 1e-7 (the others), the
    positions at the output times within 1.5e-6 (K) to 1.1e-5 (e: a grid
    time near an impact makes the differences' own truncation error larger)."""
    cm = _bouncing()
    names = ["contact.K", "contact.e", "push.f_const", "mass.m"]
    grid = np.linspace(0.0, 0.03, 31)
    kw = dict(t_end=0.03, rtol=1e-11, atol=1e-15, output_times=grid)
    res = cm.simulate(sensitivities=names, **kw)
    events = [n for _, n in res.events]
    assert events.count("contact.onset") >= 4
    inner = grid[1:-1]
    for name in names:
        p0 = float(cm.param_vector()[cm.param_index(name)])
        h = 1e-3 * p0
        runs = {k: cm.simulate(params={name: p0 + k * h}, **kw) for k in (-2, -1, 1, 2)}
        assert all([n for _, n in r.events] == events for r in runs.values())
        fd = _five_point(runs, lambda r: r.event_times(), h)
        err = np.max(np.abs(res.event_sensitivity(name) - fd)) / np.max(np.abs(fd))
        assert err < 3e-6, (name, err)
        fdx = _five_point(runs, lambda r: np.interp(inner, r.t, r["mass.s"]), h)
        sx = np.interp(inner, res.t, res.sensitivity("mass.s", name))
        assert np.max(np.abs(sx - fdx)) / np.max(np.abs(fdx)) < 2e-5, name


@pytest.mark.slow
def test_breaker_event_times_against_central_differences():
    """The breaker (models/breaker_24kv.py): the times of the contact's
    onset, force peak and release and of the hook's release (THRT) move
    with the contact stiffness and the hook parameter; measured agreement
    with five-point differences (step 3e-3): 1e-8 to 5e-8, 3e-6 for the
    hook release against K (which moves it by 1e-5 s per unit log K, so the
    differences' noise dominates)."""
    import os

    from acausal.modelfile import compile_file
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    mf, cm = compile_file(os.path.join(root, "models", "breaker_24kv.py"))
    opts = dict(mf.experiment.run_options(), rtol=1e-11, atol=1e-14)
    names = ["contact.K", "hook.bh"]
    res = cm.simulate(sensitivities=names, **opts)
    events = [n for _, n in res.events]
    for name in names:
        p0 = float(cm.param_vector()[cm.param_index(name)])
        h = 3e-3 * p0
        runs = {k: cm.simulate(params={name: p0 + k * h}, **opts) for k in (-2, -1, 1, 2)}
        assert all([n for _, n in r.events] == events for r in runs.values())
        fd = _five_point(runs, lambda r: r.event_times(), h)
        got = res.event_sensitivity(name)
        for k, ev in enumerate(events):
            if ev == "contact.onset":   # the free flight to the contact: no K, bh
                assert abs(got[k]) < 1e-9 * max(np.max(np.abs(fd)), 1e-300)
                continue
            assert got[k] == pytest.approx(fd[k], rel=1e-5), (name, ev)


def _smooth():
    """Two masses, a spring-damper between them and a driven nonlinear force:
    smooth, with algebraic unknowns."""
    model = Model()
    k3 = model.parameter("k3", 4.0e4, "N/m^3", "cubic stiffness")
    model.m1 = Mass(m=1.0, s=0.05, v=0.0)
    model.m2 = Mass(m=0.5, s=0.0, v=0.2)
    model.spring = Spring(c=200.0, s_rel0=0.0)
    model.damper = Damper(d=1.5)
    model.ground = Fixed()
    model.cubic = Force(f=lambda s: -k3 * s ** 3)
    model.drive = Force(f=3.0 * sp.sin(7.0 * time))
    model.connect(model.ground.flange, model.spring.flange_a)
    model.connect(model.spring.flange_b, model.m1.flange)
    model.connect(model.m1.flange, model.damper.flange_a)
    model.connect(model.damper.flange_b, model.m2.flange)
    model.connect(model.cubic.flange, model.m2.flange)
    model.connect(model.drive.flange, model.m1.flange)
    return compile_model(model)


@pytest.mark.slow
def test_smooth_model_against_central_differences():
    cm = _smooth()
    names = ["k3", "spring.c", "damper.d", "m2.m"]
    kw = dict(t_end=1.0, rtol=1e-12, atol=1e-15, output_step=0.05)
    res = cm.simulate(sensitivities=names, **kw)
    for name in names:
        p0 = float(cm.param_vector()[cm.param_index(name)])
        # the five-point central difference (error O(h^4)) with h = 5e-4 of the
        # parameter: its truncation error is then far below 1e-6, its noise
        # (the runs' global error / h) about 3e-7; a three-point one is above
        # 1e-6 from truncation at h = 1e-3 and from noise at h = 1e-4
        h = 5e-4 * p0
        runs = {k: cm.simulate(params={name: p0 + k * h}, **kw) for k in (-2, -1, 1, 2)}
        for var in ("m1.s", "m2.v", "damper.f"):
            fd = (runs[-2][var] - 8 * runs[-1][var] + 8 * runs[1][var] - runs[2][var]) / (12 * h)
            err = np.max(np.abs(res.sensitivity(var, name) - fd)) / np.max(np.abs(fd))
            assert err < 1e-6, (name, var, err)


@pytest.mark.slow
def test_backends_agree_on_sensitivities():
    cm = _bouncing()
    names = ["contact.K", "contact.e"]
    kw = dict(t_end=0.02, rtol=1e-10, atol=1e-14, output_times=np.linspace(0, 0.02, 21))
    a = cm.simulate(sensitivities=names, backend="sundae", **kw)
    b = cm.simulate(sensitivities=names, backend="compiled", **kw)
    if compiled_available() is None:
        assert b.stats["backend"] == "compiled", b.stats
    assert [n for _, n in a.events] == [n for _, n in b.events]
    for name in names:
        ea, eb = a.event_sensitivity(name), b.event_sensitivity(name)
        assert np.max(np.abs(ea - eb)) <= 1e-5 * np.max(np.abs(ea))
        sa = a.sensitivity("mass.s", name)[np.isin(a.t, kw["output_times"])]
        sb = b.sensitivity("mass.s", name)[np.isin(b.t, kw["output_times"])]
        assert np.max(np.abs(sa - sb)) <= 1e-5 * np.max(np.abs(sa))


def test_asking_for_what_was_not_computed(oscillator):
    res = oscillator.simulate(t_end=0.01, sensitivities=["spring.c"])
    with pytest.raises(UsageError, match="damper.d"):
        res.sensitivity("mass.s", "damper.d")
    with pytest.raises(ParameterError, match="no parameter 'spring.k'"):
        oscillator.simulate(t_end=0.01, sensitivities=["spring.k"])
    plain = oscillator.simulate(t_end=0.01)
    with pytest.raises(UsageError, match="sensitivities="):
        plain.sensitivity("mass.s", "spring.c")
    # the same trajectory within the tolerance (the error test of a sensitivity
    # run also covers the sensitivities, so it takes other steps)
    np.testing.assert_allclose(plain["mass.s"], res["mass.s"], rtol=0, atol=20 * 1e-6 * 0.1)


@pytest.mark.slow
def test_hertz_exponent_sensitivity_against_central_differences():
    """d/d gamma takes PosPow's derivative in its exponent, x^g log x, which
    must not evaluate log x out of contact (x <= 0): the generated code
    computes shared sub-expressions ahead of the branches."""
    cm = _hertz()
    kw = dict(t_end=5e-4, rtol=1e-11, atol=1e-15)
    res = cm.simulate(sensitivities=["contact.gamma"], **kw)
    h = 1e-4 * 1.5
    a = cm.simulate(params={"contact.gamma": 1.5 + h}, **kw)
    b = cm.simulate(params={"contact.gamma": 1.5 - h}, **kw)
    fd = (np.array(a.event_times()) - np.array(b.event_times())) / (2 * h)
    got = res.event_sensitivity("contact.gamma")
    assert np.max(np.abs(got - fd)) < 1e-6 * np.max(np.abs(fd))


@pytest.mark.slow
def test_compiled_callbacks_of_a_sensitivity_model_match_its_python_ones():
    """The compiled backend serves a sensitivity run's callbacks from C, the
    observed variables' sensitivities included: the same values as the
    generated Python at an arbitrary point (in contact, so the impact law's
    discrete values and their sensitivities are used)."""
    if compiled_available() is not None:
        pytest.skip(compiled_available())
    from acausal.runtime.backends.compiled import CompiledSolver
    from acausal.runtime.sensitivity import sensitivity_model
    cm = _bouncing()
    sm = sensitivity_model(cm, ["contact.K", "contact.e"])
    p = cm.param_vector({})
    rng = np.random.default_rng(4)
    d = list(rng.uniform(0.1, 1.0, len(sm.disc_syms)))
    N = len(sm.dae.y)
    y, yp = rng.normal(size=N) * 1e-3, rng.normal(size=N)
    solver = CompiledSolver(sm, p, dict(rtol=1e-6, atol=1e-8, max_num_steps=500))
    c, py = solver.serve(sm, p, d), sm.callbacks(p, d)
    assert c[4] is not py[4]                      # observe runs in C
    assert len(c[4](0.0, y, yp)) == sm.n_observed == 3 * len(cm.var_names)
    np.testing.assert_allclose(c[4](0.0, y, yp), py[4](0.0, y, yp), rtol=1e-12, atol=1e-300)
    rc, rp = np.zeros(N), np.zeros(N)
    c[0](0.0, y, yp, rc)
    py[0](0.0, y, yp, rp)
    np.testing.assert_allclose(rc, rp, rtol=1e-12, atol=1e-300)


class _QuadraticDrag(PartialCompliantWithRelativeStates):
    """f = c v_rel |v_rel| (tension positive): a drag whose Jacobian holds
    sign(v_rel) and whose sensitivity equations its derivative."""

    c = Parameter(0.0, "N*s^2/m^2", "drag coefficient", min=0.0)

    def equations(self):
        return [Eq(self.f, self.c * self.v_rel * sp.Abs(self.v_rel))]


def test_quadratic_drag_closed_form():
    """m v' = -c v |v| from v0 > 0: v = v0 / (1 + a t), s = ln(1 + a t) m / c
    with a = c v0 / m, differentiated by sympy here. The sensitivity
    equations hold d sign(v)/dv (zero where it has a value); sympy's own
    derivative of it is not printable, and no sensitivity of a quadratic
    drag could be generated."""
    model = Model()
    model.mass = Mass(m=0.5, s=0.0, v=3.0)
    model.drag = _QuadraticDrag(c=0.8)
    model.ground = Fixed()
    model.connect(model.ground.flange, model.drag.flange_a)
    model.connect(model.drag.flange_b, model.mass.flange)
    cm = compile_model(model)
    res = cm.simulate(t_end=1.0, rtol=1e-11, atol=1e-14, output_step=0.05,
                      sensitivities=["drag.c", "mass.m"])
    t, M, C = sp.symbols("t M C", positive=True)
    a = C * 3.0 / M
    exact = {"mass.v": 3.0 / (1 + a * t), "mass.s": sp.log(1 + a * t) * M / C}
    exact["drag.f"] = C * exact["mass.v"] ** 2
    for var, e in exact.items():
        for name, sym in (("drag.c", C), ("mass.m", M)):
            want = sp.lambdify(t, sp.diff(e, sym).subs({M: 0.5, C: 0.8}), "numpy")(res.t)
            got = res.sensitivity(var, name)
            assert np.max(np.abs(got - want)) < 1e-7 * np.max(np.abs(want)), (var, name)


def test_observed_sensitivities_by_column_equal_the_per_row_table():
    """A sensitivity of one observed variable is computed alone, over all
    rows of each mode at once (a fit's Jacobian reads one or two); the
    bouncing contact (modes, discrete values that move with the parameters):
    every variable's against the per-row table of all of them."""
    cm = _bouncing()
    names = ["contact.K", "contact.e"]
    kw = dict(t_end=0.02, rtol=1e-10, atol=1e-14, sensitivities=names)
    res = cm.simulate(**kw)
    table = cm.simulate(**kw).sensitivities.observed()    # another run: its own table
    assert len({n for _, n in res.events}) > 1 and res.d.shape[1] > 0
    for j, name in enumerate(names):
        for k, var in enumerate(cm.var_names):
            want = table[:, j, k]
            np.testing.assert_allclose(res.sensitivity(var, name), want, rtol=1e-12,
                                       atol=1e-12 * np.max(np.abs(want)), err_msg=var)
    assert res.sensitivities._obs is None      # never the whole table
