"""Circle-against-line contact from geometry: the normal law against the
1-D Contact of acausal.mechanics.contact (same law, independent
kinematics), and Coulomb friction against the sliding-to-rolling closed
form of a disc."""
import numpy as np
import pytest

from acausal import Model, compile_model
from acausal.mechanics import translational as tr
from acausal.mechanics.contact import Contact
from acausal.mechanics.planar.contact import CircleLineContact
from acausal.mechanics.planar.parts import Body, Fixed

M, R, K, G = 0.1, 0.01, 1e7, 9.81


def test_disc_dropped_on_an_inclined_line_bounces_as_the_1d_contact():
    """A disc falls (no gravity: a set velocity) onto a line turned by 30 deg
    whose point is offset in the line's axes; along the normal it is the 1-D
    contact of a mass on a wall; along the tangent nothing happens (mu = 0)."""
    a, e, vn = np.radians(30.0), 0.8, 1.0
    n = np.array([-np.sin(a), np.cos(a)])
    t = np.array([np.cos(a), np.sin(a)])
    base = np.array([0.2, -0.1])
    p = base + 0.05 * t                         # the line's point px = 0.05 in its axes
    h0, v_t = R + 1e-3, 0.3
    c0 = p + h0 * n
    m = Model()
    m.ground = Fixed(x0=base[0], y0=base[1], phi0=a)
    m.disc = Body(m=M, I=0.5 * M * R**2, x=c0[0], y=c0[1], vx=-vn * n[0] + v_t * t[0],
                  vy=-vn * n[1] + v_t * t[1], phi=0.0, w=0.0)
    m.c = CircleLineContact(R=R, px=0.05, K=K, e=e, peak_event=False)
    m.connect(m.ground.frame, m.c.frame_a)
    m.connect(m.c.frame_b, m.disc.frame)
    ts = np.linspace(0, 0.006, 601)
    res = compile_model(m).simulate(t_end=0.006, rtol=1e-10, atol=1e-12, output_times=ts)
    r = Model()
    r.m = tr.Mass(m=M, s=h0, v=-vn)
    r.c = Contact(K=K, e=e, gap=R, peak_event=False)
    r.w = tr.Fixed()
    r.connect(r.w.flange, r.c.flange_a)
    r.connect(r.c.flange_b, r.m.flange)
    ref = compile_model(r).simulate(t_end=0.006, rtol=1e-10, atol=1e-12, output_times=ts)
    i, j = np.searchsorted(res.t, ts), np.searchsorted(ref.t, ts)   # the output times
    assert np.array_equal(res.t[i], ts) and np.array_equal(ref.t[j], ts)
    xy = np.column_stack([res["disc.x"][i], res["disc.y"][i]]) - p
    assert np.max(np.abs(xy @ n - ref["m.s"][j])) < 1e-9
    assert np.max(np.abs(xy @ t - v_t * ts)) < 1e-9
    names = [nm for _, nm in res.events]
    assert names[:2] == ["c.onset", "c.release"]
    for (t1, _), (t2, _) in zip(res.events[:2], ref.events[:2]):
        assert abs(t1 - t2) < 1e-9
    assert np.max(np.abs(res["disc.w"])) < 1e-12             # no friction: no spin
    assert 0.5 < ref["m.v"][-1] / vn < 1.0                   # it bounced off


@pytest.mark.slow
def test_sliding_disc_rolls_with_coulomb_friction():
    """A disc put down sliding at v0 without spin: friction mu m g slows it
    and spins it up until it rolls at v0 / (1 + I / (m R^2))."""
    mu, v0 = 0.3, 0.5
    Ic = 0.4 * M * R**2
    d_eq = (M * G / K) ** (1 / 1.5)            # resting indentation (Hertz)
    m = Model()
    m.ground = Fixed()
    m.disc = Body(m=M, I=Ic, g=G, x=0.0, y=R - d_eq, vx=v0, vy=0.0, phi=0.0, w=0.0)
    m.c = CircleLineContact(R=R, K=K, e=0.5, mu=mu, peak_event=False)
    m.connect(m.ground.frame, m.c.frame_a)
    m.connect(m.c.frame_b, m.disc.frame)
    res = compile_model(m).simulate(t_end=0.1, rtol=1e-9, atol=1e-12, output_step=1e-4)
    t_roll = v0 / (mu * G * (1 + M * R**2 / Ic))
    k = np.searchsorted(res.t, t_roll / 2)
    assert abs(res["disc.vx"][k] - (v0 - mu * G * res.t[k])) < 1e-6
    assert abs(res["disc.w"][k] + mu * M * G * R / Ic * res.t[k]) < 1e-4
    assert abs(res["disc.vx"][-1] - v0 / (1 + Ic / (M * R**2))) < 1e-6
    assert abs(res["disc.vx"][-1] + R * res["disc.w"][-1]) < 1e-6      # rolling
    assert [nm for _, nm in res.events] == ["c.onset"]                  # stays in contact
