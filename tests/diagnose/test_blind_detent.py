"""Out-of-library forces the located generic term must show: a
position-periodic detent (6 cycles over the stroke) and a localised bump,
both on the second mass of the two-mass chain (tests/diagnose/two_mass.py,
two similar body nodes), with data from an independent scipy simulator
(tests/diagnose/detent_truth.py: no code of the project's model); and a
null. Slow tier: each case is a full diagnosis. Numbers: docs/diagnosis.md."""
import os
import sys

import numpy as np
import pytest
from scipy.optimize import least_squares

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import blind  # noqa: E402
import detent_truth  # noqa: E402

MODEL = os.path.join(HERE, "two_mass.py")
STROKE = 0.9 * max(detent_truth.STARTS)   # positions every experiment's record covers


def _position_part(term, n=801):
    from acausal.diagnose.library import generic
    sh = generic.shape(term["values"], generic.GENERIC.prefix, term["ranges"], n=n)
    m = np.abs(sh["x"]) <= STROKE
    return sh["x"][m], sh["f_x"][m]


def _periodic_fit(x, f, period0):
    """(amplitude, period) of f ~ A sin(2 pi x / P + phi) + c0 + c1 x."""
    best = None
    for p0 in period0 * np.linspace(0.7, 1.3, 13):
        for ph in (0.0, 1.6, 3.1, 4.7):
            r = least_squares(lambda q: q[0] * np.sin(2 * np.pi * x / q[1] + q[2]) + q[3]
                              + q[4] * x - f, [np.std(f), p0, ph, 0.0, 0.0])
            if best is None or r.cost < best.cost:
                best = r
    A, P = best.x[0], best.x[1]
    return abs(A), P


@pytest.fixture(scope="module")
def detent_case(tmp_path_factory):
    """One diagnosis of the detent case, shared by the tests below."""
    tmp = tmp_path_factory.mktemp("detent")
    out, det, floors = blind.run_case(MODEL, detent_truth, tmp, "m2_detent", DETENT_A,
                                      name="two-mass detent")
    return out, det, floors, tmp


DETENT_A = 0.04


@pytest.mark.slow
def test_detent_is_located_at_m2_and_its_period_and_amplitude_recovered(detent_case):
    """A = 0.04 N, P = 4 mm on m2 (about 27 floors): not explained by the
    library, the best located term sits at m2 (not m1), and its position
    part is the truth's law: period within 3 %, amplitude within 20 % (the
    smoothing may shave the peaks). Measured 2026-11-27: m2 (m1's term
    held-out 22.8), 33 x 33 knots, P 4.030 mm, A 0.0379 N."""
    out, det, floors, tmp = detent_case
    P = detent_truth.P_DETENT
    assert 20 < floors < 60
    assert out["causes"] == []
    assert out["unexplained"]["value"] is True and out["unexplained"]["node"] == "m2"
    best = det["located"][0]
    print("DETENT", best["node"], best["heldout_rmse"], [t["node"] for t in det["located"]])
    assert best["node"] == "m2"
    x, f = _position_part(best)
    A_fit, P_fit = _periodic_fit(x, f, P)
    print(f"DETENT recovered A {A_fit:.4g} (truth {DETENT_A}), P {P_fit:.4g} (truth {P})")
    assert P_fit == pytest.approx(P, rel=0.03)
    assert A_fit == pytest.approx(DETENT_A, rel=0.20)
    assert (tmp / "out" / "located.png").stat().st_size > 1000


@pytest.mark.slow
def test_detent_term_reaches_the_held_out_floor(detent_case):
    """The located term predicts each left-out release within 1.5 floors
    (every release's positions lie inside the others'). A strict xfail at
    2.43 floors until the term's knots spanned every experiment's calibrated
    run, not only the model file's nominal run (locate25, 2026-11-27): it
    then passed in the slow tier on 70854a8."""
    _, det, _, _ = detent_case
    print(f"DETENT located term held-out {det['located'][0]['heldout_rmse']:.3f} floors")
    assert det["located"][0]["heldout_rmse"] <= 1.5


@pytest.mark.slow
def test_bump_is_located_at_m2_where_it_acts(tmp_path):
    """A Gaussian bump of 0.03 N at x2 = 4 mm (half-width 0.8 mm) on m2:
    located at m2, held-out within 1.5 floors, and the recovered position
    part (net of its straight-line part) peaks within one half-width of
    the bump."""
    out, det, floors = blind.run_case(MODEL, detent_truth, tmp_path, "m2_bump", 0.03,
                                      name="two-mass bump")
    assert out["causes"] == [] or all(c["location"] == "m2" for c in out["causes"])
    best = det["located"][0]
    print("BUMP", best["node"], best["heldout_rmse"], floors)
    assert best["node"] == "m2"
    assert best["heldout_rmse"] <= 1.5
    x, f = _position_part(best)
    resid = f - np.polyval(np.polyfit(x, f, 1), x)
    peak = x[np.argmax(np.abs(resid))]
    assert abs(peak - detent_truth.X_BUMP) < detent_truth.W_BUMP


@pytest.mark.slow
def test_null_claims_no_located_force(tmp_path):
    """Noise only: no discrepancy, nothing named, nothing "not explained"."""
    out, det, _ = blind.run_case(MODEL, detent_truth, tmp_path, None, 0.0, seed=11,
                                 name="two-mass null")
    assert out["causes"] == []
    assert out["unexplained"]["value"] is False
