"""acausal.mechanics.translational against closed forms (IDA at rtol 1e-10).

Each tolerance is a few times the error measured with the law as written;
changing a law (sign, factor, preload) breaks the test by orders of
magnitude more."""
import numpy as np
import pytest
import sympy as sp

from acausal import Model, ParameterError, compile_model, time
from acausal.mechanics.translational import (AccSensor, Damper, Fixed, Force, ForceSensor, Mass,
                                      RelativeForce,
                                      Position, PositionSensor, RelPositionSensor,
                                      RelSpeedSensor, SpeedSensor, Spring, SpringDamper)

TOL = dict(rtol=1e-10, atol=1e-12)
REL = 1e-7   # IDA at rtol 1e-10: measured <= 3e-8 relative to the amplitude


def run(model, t_end=1.0, params=None, step=1e-2):
    return compile_model(model).simulate(t_end=t_end, output_step=step, params=params, **TOL)


def maxerr(res, name, exact):
    """Largest error over the run relative to the largest |exact| value."""
    exact = np.broadcast_to(exact, res.t.shape)
    return float(np.max(np.abs(res[name] - exact)) / np.max(np.abs(exact)))


def oscillator(m=2.0, c=200.0, s0=0.1, v0=0.5):
    model = Model()
    model.ground = Fixed()
    model.spring = Spring(c=c)
    model.mass = Mass(m=m, s=s0, v=v0)
    model.connect(model.ground.flange, model.spring.flange_a)
    model.connect(model.spring.flange_b, model.mass.flange)
    return model


def test_mass_spring_harmonic():
    m, c, s0, v0 = 2.0, 200.0, 0.1, 0.5
    res = run(oscillator(m, c, s0, v0))
    w = np.sqrt(c / m)
    t = res.t
    assert maxerr(res, "mass.s", s0 * np.cos(w * t) + v0 / w * np.sin(w * t)) < REL
    assert maxerr(res, "mass.v", -s0 * w * np.sin(w * t) + v0 * np.cos(w * t)) < REL
    # tension positive: the stretched spring pulls the mass back
    assert maxerr(res, "spring.f", c * res["mass.s"]) < REL
    assert maxerr(res, "mass.flange.f", -c * res["mass.s"]) < REL


def test_fixed_position_offsets_the_spring():
    model = oscillator(m=1.0, c=100.0, s0=0.35, v0=0.0)
    model.ground.set(s0=0.25)
    res = run(model)
    assert maxerr(res, "mass.s", 0.25 + 0.1 * np.cos(10 * res.t)) < REL


def test_damper_exponential_decay():
    m, d, v0, s0 = 2.0, 3.0, 1.5, 0.2
    model = Model()
    model.ground = Fixed()
    model.damper = Damper(d=d)
    model.mass = Mass(m=m, s=s0, v=v0)
    model.connect(model.ground.flange, model.damper.flange_a)
    model.connect(model.damper.flange_b, model.mass.flange)
    res = run(model, t_end=2.0)
    t = res.t
    assert maxerr(res, "mass.v", v0 * np.exp(-d * t / m)) < REL
    assert maxerr(res, "mass.s", s0 + v0 * m / d * (1 - np.exp(-d * t / m))) < REL
    assert maxerr(res, "damper.f", d * res["mass.v"]) < REL


def _damped_closed_form(t, m, c, d, x0, v0):
    a = d / (2 * m)
    wd = np.sqrt(c / m - a * a)
    x = np.exp(-a * t) * (x0 * np.cos(wd * t) + (v0 + a * x0) / wd * np.sin(wd * t))
    return x


@pytest.mark.parametrize("combined", [False, True])
def test_damped_oscillator(combined):
    m, c, d, x0, v0 = 1.5, 300.0, 4.0, 0.05, -0.3
    model = Model()
    model.ground = Fixed()
    model.mass = Mass(m=m, s=x0, v=v0)
    if combined:
        model.sd = SpringDamper(c=c, d=d)
        model.connect(model.ground.flange, model.sd.flange_a)
        model.connect(model.sd.flange_b, model.mass.flange)
    else:
        model.spring = Spring(c=c)
        model.damper = Damper(d=d)
        model.connect(model.ground.flange, model.spring.flange_a, model.damper.flange_a)
        model.connect(model.spring.flange_b, model.damper.flange_b, model.mass.flange)
    res = run(model, t_end=1.0)
    assert maxerr(res, "mass.s", _damped_closed_form(res.t, m, c, d, x0, v0)) < REL


@pytest.mark.parametrize("combined", [False, True])
def test_spring_preload_equilibrium(combined):
    """Installed length L with installed force F0 (tension +) and an
    external force Fext: equilibrium s_eq = L + (Fext - F0)/c, oscillation
    about it at sqrt(c/m)."""
    m, c, L, F0, Fext, s0 = 0.5, 2000.0, 0.15, -300.0, 100.0, 0.3
    model = Model()
    model.ground = Fixed()
    if combined:
        model.spring = SpringDamper(c=c, s_rel0=L, f0=F0, d=0.0)
    else:
        model.spring = Spring(c=c, s_rel0=L, f0=F0)
    model.mass = Mass(m=m, s=s0, v=0.0)
    model.push = Force(f=Fext)
    model.connect(model.ground.flange, model.spring.flange_a)
    model.connect(model.spring.flange_b, model.mass.flange, model.push.flange)
    res = run(model, t_end=0.3, step=1e-3)
    s_eq = L + (Fext - F0) / c
    assert s_eq == pytest.approx(0.35)
    w = np.sqrt(c / m)
    assert maxerr(res, "mass.s", s_eq + (s0 - s_eq) * np.cos(w * res.t)) < REL
    assert res["spring.f"][0] == pytest.approx(c * (s0 - L) + F0, rel=1e-12)
    # a compression spring installed pushing with 300 N: free length L + 300/c
    assert res["spring.f"][0] == pytest.approx(c * (s0 - (L - F0 / c)), rel=1e-12)


def test_force_of_time():
    m, F0, W = 2.0, 30.0, 7.0
    model = Model()
    model.mass = Mass(m=m, s=0.0, v=0.0)
    model.force = Force(f=F0 * sp.sin(W * time))
    model.connect(model.mass.flange, model.force.flange)
    res = run(model, t_end=1.0)
    t = res.t
    assert maxerr(res, "mass.v", F0 / (m * W) * (1 - np.cos(W * t))) < REL
    assert maxerr(res, "mass.s", F0 / (m * W) * (t - np.sin(W * t) / W)) < REL
    assert maxerr(res, "force.f", F0 * np.sin(W * t)) < 1e-12
    assert maxerr(res, "force.flange.f", -F0 * np.sin(W * t)) < 1e-12


@pytest.mark.parametrize("kind", ["lambda", "sympy.Lambda"])
def test_force_of_position_harmonic(kind):
    """F = k0*(g0 - s): harmonic about g0 at sqrt(k0/m)."""
    m, k0, g0, s0 = 0.8, 500.0, 0.02, 0.07
    x = sp.Symbol("x")
    law = (lambda s: k0 * (g0 - s)) if kind == "lambda" else sp.Lambda(x, k0 * (g0 - x))
    model = Model()
    model.mass = Mass(m=m, s=s0, v=0.0)
    model.sol = Force(f=law)
    model.connect(model.mass.flange, model.sol.flange)
    res = run(model, t_end=0.5, step=1e-3)
    w = np.sqrt(k0 / m)
    assert maxerr(res, "mass.s", g0 + (s0 - g0) * np.cos(w * res.t)) < REL
    assert maxerr(res, "sol.f", k0 * (g0 - res["mass.s"])) < REL


def test_force_of_position_and_velocity():
    """F = -d0*v: v = v0 exp(-d0 t/m)."""
    m, d0, v0 = 2.0, 5.0, 1.0
    model = Model()
    model.mass = Mass(m=m, s=0.0, v=v0)
    model.brake = Force(f=lambda s, v: -d0 * v)
    model.connect(model.mass.flange, model.brake.flange)
    res = run(model)
    assert maxerr(res, "mass.v", v0 * np.exp(-d0 * res.t / m)) < REL


def test_force_constant_is_a_runtime_parameter():
    model = Model()
    model.mass = Mass(m=2.0, s=0.0, v=0.0)
    model.force = Force(f=3.0)
    model.connect(model.mass.flange, model.force.flange)
    cm = compile_model(model)
    assert "force.f_const" in [p.name for p in cm.params]
    for F in (3.0, -8.0):
        res = cm.simulate(t_end=1.0, params={"force.f_const": F}, **TOL)
        assert res.final()["mass.s"] == pytest.approx(F / 2.0 / 2.0, rel=1e-9)
        assert res.final()["force.f"] == pytest.approx(F, rel=1e-12)
    # an expression law has no f_const
    model2 = Model()
    model2.mass = Mass(m=1.0)
    model2.force = Force(f=2 * time)
    model2.connect(model2.mass.flange, model2.force.flange)
    assert "force.f_const" not in [p.name for p in compile_model(model2).params]


def test_force_expression_with_model_parameter():
    model = Model()
    F = model.parameter("F", 4.0, "N/s", "rate of the push")
    model.mass = Mass(m=1.0, s=0.0, v=0.0)
    model.force = Force(f=F * time)
    model.connect(model.mass.flange, model.force.flange)
    cm = compile_model(model)
    res = cm.simulate(t_end=1.0, params={"F": 6.0}, **TOL)
    assert res.final()["mass.s"] == pytest.approx(6.0 / 6.0, rel=1e-9)


def test_position_source_through_spring():
    """Support moved as A sin(W t), mass on a spring: forced response; a
    force sensor between the support and the spring reads the spring force."""
    m, c, A, W = 1.0, 400.0, 0.01, 7.0
    model = Model()
    model.drive = Position(s=A * sp.sin(W * time))
    model.sensor = ForceSensor()
    model.spring = Spring(c=c)
    model.mass = Mass(m=m, s=0.0, v=0.0)
    model.connect(model.drive.flange, model.sensor.flange_a)
    model.connect(model.sensor.flange_b, model.spring.flange_a)
    model.connect(model.spring.flange_b, model.mass.flange)
    res = run(model, t_end=1.0, step=1e-3)
    w = np.sqrt(c / m)
    t = res.t
    exact = A * w**2 / (w**2 - W**2) * (np.sin(W * t) - W / w * np.sin(w * t))
    assert maxerr(res, "mass.s", exact) < REL
    assert maxerr(res, "drive.s", A * np.sin(W * t)) < 1e-12
    # MSL's sign: the force on the sensor at flange_a, -spring.f in series
    assert maxerr(res, "sensor.f", -c * (exact - A * np.sin(W * t))) < REL
    assert maxerr(res, "sensor.f", -res["spring.f"]) < REL


def test_sensors_read_the_right_values():
    m, c, s0, v0 = 2.0, 200.0, 0.1, 0.5
    model = Model()
    model.ground = Fixed()
    model.spring = Spring(c=c)
    model.mass = Mass(m=m, s=s0, v=v0)
    model.ps = PositionSensor()
    model.vs = SpeedSensor()
    model.acc = AccSensor()
    model.rel = RelPositionSensor()
    model.relv = RelSpeedSensor()
    model.fs = ForceSensor()
    model.anchor = Fixed(s0=-0.5)
    # the force sensor sits in series between the spring and the mass
    model.connect(model.ground.flange, model.spring.flange_a)
    model.connect(model.spring.flange_b, model.fs.flange_a)
    model.connect(model.fs.flange_b, model.mass.flange, model.ps.flange, model.vs.flange,
                  model.acc.flange, model.rel.flange_b, model.relv.flange_b)
    model.connect(model.anchor.flange, model.rel.flange_a, model.relv.flange_a)
    res = run(model)
    w = np.sqrt(c / m)
    t = res.t
    s = s0 * np.cos(w * t) + v0 / w * np.sin(w * t)
    v = -s0 * w * np.sin(w * t) + v0 * np.cos(w * t)
    assert maxerr(res, "mass.s", s) < REL          # the sensors take no force
    assert maxerr(res, "ps.s", s) < REL
    assert maxerr(res, "vs.v", v) < REL
    assert maxerr(res, "acc.a", -w * w * s) < REL
    assert maxerr(res, "rel.s_rel", s + 0.5) < REL
    assert maxerr(res, "relv.v_rel", v) < REL
    # MSL's sign (f = flange_a.f): the opposite of the spring's force
    assert maxerr(res, "fs.f", -c * s) < REL
    assert maxerr(res, "fs.f", -res["spring.f"]) < REL


# -- validation ------------------------------------------------------------------
def test_negative_mass_is_rejected_with_the_parameter_name():
    with pytest.raises(ParameterError, match=r"Mass\.m = -1 \[kg\] must be > 0"):
        Mass(m=-1.0)
    with pytest.raises(ParameterError, match=r"Mass\.m = 0 .* must be > 0"):
        Mass(m=0)
    cm = compile_model(oscillator())
    with pytest.raises(ParameterError, match=r"mass\.m = -2"):
        cm.simulate(t_end=0.1, params={"mass.m": -2.0})


@pytest.mark.parametrize("cls, name", [(Spring, "c"), (Damper, "d"), (SpringDamper, "c"),
                                       (SpringDamper, "d")])
def test_negative_stiffness_or_damping_is_rejected(cls, name):
    with pytest.raises(ParameterError, match=rf"{cls.__name__}\.{name} = -1 .* must be >= 0"):
        cls(**{name: -1.0})


def test_force_law_validation():
    with pytest.raises(ParameterError, match=r"Force\.f must be a number, a sympy "
                                             r"expression or a function"):
        Force(f="100 N")
    with pytest.raises(ParameterError, match=r"Force\.f"):
        Force(f=True)
    with pytest.raises(ParameterError, match=r"law must take 1 argument .* it takes 3"):
        Force(f=lambda s, v, a: s)
    with pytest.raises(ParameterError, match=r"the f law failed: ZeroDivisionError"):
        Force(f=lambda s: 1 / 0)
    with pytest.raises(ParameterError, match=r"use sympy\.Max/Min/Piecewise"):
        Force(f=lambda s: max(s, 0.0))
    with pytest.raises(ParameterError, match=r"parameter Force\.f_const = inf"):
        Force(f=float("inf"))
    with pytest.raises(ParameterError, match=r"Position\.s must be"):
        Position(s="abc")
    with pytest.raises(ParameterError, match=r"has no parameter or variable 'k'"):
        Spring(k=3.0)


def test_relative_force_cubic_spring_against_solve_ivp():
    """Duffing oscillator m x'' = -c x - k3 x^3 with the cubic term as a
    RelativeForce in parallel with a linear Spring (ground on flange_a)."""
    from scipy.integrate import solve_ivp
    m_, c, k3, x0 = 0.5, 200.0, 4.0e5, 0.03
    model = Model()
    model.ground = Fixed()
    model.spring = Spring(c=c)
    model.cubic = RelativeForce(f=lambda x: k3 * x ** 3)
    model.mass = Mass(m=m_, s=x0, v=0.0)
    model.connect(model.ground.flange, model.spring.flange_a, model.cubic.flange_a)
    model.connect(model.mass.flange, model.spring.flange_b, model.cubic.flange_b)
    res = compile_model(model).simulate(t_end=0.3, output_step=1e-3, rtol=1e-10, atol=1e-12)
    ref = solve_ivp(lambda t, y: [y[1], -(c * y[0] + k3 * y[0] ** 3) / m_], (0, 0.3),
                    [x0, 0.0], t_eval=res.t, rtol=1e-12, atol=1e-14, method="DOP853")
    assert np.max(np.abs(res["mass.s"] - ref.y[0])) / x0 < 1e-7
    # tension positive: flange_b.f = f = k3 s_rel^3 (the outside pulls b to keep it)
    assert np.allclose(res["cubic.f"], k3 * res["mass.s"] ** 3, rtol=1e-12, atol=1e-9)
    assert np.allclose(res["cubic.flange_a.f"], -res["cubic.f"], rtol=1e-12)


def test_relative_force_velocity_law_and_constant():
    """f = d2 v|v| between a mass and the ground: v = v0 / (1 + d2 v0 t / m);
    a number is the run-time parameter f_const (constant tension)."""
    model = Model()
    model.ground = Fixed()
    model.drag = RelativeForce(f=lambda x, v: 0.5 * v * sp.Abs(v))
    model.mass = Mass(m=2.0, s=0.0, v=3.0)
    model.connect(model.ground.flange, model.drag.flange_a)
    model.connect(model.drag.flange_b, model.mass.flange)
    res = compile_model(model).simulate(t_end=1.0, output_step=1e-2, rtol=1e-10, atol=1e-12)
    assert np.max(np.abs(res["mass.v"] - 3.0 / (1 + 0.75 * res.t))) < 1e-8
    model = Model()
    model.ground = Fixed()
    model.pull = RelativeForce(f=4.0)
    model.mass = Mass(m=2.0, s=0.0, v=0.0)
    model.connect(model.ground.flange, model.pull.flange_a)
    model.connect(model.pull.flange_b, model.mass.flange)
    cm = compile_model(model)
    res = cm.simulate(t_end=1.0, output_step=0.1, rtol=1e-10, atol=1e-12,
                      params={"pull.f_const": 8.0})
    assert np.max(np.abs(res["mass.s"] + 2.0 * res.t ** 2)) < 1e-9   # pulled towards a
