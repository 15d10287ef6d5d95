"""The diagnosis statistics: tests, information criteria, classes, evidence
rules, and the leave-one-out and interval shortcuts of the fitting module,
checked against closed forms and brute force."""
import math

import numpy as np
import pytest
from scipy import stats as sps

from acausal.diagnose.stages import stats as st
from acausal.diagnose.stages.fitting import Fit, confidence, heldout_rms, linear_loo


def test_chi2_test_matches_scipy():
    d = st.chi2_test(110.0, 102, 2, 0.01)
    assert d["dof"] == 100
    assert d["p_value"] == pytest.approx(sps.chi2.sf(110.0, 100), rel=1e-12)
    assert not d["reject"]
    assert st.chi2_test(160.0, 102, 2, 0.01)["reject"]      # p = 2e-4


def test_runs_test_formula_and_direction():
    # blocks of one sign: 2 runs, far fewer than expected -> tiny p
    r = np.r_[np.ones(30), -np.ones(30)]
    d = st.runs_test(r)
    assert d["runs"] == 2
    n1 = n2 = 30
    mu = 2 * n1 * n2 / 60 + 1
    assert d["expected"] == pytest.approx(mu)
    assert d["p_value"] < 1e-10
    # alternating signs: as many runs as samples -> p close to 1
    assert st.runs_test(np.tile([1.0, -1.0], 30))["p_value"] > 0.999
    # zeros are dropped, too few of one sign -> no test (p = 1)
    assert st.runs_test(np.r_[np.zeros(50), np.ones(5)])["p_value"] == 1.0


def test_runs_test_size_on_white_noise():
    """Under independent noise the one-sided test rejects at most at its
    level (the continuity correction makes it slightly conservative: 3.4 %
    at 5 % for 200 samples)."""
    rng = np.random.default_rng(0)
    p = np.array([st.runs_test(rng.normal(size=200))["p_value"] for _ in range(2000)])
    assert 0.025 < np.mean(p < 0.05) <= 0.055


def test_aicc_and_lr():
    # notes.md: AICc = 2k - 2 ln L + 2k(k+1)/(n-k-1), -2 ln L = S + const
    assert st.aicc(100.0, 50, 3) == pytest.approx(100 + 6 + 24 / 46)
    assert st.aicc(100.0, 50, 3, c=2.0) == pytest.approx(50 + 6 + 24 / 46)
    assert st.aicc(1.0, 4, 3) == math.inf
    assert st.lr_test(10.0, 10.0 - 3.841458820694124, 1) == pytest.approx(0.05, rel=1e-9)
    assert st.lr_test(10.0, 12.0, 1) == 1.0        # a worse fit is no evidence
    assert st.overdispersion([(100.0, 102, 2), (300.0, 102, 2)]) == 1.0
    assert st.overdispersion([(400.0, 102, 2), (300.0, 102, 2)]) == pytest.approx(3.0)


def test_discrepancy_decision_bonferroni():
    chi = st.chi2_test(105.0, 102, 2, 0.01)                 # p = 0.35
    runs = [{"p_value": 0.004}, {"p_value": 0.5}]            # 0.004 x 2 = 0.008 > 0.01/3
    d = st.discrepancy_decision(chi, runs, {"p_value": 1e-4, "m": 40}, 0.01)
    assert not d["discrepancy"]                               # 1e-4 x 40 > 0.01/3
    d = st.discrepancy_decision(chi, runs, {"p_value": 1e-4, "m": 10}, 0.01)
    assert d["discrepancy"]                                   # 1e-3 < 3.3e-3
    assert [p["name"] for p in d["parts"]] == ["chi-square", "runs", "likelihood ratio"]


def test_family_false_positive_rate_linear_null():
    """Pure-noise residuals of a linear model with calibrated parameters:
    chi-square + runs + LR over 5 candidate regressors at alpha = 0.05 must
    reject at most about 5 % of 1000 datasets."""
    rng = np.random.default_rng(1)
    n = 120
    t = np.linspace(0, 1, n)
    X0 = np.c_[np.ones(n), t]
    cands = [t ** 2, np.sin(6 * t), np.sign(t - 0.5), t ** 3, np.exp(-5 * t)]
    hits = 0
    for _ in range(1000):
        y = rng.normal(size=n)
        r0 = y - X0 @ np.linalg.lstsq(X0, y, rcond=None)[0]
        S0 = r0 @ r0
        ps = []
        for c in cands:
            X = np.c_[X0, c]
            r = y - X @ np.linalg.lstsq(X, y, rcond=None)[0]
            ps.append(st.lr_test(S0, r @ r, 1))
        d = st.discrepancy_decision(st.chi2_test(S0, n, 2, 0.05),
                                    [st.runs_test(r0)], {"p_value": min(ps), "m": 5}, 0.05)
        hits += d["discrepancy"]
    assert hits / 1000 <= 0.06


def test_equivalence_classes():
    rows = [dict(aicc=a, heldout_rmse=h) for a, h in
            [(0.0, 1.0), (3.5, 1.2), (6.5, 0.9), (7.5, 0.8), (30.0, 1.0)]]
    # 3.5 within 4; 6.5 within 7 with a better held-out error; 7.5 neither
    assert st.equivalence_classes(rows) == [[0, 1, 2], [3], [4]]


def test_akaike_weights():
    w = st.akaike_weights([0.0, 2.0, 10.0])
    assert w.sum() == pytest.approx(1.0)
    assert w[0] / w[1] == pytest.approx(math.e)


def test_weak_evidence_rules_real_data_like():
    """Six 0.1 ms readings and one more, four parameters, a small gain."""
    reasons = st.weak_evidence(st.Evidence(n=7, k=3, d_null=-4.0, d_runner=0.5,
                                           heldout_nominal=2.0, heldout_best=1.9, ci_rel=3.0,
                                           c_hat=4.0, coarse=0.66))
    text = " | ".join(reasons)
    for part in ("too few data: 7 values for 3", "4.0 units worse", "only 0.5", "1.9",
                 "300%", "2x the noise", "0.66 resolution steps"):
        assert part in text
    assert st.weak_evidence(st.Evidence(n=600, k=3, d_null=300, d_runner=20, heldout_nominal=3.0,
                                        heldout_best=1.0, ci_rel=0.05, c_hat=1.0,
                                        coarse=4.0)) == []


def _linear_fit(X, y, groups):
    beta = np.linalg.lstsq(X, y, rcond=None)[0]
    r = X @ beta - y
    names = [f"b{i}" for i in range(X.shape[1])]
    return Fit(names, dict(zip(names, beta)), float(r @ r), r, X, list(groups),
               ["y"] * len(y)), beta


def test_linear_loo_is_exact_for_linear_models():
    rng = np.random.default_rng(2)
    groups = np.repeat(["a", "b", "c", "d"], 10)
    X = np.c_[np.ones(40), rng.normal(size=40), rng.normal(size=40)]
    y = X @ [1.0, 2.0, -1.0] + rng.normal(size=40)
    f, _ = _linear_fit(X, y, groups)
    loo = linear_loo(f)
    for g in "abcd":
        m = groups == g
        b = np.linalg.lstsq(X[~m], y[~m], rcond=None)[0]
        np.testing.assert_allclose(loo[g], X[m] @ b - y[m], atol=1e-10)
    allr = np.concatenate([loo[g] for g in "abcd"])
    assert heldout_rms(loo) == pytest.approx(np.sqrt(np.mean(allr ** 2)))


def test_linear_loo_of_a_penalised_fit_is_the_penalised_refit():
    """With smoothing rows on the last parameters (value/scale), the
    linearised leave-one-out is exactly the penalised refit without the
    group (the PRESS residuals of a penalised linear model)."""
    rng = np.random.default_rng(5)
    groups = np.repeat(["a", "b", "c"], 12)
    X = rng.normal(size=(36, 5))
    y = X @ [1.0, 0.5, -1.0, 2.0, 0.3] + rng.normal(size=36)
    P = 3.0 * np.diff(np.eye(4), 2, axis=0)          # on the last 4 parameters
    sc = np.array([2.0, 2.0, 2.0, 2.0])
    Pf = np.c_[np.zeros((2, 1)), P / sc]

    def solve(m):
        return np.linalg.lstsq(np.vstack([X[m], Pf]), np.r_[y[m], np.zeros(2)], rcond=None)[0]

    b = solve(np.ones(36, bool))
    names = [f"p{i}" for i in range(5)]
    f = Fit(names, dict(zip(names, b)), float(np.sum((X @ b - y) ** 2)), X @ b - y, X,
            list(groups), ["y"] * 36)
    loo = linear_loo(f, (P, sc))
    for g in "abc":
        m = groups == g
        np.testing.assert_allclose(loo[g], X[m] @ solve(~m) - y[m], atol=1e-10)
    assert not np.allclose(linear_loo(f)["a"], loo["a"])


def test_confidence_matches_ols_with_known_sigma():
    rng = np.random.default_rng(3)
    X = np.c_[np.ones(50), np.linspace(0, 1, 50)]
    y = X @ [2.0, 3.0] + 0.5 * rng.normal(size=50)      # S/(n-k) < 1: sigma = 1 kept
    f, beta = _linear_fit(X, y, ["g"] * 50)
    ci = confidence(f)
    sd = np.sqrt(np.diag(np.linalg.inv(X.T @ X)))
    q = sps.t.ppf(0.975, 48)
    for i, nm in enumerate(f.names):
        assert ci[nm][0] == pytest.approx(beta[i] - q * sd[i], rel=1e-9)
        assert ci[nm][1] == pytest.approx(beta[i] + q * sd[i], rel=1e-9)


def test_confidence_unidentifiable_parameter_gets_no_interval():
    X = np.c_[np.ones(20), np.zeros(20), np.linspace(0, 1, 20)]
    y = X @ [1.0, 0.0, 2.0]
    f, _ = _linear_fit(X, y, ["g"] * 20)
    f.values["b1"] = 5.0
    ci = confidence(f)
    assert ci["b1"] == (-math.inf, math.inf)
    assert math.isfinite(ci["b0"][0]) and math.isfinite(ci["b2"][1])


def test_confidence_of_a_positive_parameter_is_on_its_logarithm():
    """A positive parameter's interval is exp(log b +- q sd(log b)), with
    sd(log b) = sd(b) / b to first order: asymmetric, above zero."""
    rng = np.random.default_rng(4)
    X = np.c_[np.ones(30), np.linspace(0, 1, 30)]
    y = X @ [2.0, 1.0] + 0.6 * rng.normal(size=30)      # b1 loosely determined
    f, beta = _linear_fit(X, y, ["g"] * 30)
    ci = confidence(f, positive=["b1"])
    sd = np.sqrt(np.diag(np.linalg.inv(X.T @ X)) * max(1.0, f.cost / 28))
    w = sps.t.ppf(0.975, 28) * sd[1] / beta[1]
    assert ci["b1"] == pytest.approx((beta[1] * np.exp(-w), beta[1] * np.exp(w)), rel=1e-9)
    assert ci["b1"][0] > 0 and beta[1] - ci["b1"][0] < ci["b1"][1] - beta[1]
    assert ci["b0"][0] == pytest.approx(beta[0] - sps.t.ppf(0.975, 28) * sd[0], rel=1e-9)


def test_heldout_no_worse_is_a_paired_test_with_autocorrelation():
    rng = np.random.default_rng(5)
    e = rng.normal(size=600)
    b = dict(aicc=0.0, heldout_rmse=0.0, heldout=e + 0.2 * rng.normal(size=600))
    tie = dict(aicc=4.5, heldout_rmse=0.0, heldout=e + 0.2 * rng.normal(size=600))
    assert st.heldout_no_worse(tie, b)                  # equally good, other noise
    assert not st.heldout_no_worse(dict(tie, heldout=1.3 * b["heldout"]), b)
    # the same squared-error differences (mean 0.08, sd 0.52): in random
    # order they are significant (z about 3.8); as one slow drift they are
    # a handful of independent values (lag-1 correlation near 1)
    one = dict(aicc=0.0, heldout_rmse=0.0, heldout=np.ones(600))
    d = np.sort(0.08 + 0.9 * rng.uniform(-1.0, 1.0, 600))
    assert st.heldout_no_worse(dict(tie, heldout=np.sqrt(1.0 + d)), one)
    assert not st.heldout_no_worse(dict(tie, heldout=np.sqrt(1.0 + rng.permutation(d))), one)
    # without residual vectors: the plain comparison of RMS values
    assert st.heldout_no_worse(dict(aicc=1, heldout_rmse=1.0), dict(aicc=0, heldout_rmse=1.0))
    assert not st.heldout_no_worse(dict(aicc=1, heldout_rmse=1.01),
                                   dict(aicc=0, heldout_rmse=1.0))


def test_equivalence_class_takes_a_rival_whose_heldout_error_is_no_worse_within_noise():
    rng = np.random.default_rng(6)
    e = rng.normal(size=500)
    best = e + 0.2 * rng.normal(size=500)
    rows = [dict(aicc=0.0, heldout_rmse=1.0, heldout=best),
            dict(aicc=4.1, heldout_rmse=1.0, heldout=best[::-1]),   # the same errors
            dict(aicc=5.0, heldout_rmse=1.4, heldout=1.4 * best),   # clearly worse
            dict(aicc=30.0, heldout_rmse=0.9, heldout=0.9 * best)]  # too far by AICc
    assert st.equivalence_classes(rows) == [[0, 1], [2], [3]]
