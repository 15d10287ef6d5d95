"""acausal.mechanics.rotational against closed forms (IDA at rtol 1e-10).

Each tolerance is a few times the error measured with the law as written."""
import numpy as np
import pytest
import sympy as sp

from acausal import Model, ParameterError, compile_model, time
from acausal.mechanics.rotational import (AccSensor, Angle, AngleSensor, Damper, Fixed, Inertia,
                                   RelAngleSensor, RelSpeedSensor, RotationalDamper,
                                   SpeedSensor, Spring, SpringDamper, Torque, TorqueSensor,
                                   TorsionSpring, RelativeTorque)

TOL = dict(rtol=1e-10, atol=1e-12)
REL = 1e-7   # IDA at rtol 1e-10: measured <= 3e-8 relative to the amplitude


def run(model, t_end=1.0, params=None, step=1e-2):
    return compile_model(model).simulate(t_end=t_end, output_step=step, params=params, **TOL)


def maxerr(res, name, exact):
    """Largest error over the run relative to the largest |exact| value."""
    exact = np.broadcast_to(exact, res.t.shape)
    return float(np.max(np.abs(res[name] - exact)) / np.max(np.abs(exact)))


def test_aliases_are_the_same_classes():
    assert Spring is TorsionSpring and Damper is RotationalDamper


def test_inertia_spring_harmonic():
    J, c, p0, w0 = 0.02, 8.0, 0.3, -1.0
    model = Model()
    model.ground = Fixed(phi0=0.1)
    model.spring = TorsionSpring(c=c, phi_rel0=0.0)
    model.body = Inertia(J=J, phi=0.1 + p0, w=w0)
    model.connect(model.ground.flange, model.spring.flange_a)
    model.connect(model.spring.flange_b, model.body.flange)
    res = run(model)
    w = np.sqrt(c / J)
    t = res.t
    assert maxerr(res, "body.phi", 0.1 + p0 * np.cos(w * t) + w0 / w * np.sin(w * t)) < REL
    assert maxerr(res, "body.w", -p0 * w * np.sin(w * t) + w0 * np.cos(w * t)) < REL
    assert maxerr(res, "spring.tau", c * (res["body.phi"] - 0.1)) < 1e-12


def test_rotational_damper_decay():
    J, d, w0 = 0.5, 2.0, 3.0
    model = Model()
    model.ground = Fixed()
    model.damper = RotationalDamper(d=d)
    model.body = Inertia(J=J, phi=0.0, w=w0)
    model.connect(model.ground.flange, model.damper.flange_a)
    model.connect(model.damper.flange_b, model.body.flange)
    res = run(model)
    t = res.t
    assert maxerr(res, "body.w", w0 * np.exp(-d * t / J)) < REL
    assert maxerr(res, "body.phi", w0 * J / d * (1 - np.exp(-d * t / J))) < REL


@pytest.mark.parametrize("combined", [False, True])
def test_damped_torsional_oscillator(combined):
    J, c, d, x0, v0 = 0.1, 40.0, 0.3, 0.2, 1.0
    model = Model()
    model.ground = Fixed()
    model.body = Inertia(J=J, phi=x0, w=v0)
    if combined:
        model.sd = SpringDamper(c=c, d=d)
        model.connect(model.ground.flange, model.sd.flange_a)
        model.connect(model.sd.flange_b, model.body.flange)
    else:
        model.spring = TorsionSpring(c=c)
        model.damper = RotationalDamper(d=d)
        model.connect(model.ground.flange, model.spring.flange_a, model.damper.flange_a)
        model.connect(model.spring.flange_b, model.damper.flange_b, model.body.flange)
    res = run(model)
    a = d / (2 * J)
    wd = np.sqrt(c / J - a * a)
    t = res.t
    exact = np.exp(-a * t) * (x0 * np.cos(wd * t) + (v0 + a * x0) / wd * np.sin(wd * t))
    assert maxerr(res, "body.phi", exact) < REL


@pytest.mark.parametrize("combined", [False, True])
def test_torsion_spring_preload_equilibrium(combined):
    """Installed angle P with installed torque T0 and an external torque T:
    equilibrium phi_eq = P + (T - T0)/c."""
    J, c, P, T0, T, p0 = 0.01, 50.0, 0.5, 20.0, 5.0, 0.0
    model = Model()
    model.ground = Fixed()
    if combined:
        model.spring = SpringDamper(c=c, phi_rel0=P, tau0=T0)
    else:
        model.spring = TorsionSpring(c=c, phi_rel0=P, tau0=T0)
    model.body = Inertia(J=J, phi=p0, w=0.0)
    model.motor = Torque(tau=T)
    model.connect(model.ground.flange, model.spring.flange_a)
    model.connect(model.spring.flange_b, model.body.flange, model.motor.flange)
    res = run(model, t_end=0.3, step=1e-3)
    phi_eq = P + (T - T0) / c
    assert phi_eq == pytest.approx(0.2)
    w = np.sqrt(c / J)
    assert maxerr(res, "body.phi", phi_eq + (p0 - phi_eq) * np.cos(w * res.t)) < REL
    assert res["spring.tau"][0] == pytest.approx(c * (p0 - P) + T0, rel=1e-12)


def test_torque_of_time():
    J, T0, W = 0.2, 3.0, 5.0
    model = Model()
    model.body = Inertia(J=J, phi=0.0, w=0.0)
    model.motor = Torque(tau=T0 * sp.cos(W * time))
    model.connect(model.body.flange, model.motor.flange)
    res = run(model)
    t = res.t
    assert maxerr(res, "body.w", T0 / (J * W) * np.sin(W * t)) < REL
    assert maxerr(res, "body.phi", T0 / (J * W * W) * (1 - np.cos(W * t))) < REL
    assert maxerr(res, "motor.tau", T0 * np.cos(W * t)) < 1e-12


def test_torque_of_angle_and_speed():
    """tau = k0*(g0 - phi) - d0*w: damped oscillation about g0."""
    J, k0, g0, d0, p0 = 0.05, 20.0, 0.4, 0.1, 0.0
    model = Model()
    model.body = Inertia(J=J, phi=p0, w=0.0)
    model.motor = Torque(tau=lambda phi, w: k0 * (g0 - phi) - d0 * w)
    model.connect(model.body.flange, model.motor.flange)
    res = run(model)
    a = d0 / (2 * J)
    wd = np.sqrt(k0 / J - a * a)
    t = res.t
    x0 = p0 - g0
    exact = g0 + np.exp(-a * t) * (x0 * np.cos(wd * t) + a * x0 / wd * np.sin(wd * t))
    assert maxerr(res, "body.phi", exact) < REL


def test_torque_of_angle_only():
    J, k0, g0 = 0.05, 20.0, 0.4
    model = Model()
    model.body = Inertia(J=J, phi=0.0, w=0.0)
    model.motor = Torque(tau=lambda phi: k0 * (g0 - phi))
    model.connect(model.body.flange, model.motor.flange)
    res = run(model)
    assert maxerr(res, "body.phi", g0 * (1 - np.cos(np.sqrt(k0 / J) * res.t))) < REL


def test_torque_constant_is_a_runtime_parameter():
    model = Model()
    model.body = Inertia(J=0.5, phi=0.0, w=0.0)
    model.motor = Torque(tau=1.0)
    model.connect(model.body.flange, model.motor.flange)
    res = compile_model(model).simulate(t_end=1.0, params={"motor.tau_const": -3.0}, **TOL)
    assert res.final()["body.w"] == pytest.approx(-6.0, rel=1e-9)


def test_angle_source_and_sensors():
    """A shaft driven at phi = A sin(W t) twists a spring to an inertia;
    the sensors read angle, speed, acceleration, relative motion and the
    transmitted torque (MSL's sign)."""
    J, c, A, W = 0.01, 4.0, 0.2, 9.0
    model = Model()
    model.drive = Angle(phi=A * sp.sin(W * time))
    model.ts = TorqueSensor()
    model.spring = TorsionSpring(c=c)
    model.body = Inertia(J=J, phi=0.0, w=0.0)
    model.ang = AngleSensor()
    model.spd = SpeedSensor()
    model.acc = AccSensor()
    model.rel = RelAngleSensor()
    model.relw = RelSpeedSensor()
    model.connect(model.drive.flange, model.ts.flange_a, model.rel.flange_a,
                  model.relw.flange_a)
    model.connect(model.ts.flange_b, model.spring.flange_a)
    model.connect(model.spring.flange_b, model.body.flange, model.ang.flange, model.spd.flange,
                  model.acc.flange, model.rel.flange_b, model.relw.flange_b)
    res = run(model, step=1e-3)
    w = np.sqrt(c / J)
    t = res.t
    phi = A * w**2 / (w**2 - W**2) * (np.sin(W * t) - W / w * np.sin(w * t))
    dphi = A * w**2 / (w**2 - W**2) * W * (np.cos(W * t) - np.cos(w * t))
    drive = A * np.sin(W * t)
    assert maxerr(res, "body.phi", phi) < REL
    assert maxerr(res, "ang.phi", phi) < REL
    assert maxerr(res, "spd.w", dphi) < REL
    assert maxerr(res, "acc.a", c / J * (drive - phi)) < REL
    assert maxerr(res, "rel.phi_rel", phi - drive) < REL
    assert maxerr(res, "relw.w_rel", dphi - A * W * np.cos(W * t)) < REL
    # MSL's sign (tau = flange_a.tau): the opposite of the spring's torque
    assert maxerr(res, "ts.tau", -c * (phi - drive)) < REL
    assert maxerr(res, "ts.tau", -res["spring.tau"]) < 1e-12


def test_validation_names_the_parameter():
    with pytest.raises(ParameterError, match=r"Inertia\.J = -0\.1 \[kg\*m\^2\] must be > 0"):
        Inertia(J=-0.1)
    with pytest.raises(ParameterError, match=r"TorsionSpring\.c = -1 .* must be >= 0"):
        TorsionSpring(c=-1.0)
    with pytest.raises(ParameterError, match=r"RotationalDamper\.d = -1 .* must be >= 0"):
        RotationalDamper(d=-1.0)
    with pytest.raises(ParameterError, match=r"Torque\.tau must be a number, a sympy "
                                             r"expression or a function of the flange angle"):
        Torque(tau=[1.0])
    with pytest.raises(ParameterError, match=r"Angle\.phi must be"):
        Angle(phi=None)


def test_relative_torque_cubic_against_solve_ivp():
    """J phi'' = -c phi - k3 phi^3 - d2 w|w|: linear torsion spring, a
    RelativeTorque cubic spring and a RelativeTorque quadratic damper."""
    from scipy.integrate import solve_ivp
    J, c, k3, d2, p0 = 0.01, 5.0, 300.0, 0.002, 0.4
    model = Model()
    model.ground = Fixed()
    model.spring = TorsionSpring(c=c)
    model.cubic = RelativeTorque(tau=lambda p: k3 * p ** 3)
    model.drag = RelativeTorque(tau=lambda p, w: d2 * w * sp.Abs(w))
    model.body = Inertia(J=J, phi=p0, w=0.0)
    model.connect(model.ground.flange, model.spring.flange_a, model.cubic.flange_a,
                  model.drag.flange_a)
    model.connect(model.body.flange, model.spring.flange_b, model.cubic.flange_b,
                  model.drag.flange_b)
    res = run(model, t_end=0.5, step=1e-3)
    ref = solve_ivp(lambda t, y: [y[1], -(c * y[0] + k3 * y[0] ** 3 + d2 * y[1] * abs(y[1])) / J],
                    (0, 0.5), [p0, 0.0], t_eval=res.t, rtol=1e-12, atol=1e-14,
                    method="DOP853")
    assert maxerr(res, "body.phi", ref.y[0]) < REL
    assert np.allclose(res["cubic.tau"], k3 * res["body.phi"] ** 3, rtol=1e-12, atol=1e-9)
