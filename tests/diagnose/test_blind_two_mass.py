"""Blind cases on a two-mass chain (tests/diagnose/two_mass.py, written as a
user would), with data from an independent scipy simulator
(tests/diagnose/two_mass_truth.py): two similar nodes, so the location is
the hard part. Issue 11's acceptance on a new mechanism: a strong single
cause named at its node within 10 % and held-out <= 1.2 floors; a pair
both named; an effect no library law has: "not explained by the
library" at the right node.

The default tier checks the model file against the truth; each blind case
is a full diagnosis (slow tier, 1-6 min on 2 cores)."""
import os
import sys

import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import blind  # noqa: E402
import two_mass_truth  # noqa: E402

MODEL = os.path.join(HERE, "two_mass.py")


def _run(tmp_path, effect, value=None, name=None):
    return blind.run_case(MODEL, two_mass_truth, tmp_path, effect, value, seed=11,
                          name=name or f"two-mass {effect} {value}")


def test_truth_matches_the_model():
    """The user's model file (compiled by acausal) and the scipy truth agree
    with no hidden effect: 3e-8 m measured, 0.3 % of a noise floor."""
    from acausal.runtime.model import compile_model
    from acausal.modelfile import load_model_file
    mf = load_model_file(MODEL)
    t, x1, x2 = two_mass_truth.simulate(0.012)
    opts = {k: v for k, v in mf.experiment.run_options().items()
            if k not in ("output_step", "output_times")}
    res = compile_model(mf.model).simulate(params={"x2_start": 0.012}, output_times=t, **opts)
    i = np.searchsorted(res.t, t)
    assert np.max(np.abs(res["m1.s"][i] - x1)) < 0.05 * two_mass_truth.NOISE
    assert np.max(np.abs(res["m2.s"][i] - x2)) < 0.05 * two_mass_truth.NOISE


@pytest.mark.slow
def test_two_mass_strong_single_cause(tmp_path):
    """Dry friction on m2 (146 floors). Measured 2026-11-23: coulomb_friction
    at m2, F = 0.0199990 (truth 0.02), held-out 80.7 -> 1.001, 49 s."""
    out, det, floors = _run(tmp_path, "m2_coulomb", 0.02)
    assert 50 <= floors <= 500
    # Coulomb's law: smoothed (coulomb_friction) or by events
    # (stick_slip_friction, which refines it and was added after this case;
    # named here on e3ef4d4: the same law while the body slides)
    (named,) = blind.named(out)
    assert named in {("coulomb_friction", "m2"), ("stick_slip_friction", "m2")}
    key = {"coulomb_friction": "hyp_cf.F", "stick_slip_friction": "hyp_ssf.F"}[named[0]]
    assert blind.values(out)[key] == pytest.approx(0.02, rel=0.10)
    assert out["gain"]["after"]["heldout"] <= 1.2


@pytest.mark.slow
def test_two_mass_hardening_coupling_spring(tmp_path):
    """A hardening coupling spring (316 floors): the frequency shifts with
    the amplitude, so the phase drifts over the 10-20 periods of the record
    (the issue's local-minimum trap). Measured 2026-11-23: hardening_spring
    at k2, k3 = 300001 (truth 3e5), held-out 228.1 -> 1.003, 168 s at load 5."""
    out, det, floors = _run(tmp_path, "k2_cubic", 3e5)
    assert 50 <= floors <= 500
    assert blind.named(out) == {("hardening_spring", "k2")}
    assert blind.values(out)["hyp_hs.k3"] == pytest.approx(3e5, rel=0.10)
    assert out["gain"]["after"]["heldout"] <= 1.2


@pytest.mark.slow
def test_two_mass_two_causes_at_two_sites(tmp_path):
    """Quadratic drag on m1 and dry friction on m2 (197 floors): both named
    at their nodes. Measured 2026-11-23: coulomb_viscous_friction at m2 (F
    0.019998, b 9e-6) + quadratic_damping at m1 (c 0.50006), held-out
    67.5 -> 1.000, 355 s at load 5-7. Since the best pair's simpler mates are
    fitted (pairsearch.simpler_tasks; 2026-11-26): coulomb_friction at m2 (F
    0.0200000) + quadratic_damping at m1 (c 0.50016), S 17999.19 as the
    Coulomb + viscous pair's (b 1.8e-6 there), so 2 AICc units ahead of it;
    the simpler pair's fit took 102 simulations of 11193; held-out 67.5 ->
    1.000, 210 s at load 8. The simplest friction law is now required."""
    out, det, floors = _run(tmp_path, {"m1_drag": 0.5, "m2_coulomb": 0.02}, name="two-mass pair")
    assert 50 <= floors <= 500
    got = blind.named(out)
    assert ("quadratic_damping", "m1") in got
    # the simplest Coulomb law, smoothed or by events (stick_slip_friction,
    # named here on e3ef4d4: the same law while the body slides)
    assert got & {("coulomb_friction", "m2"), ("stick_slip_friction", "m2")}
    vals = blind.values(out)
    assert vals["hyp_qd.c"] == pytest.approx(0.5, rel=0.10)
    assert next(v for k, v in vals.items() if k.endswith(".F")) == pytest.approx(0.02, rel=0.10)
    assert out["gain"]["after"]["heldout"] <= 1.2


@pytest.mark.slow
def test_two_mass_out_of_library(tmp_path):
    """A force on m1 that sets in above 0.1 m/s (133 floors): no library
    law; "not explained by the library", located at m1. Measured
    2026-11-23: not explained, m1 first (located held-out 12.2, the best
    library candidate's 29.7), 278 s at load 7."""
    out, det, floors = _run(tmp_path, "m1_threshold", 0.1)
    assert 50 <= floors <= 500
    assert out["causes"] == [] and out["cause"] is None
    assert out["unexplained"]["value"] is True
    assert out["unexplained"]["node"] == "m1"
