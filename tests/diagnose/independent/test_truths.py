"""The independent truths checked twice (fast tier):

* against the library's nominal model with the hidden effect at zero: the
  hand-written equations (``cam_truth``, ``gear_truth``) and the user's
  model files (``cam_follower.py``, ``geared_drive.py``) simulated by
  acausal at rtol 1e-11 agree to 1e-6 of each signal's range (measured:
  7e-9 at worst, the cam's follower lift on the fast run; the geared drive
  2e-9), which checks both;
* the hybrid integrator's dry friction against the closed form of an
  undamped oscillator with Coulomb friction (half-cycles of shrinking
  amplitude about alternating centres, then stuck), which no library code
  enters."""
import math
import os
import sys

import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import cam_truth  # noqa: E402
import gear_truth  # noqa: E402
import truth_core  # noqa: E402
from truth_core import Law  # noqa: E402


@pytest.mark.parametrize("truth", [cam_truth, gear_truth], ids=["cam", "gear"])
def test_truth_agrees_with_the_nominal_model(truth):
    from acausal.modelfile import compile_file
    mf, cm = compile_file(os.path.join(HERE, truth.MODEL))
    for cond in truth.CONDITIONS:
        out, events = truth.run(cond)
        assert events == []
        res = cm.simulate(params=cond, t_end=truth.T_END, rtol=1e-11, atol=1e-13,
                          output_step=1.0 / truth.RATE, backend="sundae")
        for s in truth.SIGNALS:
            y = np.interp(out["time"], res.t, res[s])
            dev = np.max(np.abs(y - out[s])) / np.ptp(out[s])
            assert dev < 1e-6, (truth.__name__, cond, s, dev)


def _coulomb_closed_form(t, M, c, Q, F, n_half=40):
    """q(t) of M q'' = Q - c q - F sign(q') from rest at q = 0 (Q > F)."""
    w = math.sqrt(c / M)
    qe, q0, t0 = Q / c, 0.0, 0.0
    out = np.full_like(t, np.nan)
    sign = 1.0
    for _ in range(n_half):
        centre = qe - sign * F / c
        if abs(Q - c * q0) <= F:                # stuck from t0 on
            out[t >= t0] = q0
            return out, t0
        a = q0 - centre
        m = (t >= t0) & (t <= t0 + math.pi / w)
        out[m] = centre + a * np.cos(w * (t[m] - t0))
        t0, q0, sign = t0 + math.pi / w, centre - a, -sign
    return out, None


def test_dry_friction_matches_the_closed_form():
    M, c, Q, F = 0.01, 2.0, 0.5, 0.03
    mech = truth_core.Mechanism(lambda q: (M, 0.0), lambda q, w, t: Q - c * q,
                                {"load": (lambda q: q, lambda q: 1.0)})
    t = np.linspace(0.0, 3.0, 3001)
    q, w, events = truth_core.simulate(mech, 0.0, 0.0, t, [Law("coulomb", "load", {"F": F})])
    ref, t_stick = _coulomb_closed_form(t, M, c, Q, F)
    assert t_stick is not None and t_stick < 3.0
    assert [e for _, e in events][-1] == "stick"
    assert events[-1][0] == pytest.approx(t_stick, abs=1e-9)
    assert np.max(np.abs(q - ref)) < 1e-9 * np.ptp(ref)
    assert np.all(w[t > t_stick + 1e-6] == 0.0)


def test_friction_at_a_moving_lever_does_not_stick_where_the_lever_vanishes():
    """Dry friction in the cam follower's guide (lever e sin q) reverses as
    the cam passes the top and bottom, without sticking the cam; energy
    only falls."""
    laws = [Law("coulomb", "follower", {"F": 1.0})]
    out, events = cam_truth.run({"w0": 35.0}, laws)
    assert all(e != "stick" for _, e in events)
    q, w = out["cam.phi"], out["cam.w"]
    s = cam_truth.lift(q)
    energy = 0.5 * (cam_truth.J + cam_truth.M_F * (cam_truth.E * np.sin(q)) ** 2) * w ** 2 \
        + 0.5 * cam_truth.C * s ** 2 + cam_truth.PRELOAD * s
    assert np.all(np.diff(energy) <= 1e-9 * energy[0])
