"""Blind cases on the latch striker (models/latch_striker.py) with data
from an independent scipy simulator written from the physics
(tests/diagnose/latch_truth.py: contact onsets and releases as events,
nothing imported from the project's model or component code). The first
test checks that truth against the model's nominal simulation to the
solvers' tolerance: that agreement is what makes it a trustworthy truth.

Slow tier: each case is a full diagnosis of five experiments (coil forces
20-45 N, plunger and latch positions at 50 kHz with a 1 um sensor).
Issue 11's acceptance: a strong single cause named at its site within
10 % and held-out error <= 1.2 floors; a pair both named; an effect no
library law has reported as "not explained by the library" with the right
node first; a standard law other than the library's first form (Stribeck
friction) named with held-out error <= 1.5 floors; never a wrong cause."""
import os
import sys

import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import blind  # noqa: E402
import latch_truth  # noqa: E402

LATCH = os.path.abspath(os.path.join(HERE, "..", "..", "models", "latch_striker.py"))


def _run(tmp_path, effect, value=None, name=None):
    return blind.run_case(LATCH, latch_truth, tmp_path, effect, value, seed=5,
                          name=name or f"latch {effect} {value}")


@pytest.mark.parametrize("coil", [20.0, 45.0])
def test_truth_matches_the_model(coil):
    """The scipy truth and the model file's nominal simulation (both at
    rtol 1e-11) agree on both positions to 1e-10 m (measured about 4e-13 m)
    and on the trip time to 1e-10 s."""
    from acausal.modelfile import compile_file
    mf, cm = compile_file(LATCH)
    opts = mf.experiment.run_options(dense=True)
    opts.update(rtol=1e-11, atol=1e-14)
    res = cm.simulate(params={"F_coil": coil}, **opts)
    segs, t_trip = latch_truth.simulate(coil)
    assert t_trip == pytest.approx(res.t[-1], abs=1e-10)
    x, y = latch_truth.sample(segs, np.minimum(res.t, t_trip))
    assert np.abs(x - res["plunger.s"]).max() < 1e-10
    assert np.abs(y - res["latch.s"]).max() < 1e-10
    assert y.max() > 2.9e-3 and x.max() > 1e-3   # it struck and tripped


@pytest.mark.slow
def test_latch_strong_single_cause(tmp_path):
    """A solenoid force rising with the stroke (+5 kN/m, about 70 floors):
    position_dependent_force at the coil, k within 10 %, held-out <= 1.2."""
    out, det, floors = _run(tmp_path, "coil_slope", 5000.0)
    assert 50 <= floors <= 500
    assert blind.named(out) == {("position_dependent_force", "coil")}
    assert blind.values(out)["hyp_pf.k"] == pytest.approx(5000.0, rel=0.10)
    assert out["gain"]["after"]["heldout"] <= 1.2


@pytest.mark.slow
def test_latch_two_causes_at_two_sites(tmp_path):
    """Quadratic drag on the latch and a rising coil force, both present
    (about 40 floors): both named, each at its site.

    The free ``latch_damper.d`` takes most of the latch's drag (4.27
    calibrated, 6.14 in the best single fit, position_dependent_force at
    the coil, k = 3070 for 3000). Alone, quadratic drag on the latch ranks
    low (its fit runs to its bound with d at 0.77), so the pairs among the
    four best singles missed it, and a linear score test at the best fit's
    point ranked it third (gain 2306, where the pair removes about 17000):
    xfail until 2026-11-23, nothing named. The pair search now screens the
    best single with every candidate at another site by a short fit with
    the free parameters refitted (acausal/diagnose/pairsearch.py).
    Measured 2026-11-23 (dev run, 100 s wall at load 7): k 3000.3, c
    1.4973, latch_damper.d back to 4.008, held-out 42.6 -> 0.986; the next
    pair (with the restitution power law at the contact) 7130 AICc units
    behind; screening 1410 simulations of 16155."""
    out, det, floors = _run(tmp_path, {"latch_drag": 1.5, "coil_slope": 3000.0},
                            name="latch pair")
    assert blind.named(out) == {("quadratic_damping", "latch"),
                                ("position_dependent_force", "coil")}
    got = blind.values(out)
    assert got["hyp_qd.c"] == pytest.approx(1.5, rel=0.10)
    assert got["hyp_pf.k"] == pytest.approx(3000.0, rel=0.10)


@pytest.mark.slow
def test_latch_out_of_library(tmp_path):
    """A force on the plunger that sets in above 0.8 m/s (about 60 floors):
    no library law; "not explained by the library" at the plunger's node."""
    out, det, floors = _run(tmp_path, "plunger_threshold", 20.0)
    assert floors > 50
    assert out["causes"] == [] and out["cause"] is None
    assert out["unexplained"]["value"] is True
    assert out["unexplained"]["node"] == "plunger"


@pytest.mark.slow
def test_latch_stribeck_friction(tmp_path):
    """Stribeck friction in the plunger's guide (3 N kinetic, 3 N static
    excess over 0.2 m/s): a friction-family cause at the plunger (or its
    kinematic class: the plunger never reverses, so a constant load is
    equivalent to the kinetic level), held-out error <= 1.5 floors."""
    out, det, floors = _run(tmp_path, "plunger_stribeck", (3.0, 3.0, 0.2))
    assert len(out["causes"]) >= 1
    for c in out["causes"]:
        assert c["location"] == "plunger"
    fam = {c.get("family") for c in out["causes"]} | {
        e["cause"] for e in out["equivalent_causes"] if e["location"] == "plunger"}
    assert fam & {"friction", "coulomb_friction", "stribeck_friction",
                  "coulomb_viscous_friction"}
    assert out["gain"]["after"]["heldout"] <= 1.5
