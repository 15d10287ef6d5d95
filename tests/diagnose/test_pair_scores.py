"""The pair search's score test (stages._complements): the candidate whose
own column, made orthogonal to the best fit's columns, explains the best
fit's residuals is chosen, even where its column alone is mostly a free
parameter's (closed form on small Jacobians)."""
from types import SimpleNamespace

import numpy as np

from acausal.diagnose.stages import _complements


def _row(names, own, J, r):
    return SimpleNamespace(fit=SimpleNamespace(names=names, jacobian=J, residuals=r,
                                               n=r.size), own=own)


def test_score_test_picks_what_the_best_fit_leaves():
    rng = np.random.default_rng(2)
    n = 300
    free, first = rng.normal(size=n), rng.normal(size=n)
    missing = rng.normal(size=n)                    # the second cause's own effect
    best = _row(["d", "k"], ["k"], np.column_stack([free, first]), 0.5 * missing)
    # mostly the free parameter's column, plus the missing effect: absorbed alone
    absorbed = _row(["d", "c"], ["c"], np.column_stack([free, 5 * free + missing]),
                    rng.normal(size=n))
    unrelated = _row(["d", "F"], ["F"], np.column_stack([free, 3 * first + free]),
                     rng.normal(size=n))
    noise = _row(["d", "g"], ["g"], np.column_stack([free, rng.normal(size=n)]),
                 rng.normal(size=n))
    assert _complements(best, [unrelated, noise, absorbed], n=1) == [absorbed]
    # a column inside the best fit's span explains nothing and is left out
    assert unrelated not in _complements(best, [unrelated, noise, absorbed], n=2)
