"""Planar components, each against a closed form or an independent scipy
solution of its own equations of motion (written here from first
principles, not from the components)."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from acausal import Model, compile_model
from acausal.mechanics import rotational as rot
from acausal.mechanics import translational as tr
from acausal.mechanics.planar.forces import SpringDamper
from acausal.mechanics.planar.joints import Prismatic, Revolute
from acausal.mechanics.planar.parts import Body, Fixed, FixedTranslation

TOL = dict(rtol=1e-10, atol=1e-12)


@pytest.mark.slow
def test_body_free_flight_and_spin():
    """Projectile under gravity and a constant spin: closed form."""
    m = Model()
    m.b = Body(m=0.3, I=0.02, g=9.81, x=0.5, y=1.0, vx=2.0, vy=3.0, phi=0.1, w=-4.0)
    m.ground = Fixed()                     # a model needs no connection to the ground
    m.link = SpringDamper(c=0.0, d=0.0, s0=0.0)
    m.connect(m.ground.frame, m.link.frame_a)
    m.connect(m.link.frame_b, m.b.frame)
    res = compile_model(m).simulate(t_end=1.0, output_step=0.01, **TOL)
    t = res.t
    assert np.max(np.abs(res["b.x"] - (0.5 + 2.0 * t))) < 1e-9
    assert np.max(np.abs(res["b.y"] - (1.0 + 3.0 * t - 0.5 * 9.81 * t**2))) < 1e-9
    assert np.max(np.abs(res["b.phi"] - (0.1 - 4.0 * t))) < 1e-9


@pytest.mark.slow
def test_line_spring_damper_against_scipy():
    """A body on a spring-damper to a fixed point, in 2-D with gravity."""
    mass, c, d, s0, g, x0, y0 = 0.4, 30.0, 0.5, 0.2, 9.81, 0.15, -0.25
    px, py = 0.05, 0.1                                  # the fixed point
    m = Model()
    m.top = Fixed(x0=px, y0=py)
    m.sd = SpringDamper(c=c, d=d, s0=s0)
    m.b = Body(m=mass, I=1e-3, g=g, x=x0, y=y0, vx=0.5, vy=0.0, phi=0.0, w=0.0)
    m.connect(m.top.frame, m.sd.frame_a)
    m.connect(m.sd.frame_b, m.b.frame)
    ts = np.linspace(0, 2.0, 201)
    res = compile_model(m).simulate(t_end=2.0, output_times=ts, **TOL)

    def rhs(t, z):
        x, y, vx, vy = z
        rx, ry = x - px, y - py
        s = np.hypot(rx, ry)
        sd = (rx * vx + ry * vy) / s
        f = c * (s - s0) + d * sd                        # tension
        return [vx, vy, -f * rx / s / mass, -f * ry / s / mass - g]

    ref = solve_ivp(rhs, [0, 2.0], [x0, y0, 0.5, 0.0], t_eval=ts, rtol=1e-12, atol=1e-14,
                    method="DOP853")
    assert np.max(np.abs(res["b.x"] - ref.y[0])) < 1e-8
    assert np.max(np.abs(res["b.y"] - ref.y[1])) < 1e-8
    assert np.max(np.abs(res["sd.s"] - np.hypot(ref.y[0] - px, ref.y[1] - py))) < 1e-8
    assert np.ptp(res["sd.s"]) > 0.05                    # it does stretch and swing


def test_revolute_with_torsion_spring_and_offset_body_against_scipy():
    """A physical pendulum: pin at (0.1, 0.2), body centre at L along the
    rod, torsion spring on the pin's axis, gravity:
    (I + m L^2) th'' = -c (th - th0) - m g L cos(th)."""
    mass, Ic, L, c, th0, g = 1.5, 0.02, 0.3, 4.0, 0.4, 9.81
    m = Model()
    m.ground = Fixed(x0=0.1, y0=0.2)
    m.pin = Revolute(phi=1.0, w=0.0)
    m.rod = FixedTranslation(rx=L, ry=0.0)
    m.b = Body(m=mass, I=Ic, g=g)
    m.spring = rot.TorsionSpring(c=c, phi_rel0=th0)
    m.support = rot.Fixed()
    m.connect(m.ground.frame, m.pin.frame_a)
    m.connect(m.pin.frame_b, m.rod.frame_a)
    m.connect(m.rod.frame_b, m.b.frame)
    m.connect(m.support.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.pin.axis)
    ts = np.linspace(0, 3.0, 301)
    res = compile_model(m).simulate(t_end=3.0, output_times=ts, **TOL)
    J = Ic + mass * L**2
    ref = solve_ivp(lambda t, z: [z[1], (-c * (z[0] - th0) - mass * g * L * np.cos(z[0])) / J],
                    [0, 3.0], [1.0, 0.0], t_eval=ts, rtol=1e-12, atol=1e-14, method="DOP853")
    th = res["pin.phi"]
    assert np.max(np.abs(th - ref.y[0])) < 1e-8
    assert np.ptp(th) > 1.0
    assert np.max(np.abs(res["b.x"] - (0.1 + L * np.cos(th)))) < 1e-10
    assert np.max(np.abs(res["b.y"] - (0.2 + L * np.sin(th)))) < 1e-10
    # the pin carries the spring torque between the frames: frame_b gets -tau
    assert np.max(np.abs(res["pin.frame_b.tau"] - c * (th - th0))) < 1e-7


def test_prismatic_on_an_inclined_frame_with_spring():
    """A slider on a 30 deg incline (frame_a turned by the fixed frame),
    spring on the joint axis, gravity: m s'' = -c s - m g sin(30 deg)."""
    a, mass, c, g, s0 = np.radians(30.0), 0.8, 20.0, 9.81, 0.05
    m = Model()
    m.ground = Fixed(x0=1.0, y0=0.5, phi0=a)
    m.slide = Prismatic(ex=1.0, ey=0.0, s=s0, v=0.0)
    m.b = Body(m=mass, I=0.01, g=g)
    m.spring = tr.Spring(c=c)
    m.wall = tr.Fixed()
    m.connect(m.ground.frame, m.slide.frame_a)
    m.connect(m.slide.frame_b, m.b.frame)
    m.connect(m.wall.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.slide.axis)
    res = compile_model(m).simulate(t_end=1.5, output_step=0.01, **TOL)
    t = res.t
    s_eq = -mass * g * np.sin(a) / c
    s = s_eq + (s0 - s_eq) * np.cos(np.sqrt(c / mass) * t)
    assert np.max(np.abs(res["slide.s"] - s)) < 1e-8
    assert np.max(np.abs(res["b.x"] - (1.0 + s * np.cos(a)))) < 1e-8
    assert np.max(np.abs(res["b.y"] - (0.5 + s * np.sin(a)))) < 1e-8
    assert np.max(np.abs(res["b.phi"] - a)) < 1e-12
    # the guide holds the body against gravity across the axis: it pushes the
    # body with m g cos(a) along the normal, so the body pushes the joint's
    # frame_b (force into the joint) with minus that
    nx, ny = -np.sin(a), np.cos(a)
    fn = res["slide.frame_b.fx"] * nx + res["slide.frame_b.fy"] * ny
    assert np.max(np.abs(fn + mass * g * np.cos(a))) < 1e-7


@pytest.mark.slow
def test_prismatic_end_stop_on_its_axis_equals_the_1d_mass_on_a_stop():
    """An end stop is the 1-D EndStop on the joint's axis flange: a slider on
    a 45 deg guide hits it exactly as a 1-D mass hits the same stop."""
    from acausal.mechanics.contact import EndStop
    a, mass = np.radians(45.0), 0.3
    stop = dict(s_limit=0.05, side="upper", K=1e8, e=0.7, peak_event=False)
    m = Model()
    m.ground = Fixed(phi0=a)
    m.slide = Prismatic(s=0.0, v=2.0)
    m.b = Body(m=mass, I=0.01)
    m.stop = EndStop(**stop)
    m.connect(m.ground.frame, m.slide.frame_a)
    m.connect(m.slide.frame_b, m.b.frame)
    m.connect(m.slide.axis, m.stop.flange)
    r = Model()
    r.m = tr.Mass(m=mass, s=0.0, v=2.0)
    r.stop = EndStop(**stop)
    r.connect(r.m.flange, r.stop.flange)
    ts = np.linspace(0, 0.06, 301)
    res = compile_model(m).simulate(t_end=0.06, output_times=ts, **TOL)
    ref = compile_model(r).simulate(t_end=0.06, output_times=ts, **TOL)
    i, j = np.searchsorted(res.t, ts), np.searchsorted(ref.t, ts)
    assert np.max(np.abs(res["slide.s"][i] - ref["m.s"][j])) < 1e-9
    assert np.max(np.abs(res["b.x"][i] - np.cos(a) * ref["m.s"][j])) < 1e-9
    assert res["slide.v"][-1] < -1.0                                   # it bounced back
    assert abs(res["slide.v"][-1] - ref["m.v"][-1]) < 1e-8
    # the joints' start-up bookkeeping (decide_drives at t = 0) is not an event
    assert not any(n.endswith("decide_drives") for _, n in res.events)
    assert [n for _, n in res.events if n.startswith("stop.")][:2] == \
        ["stop.onset", "stop.release"]
