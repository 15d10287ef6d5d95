"""acausal.mechanics.levers: closed forms (small angle) and scipy solve_ivp
references at rtol 1e-12 of hand-derived equations (exact kinematics)."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from acausal import Model, ParameterError, compile_model
from acausal.mechanics.levers import IdealGear, IdealLever, TwoArmLever
from acausal.mechanics.rotational import Fixed as RotFixed
from acausal.mechanics.rotational import Inertia, TorsionSpring
from acausal.mechanics.translational import Fixed, Mass, Spring

TOL = dict(rtol=1e-10, atol=1e-12)
REL = 1e-7   # IDA at rtol 1e-10: measured <= 2e-8 relative to the amplitude


def run(model, t_end=1.0, params=None, step=1e-2):
    return compile_model(model).simulate(t_end=t_end, output_step=step, params=params, **TOL)


def maxerr(res, name, exact):
    """Largest error over the run relative to the largest |exact| value."""
    exact = np.broadcast_to(exact, res.t.shape)
    return float(np.max(np.abs(res[name] - exact)) / np.max(np.abs(exact)))


def lever_model(J, m, c, arm, p0, exact):
    """Inertia J on the lever shaft, a mass m at the arm's point, a spring c
    from ground to that point."""
    model = Model()
    model.body = Inertia(J=J, phi=p0, w=0.0)
    model.lever = IdealLever(arm=arm, exact=exact)
    model.slider = Mass(m=m)
    model.spring = Spring(c=c)
    model.ground = Fixed()
    model.connect(model.body.flange, model.lever.flange_r)
    model.connect(model.lever.flange_t, model.slider.flange, model.spring.flange_b)
    model.connect(model.ground.flange, model.spring.flange_a)
    return model


def test_ideal_lever_effective_inertia():
    """Small angle: J + m*arm^2 against stiffness c*arm^2."""
    J, m, c, arm, p0 = 0.01, 2.0, 5000.0, 0.05, 0.1
    res = run(lever_model(J, m, c, arm, p0, False))
    w = np.sqrt(c * arm**2 / (J + m * arm**2))
    t = res.t
    assert maxerr(res, "body.phi", p0 * np.cos(w * t)) < REL        # measured 1.3e-8
    assert maxerr(res, "slider.s", arm * p0 * np.cos(w * t)) < REL  # measured 1.3e-8
    assert maxerr(res, "slider.v", -arm * p0 * w * np.sin(w * t)) < REL
    # power conserving: tau*w + f*v = 0 through the lever
    power = res["lever.flange_r.tau"] * res["body.w"] + res["lever.flange_t.f"] * res["slider.v"]
    scale = np.max(np.abs(res["lever.flange_r.tau"] * res["body.w"]))
    assert np.max(np.abs(power)) < 1e-9 * scale


def test_ideal_lever_negative_arm():
    """A negative arm moves the point the other way; the dynamics are the same."""
    J, m, c, arm, p0 = 0.01, 2.0, 5000.0, -0.05, 0.1
    res = run(lever_model(J, m, c, arm, p0, False))
    w = np.sqrt(c * arm**2 / (J + m * arm**2))
    assert maxerr(res, "slider.s", arm * p0 * np.cos(w * res.t)) < REL


def test_ideal_lever_exact_against_solve_ivp():
    """(J + m r^2 cos^2 phi) phi'' = m r^2 cos phi sin phi w^2 - c r^2 sin phi cos phi."""
    J, m, c, r, p0 = 0.01, 2.0, 5000.0, 0.05, 0.9
    res = run(lever_model(J, m, c, r, p0, True), t_end=0.5, step=1e-3)

    def rhs(t, y):
        phi, w = y
        cs, sn = np.cos(phi), np.sin(phi)
        return [w, (m * r * r * cs * sn * w * w - c * r * r * sn * cs) / (J + m * r * r * cs * cs)]

    ref = solve_ivp(rhs, (0, 0.5), [p0, 0.0], t_eval=res.t, rtol=1e-12, atol=1e-14,
                    method="DOP853")
    assert maxerr(res, "body.phi", ref.y[0]) < REL                   # measured 1.2e-9
    assert maxerr(res, "slider.s", r * np.sin(ref.y[0])) < REL       # measured 1.3e-9
    assert maxerr(res, "body.w", ref.y[1]) < REL
    # the small-angle law would be far off at this amplitude
    w_small = np.sqrt(c * r * r / (J + m * r * r))
    assert np.max(np.abs(p0 * np.cos(w_small * res.t) - ref.y[0])) > 0.1


def test_ideal_gear_effective_inertia():
    """J1 + J2/ratio^2 on the driving side, spring c there."""
    for ratio in (3.0, -2.0):
        J1, J2, c, p0 = 0.02, 0.5, 10.0, 0.3
        model = Model()
        model.ground = RotFixed()
        model.spring = TorsionSpring(c=c)
        model.j1 = Inertia(J=J1, phi=p0, w=0.0)
        model.gear = IdealGear(ratio=ratio)
        model.j2 = Inertia(J=J2)
        model.connect(model.ground.flange, model.spring.flange_a)
        model.connect(model.spring.flange_b, model.j1.flange, model.gear.flange_a)
        model.connect(model.gear.flange_b, model.j2.flange)
        res = run(model)
        w = np.sqrt(c / (J1 + J2 / ratio**2))
        t = res.t
        assert maxerr(res, "j1.phi", p0 * np.cos(w * t)) < REL          # measured 8.3e-9
        assert maxerr(res, "j2.phi", p0 / ratio * np.cos(w * t)) < REL
        power = res["gear.flange_a.tau"] * res["j1.w"] + res["gear.flange_b.tau"] * res["j2.w"]
        assert np.max(np.abs(power)) < 1e-9 * np.max(np.abs(res["gear.flange_a.tau"]
                                                             * res["j1.w"]))


def two_arm_model(exact, s1):
    model = Model()
    model.lever = TwoArmLever(a=0.1, b=0.3, exact=exact)
    model.m1 = Mass(m=2.0, s=s1, v=0.0)
    model.m2 = Mass(m=1.0)
    model.spring = Spring(c=1000.0)
    model.ground = Fixed()
    model.connect(model.ground.flange, model.spring.flange_a)
    model.connect(model.spring.flange_b, model.m1.flange, model.lever.flange_a)
    model.connect(model.m2.flange, model.lever.flange_b)
    return model


def test_two_arm_lever_small_angle():
    res = run(two_arm_model(False, 0.01))
    w = np.sqrt(1000.0 * 0.01 / (2.0 * 0.01 + 1.0 * 0.09))
    assert maxerr(res, "lever.phi", 0.1 * np.cos(w * res.t)) < REL
    assert maxerr(res, "m2.s", 0.03 * np.cos(w * res.t)) < REL


def test_two_arm_lever_exact_against_solve_ivp():
    """M cos(phi) phi'' = M sin(phi) w^2 - c a^2 sin(phi), M = m1 a^2 + m2 b^2
    (the torque balance of the exact lever divided by cos(phi))."""
    a, b, m1, m2, c = 0.1, 0.3, 2.0, 1.0, 1000.0
    p0 = np.arcsin(0.08 / a)   # m1 starts at s = 0.08 (phi0 = 0.93 rad)
    res = run(two_arm_model(True, 0.08), t_end=0.5, step=1e-3)
    M = m1 * a * a + m2 * b * b

    def rhs(t, y):
        phi, w = y
        return [w, (M * np.sin(phi) * w * w - c * a * a * np.sin(phi)) / (M * np.cos(phi))]

    ref = solve_ivp(rhs, (0, 0.5), [p0, 0.0], t_eval=res.t, rtol=1e-12, atol=1e-14,
                    method="DOP853")
    assert maxerr(res, "lever.phi", ref.y[0]) < REL
    assert maxerr(res, "m2.s", b * np.sin(ref.y[0])) < REL


def test_validation_names_the_parameter():
    with pytest.raises(ParameterError, match=r"IdealLever\.arm = 0 \[m\] must be non-zero"):
        IdealLever(arm=0.0)
    with pytest.raises(ParameterError, match=r"IdealGear\.ratio = 0 .* must be non-zero"):
        IdealGear(ratio=0)
    with pytest.raises(ParameterError, match=r"IdealLever\.exact = 'yes' is not one of"):
        IdealLever(exact="yes")
    cm = compile_model(lever_model(0.01, 2.0, 5000.0, 0.05, 0.1, False))
    with pytest.raises(ParameterError, match=r"lever\.arm = 0 \[m\] must be non-zero"):
        cm.simulate(t_end=0.1, params={"lever.arm": 0.0})
