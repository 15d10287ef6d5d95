"""The pair search's score test (acausal/diagnose/pairscore.py, gains): the
candidate whose own column, made orthogonal to the best fit's columns,
explains the best fit's residuals scores highest, even where its column is
mostly a free parameter's (closed form on small Jacobians)."""
from types import SimpleNamespace

import numpy as np

from acausal.diagnose.pairscore import gains


def test_score_test_picks_what_the_best_fit_leaves():
    rng = np.random.default_rng(2)
    n = 300
    free, first = rng.normal(size=n), rng.normal(size=n)
    missing = rng.normal(size=n)                    # the second cause's own effect
    best = SimpleNamespace(jacobian=np.column_stack([free, first]),
                           residuals=0.5 * missing, n=n)
    absorbed = (5 * free + missing)[:, None]        # mostly the free parameter's column
    inside = (3 * first + free)[:, None]            # inside the best fit's span
    noise = rng.normal(size=(n, 1))
    g = gains(best, [inside, noise, absorbed, None, np.ones((n - 1, 1))])
    assert abs(g[2] - np.sum((0.5 * missing) ** 2)) < 0.1 * np.sum((0.5 * missing) ** 2)
    assert g[0] < 1e-20 and g[1] < 0.05 * g[2]
    assert np.isnan(g[3]) and np.isnan(g[4])
