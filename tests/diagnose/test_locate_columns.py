"""The located term's data Jacobians split over idle workers
(``locate.columns_of``: a node's columns in contiguous shares, one task
each) are the columns of one task: the same forward differences, joined in
order, with every share's simulations counted. Real simulations of the
latch striker's term at its latch node, on synthetic data."""
import dataclasses
import os

import numpy as np
import pytest

from acausal.diagnose.stages import locate as L
from acausal.diagnose.stages.chain import load_problem
from acausal.diagnose.stages.tasks import FitTask
from acausal.diagnose.synth import synthesize
from acausal.infra.executor import open_executor

HERE = os.path.dirname(__file__)
LATCH = os.path.abspath(os.path.join(HERE, "..", "..", "models", "latch_striker.py"))


class _Ctx:
    """What columns_of needs of a stage context: an executor and run()."""

    def __init__(self, ex):
        self.executor = ex

    def run(self, fn, tasks, desc, checkpoint=True):
        return [f.result() for f in [self.executor.submit(fn, t) for t in tasks]]


@pytest.fixture(scope="module")
def task(tmp_path_factory):
    d = tmp_path_factory.mktemp("cols")
    synthesize(LATCH, d / "data", conditions={"F_coil": [20.0, 45.0]}, traces=["latch.s"],
               sample_rate=5e3, noise={"latch.s": 5e-6}, resolution={"latch.s": 5e-6},
               units={"time": "ms", "latch.s": "mm"}, seed=3)
    problem, _ = load_problem(LATCH, d / "data")
    cand = next(c for c, _, _ in L.generic_candidates(problem, 1, 9, 9) if c.location == "latch")
    # a point away from zero weights, where the columns depend on it
    params = tuple(dataclasses.replace(q, start=0.1 * q.scale * (-1) ** i)
                   for i, q in enumerate(cand.params))
    return FitTask(problem, dataclasses.replace(cand, params=params), problem.free)


@pytest.mark.parametrize("workers", [2, 3, 5])
def test_split_columns_are_the_columns_of_one_task(task, workers):
    whole = L.column_part(L.ColumnPart(task, 0, 1))
    assert whole.error is None and whole.Jg.shape[1] == 18 and whole.Jf.shape[1] == 2
    with open_executor("serial") as ex:
        ex.workers = workers                      # as a pool of that many would say
        (split,) = L.columns_of(_Ctx(ex), [task], "test")
    assert split.error is None
    assert np.array_equal(split.r0, whole.r0) and split.groups == whole.groups
    assert np.array_equal(split.Jg, whole.Jg) and np.array_equal(split.Jf, whole.Jf)
    assert split.n_sim == whole.n_sim + (workers - 1) * 2    # the base once more per share


def test_two_tasks_on_two_workers_are_not_split(task):
    with open_executor("serial") as ex:
        ex.workers = 2
        got = L.columns_of(_Ctx(ex), [task, task], "test")
    whole = L.column_part(L.ColumnPart(task, 0, 1))
    assert all(g.n_sim == whole.n_sim and np.array_equal(g.Jg, whole.Jg) for g in got)


def test_a_term_that_cannot_be_simulated_gives_its_error_once(task):
    bad = dataclasses.replace(task, problem=dataclasses.replace(
        task.problem, model_path="/nonexistent/model.py"))
    with open_executor("serial") as ex:
        ex.workers = 2
        (got,) = L.columns_of(_Ctx(ex), [bad], "test")
    assert got.error is not None and got.Jg.size == 0
