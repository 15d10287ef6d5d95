"""The fits' Jacobian from forward sensitivities (``FitSettings(jacobian=
"sensitivities")``; the default is forward differences): a sensitivity
Jacobian spends the evaluations of the differences it stands for (one per
parameter), so a fit has the same iterations either way (it spent none, and
a fit could run up to k + 1 times the iterations), and the fit must reach
the point the differences reach. On the independent geared drive
(tests/diagnose/independent: no acausal code in its truth) with Coulomb
friction and quadratic drag at the load, 30 floors."""
import dataclasses
import os
import sys

import numpy as np
import pytest

from acausal.diagnose.problem import FitSettings
from acausal.diagnose.stages.chain import candidates, load_problem
from acausal.diagnose.stages.fitting import Budget, Objective
from acausal.diagnose.stages.tasks import FitTask, dataset_of, fit_candidate, model_of

HERE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "independent")
sys.path.insert(0, HERE)
import cases as C  # noqa: E402
import datawriter  # noqa: E402


@pytest.fixture(scope="module")
def problem(tmp_path_factory):
    case = C.CASES["gear_friction_drag"]
    laws, _ = datawriter.scaled(case.truth, case.laws, 30.0)
    folder = tmp_path_factory.mktemp("jacobian") / "data"
    datawriter.write(folder, case.truth, laws, seed=0)
    return load_problem(case.model, folder)[0]


def _cand(problem, hypothesis, location):
    return next(c for c in candidates(problem, [hypothesis]) if c.location == location)


def _objective(problem, cand, jacobian, budget=None):
    names = problem.free_names + [p.name for p in cand.params]
    return Objective(model_of(problem, cand), dataset_of(problem), names, budget=budget,
                     jacobian=jacobian, backend="compiled")


def test_a_sensitivity_jacobian_spends_one_evaluation_per_parameter(problem):
    cand = _cand(problem, "coulomb_friction", "load")
    k = len(problem.free) + len(cand.params)
    obj = _objective(problem, cand, "sensitivities", Budget(evals=k + 1))
    x = np.array([p.start for p in problem.free] + [p.start for p in cand.params])
    obj(x)
    J = obj.jac_x(x)
    assert J.shape[1] == k and obj.n_eval == k + 1
    with pytest.raises(Exception, match="evaluations"):
        obj(x)                     # the budget of one evaluation and one Jacobian is spent


def test_the_sensitivity_fit_is_the_difference_fit(problem):
    """Coulomb friction at the load (3 parameters): the same point within
    the converged-start tolerance (S within max(0.5, 1e-3 S), each
    parameter within a quarter of its 95 % interval), with fewer simulations."""
    cand = _cand(problem, "coulomb_friction", "load")
    fits = {}
    for kind in ("differences", "sensitivities"):
        p = dataclasses.replace(problem, settings=FitSettings(jacobian=kind))
        fits[kind] = fit_candidate(FitTask(p, cand, p.free)).fit
    a, b = fits["differences"], fits["sensitivities"]
    assert a.ok and b.ok
    assert abs(a.cost - b.cost) <= max(0.5, 1e-3 * a.cost), (a.cost, b.cost)
    for n in a.names:
        lo, hi = a.ci95[n]
        assert abs(a.values[n] - b.values[n]) <= (hi - lo) / 4, n
    assert b.n_sim < a.n_sim
