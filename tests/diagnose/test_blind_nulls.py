"""Null cases for the blind tier: noise-only data from the independent
truths of the two mechanisms outside models/ (tests/diagnose/rig_truth.py,
tests/diagnose/stop_truth.py) with nothing hidden, ten seeds each. The
diagnosis must declare no discrepancy and name no cause in any of the 20
(family level alpha = 0.01: 20 runs would show a false positive with
probability about 0.18 if the test were exact; it is conservative).
Slow tier: 20 full diagnoses. Verdicts and wall times: docs/diagnosis.md."""
import os
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import blind  # noqa: E402
import rig_truth  # noqa: E402
import stop_truth  # noqa: E402

CASES = [("torsion_rig.py", rig_truth, seed) for seed in range(10, 20)] + \
        [("stop_rig.py", stop_truth, seed) for seed in range(10, 20)]


@pytest.mark.slow
@pytest.mark.parametrize("model, truth, seed", CASES,
                         ids=[f"{m[:-3]}-{s}" for m, _, s in CASES])
def test_null_declares_nothing(tmp_path, model, truth, seed):
    out, det, _ = blind.run_case(os.path.join(HERE, model), truth, tmp_path, None, None,
                                 seed=seed, name=f"null {model[:-3]} seed {seed}")
    assert out["discrepancy"] is False
    assert out["causes"] == [] and out["cause"] is None
    assert out["unexplained"]["value"] is False
