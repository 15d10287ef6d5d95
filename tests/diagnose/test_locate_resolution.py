"""The located term's resolution and smoothing chosen by linearised
leave-one-experiment-out (acausal/diagnose/stages/locate.py, ``choose``),
its band from the fit's covariance, and the location judged by held-out
error. Fast: linear problems whose truth is known in closed form (the data
observe a force law directly through the spline basis), no simulation."""
import numpy as np
import pytest

from acausal.diagnose.library import generic as gen
from acausal.diagnose.stages import locate as L

from .locate_fakes import RANGES, Decision as _Dec, Ranking as _Rk, term as _term



def _columns(law, seed=0, n_per=400, sigma=1.0, offset=0.0):
    """Columns of a linear 'model' whose residual is the force law at
    sampled (x, v) minus the term: r = y - H_x a - H_v b, three experiments
    covering overlapping strokes, noise ``sigma`` (the floor). One free
    parameter: a constant force (which the spline also reproduces: pinned).
    Each experiment covers the whole stroke (decaying at its own rate), so
    that a held-out experiment's positions are inside the others'."""
    rng = np.random.default_rng(seed)
    xs, vs, groups = [], [], []
    for g, rate in enumerate((0.01, 0.02, 0.03)):
        t = np.linspace(0, 12 * np.pi, n_per)
        xs.append(np.cos(t + g) * np.exp(-rate * t))
        vs.append(-2.5 * np.sin(t + g) * np.exp(-rate * t))
        groups += [f"E{g}"] * n_per
    x, v = np.concatenate(xs), np.concatenate(vs)
    y = law(x) + offset + rng.normal(0, sigma, x.size)
    Hx, Hv = gen.basis(RANGES, gen.X_LADDER[-1], gen.V_LADDER[-1], x, v)
    Jg = -np.hstack([Hx, Hv])
    Jf = -np.ones((x.size, 1))
    return L.Columns(y.copy(), Jg, Jf, tuple(groups)), x


def test_coarser_splines_are_exactly_finer_ones():
    x = np.linspace(-1.0, 1.0, 301)
    w = np.random.default_rng(1).normal(size=9)
    for n_fine in (17, 33, 65):
        T = gen.refine_matrix(9, n_fine)
        fine = gen.hats(x, -1, 1, n_fine) @ (T @ w)
        assert np.max(np.abs(fine - gen.hats(x, -1, 1, 9) @ w)) < 1e-12
    with pytest.raises(ValueError):
        gen.refine_matrix(9, 20)


def test_a_six_cycle_law_gets_a_fine_resolution_and_is_recovered():
    """A force A sin(2 pi x / P) with 6 cycles over the stroke (A = 3
    floors): the chosen position resolution must resolve it (at least 33
    knots), the linearised held-out error must reach the floor within 5 %,
    and the recovered law (net of the constant the free parameter takes)
    must be within 10 % RMS of the truth over the stroke."""
    P, A = 2.0 / 6, 3.0
    law = lambda x: A * np.sin(2 * np.pi * x / P)   # noqa: E731
    cols, x = _columns(law)
    ch = L.choose(cols, RANGES, cols.r0.size)
    assert ch.n_x >= 33
    assert ch.heldout < 1.05
    w = ch.step[1:]
    grid = np.linspace(-0.95, 0.95, 400)
    fx = gen.hats(grid, RANGES[0], RANGES[1], ch.n_x) @ w[:ch.n_x]
    truth = law(grid)
    err = np.sqrt(np.mean((fx - fx.mean() - (truth - truth.mean())) ** 2)) / np.sqrt(
        np.mean(truth ** 2))
    assert err < 0.10
    # the coarse term cannot: 9 knots leave the law's misfit on held-out data
    nine = [r for r in ch.table if r[0] == 9]
    assert min(r[4] for r in nine) > 1.5


def test_a_smooth_law_and_a_null_get_the_least_complex_term():
    """A gentle law (one bend over the stroke) needs no fine spline, and
    noise alone none at all: the least complex setting within the tie wins,
    with few effective parameters, and the null's held-out error is the
    floor's."""
    cols, _ = _columns(lambda x: 2.0 * x ** 2, seed=4)
    ch = L.choose(cols, RANGES, cols.r0.size)
    assert ch.edf < 8 and ch.heldout < 1.05
    null, _ = _columns(lambda x: 0.0 * x, seed=5, offset=0.7)
    ch0 = L.choose(null, RANGES, null.r0.size)
    assert ch0.n_x == 9 and ch0.edf < 4
    assert ch0.heldout == pytest.approx(1.0, abs=0.05)


def test_a_setting_scored_alone_matches_its_score_in_the_search():
    """``linear_heldout`` (the re-choice's score of the current setting at
    its fitted point) is the score ``choose`` gives the same setting: every
    row of the search table, recomputed alone, agrees to rounding; and on
    the six-cycle law a 9-knot setting is not tied with the chosen one (the
    re-choice would refit), while the chosen one is tied with itself."""
    P, A = 2.0 / 6, 3.0
    cols, _ = _columns(lambda x: A * np.sin(2 * np.pi * x / P), seed=2)
    n = cols.r0.size
    ch = L.choose(cols, RANGES, n)
    for row in ch.table[::7]:
        assert L.linear_heldout(cols, RANGES, n, row[:4]) == pytest.approx(row[4], rel=1e-9)
    assert L.linear_heldout(cols, RANGES, n, ch.setting) <= ch.heldout * (1 + L.tie_of(n))
    nine = min((r for r in ch.table if r[0] == 9), key=lambda r: r[4])
    assert L.linear_heldout(cols, RANGES, n, nine[:4]) > ch.heldout * (1 + L.tie_of(n))


def test_band_is_the_fit_covariance():
    """Unpenalised, the band is the least-squares standard error of the
    spline's value: compared with the spread of refits over 300 noise
    draws (within 12 %)."""
    from acausal.diagnose.stages.fitting import Fit
    rng = np.random.default_rng(7)
    x = rng.uniform(-1, 1, 300)
    H = gen.hats(x, -1.2, 1.2, 9)
    Jv = gen.hats(np.zeros(300), -3, 3, 9)     # velocity part: no data (held at rest)
    J = np.hstack([H, Jv])
    names = [f"gen.a{i}" for i in range(9)] + [f"gen.b{j}" for j in range(9)]
    pen = (np.hstack([np.zeros((9, 9)), 1e3 * np.eye(9)]), np.ones(18))
    f = Fit(names, {n: 0.0 for n in names}, 300.0, rng.normal(size=300), -J,
            ["E"] * 300, ["s"] * 300)
    cov = L.weights_cov(f, pen, 300.0, 300, 9.0)
    grid = np.linspace(-1, 1, 11)
    Hg = gen.hats(grid, -1.2, 1.2, 9)
    sd = gen.band(cov, Hg, gen.hats(grid, -3, 3, 9))["f_x_sd"]
    fits = [Hg @ np.linalg.lstsq(H, rng.normal(size=300), rcond=None)[0] for _ in range(300)]
    # sigma^2 = S / (n - edf) = 300 / 291 with unit noise
    assert np.std(fits, axis=0) * np.sqrt(300 / 291) == pytest.approx(sd, rel=0.12)


def test_location_is_the_best_held_out_and_says_if_it_reaches_the_floor():
    terms = sorted([_term("m1", 2.0, 500.0), _term("m2", 1.04, 700.0)],
                   key=lambda t: t.heldout_rmse)
    loc = L._verdict(terms, _Dec(), _Rk(), 1000)
    assert loc.unexplained and loc.node == "m2" and loc.best_node == "m2"
    assert loc.heldout == pytest.approx(1.04) and loc.reaches_floor
    far = L._verdict([_term("m1", 3.0, 500.0)], _Dec(), _Rk(), 1000)
    assert not far.reaches_floor and far.heldout == pytest.approx(3.0)
    tied = L._verdict([_term("a", 1.0, 1.0), _term("b", 1.0005, 2.0)], _Dec(), _Rk(), 1000)
    assert tied.tied_nodes == ("b",)


def test_term_beside_a_cause_builds_and_its_penalty_covers_only_the_weights():
    """The term beside a named cause (candidate ``h+generic_force`` at
    ``site+node``): built with both sub-models, the cause's parameters
    first; with zero weights and zero friction it is the model file's own
    run, and the smoothing penalty's scales are the weights' only."""
    import os
    from acausal.diagnose.library import hypotheses as hy
    from acausal.diagnose.problem import Candidate, Param
    from acausal.diagnose.stages.tasks import penalty_of
    from acausal.modelfile import compile_file
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "slider_model.py")
    mf, cm = gen.build_at(path, "mass", 9, 9, ("coulomb_friction", "mass"), hy.HYPOTHESES)
    ref = compile_file(path)[1].simulate(t_end=0.25)
    res = cm.simulate(t_end=0.25)
    assert np.max(np.abs(res["mass.s"] - np.interp(res.t, ref.t, ref["mass.s"]))) < 1e-9
    moved = cm.simulate(t_end=0.25, params={f"{gen.GENERIC.prefix}.a{i}": 1.0 for i in range(9)})
    assert np.max(np.abs(moved["mass.s"] - np.interp(moved.t, ref.t, ref["mass.s"]))) > 1e-4
    own = (Param("hyp_cf.tau", 0.1, 0.0, 10.0, 0.5, 0.0),)
    w = tuple(Param(f"gen.a{i}", 0.0, -1, 1, 0.25, 0.0) for i in range(9)) + tuple(
        Param(f"gen.b{j}", 0.0, -1, 1, 0.25, 0.0) for j in range(9))
    cand = Candidate("coulomb_friction+generic_force", "mass+mass", own + w, gen.penalty(9, 9))
    assert gen.members(cand) == (("coulomb_friction", "mass"), "mass", 9, 9)
    P, sc = penalty_of(cand)
    assert P.shape[1] == sc.size == 18 and np.all(sc == 0.25)
