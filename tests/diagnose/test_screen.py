"""The family-member screen's one-step prediction (acausal/diagnose/screen.py):
closed forms on small linear problems."""
import numpy as np
import pytest

from acausal.diagnose.stages.screen import predicted_step


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


def test_a_bounded_step_is_the_bounded_least_squares_solution():
    # one own column, the best unbounded step negative (a friction torque
    # that would have to drive): bounded at 0, the step cannot gain
    rng = np.random.default_rng(2)
    J_own = rng.normal(size=(50, 1))
    r0 = 3.0 * J_own[:, 0] + 0.01 * rng.normal(size=50)     # wants d = -3
    free = np.zeros((50, 0))
    S_unb = predicted_cost(r0, J_own, free)
    S_b, d = predicted_step(r0, J_own, free, (np.array([0.0]), np.array([np.inf])))
    assert S_unb < 0.01 * (r0 @ r0)
    assert d[0] == pytest.approx(0.0, abs=1e-12)
    assert S_b == pytest.approx(r0 @ r0, rel=1e-12)


def test_a_bounded_step_with_columns_of_very_different_sizes():
    # a free column in parameter units of a stiffness (~1e-8 per unit) and
    # an own column per unit of scale: the closed form of the box-constrained
    # problem whose bound on the own step is active
    rng = np.random.default_rng(3)
    a, b = 1e-8 * rng.normal(size=40), rng.normal(size=40)
    r0 = -(2e7 * a + 5.0 * b)
    S, d = predicted_step(r0, b[:, None], a[:, None],
                          (np.array([-1e9, 0.0]), np.array([1e9, 2.0])))
    # own step clipped at 2; the free step is then the 1-D least squares fit
    x = -(r0 + 2.0 * b) @ a / (a @ a)
    r = r0 + x * a + 2.0 * b
    assert d[1] == pytest.approx(2.0, rel=1e-9)
    assert d[0] == pytest.approx(x, rel=1e-6)
    assert S == pytest.approx(r @ r, rel=1e-6)


COSTS = (5, 10, 15, 20, 25, 30, 40, 50, 70, 90)


def test_members_within_reach_beyond_the_budget_are_returned_unfitted():
    """Ten one-parameter members whose bounded steps reach S = 5 ... 90
    from S0 = 100 (columns along the residual, each step at its upper
    bound; unbounded, every one would reach 0); the best candidate has
    S = 30 and the nominal 100. Reach: the best + 0.5 x its gain (one free
    parameter, c = 1): members up to S = 64 are within it (eight); the best six are
    fitted, the rest within reach come back unfitted, none beyond it."""
    from types import SimpleNamespace as NS

    from acausal.diagnose.stages import screen
    from acausal.diagnose.stages import stats as st
    from acausal.diagnose.problem import Candidate, Param, Problem

    n, r0 = 200, np.full(200, np.sqrt(100.0 / 200))
    rng = np.random.default_rng(4)
    ortho = rng.normal(size=n)
    ortho -= (ortho @ r0) / (r0 @ r0) * r0
    free = (Param("k.c", 1.0, 0.0, 10.0, 1.0, 1.0),)
    problem = Problem("m.py", "", "lib", free)
    J_free = ortho[:, None] / np.linalg.norm(ortho)       # the free parameter cannot help
    f0 = NS(values={"k.c": 1.0}, names=["k.c"], jacobian=J_free, n=n, k=1)
    cands, cols = [], {}
    for i, S in enumerate(COSTS):
        c = Candidate("h", f"site{i}", (Param(f"hyp{i}.x", 0.0, 0.0, 1.0, 1.0, 0.0),))
        # a column along -r0 whose unit step (the bound) leaves S: |r0| (1 - a) = sqrt(S)
        a = 1.0 - np.sqrt(S / 100.0)
        cands.append(c)
        cols[c.key] = (r0, (-a * r0)[:, None])
    a_best = st.aicc(30.0, n, 2, 1.0)
    a0 = st.aicc(100.0, n, 1, 1.0)
    dec = NS(rows=[NS(aicc=a_best)], a0=a0, c_hat=1.0)

    def run(fn, tasks, label, checkpoint=True, progress=None):
        assert not checkpoint and progress is False    # a quick screen: no checkpoint, no bar
        return [cols[t.candidate.key] for t in tasks]

    got = screen.screened(NS(run=run), problem, NS(fit=f0), dec, cands)
    reach = a_best + max(screen.MARGIN, screen.SHARE * (a0 - a_best))
    within = [c.location for c, S in zip(cands, COSTS)
              if st.aicc(float(S), n, 2, 1.0) < reach]
    assert [c.location for c, _ in got.picks] == within[:screen.MAX_FITS]
    assert [u.label for u in got.unfitted] == [f"h at {loc}" for loc in
                                               within[screen.MAX_FITS:]]
    assert len(within) > screen.MAX_FITS and len(within) < len(cands)
    for u in got.unfitted:
        assert u.predicted_aicc < reach
