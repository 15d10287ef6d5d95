"""Blind cases on a mechanism outside models/, built as a user would
(tests/diagnose/torsion_rig.py), with data from an independent scipy
simulator (tests/diagnose/rig_truth.py: no code of the project's model).
Slow tier: each case is a full diagnosis (about a minute on 2 cores).
Verdicts, numbers and wall times: docs/diagnosis.md."""
import os
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import blind  # noqa: E402
import rig_truth  # noqa: E402

RIG = os.path.join(HERE, "torsion_rig.py")


def _run(tmp_path, effect, value=None, seed=3, name=None):
    return blind.run_case(RIG, rig_truth, tmp_path, effect, value, seed=seed,
                          name=name or f"rig {effect} {value}")


@pytest.mark.slow
@pytest.mark.parametrize("effect, value, cause, location, param", [
    # the local-minimum case: the frequency shifts with amplitude and
    # the phase wraps over 16 cycles
    ("hardening", 1.6, "hardening_spring", "spring", "hyp_hs.k3"),
    ("coulomb", 8e-3, "coulomb_friction", "rotor", "hyp_cf.tau"),
    ("drag", 1e-4, "quadratic_damping", "rotor", "hyp_qd.c"),
    # play in the spring's attachment: out of the library until the spring
    # nonlinearity family gained its dead-band member (issue 11, item 5)
    ("dead_band", 0.005, "dead_band_spring", "spring", "hyp_db.b"),
])
def test_rig_strong_single_cause(tmp_path, effect, value, cause, location, param):
    """50-500 noise floors over 16 periods: the right cause at the right
    location, its parameter within 10 %, held-out error at most 1.2 floors."""
    out, det, floors = _run(tmp_path, effect, value)
    assert 50 <= floors <= 500
    assert blind.named(out) == {(cause, location)}
    assert blind.values(out)[param] == pytest.approx(value, rel=0.10)
    assert out["gain"]["after"]["heldout"] <= 1.2


@pytest.mark.slow
@pytest.mark.parametrize("effect, value", [
    ("threshold", 0.02),      # a torque that sets in above 10 rad/s
])
def test_rig_out_of_library_is_not_explained(tmp_path, effect, value):
    """No library hypothesis has this law: the diagnosis must say so and
    locate the rotor's node (where the spring, damper and inertia meet),
    never name a library cause, and plot the located term's shape. The
    shape reads as the threshold law: the velocity part, net of the
    constant and linear parts the free damper shares, within 25 % RMS of
    the truth's torque over the speeds the data cover and no rougher than
    2x the truth's own second differences on the knots. Measured
    2026-11-23: 0.125 and 1.41 (located held-out 1.106 floors); with the
    earlier term (9 velocity knots, nothing pinned) 0.834 and 3.18, a
    zigzag (held-out 1.80). With the resolution chosen at the calibrated
    point only (9 x 9 knots): 0.60 and 2.37 (held-out 2.61); chosen again at
    the fitted point (2026-11-27, 9 x 33): 0.071 and 1.23 (held-out 1.024)."""
    out, det, floors = _run(tmp_path, effect, value)
    assert floors > 50
    assert out["causes"] == [] and out["cause"] is None
    assert out["unexplained"]["value"] is True
    assert out["unexplained"]["node"] == "rotor"
    assert (tmp_path / "out" / "located.png").stat().st_size > 1000
    assert "Not explained by the library" in (tmp_path / "out" / "report.md").read_text()
    term = det["located"][0]
    w_max = 0.5 * (rig_truth.C / rig_truth.J) ** 0.5      # the fastest release's peak speed
    err, rough = blind.velocity_shape_error(
        term, lambda w: -rig_truth.extra_torque(w, {effect: value}), 0.9 * w_max)
    print(f"SHAPE rig {effect}: relative error {err:.3f}, roughness {rough:.2f}")
    assert err < 0.25 and rough < 2.0


@pytest.mark.slow
def test_rig_two_causes_at_two_sites(tmp_path):
    """Coulomb friction at the bearing and a hardening spring, both present:
    both named, each at its site, parameters within 10 %."""
    out, det, floors = _run(tmp_path, {"coulomb": 2e-3, "hardening": 0.8}, name="rig pair")
    assert blind.named(out) == {("coulomb_friction", "rotor"), ("hardening_spring", "spring")}
    got = blind.values(out)
    assert got["hyp_cf.tau"] == pytest.approx(2e-3, rel=0.10)
    assert got["hyp_hs.k3"] == pytest.approx(0.8, rel=0.10)
