"""Circle against circle and circle against a polyline profile: closed forms
(touch time, the rebound off a tilted segment, Hertz contact duration,
energy and angular momentum without damping) and an independent scipy
solution of a ball under the nearest-point Hertz force, computed by brute
force over the polyline's segments and vertices."""
import math

import numpy as np
import pytest
from scipy.integrate import quad, solve_ivp

from acausal import Model, compile_model
from acausal.errors import ParameterError
from acausal.mechanics.planar.contact import CircleCircleContact
from acausal.mechanics.planar.parts import Body, Fixed
from acausal.mechanics.planar.polyline import CirclePolylineContact, Profile

M, R, K, G = 0.1, 0.01, 1e9, 9.81
TOL = dict(rtol=1e-11, atol=1e-13)


def hertz_duration(v, m=M, k=K):
    """Contact duration of a Hertz impact (F = k delta^1.5) at speed v:
    2 delta_max / v * int_0^1 dx / sqrt(1 - x^2.5), delta_max =
    (5 m v^2 / 4 k)^0.4."""
    dmax = (5 * m * v**2 / (4 * k)) ** 0.4
    return 2 * dmax / v * quad(lambda x: 1 / math.sqrt(1 - x**2.5), 0, 1)[0]


def nearest_point(c, pts):
    """Brute force: the nearest point of the polyline ``pts`` to ``c``."""
    best = None
    for p, q in zip(pts[:-1], pts[1:]):
        d = q - p
        u = min(max(np.dot(c - p, d) / np.dot(d, d), 0.0), 1.0)
        x = p + u * d
        if best is None or np.linalg.norm(c - x) < np.linalg.norm(c - best):
            best = x
    return best


def ball_reference(c0, v0, nearest, g, t_end, ts):
    """A point mass of radius R under gravity g and the Hertz force
    K delta^1.5 from the nearest point ``nearest(c)`` of a profile, with
    scipy (DOP853), restarted at each touch and separation. The steps are
    bounded (``max_step``, a tenth of the time a ball at 1 m/s takes to
    cross its radius): in free flight the right-hand side is exact for any
    step, and scipy 1.17's DOP853 stepped over a whole passage of the ball
    through the profile, where the gap falls below 0 and rises again within
    one step, so no touch was found and the reference fell through."""
    def rhs(t, z):
        c = z[:2]
        r = c - nearest(c)
        d = np.linalg.norm(r)
        f = K * max(R - d, 0.0) ** 1.5 / M
        return [z[2], z[3], f * r[0] / d, f * r[1] / d - g]

    def gap(t, z):
        return np.linalg.norm(z[:2] - nearest(z[:2])) - R

    gap.terminal = True
    gap.direction = -1 if gap(0.0, np.r_[c0, v0]) > 0 else 1
    z, t, out_t, out_z, events = np.r_[c0, v0], 0.0, [ts[:1]], [np.r_[c0, v0][None]], []
    while t < t_end:
        sol = solve_ivp(rhs, [t, t_end], z, method="DOP853", rtol=1e-12, atol=1e-15,
                        t_eval=ts[(ts > t) & (ts <= t_end)], events=gap, max_step=0.1 * R)
        out_t.append(sol.t)
        out_z.append(sol.y.T)
        if sol.status != 1:
            break
        t, z = sol.t_events[0][0], sol.y_events[0][0]
        events.append(t)
        gap.direction = -gap.direction          # touch, then separation, then touch...
    return np.concatenate(out_t), np.concatenate(out_z), events


def drop_model(contact, frame=(0.0, 0.0, 0.0), g=G, c0=(0.0, 0.05), v0=(0.0, 0.0)):
    m = Model()
    m.ground = Fixed(x0=frame[0], y0=frame[1], phi0=frame[2])
    m.ball = Body(m=M, I=0.4 * M * R**2, g=g, x=c0[0], y=c0[1], vx=v0[0], vy=v0[1],
                  phi=0.0, w=0.0)
    m.c = contact
    m.connect(m.ground.frame, m.c.frame_a)
    m.connect(m.c.frame_b, m.ball.frame)
    return m


def energy(res, g=G):
    """Kinetic, gravity and Hertz elastic energy (K delta^2.5 / 2.5) [J]."""
    return (0.5 * M * (res["ball.vx"]**2 + res["ball.vy"]**2) + M * g * res["ball.y"]
            + 0.5 * 0.4 * M * R**2 * res["ball.w"]**2
            + K * np.maximum(res["c.delta"], 0.0)**2.5 / 2.5)


# -- circle against circle -----------------------------------------------------------
def test_ball_scatters_off_a_circle_as_a_central_force():
    """A ball (no gravity) passes a fixed circle Ra at impact parameter b:
    the Hertz force is central, so energy and the angular momentum about the
    circle's centre are conserved; the path matches scipy's; the touch is at
    the closed-form time; a head-on impact lasts the Hertz duration."""
    Ra, v, b, x0 = 0.02, 1.0, 0.015, -0.05
    cx, cy = 0.3, -0.2                                # circle centre (px offset on a turned frame)
    model = drop_model(CircleCircleContact(R=R, Ra=Ra, px=0.1, py=0.0, K=K, e=1.0,
                                           peak_event=False),
                       frame=(cx - 0.1 * math.cos(0.4), cy - 0.1 * math.sin(0.4), 0.4), g=0.0,
                       c0=(cx + x0, cy + b), v0=(v, 0.0))
    cm = compile_model(model)
    ts = np.linspace(0, 0.08, 801)
    res = cm.simulate(t_end=0.08, output_times=ts, **TOL)
    names = [nm for _, nm in res.events]
    assert names == ["c.onset", "c.release"]
    # onset: delta through -delta_tol (1e-12 m, PartialContact), i.e. d = R + Ra + 1e-12
    t_touch = (-x0 - math.sqrt((R + Ra + 1e-12)**2 - b**2)) / v
    assert abs(res.events[0][0] - t_touch) < 1e-13
    rx, ry = res["ball.x"] - cx, res["ball.y"] - cy
    Lz = M * (rx * res["ball.vy"] - ry * res["ball.vx"])
    assert np.max(np.abs(Lz - Lz[0])) < 1e-12 * M
    E = energy(res, 0.0)
    assert np.max(np.abs(E / E[0] - 1)) < 1e-9
    assert np.max(np.abs(res["ball.w"])) < 1e-12                    # no friction: no spin
    i = np.searchsorted(res.t, ts)
    _, ref, _ = ball_reference(np.r_[x0, b], np.r_[v, 0.0],
                               lambda c: Ra * c / np.linalg.norm(c), 0.0, 0.08, ts)
    assert np.max(np.abs(rx[i] - ref[:, 0])) < 1e-9
    assert np.max(np.abs(ry[i] - ref[:, 1])) < 1e-9
    # head-on: the contact lasts the Hertz duration and gives back the speed
    head = cm.simulate(t_end=0.08, params={"ball.y": cy}, **TOL)
    (t1, _), (t2, _) = head.events[:2]
    assert abs((t2 - t1) / hertz_duration(v) - 1) < 1e-8
    assert abs(head["ball.vx"][-1] + v) < 1e-9


# -- circle against a polyline ----------------------------------------------------------
def rot(phi, v):
    c, s = math.cos(phi), math.sin(phi)
    return np.array([c * v[0] - s * v[1], s * v[0] + c * v[1]])


def test_profile_refuses_bad_points_and_finds_the_nearest_feature():
    with pytest.raises(ParameterError, match="segment 1 has zero length"):
        CirclePolylineContact(points=((0, 0), (1, 0), (1, 0)))
    with pytest.raises(ParameterError, match="turns back on itself at vertex 1"):
        CirclePolylineContact(points=((0, 0), (1, 0), (0.5, 0)))
    with pytest.raises(ParameterError, match="at least two"):
        CirclePolylineContact(points=((0, 0),))
    pr = Profile(((0, 0), (1, 0), (2, -1), (3, 0)))    # convex at 1, concave at 2
    assert pr.convex == [False, True, False, False]
    assert pr.nearest(0.5, 0.3) == 1                    # segment 0
    assert pr.nearest(1.05, 0.3) == 2                   # vertex 1 (between the normals)
    assert pr.nearest(-0.2, 0.1) == 0                   # vertex 0 (the end)
    assert pr.nearest(2.0, -0.5) in (3, 5)              # on the bisector of the V
    assert pr.nearest(1.9, -0.5) == 3 and pr.nearest(2.1, -0.5) == 5


@pytest.mark.slow
def test_ball_bounces_on_a_tilted_polyline_segment():
    """A ball dropped (frictionless, e = 1) above the middle, tilted segment
    of a polyline on a turned, shifted frame: along the segment it slides
    freely, s = s0 + g sin(a) t^2 / 2, through the impacts; it touches at
    t1 = sqrt(2 (h0 - R) / (g cos a)), the contact lasts as the 1-D Hertz
    impact with the normal part of gravity (scipy), the normal speed is given
    back and the next touch is 2 t1 after the release."""
    frame, tilt = (0.2, -0.1, -0.3), 0.5          # the segment's world angle is -tilt
    local = [(-0.1, 0.03), (-0.05, 0.0), (-0.05 + 0.1 * math.cos(0.2), -0.1 * math.sin(0.2)),
             (0.2, -0.1)]
    P1 = np.r_[frame[:2]] + rot(frame[2], local[1])
    t_hat = rot(-tilt, (1.0, 0.0))
    n_hat = rot(-tilt, (0.0, 1.0))
    s0, h0 = 0.01, R + 0.01
    c0 = P1 + s0 * t_hat + h0 * n_hat
    model = drop_model(CirclePolylineContact(R=R, K=K, e=1.0, points=local, peak_event=False),
                       frame=frame, c0=tuple(c0))
    ts = np.linspace(0, 0.16, 1601)
    res = compile_model(model).simulate(t_end=0.16, output_times=ts, **TOL)
    ev = [(t, nm) for t, nm in res.events if nm in ("c.onset", "c.release")]
    assert [nm for _, nm in ev] == ["c.onset", "c.release"] * 2
    assert set(res["c.feature"]) == {3.0}                      # segment 1 throughout
    gn, gt = G * math.cos(tilt), G * math.sin(tilt)
    rel = np.column_stack([res["ball.x"], res["ball.y"]]) - P1
    assert np.max(np.abs(rel @ t_hat - (s0 + 0.5 * gt * res.t**2))) < 1e-9
    t1 = math.sqrt(2 * (h0 - R - 1e-12) / gn)                  # onset at delta = -1e-12 m
    assert abs(ev[0][0] - t1) < 1e-12
    vn = gn * t1

    def normal(t, z):
        return [z[1], -gn + K * max(-z[0], 0.0)**1.5 / M]
    out = solve_ivp(normal, [0, 1e-3], [0.0, -vn], method="DOP853", rtol=1e-13, atol=1e-18,
                    events=lambda t, z: z[0] if t > 0 else -1.0)
    tau = out.t_events[0][0]
    assert abs((ev[1][0] - ev[0][0]) / tau - 1) < 1e-7
    assert abs(tau / hertz_duration(vn) - 1) < 5e-3           # gravity barely matters
    assert abs(ev[2][0] - ev[1][0] - 2 * t1) < 1e-9
    E = energy(res)
    assert np.max(np.abs(E / E[0] - 1)) < 1e-9


@pytest.mark.slow
def test_ball_rolls_off_polyline_vertices_as_scipy_nearest_point_reference():
    """A ball dropped next to the apex of a roof-shaped polyline (on a turned
    frame) hits the convex vertex, flies to the next flank and bounces on
    (frictionless, e = 1): the path matches scipy's solution with the
    nearest point found by brute force, and energy is kept."""
    frame = (0.05, 0.02, 0.15)
    local = [(-0.15, -0.06), (-0.05, 0.0), (0.0, 0.02), (0.06, -0.01), (0.15, -0.08)]
    pts = [np.r_[frame[:2]] + rot(frame[2], p) for p in local]
    c0 = pts[2] + np.r_[0.004, 0.03]
    model = drop_model(CirclePolylineContact(R=R, K=K, e=1.0, points=local, peak_event=False),
                       frame=frame, c0=tuple(c0))
    ts = np.linspace(0, 0.25, 2501)
    res = compile_model(model).simulate(t_end=0.25, output_times=ts, **TOL)
    tr, z, touches = ball_reference(c0, np.zeros(2), lambda c: nearest_point(c, pts), G, 0.25,
                                    ts)
    assert np.array_equal(tr, ts)
    i = np.searchsorted(res.t, ts)
    err = np.hypot(res["ball.x"][i] - z[:, 0], res["ball.y"][i] - z[:, 1])
    assert np.max(err) < 1e-7
    assert len(touches) >= 4                              # two impacts at least
    feats = set(res["c.feature"])
    assert 4.0 in feats and len(feats) >= 3          # vertex 2 (the apex) and flanks met
    E = energy(res)
    assert np.max(np.abs(E / E[0] - 1)) < 1e-9


@pytest.mark.slow
def test_polyline_on_a_free_body_keeps_momentum_with_friction_and_damping():
    """A ball (spinning) strikes a polyline attached to a free, turned body
    (no gravity), with Coulomb friction and Hunt-Crossley damping: the force
    and its moment act on both bodies at the same contact point, so linear
    momentum and angular momentum about the origin are kept exactly, while
    the energy drops."""
    m2, I2 = 0.5, 2e-3
    model = Model()
    model.plate = Body(m=m2, I=I2, x=0.0, y=0.0, phi=0.3, vx=0.1, vy=0.0, w=0.5)
    model.ball = Body(m=M, I=0.4 * M * R**2, x=0.01, y=0.05, phi=0.0, vx=-0.2, vy=-2.0,
                      w=30.0)
    model.c = CirclePolylineContact(R=R, K=K, e=0.6, law="hunt_crossley", mu=0.3,
                                    v_reg=1e-3, peak_event=False,
                                    points=((-0.06, 0.0), (-0.01, 0.005), (0.03, 0.0),
                                            (0.06, -0.02)))
    model.connect(model.plate.frame, model.c.frame_a)
    model.connect(model.c.frame_b, model.ball.frame)
    res = compile_model(model).simulate(t_end=0.05, output_step=1e-4, **TOL)
    assert "c.onset" in [nm for _, nm in res.events]
    p = np.column_stack([M * res["ball.vx"] + m2 * res["plate.vx"],
                         M * res["ball.vy"] + m2 * res["plate.vy"]])
    assert np.max(np.abs(p - p[0])) < 1e-10
    L = (M * (res["ball.x"] * res["ball.vy"] - res["ball.y"] * res["ball.vx"])
         + 0.4 * M * R**2 * res["ball.w"]
         + m2 * (res["plate.x"] * res["plate.vy"] - res["plate.y"] * res["plate.vx"])
         + I2 * res["plate.w"])
    assert np.max(np.abs(L - L[0])) < 1e-11
    E = (0.5 * M * (res["ball.vx"]**2 + res["ball.vy"]**2) + 0.2 * M * R**2 * res["ball.w"]**2
         + 0.5 * m2 * (res["plate.vx"]**2 + res["plate.vy"]**2) + 0.5 * I2 * res["plate.w"]**2)
    assert E[-1] < 0.9 * E[0]                     # damping and friction took energy
    assert abs(res["ball.w"][-1] - 30.0) > 1.0    # friction changed the spin
