"""The hand-written IDA reference of the trigger-hook model against the report.

Targets: Yu, Wang & Hsu (NSC 99-2221-E-011-015), Figs 7 and 10 and Table 2.
Model choices: docs/breaker_model.md.  Runs in about 2 s.
"""
import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

_PATH = Path(__file__).parents[2] / "benchmarks" / "handwritten" / "breaker_sundae.py"
_spec = importlib.util.spec_from_file_location("breaker_sundae", _PATH)
bs = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(bs)

MS = 1e-3
TABLE2 = dict(zip(bs.TABLE2_V, (2.50, 2.20, 1.90, 1.74, 1.62, 1.47)))


@pytest.mark.parametrize("assembly", [1, -1])
def test_fourbar_closed_form_closes_and_eq16_is_its_derivative(assembly):
    p = {**bs.TABLE1, **bs.CHOICES, "assembly": assembly}
    L = p["r2"] + p["r3"]
    for th1 in np.radians([-30.0, -5.0, 0.0, 20.0]):
        th2, th3 = bs.fourbar_position(th1, p)
        assert abs(L * math.sin(th2) - p["r1"] * math.sin(th3) - p["e"] * math.sin(th1)) < 1e-14
        assert abs(L * math.cos(th2) - p["f"] + p["r1"] * math.cos(th3) + p["e"] * math.cos(th1)) < 1e-14
        h = 1e-5
        R, dR = bs.fourbar_ratio(th1, th2, th3, p)
        fd = lambda k: bs.fourbar_position(th1 + k * h, p)[1]
        assert R == pytest.approx((fd(1) - fd(-1)) / (2 * h), rel=1e-6)
        Rk = lambda k: bs.fourbar_ratio(th1 + k * h, *bs.fourbar_position(th1 + k * h, p), p)[0]
        assert dR == pytest.approx((Rk(1) - Rk(-1)) / (2 * h), rel=1e-5)


@pytest.mark.parametrize("contact", [True, False])
def test_analytic_jacobian_matches_finite_differences(contact):
    # Js = 0 removes the one term the Jacobian neglects; exact lever exercises c'(th1).
    p = {**bs.TABLE1, **bs.CHOICES, "Js": 0.0, "exact_lever": True, "th1_0": 0.1}
    th2, th3 = bs.fourbar_position(0.09, p)
    p["th3_0"] = th3 - 1e-4
    res, _, jac, force = bs._callbacks(p, 6.25e8, 0.219, (contact, 7e7, 160.0))
    y = np.array([-8e-4, -2.5, 0.09, -50.0, th2 + 1e-3, th3 - 2e-3])
    yp = np.array([1.0, -3000.0, 2.0, -1e4, 0.3, 0.2])
    assert (force(y)[2] > 0) == contact
    cj, JJ, r0 = 3e4, np.zeros((6, 6)), np.zeros(6)
    jac(0.0, y, yp, r0, cj, JJ)
    res(0.0, y, yp, r0)
    for j in range(6):
        h = 1e-7 * max(1e-2, abs(y[j]))
        y2, yp2, r1 = y.copy(), yp.copy(), np.zeros(6)
        y2[j] += h
        yp2[j] += cj * h
        res(0.0, y2, yp2, r1)
        np.testing.assert_allclose(JJ[:, j], (r1 - r0) / h, rtol=1e-4, atol=2e-2)


def test_elastic_hertz_impact_matches_closed_form():
    """er = 1, no loads: t_c = 2.9432 dmax/v0 and an elastic momentum exchange."""
    free = dict(er=1.0, Fe=0.0, kh=0.0, ko=0.0, kw=0.0, ka=0.0, Js=0.0,
                Fo_pre=0.0, Fw_pre=0.0)
    K, v0 = 1e9, 3.8
    r = bs.simulate(v0, K=K, bh=0.0, **free)
    ma, mh = bs.TABLE1["ma"], bs.TABLE1["Jh"] / bs.TABLE1["s3"] ** 2
    m = ma * mh / (ma + mh)
    dmax = (5 * m * v0 ** 2 / (4 * K)) ** 0.4
    assert r["contact_period"] == pytest.approx(2.9432 * dmax / v0, rel=1e-4)
    assert r["peak_force"] == pytest.approx(K * dmax ** 1.5, rel=1e-6)
    assert r["v_hook_sep"] == pytest.approx(-2 * ma * v0 / (ma + mh), rel=1e-6)
    assert r["v_arm_sep"] == pytest.approx(-(ma - mh) * v0 / (ma + mh), rel=1e-5)


def test_before_calibration_110V():
    r = bs.simulate(3.8, K=8.3e9, bh=0.0)
    assert r["contact_period"] == pytest.approx(0.10 * MS, abs=0.01 * MS)
    assert r["thrt"] == pytest.approx(1.24 * MS, abs=0.06 * MS)
    assert r["n_impacts"] == 1


def test_after_calibration_110V():
    r = bs.simulate(3.8, K=6.25e8, bh=0.219)
    assert r["contact_period"] == pytest.approx(0.30 * MS, abs=0.02 * MS)
    assert r["thrt"] == pytest.approx(1.90 * MS, abs=0.02 * MS)
    assert r["n_impacts"] == 1


@pytest.mark.parametrize("v", bs.TABLE2_V)
def test_table2_calculated_column(v):
    r = bs.simulate(v, K=6.25e8, bh=0.219)
    assert r["thrt"] == pytest.approx(TABLE2[v] * MS, abs=0.1 * MS)


def test_report_calibration_procedure():
    """Section 3: K from the contact period (bh = 0), then bh from THRT."""
    K = brentq(lambda k: bs.simulate(3.8, K=k, bh=0.0)["contact_period"] - 0.30 * MS,
               2e8, 2e9, rtol=1e-5)
    assert K == pytest.approx(6.25e8, rel=0.10)
    bh = brentq(lambda b: bs.simulate(3.8, K=K, bh=b)["thrt"] - 1.90 * MS,
                0.05, 0.6, xtol=1e-5)
    assert bh == pytest.approx(0.219, rel=0.05)
