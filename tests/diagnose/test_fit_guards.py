"""Guards against a fit that misses the minimum it could reach, the cause
of wrong names in the breaker's detection-power table (docs/diagnosis.md,
"Wrong causes named, session 8"):

* a growing-window path that ends above its own start on the whole record
  is replaced by the start's refinement on the whole record
  (``tasks.Refiner.direct``; on the slider of test_outputs.py, simulated);
* a screened family member's predicted step moves the free parameters too,
  and that point is one of its fit's starts (``screen._free_step``,
  ``FitTask.seed_free``);
* when a pair is best, each member is refitted alone from the pair's point
  (``stages.member_refit_tasks``), and a candidate fitted twice keeps its
  lower fit (``stages._lowest_per_key``). Pure data except the first."""
import os

import numpy as np
import pytest

from acausal.data import Dataset, MeasuredExperiment, Instrument, Trace
from acausal.diagnose.stages.fitting import Fit
from acausal.diagnose.problem import Candidate, FitSettings, Param, Problem
from acausal.diagnose.stages.screen import _free_step
from acausal.diagnose.stages.chain import NominalFit, Row, _lowest_per_key, member_refit_tasks
from acausal.diagnose.stages.tasks import CandidateFit, FitTask, Refiner, Starts, start_points
from acausal.modelfile import compile_file

SLIDER = os.path.join(os.path.dirname(__file__), "slider_model.py")
TIMES = np.arange(0.0, 0.25 + 1e-12, 5e-3)


def _slider_data(c=100.0):
    """Noise-free slider traces (x = 0.1 cos(sqrt(c) t)), rate ``c``."""
    x = 0.1 * np.cos(np.sqrt(c) * TIMES)
    return Dataset(None, [MeasuredExperiment("a", dict(s0=0.1, v0=0.0), {},
                                             Trace(TIMES, {"mass.s": x}))],
                   {"mass.s": Instrument("mass.s", 0.0, 1e-4)})


def _fit(values, cost):
    names = list(values)
    return Fit(names, dict(values), cost, np.zeros(3), np.zeros((3, len(names))), [], [])


def test_a_path_that_ends_above_its_start_is_refined_from_the_start():
    ds = _slider_data()
    lo, hi, sc = np.array([50.0]), np.array([200.0]), np.array([50.0])
    ref = Refiner(compile_file(SLIDER), ds, ["spring.c"], lo, hi, sc, (0.3, 1.0),
                  FitSettings(max_nfev=30))
    start = np.array([95.0])                   # S about 1e5 on the whole record
    astray = _fit({"spring.c": 180.0}, 1e7)    # where a window might have led
    got, n_sim = ref.direct(start, astray)
    assert got is not astray and n_sim > 1
    assert got.cost < 1.0 and abs(got.values["spring.c"] - 100.0) < 0.1
    # a path that ends at or below its start is kept (one evaluation spent)
    good = _fit({"spring.c": 100.0}, 0.0)
    kept, n_sim = ref.direct(start, good)
    assert kept is good and n_sim == 1
    # one window only: nothing to check
    kept, n_sim = Refiner(compile_file(SLIDER), ds, ["spring.c"], lo, hi, sc, (1.0,),
                          FitSettings()).direct(start, astray)
    assert kept is astray and n_sim == 0


def test_a_screened_step_moves_the_free_parameters_too():
    free = (Param("k.c", 60.0, 10.0, 100.0, 50.0, 50.0),
            Param("k.b", 0.2, 0.0, 1.0, 0.1, 0.2))
    problem = Problem("m.py", "", "lib", free, FitSettings(lhs=0, refine=1))
    f0 = _fit({"k.b": 0.3, "k.c": 60.0}, 1.0)            # the calibration's order differs
    assert _free_step(problem, f0, np.array([-0.1, 70.0])) == pytest.approx((100.0, 0.2))
    cand = Candidate("h", "a", (Param("hyp_h.k", 2.0, -5.0, 5.0, 1.0, 0.0),))
    task = FitTask(problem, cand, free, seed_free=(55.0, 0.25))
    pts = [list(x) for x, _ in start_points(task)]
    assert [60.0, 0.2, 0.0] in pts and [60.0, 0.2, 2.0] in pts
    assert [55.0, 0.25, 2.0] in pts      # the step's point, as predicted


def _row(hid, loc, values, cost=1.0):
    cand = Candidate(hid, loc, tuple(Param(k, 0.0, -10.0, 10.0, 1.0, 0.0)
                                     for k in values if k.startswith("hyp")))
    return Row(cand, _fit(values, cost), Starts(), {}, cost, 1.0, 1.0)


class _Dec:
    def __init__(self, rows):
        self.rows, self.failed = tuple(rows), ()


def _cal():
    fit = _fit({"k.c": 50.0}, 10.0)
    fit.jacobian = np.ones((3, 1))
    return NominalFit(CandidateFit(Candidate(None, None, ()), fit, wall_s=0.1))


def test_a_best_pair_has_its_members_refitted_alone_from_its_point():
    problem = Problem("m.py", "", "lib", (Param("k.c", 50.0, 10.0, 100.0, 50.0, 50.0),),
                      FitSettings())
    pair = _row("h+h", "a+b", {"k.c": 61.0, "hyp_h.k": 2.0, "hyp_h2.k": -3.0}, cost=5.0)
    rows = [pair, _row("h", "a", {"k.c": 52.0, "hyp_h.k": 0.5}, cost=9.0),
            _row("h", "b", {"k.c": 53.0, "hyp_h.k": -0.5}, cost=9.5)]
    tasks = member_refit_tasks(problem, _cal(), _Dec(rows))
    assert [t.candidate.key for t in tasks] == [("h", "a"), ("h", "b")]
    for t, k in zip(tasks, (2.0, -3.0)):
        (p,) = t.candidate.params
        assert (p.name, p.start, p.prior) == ("hyp_h.k", k, 0.0)   # the pair's value
        assert [q.start for q in t.free] == [61.0] and t.free[0].prior == 50.0
        st = t.problem.settings
        assert st.refine == 1 and st.lhs == 0 and st.windows == (1.0,)
    # a single on top: nothing to refit
    assert member_refit_tasks(problem, _cal(), _Dec(rows[1:] + rows[:1])) == []


def test_a_candidate_fitted_twice_keeps_its_lower_fit():
    c = Candidate("h", "a", ())
    first = CandidateFit(c, _fit({"k.c": 1.0}, 3066.0))
    again = CandidateFit(c, _fit({"k.c": 2.0}, 695.0))
    other = CandidateFit(Candidate("g", "a", ()), _fit({"k.c": 1.0}, 800.0))
    assert _lowest_per_key([first, other, again]) == [again, other]
    assert _lowest_per_key([again, other, first]) == [again, other]


def test_a_pair_fit_has_a_floor_at_each_member_alone():
    """``chain.with_floors``: the free values and the member's own at its
    single fit, the other member at its neutral value (pure data)."""
    from acausal.diagnose.stages.chain import with_floors
    problem = Problem("m.py", "", "lib", (Param("k.c", 50.0, 10.0, 100.0, 50.0, 50.0),),
                      FitSettings())
    a = _row("h", "a", {"k.c": 52.0, "hyp_h.k": 0.5})
    b = _row("g", "b", {"k.c": 47.0, "hyp_g.k": -0.5})
    cand = Candidate("h+g", "a+b", (Param("hyp_h.k", 0.4, -10.0, 10.0, 1.0, 0.0),
                                     Param("hyp_g.k", -0.3, -10.0, 10.0, 1.0, 0.0)))
    task = FitTask(problem, cand, problem.free)
    got = with_floors(task, {r.candidate.key: r for r in (a, b)}).floors
    assert got == ((52.0, 0.5, 0.0), (47.0, 0.0, -0.5))
    # a member with no single fit has no floor; a single candidate has none
    assert with_floors(task, {a.candidate.key: a}).floors == ((52.0, 0.5, 0.0),)
    assert with_floors(FitTask(problem, a.candidate, problem.free), {}).floors == ()


def test_a_fit_that_ends_above_a_floor_is_refined_from_it():
    """``Refiner.lowest``: a multi-start's end above one of the floors (a
    pair's member alone) is replaced by the refinement of the lowest floor
    on the whole record; an end at or below every floor is kept (one
    simulation per floor). On the simulated slider, rate 100."""
    ds = _slider_data()
    lo, hi, sc = np.array([50.0]), np.array([200.0]), np.array([50.0])
    ref = Refiner(compile_file(SLIDER), ds, ["spring.c"], lo, hi, sc, (1.0,),
                  FitSettings(max_nfev=30))
    stuck = _fit({"spring.c": 180.0}, 1e7)
    got, n_sim = ref.lowest(stuck, [np.array([150.0]), np.array([97.0])])
    assert got is not stuck and n_sim > 2
    assert got.cost < 1.0 and abs(got.values["spring.c"] - 100.0) < 0.1
    good = _fit({"spring.c": 100.0}, 0.0)
    kept, n_sim = ref.lowest(good, [np.array([150.0]), np.array([97.0])])
    assert kept is good and n_sim == 2
    assert ref.lowest(good, []) == (good, 0)


def test_scored_starts_keep_the_penalty_rows_when_the_free_parameters_are_absorbed():
    """``fitting.score_starts`` with ``absorb``: the data rows are moved by
    the linearised re-calibration, the penalty's rows (after them) still
    count (a leftover line had dropped them)."""
    from acausal.diagnose.stages.fitting import score_starts

    class _Obj:
        names = ["k.c", "hyp.w"]

        def __call__(self, x):       # 3 data rows on k.c, 1 penalty row on hyp.w
            return np.array([x[0] - 1.0, x[0] - 1.0, x[0] - 1.0, 10.0 * x[1]])

    J = np.ones((3, 1))              # the nominal's Jacobian of the data rows on k.c
    (c, x), = score_starts(_Obj(), [np.array([3.0, 0.2])], np.array([-9.0, -9.0]),
                           np.array([9.0, 9.0]), (["k.c"], J))
    assert x[0] == pytest.approx(1.0)          # the data rows absorbed
    assert c == pytest.approx(4.0)             # the penalty row's (10 * 0.2)^2
