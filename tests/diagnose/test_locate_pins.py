"""The located term's degenerate directions (acausal/diagnose/locate.py,
degenerate_directions): closed-form cases on small Jacobians."""
import numpy as np

from acausal.diagnose.locate import PIN_TOL, degenerate_directions


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
