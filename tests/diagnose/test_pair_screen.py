"""The linearised screen of every pair (acausal/diagnose/stages/pairscreen.py),
the rules of which singles make a pair, the tie rule on constructed rate
histories (stages/kinematics.py) and a cause fitted at a tied site before it
is shown. Pure data or one graph, no fit: fast."""
import os
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.optimize import lsq_linear

from acausal.diagnose.library.loader import FamilyIndex
from acausal.diagnose.problem import Candidate, Param, Problem, free_param
from acausal.diagnose.stages import pairscreen as psc
from acausal.diagnose.stages import stats as st
from acausal.diagnose.stages.chain import Row
from acausal.diagnose.stages.fitting import Fit
from acausal.diagnose.stages.kinematics import Kinematics, Tie, tie, tied_candidates
from acausal.diagnose.stages.tasks import Starts

HERE = os.path.dirname(__file__)
RNG = np.random.default_rng(24)
N = 60
F_COL = RNG.normal(size=(N, 1))          # the free parameter's column
A_COL = RNG.normal(size=(N, 2))          # hypothesis a's two parameters
B_COL = RNG.normal(size=(N, 1))          # hypothesis b's one
R_BASE = RNG.normal(size=N) * 0.1 + F_COL[:, 0] * 0.3 + A_COL @ [0.8, -0.4] + B_COL[:, 0] * 1.5
FREE = (free_param("k.c", 0.0, -100.0, 100.0),)
WIDE = (-100.0, 100.0)


def _residuals(f, ta=(0.0, 0.0), tb=(0.0,)):
    """A model linear in its parameters: r = r_base - F f - A ta - B tb."""
    return R_BASE - F_COL[:, 0] * f - A_COL @ np.asarray(ta) - B_COL @ np.asarray(tb)


def _lsq(cols, r0, bounds=None):
    A = np.hstack(cols)
    x = (np.linalg.lstsq(A, r0, rcond=None)[0] if bounds is None
         else lsq_linear(A, r0, bounds=bounds).x)
    r = r0 - A @ x
    return x, float(r @ r)


def _fit(cols, names):
    """The exact least-squares fit of the linear model over ``names`` (the
    free parameter first), as the fit stage returns it."""
    x, S = _lsq(cols, R_BASE)
    vals = dict(zip(names, x))
    ta = [vals.get("hyp_a.p", 0.0), vals.get("hyp_a.q", 0.0)]
    tb = [vals.get("hyp_b.c", 0.0)]
    r = _residuals(vals["k.c"], ta, tb)
    return Fit(list(names), vals, float(r @ r), r, -np.hstack(cols), [], [])


def _row(hid, loc, fit, own, aicc=0.0, bounds=WIDE):
    cand = Candidate(hid, loc, tuple(Param(n, 0.0, *bounds, 1.0, 0.0) for n in own))
    return Row(cand, fit, Starts(), {}, aicc, 1.0, 1.0)


def test_the_one_step_prediction_is_exact_on_a_linear_model():
    """From the singles' own fits, the superposition of their effects with
    their columns predicts the pair's cost exactly when the residuals are
    linear in the parameters, unbounded and bounded alike."""
    f0 = _fit([F_COL], ["k.c"])
    a = _row("ha", "s1", _fit([F_COL, A_COL], ["k.c", "hyp_a.p", "hyp_a.q"]),
             ["hyp_a.p", "hyp_a.q"])
    b = _row("hb", "s2", _fit([F_COL, B_COL], ["k.c", "hyp_b.c"]), ["hyp_b.c"])
    _, S_pair = _lsq([F_COL, A_COL, B_COL], R_BASE)
    S, d = psc.predict(f0, FREE, a, b, lambda n: WIDE)
    assert S == pytest.approx(S_pair, rel=1e-9)
    assert S < min(a.fit.cost, b.fit.cost) - 1.0     # the pair explains what neither does
    # the step lands on the pair's own optimum (free, a's two, b's one)
    x, _ = _lsq([F_COL, A_COL, B_COL], R_BASE)
    got = [a.fit.values["k.c"] + b.fit.values["k.c"] - f0.values["k.c"] + d[0],
           a.fit.values["hyp_a.p"] + d[1], a.fit.values["hyp_a.q"] + d[2],
           b.fit.values["hyp_b.c"] + d[3]]
    np.testing.assert_allclose(got, x, rtol=1e-8, atol=1e-10)
    # b's parameter bounded to [0, 1] (its optimum is 1.5): the bounded optimum
    _, S_b = _lsq([F_COL, A_COL, B_COL], R_BASE,
                  bounds=([-100, -100, -100, 0.0], [100, 100, 100, 1.0]))
    S1, _ = psc.predict(f0, FREE, a, b, lambda n: (0.0, 1.0) if n == "hyp_b.c" else WIDE)
    assert S1 == pytest.approx(S_b, rel=1e-6) and S1 > S_pair


def _fake(hid, loc, aicc, cost=10.0, n=4):
    names = ["k.c", f"hyp_{hid}.x"]
    fit = Fit(names, {n_: 0.0 for n_ in names}, cost, np.zeros(n), np.zeros((n, 2)), [], [])
    return _row(hid, loc, fit, [names[1]], aicc)


INDEX = FamilyIndex({"cf": ("friction", 0), "cvf": ("friction", 1), "qd": ("drag", 0)},
                    {"friction": ("cf", "cvf"), "drag": ("qd",)})


def test_one_family_at_one_site_is_never_a_pair_but_two_families_are():
    rows = [_fake("cf", "rotor", 1.0), _fake("cvf", "rotor", 2.0), _fake("qd", "rotor", 3.0),
            _fake("cf", "shaft", 4.0), _fake("cl", "rotor", 5.0)]
    f0 = Fit(["k.c"], {"k.c": 0.0}, 20.0, np.zeros(4), np.zeros((4, 1)), [], [])
    got = {frozenset(p.key) for p in psc.screen_all(f0, FREE, rows, INDEX, 1.0)}
    pairs = {frozenset(((a.candidate.key), (b.candidate.key)))
             for i, a in enumerate(rows) for b in rows[i + 1:]}
    left_out = pairs - got
    assert left_out == {frozenset({("cf", "rotor"), ("cvf", "rotor")})}
    assert frozenset({("cf", "rotor"), ("qd", "rotor")}) in got       # one site, two families
    assert frozenset({("cf", "rotor"), ("cf", "shaft")}) in got       # one law, two sites
    assert frozenset({("cvf", "rotor"), ("cf", "shaft")}) in got      # one family, two sites
    assert psc.same_cause(INDEX, Candidate("cf", "rotor"), Candidate("cf", "rotor"))
    assert not psc.same_cause(INDEX, Candidate("cf", "rotor"), Candidate("cl", "rotor"))
    # pairs already fitted are not screened again
    done = {frozenset({("cf", "rotor"), ("qd", "rotor")})}
    assert done.isdisjoint({p.key for p in psc.screen_all(f0, FREE, rows, INDEX, 1.0, done)})


def _pred(single_aicc, aicc, name):
    a, b = _fake(name, "s1", single_aicc), _fake(name + "b", "s2", single_aicc + 5)
    gain = max(0.0, single_aicc - aicc)
    return psc.Predicted(a, b, 0.0, aicc, single_aicc, psc.MARGIN + psc.SHARE * gain)


def test_pairs_within_the_screens_reach_of_the_best_are_fitted():
    """The best predicted pair gains 100 AICc units over its better member:
    its pessimistic AICc is 0 + 10 + 50 = 60. A pair predicted at 40 whose
    own gain is 20 (optimistic 40 - 20 = 20) is within reach; one at 100
    predicted to gain nothing (optimistic 90) is not."""
    best, near, far = _pred(100.0, 0.0, "p"), _pred(60.0, 40.0, "q"), _pred(100.0, 100.0, "r")
    fit, beyond = psc.picks(sorted([far, near, best], key=lambda p: p.aicc))
    assert [p.a.candidate.hypothesis for p in fit] == ["p", "q"] and beyond == []
    fit, beyond = psc.picks([best, near], limit=1)
    assert fit == [best] and beyond == [near]
    # a fitted pair that beat its prediction: its under-prediction is
    # reported as a share of its predicted gain
    fitted = {best.key: 0.0, near.key: -80.0}
    assert psc.observed_share([best, near, far], fitted) == pytest.approx((40 + 80 - 10) / 20)
    # the second round: reach measured against the best pair fitted, with
    # the stated share; a pair left beyond the limit of the first is fitted
    # now when it reaches the fitted best (optimistic 40 - 10 - 10 = 20)
    more, left = psc.more_picks([best, near, far], {best.key: 0.0}, 30.0, 5)
    assert more == [near] and left == []
    more, left = psc.more_picks([best, near, far], {best.key: 0.0}, 30.0, 0)
    assert more == [] and left == [near]
    more, left = psc.more_picks([best, near, far], {best.key: 0.0}, 30.0, 5, {near.key})
    assert more == [] and left == []          # attempted (its fit failed): not again
    more, left = psc.more_picks([best, near, far], fitted, -80.0, 5)
    assert more == [] and left == []          # the fitted best is beyond every prediction


def _crank(n=4000, low=0.68):
    """A crank slowing down and the guide of a slider-crank (rate -r
    sin(theta) w, sin(theta) falling from 1 to ``low`` late in each run,
    where the crank is slow), three experiments joined."""
    out_w, out_g = [], []
    for w0 in (3.0, 4.0, 5.0):
        t = np.linspace(0, 1, n)
        w = w0 * (1 - 0.85 * t)
        out_w.append(w)
        out_g.append(-0.05 * (1 - (1 - low) * t ** 4) * w)
    return np.concatenate(out_w), np.concatenate(out_g)


def test_a_ratio_that_varies_over_the_runs_is_not_a_tie():
    """The guide's rate is -r sin(theta) times the crank's, sin(theta) from
    0.68 to 1: the angle between the two rate histories is under 5 % (the
    old rule tied them), the ratio itself varies by 38 %: not tied. A
    four-bar's ratio varying by +-2.5 % is a tie, at its mean ratio."""
    w, g = _crank(low=0.68)
    cos = w @ g / np.linalg.norm(w) / np.linalg.norm(g)
    assert np.sqrt(1 - cos ** 2) < 0.05
    assert tie(w, g) is None and tie(g, w) is None
    w, g = _crank(low=0.96)
    ratio, spread = tie(w, g)
    assert ratio == pytest.approx(-0.05, rel=0.02) and spread <= 0.05
    # a rigid lever: exactly proportional, no spread
    assert tie(w, -0.05 * w) == pytest.approx((-0.05, 0.0), abs=1e-12)
    # a site at rest half of the time is compared only where the divisor moves
    v = np.where(np.arange(w.size) % 2 == 0, w, 0.0)
    assert tie(v, 2.0 * v) == pytest.approx((2.0, 0.0), abs=1e-12)


def test_a_cause_at_a_tied_site_is_fitted_at_the_other_site_too():
    """Coulomb friction named at the lever's slider, tied to the wheel at
    the arm ARM: the same law at the wheel is a candidate, seeded at the
    torque the arm converts the force to; a pair member moves likewise, the
    other member kept; rows already fitted there, and rows far behind the
    best, are left alone."""
    lever = os.path.join(HERE, "lever_model.py")
    problem = Problem(lever, "", "acausal.diagnose.library.hypotheses",
                      (free_param("k.c", 500.0, 200.0, 1000.0),))
    kin = Kinematics((Tie("wheel", "slider", -0.05, 1e-8),), ())

    def row(hid, loc, values, aicc):
        cand = Candidate(hid, loc, tuple(Param(k, 0.0, 0.0, 1e3, 1.0, 0.0)
                                         for k in values if k.startswith("hyp")))
        fit = Fit(list(values), dict(values), 1.0, np.zeros(3), np.zeros((3, len(values))),
                  [], [])
        return Row(cand, fit, Starts(), {}, aicc, 1e-10, 1.0)

    cf = row("coulomb_friction", "slider", {"k.c": 500.0, "hyp_cf.F": 0.08}, 0.0)
    far = row("constant_load", "slider", {"k.c": 500.0, "hyp_cl.F": 1.0}, 50.0)
    (c,) = tied_candidates(problem, kin, [cf, far])
    assert (c.hypothesis, c.location) == ("coulomb_friction", "wheel")
    assert c.params[0].start == pytest.approx(0.08 * 0.05)   # force x |arm| = torque
    assert c.params[0].prior == 0.0
    there = row("coulomb_friction", "wheel", {"k.c": 500.0, "hyp_cf.tau": 0.004}, 0.5)
    assert tied_candidates(problem, kin, [cf, there]) == []
    assert tied_candidates(problem, kin, [cf], allowed=lambda loc: loc == "slider") == []
    pair = row("coulomb_friction+constant_load", "slider+tip",
               {"k.c": 500.0, "hyp_cf.F": 0.08, "hyp_cl.F": 0.3}, 0.0)
    (p,) = tied_candidates(problem, kin, [pair])
    assert (p.hypothesis, p.location) == ("coulomb_friction+constant_load", "wheel+tip")
    assert [q.start for q in p.params] == pytest.approx([0.004, 0.3])
    assert tied_candidates(problem, Kinematics(), [cf]) == []



def test_rigidly_tied_sites_are_one_place_and_loose_ties_are_not():
    """A gear (spread 3e-14) and a chain of rigid ties through a third site
    make one place, named by its first site; a tie at 2 % (a four-bar over
    its stroke) leaves its sites apart; no ties, no places."""
    kin = Kinematics((Tie("motor", "load", 0.2, 3e-14), Tie("hook", "shaft", -1.6e-3, 0.02),
                      Tie("pin", "hook", -1.0, 1e-4), Tie("lever", "pin", 2.0, 5e-4)))
    assert kin.places() == {"motor": "load", "load": "load", "pin": "hook", "hook": "hook",
                            "lever": "hook"}
    assert kin.places(tol=1e-6) == {"motor": "load", "load": "load"}
    assert Kinematics().places() == {}


def test_a_pair_at_rigidly_tied_sites_is_screened_once():
    """The geared drive's motor and load as one place: Coulomb friction at
    both is one law (not a pair), and of the four placements of friction +
    drag only the first predicted is screened; without places each
    placement is its own pair."""
    places = {"motor": "load", "load": "load"}
    rows = [_fake("cf", "load", 1.0), _fake("cf", "motor", 1.0), _fake("qd", "load", 2.0),
            _fake("qd", "motor", 2.0), _fake("cl", "frame", 3.0)]
    assert psc.same_cause(INDEX, Candidate("cf", "motor"), Candidate("cf", "load"), places)
    assert not psc.same_cause(INDEX, Candidate("cf", "motor"), Candidate("cf", "load"))
    f0 = Fit(["k.c"], {"k.c": 0.0}, 20.0, np.zeros(4), np.zeros((4, 1)), [], [])
    every = [p.key for p in psc.screen_all(f0, FREE, rows, INDEX, 1.0)]
    once = [p.key for p in psc.screen_all(f0, FREE, rows, INDEX, 1.0, places=places)]
    assert len(every) == 10 and frozenset({("cf", "motor"), ("cf", "load")}) in every
    placed = [psc.placed_key(tuple(k), places) for k in once]
    assert sorted(map(sorted, placed)) == sorted(map(sorted, [
        {("cf", "load"), ("qd", "load")}, {("cf", "load"), ("cl", "frame")},
        {("qd", "load"), ("cl", "frame")}]))
    assert frozenset({("cf", "load"), ("qd", "load")}) in once     # the first placement


def test_the_other_placements_of_a_pair_at_rigid_sites_are_fitted_from_its_fit():
    """A pair fitted at the lever's slider (rigidly tied to the wheel at the
    arm ARM) and the free tip: its friction moved to the wheel, seeded at
    the torque the arm converts the force to, the other member and the
    free parameter at the pair's fit; a loose tie, a single cause, or a
    placement already fitted gives nothing."""
    from acausal.diagnose.stages.chain import placement_tasks
    from acausal.diagnose.stages.kinematics import placements
    lever = os.path.join(HERE, "lever_model.py")
    problem = Problem(lever, "", "acausal.diagnose.library.hypotheses",
                      (free_param("k.c", 500.0, 200.0, 1000.0),))

    def fitted(hid, loc, values):
        cand = Candidate(hid, loc, tuple(Param(k, 0.0, 0.0, 1e3, 1.0, 0.0)
                                         for k in values if k.startswith("hyp")))
        fit = Fit(list(values), dict(values), 1.0, np.zeros(3), np.zeros((3, len(values))),
                  [], [])
        return SimpleNamespace(candidate=cand, fit=fit)

    pair = fitted("coulomb_friction+constant_load", "slider+tip",
                  {"k.c": 510.0, "hyp_cf.F": 0.08, "hyp_cl.F": 0.3})
    rigid = Kinematics((Tie("wheel", "slider", -0.05, 1e-8),), ())
    ((row, cand),) = placements(problem, rigid, [pair])
    assert row is pair
    assert (cand.hypothesis, cand.location) == ("coulomb_friction+constant_load", "wheel+tip")
    assert [q.start for q in cand.params] == pytest.approx([0.08 * 0.05, 0.3])
    cal = SimpleNamespace(fit=pair.fit, nominal=SimpleNamespace(wall_s=0.1))
    (task,) = placement_tasks(problem, cal, [(row, cand)])
    assert [q.start for q in task.free] == [510.0]
    assert task.problem.settings.windows == (1.0,) and task.problem.settings.lhs == 0
    loose = Kinematics((Tie("wheel", "slider", -0.05, 0.02),), ())
    assert placements(problem, loose, [pair]) == []
    single = fitted("coulomb_friction", "slider", {"k.c": 500.0, "hyp_cf.F": 0.08})
    assert placements(problem, rigid, [single]) == []
    # a single cause (a family member) moves too when asked, unless the
    # other placement is among the rows already fitted
    ((_, moved),) = placements(problem, rigid, [single], singles=True)
    assert (moved.hypothesis, moved.location) == ("coulomb_friction", "wheel")
    assert moved.params[0].start == pytest.approx(0.08 * 0.05)
    at_wheel = fitted("coulomb_friction", "wheel", {"k.c": 500.0, "hyp_cf.tau": 0.004})
    assert placements(problem, rigid, [single], singles=True, fitted=[at_wheel]) == []
    there = fitted("coulomb_friction+constant_load", "wheel+tip",
                   {"k.c": 510.0, "hyp_cf.tau": 0.004, "hyp_cl.F": 0.3})
    assert placements(problem, rigid, [pair, there]) == []
