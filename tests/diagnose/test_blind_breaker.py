"""Blind cases on the breaker (models/breaker_24kv.py). The data come from
an independent simulator (tests/diagnose/breaker_scipy.py, written with
scipy from the report's equations; it shares no simulation code with the
project, and agrees with the model file to 3e-9 relative without hidden
effects, tests/diagnose/test_breaker_scipy.py). Until 2026-11-23 they came
from tests/diagnose/breaker_truth.py (the project's model plus hidden
effects as generic sources; the numbers in the docstrings below before
that date were measured with it). Six experiments (impact speeds 3.3-4.5
m/s), the hook angle (17-bit encoder) and the armature's travel (1 um
sensor) at 50 kHz.

Slow tier: each case is a full diagnosis (2-6 min on 2 cores). Issue 11's
acceptance: a strong single cause named at its site within 10 % and
held-out error <= 1.2 floors; a pair both named; an effect no library law
has reported as "not explained by the library" with the right node first;
Hunt-Crossley contact damping where the model has Lankarani-Nikravesh
named with held-out error <= 1.5 floors; never a wrong cause."""
import os
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import blind  # noqa: E402
import breaker_scipy  # noqa: E402
import breaker_truth  # noqa: E402

BREAKER = breaker_truth.BREAKER
# the hook drives the main shaft through the four-bar: a torque at the hook
# and one at the main shaft are kinematically equivalent sites
HOOK_SITES = {"hook.body", "main_shaft.body"}


def _run(tmp_path, effect, value=None, name=None):
    return blind.run_case(BREAKER, breaker_scipy, tmp_path, effect, value, seed=7,
                          name=name or f"breaker {effect} {value}")


def _members(out):
    """(cause, location) of the named causes and of their equivalents."""
    return blind.named(out) | {(e["cause"], e["location"]) for e in out["equivalent_causes"]}


@pytest.mark.slow
def test_breaker_strong_single_cause(tmp_path):
    """Quadratic drag on the hook (about 60 floors): named at the hook,
    within 10 %, held-out error <= 1.2 floors."""
    out, det, floors = _run(tmp_path, "hook_drag", 8e-4)
    assert 50 <= floors <= 500
    assert blind.named(out) == {("quadratic_damping", "hook.body")}
    assert blind.values(out)["hyp_qd.c"] == pytest.approx(8e-4, rel=0.10)
    assert out["gain"]["after"]["heldout"] <= 1.2


@pytest.mark.slow
def test_breaker_two_causes_at_two_sites(tmp_path):
    """The issue's pair: dry friction at the hook (1 N*m) and a solenoid
    force rising with the stroke (20 kN/m), about 47 floors: both named.
    The hook never reverses before release, so a constant load there is
    the same cause as its friction (its equivalence class).

    The free hook viscous friction ``hook.bh`` rises 0.219 -> 0.239 in the
    calibration and stands in for the dry friction (bh |w| is 1.6 N*m at
    80 rad/s); alone, Coulomb friction at the hook stays at zero from every
    start ("not tested"), so the pairs among the best singles never
    reached it (xfail until 2026-11-23: "not explained", located at
    armature.mass). The pair search now screens the best single
    (position_dependent_force at the coil, k = 18860 alone) with every
    candidate at another site (acausal/diagnose/pairsearch.py). Measured
    2026-11-23 (dev run, 253 s wall at load 7): Coulomb friction at
    hook.body tau 0.986 and k 19998, hook.bh back to 0.2192, held-out
    35.7 -> 0.966; the pairs with a constant load at the hook and at the
    main shaft next (23 and 44 AICc units behind); screening 2304
    simulations of 24510. On the independent scipy data (breaker_scipy.py,
    2026-11-23): the same pair, held-out 35.66 -> 0.966, 248 s at load 1.5-2;
    2026-11-26: the same, 309 s wall, 152 s CPU at load 7.8-8.8 (this run's
    fresh model cache: every hypothesis model compiled; the diagnosis's
    timing: total 307 s, 22668 simulations, pairs 109 s); after the
    model-build cuts (776dac1, 14d0b3b) 150 s alone (104 s CPU, load 5.5)
    and 111 s in the whole file's run (load 5-6).
    With the tied sites (2026-11-26, 366 s at load 7-8): the same pair (tau
    0.9861, k 19998), the hook's friction reported at the main shaft too,
    rate ratio -1.5702e-3 (constant within 1.4 % over the six experiments),
    tau 628 N*m there (that pair was not fitted; the constant load's pair at
    the main shaft was: -630.8 against the hook's 0.9832 converted, -626)."""
    out, det, floors = _run(tmp_path, {"hook_coulomb": 1.0, "coil_slope": 2e4},
                            name="breaker pair")
    assert len(out["causes"]) == 2
    got = _members(out)
    assert ("position_dependent_force", "armature.coil") in blind.named(out)
    assert got & {(h, s) for h in ("coulomb_friction", "constant_load") for s in HOOK_SITES}
    assert blind.values(out)["hyp_pf.k"] == pytest.approx(2e4, rel=0.10)
    # the hook's cause is also reported at the kinematically tied site, through the
    # four-bar's ratio (main shaft per hook)
    hook = next(c for c in out["causes"] if c["location"] in HOOK_SITES)
    (tied,) = [e for e in hook["equivalent_sites"] if e["location"] in HOOK_SITES]
    ratio = tied["ratio"] if hook["location"] == "hook.body" else 1 / tied["ratio"]
    assert ratio == pytest.approx(-1.57e-3, rel=0.05)
    (name, v), = ((k, p["value"]) for k, p in hook["parameters"].items())
    assert abs(tied["parameters"][name]) == pytest.approx(abs(v / tied["ratio"]), rel=1e-9)


@pytest.mark.slow
def test_breaker_out_of_library(tmp_path):
    """A torque on the hook that sets in above 40 rad/s (8 N*m at full
    strength, about 68 floors): no library law; "not explained by the
    library" at the hook's node.
    Measured 2026-11-23 at 5 N*m (40 floors): first named as power_drag at the hook with its
    coefficient at the bound of its range (held-out 1.59); with the bound
    rule (stages._bound_reasons) not explained, located at hook.body first
    (held-out 1.21), main_shaft.body 26 AICc units behind. On the
    independent scipy data (breaker_scipy.py, 2026-11-26, 8 N*m, 68
    floors): not explained, located at hook.body first (held-out 0.962),
    main_shaft.body next (1.220, 71 AICc units behind), armature.mass far
    behind (9.74); the best library answer, power drag + quadratic drag at
    the hook, left held-out 19.06 -> 1.92 (nothing named); 357 s wall,
    204 s CPU at load 2.4-9.6 alone with a fresh model cache; 206 s in the
    whole file's run after 14d0b3b (pairs 80 s, about 83 s after the
    fits, mostly the located term; 25368 simulations)."""
    out, det, floors = _run(tmp_path, "hook_threshold", 8.0)
    assert 50 <= floors <= 500
    assert out["causes"] == [] and out["cause"] is None
    assert out["unexplained"]["value"] is True
    assert out["unexplained"]["node"] in HOOK_SITES


@pytest.mark.slow
def test_breaker_hunt_crossley_contact(tmp_path):
    """The contact's damping follows Hunt-Crossley where the model has
    Lankarani-Nikravesh (same e = 0.74, about 16 floors): a contact-damping
    cause at the contact, with the Hunt-Crossley member named or in its
    class, held-out error <= 1.5 floors. With the restitution refitted
    (e + de) the Hunt-Crossley and Flores members are the same law (chi is
    a function of e): measured 2026-11-23, Flores named (de 0.0639) with
    Hunt-Crossley (de -2.3e-4, the truth) 0.0006 AICc units behind in its
    class, held-out 10.86 -> 0.957. On the independent scipy data
    (breaker_scipy.py, 2026-11-26, 15.8 floors): the same, Flores named
    (de 0.0639, 95 % [0.0638, 0.0640]) with Hunt-Crossley 0.0011 AICc units
    behind in its class, the model's own law (contact_damping_law) 3rd at
    held-out 1.94; held-out 10.862 -> 0.957; 184 s wall, 98 s CPU at load
    8.9-9.4 alone with a fresh model cache (34 s in the whole file's run,
    its models built by the cases before it)."""
    out, det, floors = _run(tmp_path, "hunt_crossley", 0.74)
    assert blind.named(out) and all(loc == "contact" for _, loc in blind.named(out))
    assert {c.get("family") for c in out["causes"]} == {"contact_damping"}
    assert ("contact_law_hunt_crossley", "contact") in _members(out)
    assert out["gain"]["after"]["heldout"] <= 1.5
