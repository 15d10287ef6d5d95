"""The secant (Broyden) Jacobian of acausal.differences against plain
forward differences on a least-squares problem with a closed-form optimum."""
import numpy as np
from scipy import optimize

import pytest

from acausal.studies.differences import ForwardDifferences, LinearSeed, SecantDifferences


def _problem():
    t = np.linspace(0.0, 3.0, 40)
    a, b, c = 2.0, 1.3, 0.25
    y = a * np.exp(-b * t) + c           # exact data: the optimum is (a, b, c), S = 0
    calls = []

    def res(z):
        calls.append(1)
        return z[0] * np.exp(-z[1] * t) + z[2] - y
    return res, calls, np.array([a, b, c])


def test_secant_reaches_the_same_optimum_with_fewer_evaluations():
    res, calls, truth = _problem()
    fd = ForwardDifferences(res, 1e-7, np.full(3, np.inf))
    plain = optimize.least_squares(fd, [1.0, 0.5, 0.0], jac=fd.jac, xtol=1e-12, ftol=1e-12,
                                   gtol=1e-12)
    n_plain = len(calls)
    calls.clear()
    fd2 = ForwardDifferences(res, 1e-7, np.full(3, np.inf))
    sec = SecantDifferences(fd2)
    got = optimize.least_squares(fd2, [1.0, 0.5, 0.0], jac=sec.jac, xtol=1e-12, ftol=1e-12,
                                 gtol=1e-12)
    assert np.allclose(plain.x, truth, rtol=1e-6) and np.allclose(got.x, truth, rtol=1e-6)
    assert sec.updates > 0
    assert len(calls) < n_plain


def test_a_poor_prediction_takes_fresh_differences():
    res, _, _ = _problem()
    fd = ForwardDifferences(res, 1e-7, np.full(3, np.inf))
    sec = SecantDifferences(fd, trust=0.0)       # no step is predicted exactly
    J0 = sec.jac(np.array([1.0, 0.5, 0.0]))
    J1 = sec.jac(np.array([1.5, 1.0, 0.1]))
    assert sec.fresh and sec.updates == 0
    assert np.allclose(J1, fd.jac(np.array([1.5, 1.0, 0.1])))
    assert not np.allclose(J0, J1)


def _fit(seed):
    res, calls, truth = _problem()
    fd = ForwardDifferences(res, 1e-7, np.full(3, np.inf))
    sec = SecantDifferences(fd, seed=seed, sc=np.ones(3))
    got = optimize.least_squares(fd, [1.8, 1.2, 0.2], jac=sec.jac, xtol=1e-12, ftol=1e-12,
                                 gtol=1e-12)
    return got, len(calls), sec, truth


def test_a_linear_seed_stands_for_the_first_differences():
    # the model made at a nearby point (its exact Jacobian by central differences)
    res, _, _ = _problem()
    x_ref = np.array([1.9, 1.25, 0.22])
    r_ref = res(x_ref)
    J = np.array([(res(x_ref + e) - res(x_ref - e)) / 2e-6 for e in np.eye(3) * 1e-6]).T
    seeded, n_seeded, sec, truth = _fit(LinearSeed(r_ref - J @ x_ref, J, r_ref))
    plain, n_plain, sec0, _ = _fit(None)
    assert sec.seeded and not sec0.seeded
    assert np.allclose(seeded.x, truth, rtol=1e-6) and np.allclose(plain.x, truth, rtol=1e-6)
    assert n_seeded <= n_plain - 3          # the first differences (3 evaluations) saved


def test_a_seed_that_predicts_badly_is_not_used():
    res, _, _ = _problem()
    x_ref = np.array([1.9, 1.25, 0.22])
    r_ref = res(x_ref)
    J = np.ones((r_ref.size, 3))            # nothing like the problem's Jacobian
    seeded, n_seeded, sec, truth = _fit(LinearSeed(r_ref - J @ x_ref, J, r_ref))
    plain, n_plain, _, _ = _fit(None)
    assert not sec.seeded
    assert np.array_equal(seeded.x, plain.x) and n_seeded == n_plain


def test_a_seed_of_the_wrong_shape_is_refused():
    res, _, _ = _problem()
    fd = ForwardDifferences(res, 1e-7, np.full(3, np.inf))
    bad = LinearSeed(np.zeros(5), np.zeros((5, 3)), np.zeros(5))
    with pytest.raises(ValueError, match="LinearSeed of shape"):
        SecantDifferences(fd, seed=bad).jac(np.array([1.0, 1.0, 0.0]))
