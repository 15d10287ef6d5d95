"""The whitened held-out error (``fitting.whitened_heldout``) that the
verdict judges a name by (``verdict.explains``), against closed forms on
linear models: a model linear in its parameters with unit Gaussian noise,
whose leave-one-experiment-out residuals are known exactly (PRESS, here
``linear_loo``, is exact for it)."""
import math
from types import SimpleNamespace

import numpy as np
import pytest

from acausal.diagnose.stages import stats as st
from acausal.diagnose.stages import verdict as vd
from acausal.diagnose.stages.fitting import Fit, heldout_rms, linear_loo, whitened_heldout


def _design(rng, E, nh, k, lopsided):
    J = rng.normal(size=(E * nh, k))
    if lopsided:      # the last parameter is seen (almost) only in the last experiment
        J[:(E - 1) * nh, -1] *= 0.02
    groups = [f"E{i}" for i in range(E) for _ in range(nh)]
    return J, groups


def _fit(J, groups, y):
    """The least-squares fit of y ~ J b (residuals = model - data, as the
    diagnosis's, and their Jacobian)."""
    b = np.linalg.lstsq(J, y, rcond=None)[0]
    r = J @ b - y
    return Fit([f"p{i}" for i in range(J.shape[1])], {}, float(r @ r), r, J, groups, groups)


def _exceed(E, nh, k, lopsided, draws=400, seed=3):
    rng = np.random.default_rng(seed)
    J, groups = _design(rng, E, nh, k, lopsided)
    th = st.heldout_threshold(E * nh, k, E)
    raw = white = 0
    ss = []
    for _ in range(draws):
        f = _fit(J, groups, rng.normal(size=E * nh))
        loo = linear_loo(f)
        raw += heldout_rms(loo) > th.rms
        w = whitened_heldout(f, loo)
        white += w > th.rms
        ss.append(w * w * E * nh)
    return raw / draws, white / draws, float(np.mean(ss)), th


@pytest.mark.parametrize("E,nh,k", [(3, 200, 4), (6, 50, 3)])
def test_lopsided_null_plain_heldout_fails_whitened_keeps_its_level(E, nh, k):
    """One experiment alone determines a parameter: the plain held-out RMS
    of a right model exceeds the 1 % threshold most of the time (measured
    69-77 % over 3000 draws), the whitened one at about the level (0.5-0.7 %),
    and its mean square is n (chi2(n_h) per experiment, whatever the design)."""
    raw, white, mean_ss, th = _exceed(E, nh, k, True)
    assert raw > 0.5
    assert white <= 0.03
    n = E * nh
    assert abs(mean_ss - n) < 4 * math.sqrt(2 * n / 400)


def test_equal_design_null_both_within_level():
    """Every experiment an equal share: the plain threshold's own design;
    both exceed it at about its level."""
    raw, white, _, _ = _exceed(3, 200, 4, False)
    assert raw <= 0.04 and white <= 0.03


def test_woodbury_form_equals_predictive_covariance():
    """Each experiment's term is r_h' (I + J_h A_-h^-1 J_h')^-1 r_h, the
    held-out residuals' own covariance under the model (computed directly)."""
    rng = np.random.default_rng(0)
    J, groups = _design(rng, 3, 12, 3, True)
    f = _fit(J, groups, rng.normal(size=36))
    loo = linear_loo(f)
    g = np.asarray(groups)
    total = 0.0
    for h, r in loo.items():
        m = g == h
        A_out = J[~m].T @ J[~m]
        cov = np.eye(m.sum()) + J[m] @ np.linalg.solve(A_out, J[m].T)
        total += float(r @ np.linalg.solve(cov, r))
    assert whitened_heldout(f, loo) == pytest.approx(math.sqrt(total / 36), rel=1e-9)


def test_model_form_error_is_kept():
    """A law the model lacks, in a direction the other experiments
    determine (equal design), or outside the model's columns, stays in the
    whitened error: both fail the threshold."""
    rng = np.random.default_rng(5)
    E, nh, k = 3, 200, 3
    J, groups = _design(rng, E, nh, k, False)
    t = np.linspace(0, 1, E * nh)
    th = st.heldout_threshold(E * nh, k, E)
    for extra in (np.sin(40 * t), np.where(np.asarray(groups) == "E2", 1.0, 0.0)):
        f = _fit(J, groups, extra + rng.normal(size=E * nh))
        loo = linear_loo(f)
        assert whitened_heldout(f, loo) > th.rms
        assert whitened_heldout(f, loo) <= heldout_rms(loo) + 1e-12


def test_explains_judges_the_whitened_error_once_ranked():
    th = st.heldout_threshold(6000, 4, 3)
    row = SimpleNamespace(heldout_rmse=4.4, heldout_white=1.0004)
    assert vd.judged_heldout(row) == 1.0004 and vd.explains(row, th)
    unranked = SimpleNamespace(heldout_rmse=4.4, heldout_white=float("nan"))
    assert vd.judged_heldout(unranked) == 4.4 and not vd.explains(unranked, th)
    assert not vd.explains(SimpleNamespace(heldout_rmse=1.0, heldout_white=3.0), th)


def test_a_pair_earns_its_second_cause_by_the_judged_heldout_error():
    """The cam follower's dry friction + drag (numbers of that run): the
    plain held-out errors (pair 4.41, friction alone 4.37) are both the
    fastest run predicted without it; judged beyond the parameters'
    uncertainty (1.0002 against 1.0105), the pair predicts better and earns
    its drag. With the pair's judged error the worse one, it does not."""
    from acausal.diagnose.problem import Candidate, Param, pair_of
    from acausal.diagnose.stages.chain import _pair_reasons

    ssf = Candidate("stick_slip_friction", "cam", (Param("hyp_ssf.tau", 0, 0, 1, 1, 0),))
    qd = Candidate("quadratic_damping", "cam", (Param("hyp_qd.c", 0, 0, 1, 1, 0),))
    pair = SimpleNamespace(candidate=pair_of(ssf, qd), aicc=5993.65, heldout_rmse=4.409,
                           heldout_white=1.0002)
    single = SimpleNamespace(candidate=ssf, aicc=6042.9, heldout_rmse=4.375,
                             heldout_white=1.0105)
    drag = SimpleNamespace(candidate=qd, aicc=6100.0, heldout_rmse=9.96, heldout_white=1.12)
    assert _pair_reasons(pair, [pair, single, drag]) == []
    worse = SimpleNamespace(**{**vars(pair), "heldout_white": 1.02})
    (why,) = _pair_reasons(worse, [worse, single, drag])
    assert "stick_slip_friction at cam" in why and "1.0200 against 1.0105" in why
