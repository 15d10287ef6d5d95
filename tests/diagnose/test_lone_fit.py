"""A fit that runs alone (a round of one task: the located term's refits,
the calibration; the longest of a round of no more tasks than workers)
runs in the calling process with the idle workers as its helpers
(``tasks.Helpers``): its difference Jacobians' simulations are split over
them and taken in order as if run one by one (``fitting.Objective.many``).
The result must be the fit of one worker, bit for bit, with the same
simulations counted; an evaluation budget must stop it where it stops one
by one; a dead pool is the round's error, not the candidate's. Real
simulations of the latch striker (its generic located term, 18 weights,
and a Coulomb friction) on synthetic data, on a real pool of two
processes."""
import concurrent.futures as cf
import dataclasses
from concurrent.futures.process import BrokenProcessPool

import numpy as np
import pytest

from acausal.diagnose.stages import context as C
from acausal.diagnose.stages import locate as L
from acausal.diagnose.stages.chain import candidates
from acausal.diagnose.stages.fitting import Budget, Objective, residuals_of
from acausal.diagnose.stages.tasks import FitTask, Helpers, dataset_of, fit_candidate, \
    fit_here, model_of
from acausal.infra.executor import open_executor

from .latch_data import latch_friction_problem


@pytest.fixture(scope="module")
def problem(tmp_path_factory):
    # the data hold a friction the nominal model lacks, so the fits move
    return latch_friction_problem(tmp_path_factory.mktemp("lone") / "data", seed=3)


@pytest.fixture(scope="module")
def located(problem):
    cand = next(c for c, _, _ in L.generic_candidates(problem, 1, 9, 9) if c.location == "latch")
    return FitTask(problem, cand, problem.free)


def _same(a, b):
    assert a.error is None and b.error is None
    fa, fb = a.fit, b.fit
    assert fa.names == fb.names and fa.values == fb.values
    assert fa.cost == fb.cost and fa.n_sim == fb.n_sim and fa.ok == fb.ok
    assert np.array_equal(fa.residuals, fb.residuals) and np.array_equal(fa.jacobian, fb.jacobian)
    assert a.loo.keys() == b.loo.keys()
    assert a.starts == b.starts


@pytest.mark.parametrize("which", ["located", "friction"])
def test_a_lone_fit_with_helpers_is_the_fit_of_one_worker(problem, located, which):
    if which == "located":
        task = located
    else:
        cand = candidates(problem, ["coulomb_friction"])[0]
        task = FitTask(problem, cand, problem.free)
    alone = fit_candidate(task)
    assert alone.fit.n_sim > 4 * (len(task.free) + len(task.candidate.params))   # Jacobians ran
    with open_executor(workers=2) as ex:
        assert ex.kind == "processes" and ex.workers == 2
        counted = _Counting(ex)
        shared = fit_here(task, counted)
    _same(alone, shared)
    # the workers ran the Jacobians' simulations (at least two Jacobians of
    # every parameter, each in up to two shares per worker)
    assert counted.points >= 2 * (len(task.free) + len(task.candidate.params))
    assert counted.shares >= 4


class _Counting:
    """An executor that counts the shares and points submitted to it."""

    def __init__(self, ex):
        self.ex, self.kind, self.workers = ex, ex.kind, ex.workers
        self.shares = self.points = 0

    def submit(self, fn, share):
        self.shares += 1
        self.points += len(share.points)
        return self.ex.submit(fn, share)


def test_a_round_of_one_task_runs_here_with_helpers(problem, located):
    seen = []

    def fn(task):
        raise AssertionError("a lone task with an alone form is not submitted")

    def alone(task, ex):
        seen.append((task, ex))
        return "here"

    fn.alone = alone

    class Pool:                                   # what run_tasks reads of an executor
        kind, workers = "processes", 2

        def submit(self, f, t):
            raise AssertionError("not submitted")

        def as_completed(self, futures):
            assert not futures
            return iter(())

    pool = Pool()
    got = []
    assert C.run_tasks(pool, fn, [located], "t", False, lambda t, r: got.append(r)) == ["here"]
    assert seen == [(located, pool)] and got == ["here"]


def _submitted(task):
    return "submitted"


_submitted.alone = lambda task, ex: "here"


def test_serial_or_more_tasks_than_workers_are_submitted_as_before(located):
    fn = _submitted
    with open_executor("serial") as ex:
        ex.workers = 2                          # serial: nothing to share, whatever it says
        assert C.run_tasks(ex, fn, [located], "t", False) == ["submitted"]
    with open_executor(workers=2) as ex:
        # more tasks than workers: every one submitted
        assert C.run_tasks(ex, fn, [located] * 3, "t", False) == ["submitted"] * 3
        # no more than workers: the longest here, the others submitted
        short = dataclasses.replace(located, candidate=dataclasses.replace(
            located.candidate, params=located.candidate.params[:2]))
        assert C.run_tasks(ex, fn, [short, located], "t", False) == ["submitted", "here"]


def test_an_evaluation_budget_stops_the_batch_where_one_by_one_stops(problem, located):
    pair, ds = model_of(problem, located.candidate), dataset_of(problem)
    names = [q.name for q in located.candidate.params]
    rng = np.random.default_rng(0)
    xs = [0.05 * rng.standard_normal(len(names)) * np.array([q.scale for q in
                                                            located.candidate.params])
          for _ in range(8)]
    batches = []

    def serial_batch(points):
        batches.append(len(points))
        return [residuals_of(pair, ds, p, problem.settings.integrator) for p in points]

    def run(batched):
        obj = Objective(pair, ds, names, budget=Budget(evals=6),
                        backend=problem.settings.integrator)
        obj(np.zeros(len(names)))                 # the base: sets the size
        if batched:
            obj.batch = serial_batch
        # the Objective's budget stop (its own exception, named by its message)
        with pytest.raises(Exception, match="stopped after 6 evaluations"):
            obj.many(xs)
        return obj

    one, many = run(False), run(True)
    assert batches == [5]                          # only what the budget allows is simulated
    assert one.n_eval == many.n_eval == 6 and one.n_sim == many.n_sim
    assert one.best_cost == many.best_cost and np.array_equal(one.best_x, many.best_x)
    assert [k for k in one.recent] == [k for k in many.recent]


def test_helpers_split_points_in_order_over_the_workers(problem, located):
    with open_executor(workers=2) as ex:
        h = Helpers(ex, problem, located.candidate)
        pts = [{q.name: 0.01 * i * q.scale for q in located.candidate.params} for i in range(5)]
        got = h.on(1.0)(pts)
    pair, ds = model_of(problem, located.candidate), dataset_of(problem)
    want = [residuals_of(pair, ds, p, problem.settings.integrator) for p in pts]
    assert len(got) == 5
    assert all(np.array_equal(g.vector, w.vector) for g, w in zip(got, want))


def test_a_round_of_two_gives_the_fits_of_one_worker_each(problem, located):
    """Two tasks on two workers: the longer runs here with the other
    worker's help once that worker is done with the shorter."""
    friction = FitTask(problem, candidates(problem, ["coulomb_friction"])[0], problem.free)
    tasks = [friction, located]
    want = [fit_candidate(t) for t in tasks]
    with open_executor(workers=2) as ex:
        got = C.run_tasks(ex, fit_candidate, tasks, "t", False)
    for a, b in zip(want, got):
        _same(a, b)


class _Broken:
    """An executor whose workers have died."""

    kind, workers = "processes", 2

    def submit(self, fn, *args):
        fut = cf.Future()
        fut.set_exception(BrokenProcessPool("a worker died"))
        return fut


def test_a_lost_pool_under_a_lone_fit_is_raised_not_reported_as_a_failed_fit(problem, located):
    """A fit on a worker meets a dead pool in the round itself; a fit run
    here must not turn it into the candidate's failure (which a checkpoint
    would keep as the candidate's result)."""
    with pytest.raises(BrokenProcessPool):
        fit_here(located, _Broken())


def _stopped(task, ex):
    raise KeyboardInterrupt


def _stopping(task):
    return "submitted"


_stopping.alone = _stopped


def test_a_round_stopped_while_its_task_runs_here_keeps_what_the_workers_finished(located):
    finished = cf.Future()
    finished.set_result("done on a worker")

    class Pool:
        kind, workers = "processes", 2

        def submit(self, fn, task):
            return finished

        def as_completed(self, futures):
            return iter(futures)

    kept = []
    short = dataclasses.replace(located, candidate=dataclasses.replace(
        located.candidate, params=located.candidate.params[:2]))
    with pytest.raises(KeyboardInterrupt):
        C.run_tasks(Pool(), _stopping, [short, located], "t", False,
                    lambda t, r: kept.append((t, r)))
    assert kept == [(short, "done on a worker")]
