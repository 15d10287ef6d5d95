"""Four-bar (trigger cam and roller, report section 2.4) against the report's
closed form (eqs. 5-10, 13), the re-derived velocity ratio (eq. 16), energy
conservation and an independent Lagrange-equation solution (scipy)."""
import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

from acausal import InitializationError, Model, ParameterError, SolverError, compile_model, guess
from acausal.mechanics.fourbar import FourBar, fourbar_angles, fourbar_ratio
from acausal.mechanics.rotational import Fixed, Inertia, TorsionSpring

REPORT = dict(e=0.0002, f=0.125, r1=0.116, r2=0.036, r3=0.0533)   # Table 1
GENERIC = dict(e=0.04, f=0.1, r1=0.08, r2=0.03, r3=0.06)          # crank-rocker, large swing
LOCKING = dict(e=0.05, f=0.1, r1=0.06, r2=0.03, r3=0.05)          # d reaches r1 + r2 + r3


# -- the report's closed form, written out independently of the component ------
def closed_form(th1, g, mode=1):
    """theta2, theta3 from eqs. 5-10 and 13."""
    e, f, r1, L = g["e"], g["f"], g["r1"], g["r2"] + g["r3"]
    xd = f - e * np.cos(th1)                                          # (7)
    yd = e * np.sin(th1)                                              # (8)
    d = np.hypot(xd, yd)                                              # (5)
    phi = np.arctan2(yd, xd)                                          # (6)
    lam = np.arccos((d**2 + r1**2 - L**2) / (2 * r1 * d))             # (9)
    th3 = mode * lam - phi                                            # (10)
    th2 = np.arctan2(r1 * np.sin(th3) + e * np.sin(th1),
                     f - r1 * np.cos(th3) - e * np.cos(th1))          # (13)
    return th2, th3


def ratio16(th1, th2, th3, g):
    """Eq. 16, re-derived from eqs. 14-15: dtheta3/dtheta1."""
    return -g["e"] * np.sin(th1 + th2) / (g["r1"] * np.sin(th2 + th3))


def closure(th1, th2, th3, g):
    """Residuals of eqs. 11 and 12 [m]."""
    e, f, r1, L = g["e"], g["f"], g["r1"], g["r2"] + g["r3"]
    return (L * np.sin(th2) - r1 * np.sin(th3) - e * np.sin(th1),
            L * np.cos(th2) - f + r1 * np.cos(th3) + e * np.cos(th1))


def wrap(a):
    return (a + np.pi) % (2 * np.pi) - np.pi


def geo_params(g, **more):
    out = {f"fb.{k}": v for k, v in g.items()}
    out.update(more)
    return out


@pytest.mark.parametrize("g", [REPORT, GENERIC], ids=["report", "generic"])
@pytest.mark.parametrize("mode", [1, -1])
def test_report_equations_are_mutually_consistent(g, mode):
    th1 = np.linspace(-np.pi, np.pi, 721)
    th2, th3 = closed_form(th1, g, mode)
    # eq. 10 closes eqs. 11-12 for either sign of lambda
    assert max(np.max(np.abs(r)) for r in closure(th1, th2, th3, g)) < 1e-15
    # eq. 16 is the derivative of eq. 10
    h = 1e-5
    fd = (closed_form(th1 + h, g, mode)[1] - closed_form(th1 - h, g, mode)[1]) / (2 * h)
    k = ratio16(th1, th2, th3, g)
    assert np.max(np.abs(fd - k)) < 1e-9 * max(1.0, np.max(np.abs(k)))
    # the sign of sin(theta2 + theta3) is the assembly mode (no dead centre here)
    assert np.min(mode * np.sin(th2 + th3)) > 0.6
    # the module's helpers agree
    for a in th1[::60]:
        t2, t3 = fourbar_angles(a, mode=mode, **g)
        b2, b3 = closed_form(a, g, mode)
        assert abs(wrap(t2 - b2)) < 1e-14 and abs(wrap(t3 - b3)) < 1e-14
        assert abs(fourbar_ratio(a, mode=mode, **g) - ratio16(a, b2, b3, g)) < 1e-15


# -- free spin: an inertia on each side, lossless --------------------------------
def spin_model(mode, **fb):
    m = Model()
    m.fb = FourBar(mode=mode, **fb)
    m.hook = Inertia(J=1.0, phi=0.0, w=5.0)
    m.shaft = Inertia(J=0.5)
    m.connect(m.hook.flange, m.fb.flange_a)
    m.connect(m.shaft.flange, m.fb.flange_b)
    return m


_COMPILED = {}


def spin(mode):
    if mode not in _COMPILED:
        _COMPILED[mode] = compile_model(spin_model(mode))
    return _COMPILED[mode]


CASES = [  # geometry, J1, J2, t_end, theta1 start (= theta1_offset, hook.phi starts at 0)
    ("report", REPORT, 1e-6, 1.0, 3.0, 0.4),
    ("generic", GENERIC, 1.0, 0.5, 3.0, 2.5),
]


@pytest.mark.parametrize("mode", [1, -1])
@pytest.mark.parametrize("name, g, J1, J2, t_end, th10", CASES, ids=[c[0] for c in CASES])
def test_free_spin_matches_closed_form_and_conserves_energy(mode, name, g, J1, J2, t_end, th10):
    th30 = closed_form(th10, g, mode)[1]
    cm = spin(mode)
    res = cm.simulate(t_end=t_end, rtol=1e-11, atol=1e-12, output_step=t_end / 1000,
                      params=geo_params(g, **{"hook.J": J1, "shaft.J": J2,
                                              "fb.theta1_offset": th10,
                                              "fb.theta3_offset": th30}))
    th1, th2, th3 = res["fb.theta1"], res["fb.theta2"], res["fb.theta3"]
    w1, w3 = res["hook.w"], res["shaft.w"]
    # the input turns through more than two revolutions
    assert th1[-1] - th1[0] > 4 * np.pi
    # the offsets: the main shaft starts at 0, theta3 = flange_b.phi + offset
    assert abs(res["shaft.phi"][0]) < 1e-12
    assert np.max(np.abs(th1 - res["hook.phi"] - th10)) < 1e-12
    # theta3 against eq. 10 over the whole trajectory
    ex2, ex3 = closed_form(th1, g, mode)
    assert np.max(np.abs(wrap(th3 - ex3))) < 1e-9
    assert np.max(np.abs(wrap(th2 - ex2))) < 1e-9
    # closure (eqs. 11, 12)
    assert max(np.max(np.abs(r)) for r in closure(th1, th2, th3, g)) < 1e-10
    # velocity ratio against eq. 16, from the inertias and the component's output
    k = ratio16(th1, th2, th3, g)
    kmax = np.max(np.abs(k))
    assert np.max(np.abs(w3 / w1 - k)) < 1e-8 * kmax
    assert np.max(np.abs(res["fb.ratio"] - k)) < 1e-9 * kmax
    # swing of the main shaft (the report's e gives a tiny one)
    swing = np.ptp(th3)
    assert swing > (1.0 if name == "generic" else 3e-3)
    # massless and lossless: power balance and kinetic energy
    P = res["fb.flange_a.tau"] * w1 + res["fb.flange_b.tau"] * w3
    assert np.max(np.abs(P)) < 1e-8 * np.max(np.abs(res["fb.flange_a.tau"] * w1))
    E = 0.5 * J1 * w1**2 + 0.5 * J2 * w3**2
    assert np.max(np.abs(E / E[0] - 1)) < 1e-8
    # the coupler force gives both torques (lambda = Fc (sin theta2, cos theta2));
    # they are algebraic unknowns, solved to the Newton tolerance
    Fc, ta, tb = res["fb.Fc"], res["fb.flange_a.tau"], res["fb.flange_b.tau"]
    assert np.max(np.abs(ta + Fc * g["e"] * np.sin(th1 + th2))) < 1e-9 * np.max(np.abs(ta))
    assert np.max(np.abs(tb + Fc * g["r1"] * np.sin(th2 + th3))) < 1e-9 * np.max(np.abs(tb))


# -- a torsion spring on the main shaft vs. Lagrange's equation (scipy) ----------
def test_spring_load_against_lagrange_solution():
    g, J1, J2, c, rest, w0 = GENERIC, 2e-3, 1e-3, 0.5, 0.2, 3.0
    m = Model()
    m.fb = FourBar(**g)
    m.hook = Inertia(J=J1, phi=0.0, w=w0)
    m.shaft = Inertia(J=J2)
    m.spring = TorsionSpring(c=c, phi_rel0=rest)
    m.ground = Fixed()
    m.connect(m.hook.flange, m.fb.flange_a)
    m.connect(m.shaft.flange, m.fb.flange_b, m.spring.flange_b)
    m.connect(m.ground.flange, m.spring.flange_a)
    T = 2.0
    ts = np.linspace(0, T, 201)
    res = compile_model(m).simulate(t_end=T, rtol=1e-11, atol=1e-12, output_times=ts)
    assert np.array_equal(res.t, ts)

    # generalized coordinate q = theta1; theta3(q) from eq. 10 only, by sympy
    q = sp.Symbol("q")
    e, f, r1 = (sp.Float(g[k]) for k in ("e", "f", "r1"))
    L = sp.Float(g["r2"]) + sp.Float(g["r3"])
    xd, yd = f - e * sp.cos(q), e * sp.sin(q)
    d = sp.sqrt(xd**2 + yd**2)
    th3 = sp.acos((d**2 + r1**2 - L**2) / (2 * r1 * d)) - sp.atan2(yd, xd)
    k = sp.diff(th3, q)
    fn = sp.lambdify(q, [th3, k, sp.diff(k, q)], "math")

    def rhs(t, s):
        qq, qd = s
        t3, kk, dk = fn(qq)
        M = J1 + J2 * kk**2
        # L = 1/2 M q'^2 - 1/2 c (theta3 - rest)^2
        qdd = (-c * (t3 - rest) * kk - J2 * kk * dk * qd**2) / M
        return [qd, qdd]

    ref = solve_ivp(rhs, [0, T], [0.0, w0], t_eval=ts, rtol=1e-12, atol=1e-14,
                    method="DOP853")
    assert np.max(np.abs(res["fb.theta1"] - ref.y[0])) < 1e-8
    assert np.max(np.abs(res["hook.w"] - ref.y[1])) < 1e-7
    t3_ref = np.array([fn(a)[0] for a in ref.y[0]])
    assert np.max(np.abs(res["fb.theta3"] - t3_ref)) < 1e-8
    # the spring does work: the crank slows and speeds up, energy is kept
    w1 = res["hook.w"]
    assert np.ptp(w1) > 0.1 * w0
    E = 0.5 * J1 * w1**2 + 0.5 * J2 * res["shaft.w"]**2 \
        + 0.5 * c * (res["shaft.phi"] - rest)**2
    assert np.max(np.abs(E / E[0] - 1)) < 1e-8


# -- start angles and errors -------------------------------------------------------
def test_dead_centre_stops_the_run_naming_the_component():
    cm = spin(1)
    with pytest.raises(SolverError) as err:
        cm.simulate(t_end=2.0, rtol=1e-10, atol=1e-12,
                    params=geo_params(LOCKING, **{"shaft.J": 0.01}))
    msg = str(err.value)
    assert msg.startswith("fb: four-bar dead centre") and "sin_min" in msg
    # it stopped where mode*sin(theta2 + theta3) = sin_min (0.01), before d
    # reaches r1 + r2 + r3 = 0.14 m
    res = err.value.result
    th1 = res["fb.theta1"][-1]
    th2, th3 = closed_form(th1, LOCKING, 1)
    assert abs(np.sin(th2 + th3) - 0.01) < 1e-6
    assert 0.0 < err.value.t < 2.0


def test_start_angle_that_cannot_close_is_an_initialisation_error():
    with pytest.raises(InitializationError) as err:
        spin(1).simulate(t_end=0.1, params=geo_params(LOCKING, **{"fb.theta1_offset": np.pi}))
    assert str(err.value).startswith("fb: the four-bar cannot close")


def test_start_in_the_other_assembly_mode_is_an_initialisation_error():
    th2, th3 = closed_form(0.3, GENERIC, -1)
    m = spin_model(1, theta1_offset=0.3, theta2=guess(th2), theta3=guess(th3), **GENERIC)
    with pytest.raises(InitializationError) as err:
        compile_model(m).simulate(t_end=0.1)
    assert "fb: four-bar dead centre or wrong assembly mode" in str(err.value)


@pytest.mark.parametrize("mode", [1, -1])
@pytest.mark.parametrize("th10", [2.0, -2.5])
def test_start_given_on_the_four_bar_finds_its_assembly_mode(mode, th10):
    # the hook inertia's angle is free; the four-bar fixes theta1
    m = Model()
    m.fb = FourBar(mode=mode, theta1=th10, **GENERIC)
    m.hook = Inertia(J=1.0, w=5.0)
    m.shaft = Inertia(J=0.5)
    m.connect(m.hook.flange, m.fb.flange_a)
    m.connect(m.shaft.flange, m.fb.flange_b)
    res = compile_model(m).simulate(t_end=0.05, rtol=1e-10, atol=1e-12)
    assert abs(res["hook.phi"][0] - th10) < 1e-12
    assert abs(wrap(res["shaft.phi"][0] - closed_form(th10, GENERIC, mode)[1])) < 1e-12


def test_parameter_validation_names_the_parameter():
    with pytest.raises(ParameterError, match=r"FourBar\.e = 0"):
        FourBar(e=0.0)
    with pytest.raises(ParameterError, match=r"FourBar\.r2 = -0\.01"):
        FourBar(r2=-0.01)
    with pytest.raises(ParameterError, match=r"FourBar\.mode = 0 is not one of"):
        FourBar(mode=0)
    with pytest.raises(ParameterError, match=r"FourBar\.sin_min = 1"):
        FourBar(sin_min=1.0)
    with pytest.raises(ParameterError, match="cannot close at theta1 = 3.14159"):
        fourbar_angles(np.pi, **LOCKING)


def test_example_model_file():
    import os
    from acausal.modelfile import run_file
    path = os.path.join(os.path.dirname(__file__), "..", "..", "models", "examples", "fourbar.py")
    res, meas = run_file(path)
    ra = np.radians(5.0)
    assert res.events[-1][1] == "released" and abs(res.final()["hook.phi"] - ra) < 1e-9
    # main-shaft rotation at release: eq. 10 at Ra minus eq. 10 at the latch
    dth3 = closed_form(ra, REPORT)[1] - closed_form(0.0, REPORT)[1]
    assert abs(meas["theta3_at_release_rad"] - dth3) < 1e-12
    assert -2e-4 < dth3 < -1e-4
    assert 0.0015 < meas["max_abs_ratio"] < 0.0018
    assert meas["Fc_start_N"] > 0                    # the roller is pressed on the cam
    # energy: kinetic (hook, shaft) + spring
    c = 7.0e4 * 0.091**2 + 2.4e5 * 0.091**2
    E = 0.5 * 0.00044 * res["hook.w"]**2 + 0.5 * 0.02 * res["shaft.w"]**2 \
        + 0.5 * c * (res["shaft.phi"] + 0.035)**2
    assert np.max(np.abs(E / E[0] - 1)) < 1e-8
