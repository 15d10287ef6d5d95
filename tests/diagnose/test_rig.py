"""Blind cases on a mechanism outside models/, built as a user would
(tests/diagnose/torsion_rig.py), with data from an independent scipy
simulator (tests/diagnose/rig_truth.py: no code of the project's model).
Slow tier: each case is a full diagnosis (several minutes on 2 cores)."""
import json
import os
import sys

import pytest

from acausal.diagnose.run import diagnose

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import rig_truth  # noqa: E402

RIG = os.path.join(HERE, "torsion_rig.py")


def _run(tmp_path, effect, value=None, seed=3):
    rig_truth.write(tmp_path / "data", effect, value, seed=seed)
    out = diagnose(RIG, tmp_path / "data", out_dir=tmp_path / "out", workers=2,
                   progress=False)
    det = json.loads((tmp_path / "out" / "candidates.json").read_text())
    floors = rig_truth.effect_floors(effect, value)
    print(f"RIG {effect} {value}: effect {floors:.0f} floors; named {out['causes']}; "
          f"unexplained {out['unexplained']}; held-out {out['gain']['before']['heldout']:.3f}"
          f" -> {out['gain']['after']['heldout']:.3f}; weak {det['weak_evidence']}; "
          f"{det['timing']['total_s']:.0f} s")
    return out, det, floors


@pytest.mark.slow
def test_rig_hardening_spring_strong_effect(tmp_path):
    """A hardening spring at a few hundred noise floors: the frequency
    shifts with amplitude and the phase wraps over 16 cycles (the
    local-minimum case of issue 11)."""
    out, det, floors = _run(tmp_path, "hardening", 1.6)
    assert floors > 100
    assert (out["cause"], out["location"]) == ("hardening_spring", "spring")
    assert out["parameters"]["hyp_hs.k3"]["value"] == pytest.approx(1.6, rel=0.10)
    assert out["gain"]["after"]["heldout"] <= 1.2


@pytest.mark.slow
def test_rig_dead_band_is_not_explained_by_the_library(tmp_path):
    """A dead band (play) in the spring's attachment: no library hypothesis
    acts there; the diagnosis must say so and locate the spring's node
    (the rotor's), never name a library cause."""
    out, det, floors = _run(tmp_path, "dead_band", 0.005)
    assert floors > 100
    assert out["cause"] is None
    assert out["unexplained"]["value"] is True
    assert out["unexplained"]["node"] == "rotor"
    assert (tmp_path / "out" / "located.png").stat().st_size > 1000
    assert "Not explained by the library" in (tmp_path / "out" / "report.md").read_text()


@pytest.mark.slow
def test_rig_two_causes_at_two_sites(tmp_path):
    """Coulomb friction at the bearing and a hardening spring, both present:
    both named, each at its site."""
    out, det, floors = _run(tmp_path, {"coulomb": 2e-3, "hardening": 0.8})
    named = {(c["cause"], c["location"]) for c in out["causes"]}
    assert named == {("coulomb_friction", "rotor"), ("hardening_spring", "spring")}
    got = {k: v["value"] for c in out["causes"] for k, v in c["parameters"].items()}
    assert got["hyp_cf.tau"] == pytest.approx(2e-3, rel=0.10)
    assert got["hyp_hs.k3"] == pytest.approx(0.8, rel=0.10)
