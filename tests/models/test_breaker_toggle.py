"""The toggle-latch variant (models/breaker_24kv_toggle.py) against closed
forms of its linkage, independent of the planar parts: the main shaft's
angle is the two-circle assembly of the four-bar at the hook's angle; the
massless, lossless linkage passes power through, so its torque on the hook
is the main shaft's times d(theta3)/d(theta1); that torque changes sign
where the knee is straight (d(theta3)/d(theta1) = 0). And the first impact
is the base design's but for the linkage's torque on the hook during it:
the toggle resists with 7.2 N*m at the start, the base's cam with 2.1 N*m,
and 5 N*m more is 2.3 % of the contact's moment at its peak (4.1 kN at
55 mm): the peak force is up to that much higher."""
import math
import os
import sys
import warnings

import numpy as np
import pytest
from scipy.optimize import brentq

from acausal.modelfile import run_file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MODELS = os.path.join(ROOT, "models")
sys.path.insert(0, MODELS)

import breaker_24kv_toggle as bt  # noqa: E402
from acausal.mechanics.planar.deadcentre import DeadCentreWarning  # noqa: E402
from acausal.mechanics.planar.linkages import fourbar_assembly  # noqa: E402

GEO = bt.toggle_geometry()


def theta3(th1):
    return fourbar_assembly(th1, 1, **GEO)[0]


def ratio(th1, h=1e-6):
    return (theta3(th1 + h) - theta3(th1 - h)) / (2 * h)


@pytest.fixture(scope="module")
def toggle():
    """The run at the defaults, and the dead-centre warnings it gave."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res, m = run_file(os.path.join(MODELS, "breaker_24kv_toggle.py"))
    return res, m, [w for w in caught if issubclass(w.category, DeadCentreWarning)]


def test_toggle_geometry_is_straight_at_the_dead_centre():
    # l1 + l2 = |O C0| and the knee is straight (theta3 stationary) at one
    # hook angle, between the latched angle and the release angle
    th_dead = brentq(ratio, -math.radians(4.0), 0.0, xtol=1e-14)
    assert -math.radians(1.6) < th_dead < -math.radians(0.9)
    assert ratio(0.0) < 0 < ratio(-math.radians(5.0))


def test_toggle_linkage_against_its_closed_form(toggle):
    res, m, dead_centre_warnings = toggle
    # the straight knee locks the main shaft, not the hook that drives the
    # loop: no dead centre for it (acausal.mechanics.planar.deadcentre)
    assert dead_centre_warnings == []
    assert res["cam.pin_a.drives"][-1] == 1 and res["cam.pin_b.drives"][-1] == 0
    th1, th3 = res["hook.phi"], res["cam.pin_b.phi"]
    ref = np.array([theta3(a) for a in th1])
    assert np.max(np.abs(th3 - ref)) < 1e-9
    # lossless: torque on the hook side = -(main-shaft side) * d(theta3)/d(theta1)
    tau_a, tau_b = res["cam.pin_a.axis.tau"], res["cam.pin_b.axis.tau"]
    r = np.array([ratio(a) for a in th1])
    scale = np.max(np.abs(tau_b)) * np.max(np.abs(r))
    assert np.max(np.abs(tau_a + tau_b * r)) < 1e-6 * scale
    # the toggle resists the trip until the knee is straight, then drives it
    assert m["thrt"] * 1e3 == pytest.approx(1.483, abs=2e-3)   # docs/breaker_variants.md
    tq = bt.toggle_torque(res)
    assert tq[0] > 5.0 and tq[-1] < -20.0
    k = np.flatnonzero(np.diff(np.sign(tq)))[0]
    th_cross = np.interp(0.0, [tq[k + 1], tq[k]], [th1[k + 1], th1[k]])
    th_dead = brentq(ratio, -math.radians(4.0), 0.0, xtol=1e-14)
    assert abs(th_cross - th_dead) < 1e-5
    assert bt.knee_angle(res)[0] > 0 > bt.knee_angle(res)[-1]


@pytest.mark.slow
def test_toggle_variant_against_the_base_at_3_8(toggle):
    """Numbers of docs/breaker_variants.md (regression, 0.002 ms); the first
    impact as the base's, its peak force higher by less than the toggle's
    extra resisting torque (module docstring)."""
    res, m, _ = toggle
    mb = run_file(os.path.join(MODELS, "breaker_24kv.py"))[1]
    assert res.event_times("release")
    assert m["thrt"] * 1e3 == pytest.approx(1.483, abs=2e-3)
    assert m["n_impacts"] == 1
    assert m["contact_period"] == pytest.approx(mb["contact_period"], rel=1e-2)
    assert 1.0 < m["peak_force"] / mb["peak_force"] < 1.023
