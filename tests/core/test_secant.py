"""The secant (Broyden) Jacobian of acausal.differences against plain
forward differences on a least-squares problem with a closed-form optimum."""
import numpy as np
from scipy import optimize

from acausal.studies.differences import ForwardDifferences, SecantDifferences


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
