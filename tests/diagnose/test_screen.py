"""The family-member screen's one-step prediction (acausal/diagnose/screen.py):
closed forms on small linear problems."""
import numpy as np
import pytest

from acausal.diagnose.screen import predicted_step


def predicted_cost(r0, J_own, J_free):
    return predicted_step(r0, J_own, J_free)[0]


def test_a_residual_in_the_columns_span_is_predicted_to_vanish():
    rng = np.random.default_rng(0)
    J_free, J_own = rng.normal(size=(80, 2)), rng.normal(size=(80, 1))
    r0 = J_free @ [0.3, -1.0] + 2.0 * J_own[:, 0]
    assert predicted_cost(r0, J_own, J_free) == pytest.approx(0.0, abs=1e-20)


def test_the_prediction_is_the_least_squares_residual():
    rng = np.random.default_rng(1)
    J_free, J_own = rng.normal(size=(60, 2)), rng.normal(size=(60, 2))
    r0 = rng.normal(size=60)
    A = np.hstack([J_free, J_own])
    expected = r0 @ r0 - r0 @ A @ np.linalg.solve(A.T @ A, A.T @ r0)
    assert predicted_cost(r0, J_own, J_free) == pytest.approx(expected, rel=1e-10)
    # the member's own column alone cannot do what the free ones do
    assert predicted_cost(r0, J_own, np.zeros((60, 0))) >= expected


def test_mismatched_or_broken_columns_give_nan():
    r0 = np.ones(10)
    assert np.isnan(predicted_cost(r0, np.ones((9, 1)), np.ones((10, 1))))
    bad = np.ones((10, 1))
    bad[3] = np.nan
    assert np.isnan(predicted_cost(r0, bad, np.ones((10, 1))))
