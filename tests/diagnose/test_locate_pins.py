"""The located term's degenerate directions (acausal/diagnose/locate.py,
degenerate_directions): closed-form cases on small Jacobians."""
import numpy as np
import pytest

from acausal.diagnose.stages.locate import PIN_TOL, degenerate_directions


def _span_contains(Q, w):
    w = w / np.linalg.norm(w)
    return np.linalg.norm(Q.T @ (Q @ w) - w) < 1e-8


def test_null_direction_and_reproduced_free_parameter_are_pinned():
    rng = np.random.default_rng(0)
    Jg = rng.normal(size=(200, 5))
    Jg[:, 4] = Jg[:, 3]                      # two weights with the same effect
    w_free = np.array([1.0, -2.0, 0.5, 0.0, 0.0])
    Jf = np.column_stack([Jg @ w_free,       # a free parameter the term reproduces
                          rng.normal(size=200)])   # one it cannot
    Q, s0 = degenerate_directions(Jg, Jf)
    assert Q.shape == (2, 5)
    assert np.allclose(Q @ Q.T, np.eye(2), atol=1e-12)
    assert _span_contains(Q, np.array([0, 0, 0, 1.0, -1.0]))
    assert _span_contains(Q, w_free)
    assert abs(s0 - np.linalg.svd(Jg, compute_uv=False)[0]) < 1e-9 * s0


def test_a_partly_reproduced_free_parameter_is_not_pinned():
    rng = np.random.default_rng(1)
    Jg = rng.normal(size=(200, 4))
    j = Jg @ np.array([1.0, 0.0, 0.0, 0.0])
    other = rng.normal(size=200)
    other *= 3 * PIN_TOL * np.linalg.norm(j) / np.linalg.norm(other)
    Q, _ = degenerate_directions(Jg, (j + other)[:, None])
    assert Q.shape == (0, 4)


def _fit(J, names=None):
    from acausal.diagnose.stages.fitting import Fit
    names = names or [f"w{i}" for i in range(J.shape[1])]
    return Fit(names, {n: 0.0 for n in names}, 0.0, np.zeros(J.shape[0]), J, [], [])


def test_effective_k_of_an_unpenalised_fit_is_its_parameter_count():
    from acausal.diagnose.stages.fitting import effective_k
    J = np.random.default_rng(2).normal(size=(50, 4))
    assert effective_k(_fit(J)) == pytest.approx(4.0, abs=1e-10)


def test_effective_k_drops_pinned_directions_and_counts_ridge_in_closed_form():
    """Ridge regression's degrees of freedom sum d^2/(d^2 + lam) over J's
    singular values d (Hastie & Tibshirani 1990); a stiff pin row removes
    about one."""
    from acausal.diagnose.stages.fitting import effective_k
    rng = np.random.default_rng(3)
    J = rng.normal(size=(60, 5))
    lam = 7.0
    d = np.linalg.svd(J, compute_uv=False)
    ridge = np.sqrt(lam) * np.eye(5)
    got = effective_k(_fit(J), (ridge, np.ones(5)))
    assert got == pytest.approx(float(np.sum(d ** 2 / (d ** 2 + lam))), rel=1e-10)
    pin = 1e6 * d[0] * np.array([[1.0, -1.0, 0.0, 0.0, 0.0]]) / np.sqrt(2)
    assert effective_k(_fit(J), (pin, np.ones(5))) == pytest.approx(4.0, abs=1e-6)
    scaled = effective_k(_fit(J), (pin, np.full(5, 3.0)))   # scales divide the rows
    assert scaled == pytest.approx(4.0, abs=1e-5)
