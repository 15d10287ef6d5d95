"""Stage: profile-likelihood intervals where the linearised ones cannot be
trusted (:mod:`acausal.profile`, Raue et al., Bioinformatics 25 (2009)).

For the named cause's fit (or, when no cause is named, the nominal
calibration) every fitted parameter gets the cheap check first
(:func:`acausal.profile.linear_check`: two evaluations at the ends of its
Wald interval, moving the others along the linearised profile path); only a
parameter that fails it (an asymmetric or open profile, an end beyond a
bound, a Jacobian that cannot determine it) has its profile traced. The
variables are the fit's: the logarithm for a parameter whose lower bound is
above zero, value / scale otherwise; the threshold is the fit's (Student t,
the noise scaled by max(1, S/(n-k)), as :func:`.fitting.confidence`).

Each parameter is one task (:func:`profile_parameter`, a pure function of
its :class:`ProfileTask`), with a budget of :data:`MAX_SIMS` simulations: a
profile that runs out keeps the linearised interval and says so.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...studies.calibrate import FD_STEP
from .fitting import Budget, Objective
from ..problem import NOMINAL
from .tasks import dataset_of, model_of

MAX_SIMS = 2400       # simulations per parameter's check and traced profile (budget):
# counted in simulations, so a dataset of many experiments gets as much
# as one of few; 150 dataset evaluations (900 simulations of the report's
# six experiments) did not finish the report data's K profile (one point
# re-optimises the others: about 6 evaluations, up to 2 x MAX_POINTS points)
MIN_EVALS = 60        # ... but at least this many dataset evaluations
MAX_POINTS = 12       # traced points per side
CROSSING_TOL = 0.05   # the threshold crossing to 5 % of the last step


@dataclass(frozen=True)
class ProfileTask:
    """Profile parameter ``index`` of the fit of ``candidate`` (``params``:
    every fitted parameter, start = the optimum; ``jacobian``: d r / d x at
    the optimum, parameter units)."""

    problem: object               # problem.Problem
    candidate: object             # problem.Candidate
    params: tuple                 # problem.Param, start = fitted value
    index: int
    jacobian: np.ndarray
    dispersion: float
    dof: int
    penalty: object = None


@dataclass(frozen=True)
class ParamInterval:
    """One parameter's 95 % interval and how it was obtained: ``method`` is
    "linear (checked)" when the cheap check passed (the Wald interval is
    kept), "profile" when traced, "linear (profile not finished)" when the
    profile ran out of its budget. ``ratios``: actual / predicted rise of
    chi^2 at the Wald ends (1 for a linear model)."""

    name: str
    value: float
    wald: tuple
    ratios: tuple
    method: str
    lower: float | None
    upper: float | None
    open_lower: bool = False
    open_upper: bool = False
    n_eval: int = 0
    message: str = ""

    def to_dict(self, of: str) -> dict:
        return dict(of=of, value=self.value, ci95=[self.lower, self.upper],
                    method=self.method, wald=list(self.wald), check_ratios=list(self.ratios),
                    open_lower=self.open_lower, open_upper=self.open_upper,
                    n_eval=self.n_eval, message=self.message)


def _setup(task: ProfileTask):
    from ...studies.profile import Coordinates, jacobian_in_profile_variables
    ps = task.params
    x = np.array([p.start for p in ps])
    log = [p.low > 0 and p.start > 0 for p in ps]
    scale = [abs(p.scale) or 1.0 for p in ps]
    bounds = (np.array([p.low for p in ps]), np.array([p.high for p in ps]))
    J = jacobian_in_profile_variables(task.jacobian, x, log=log, scale=scale)
    ds = dataset_of(task.problem)
    obj = Objective(model_of(task.problem, task.candidate), ds, [p.name for p in ps],
                    budget=Budget(evals=budget_evals(len(ds.experiments))),
                    penalty=task.penalty, backend=task.problem.settings.integrator)
    return x, dict(coords=Coordinates(bounds, log, scale), jacobian=J), obj


def budget_evals(n_experiments: int) -> int:
    """Dataset evaluations within :data:`MAX_SIMS` simulations."""
    return max(MIN_EVALS, MAX_SIMS // max(1, n_experiments))


def profile_parameter(task: ProfileTask) -> ParamInterval:
    """The cheap check, then the profile if the check fails (module doc)."""
    from ...studies.profile import (Confidence, Tracing, linear_check, profile_likelihood,
                                    wald_halfwidths)
    x, common, obj = _setup(task)
    coords = common["coords"]
    i, name = task.index, task.params[task.index].name
    confidence = Confidence(0.95, task.dispersion, task.dof)
    thr = confidence.threshold()
    hw = float(wald_halfwidths(obj, x, log=coords.log, scale=coords.scale, thresh=thr,
                               jacobian=common["jacobian"])[i])
    wald = _wald(x[i], hw, coords.log[i], coords.scale[i])
    try:
        ok, ratios = linear_check(obj, x, i, thresh=thr, fd_step=FD_STEP, **common)
    except Exception as exc:  # noqa: BLE001 - the budget or a failed simulation
        return ParamInterval(name, x[i], wald, (), "linear (check failed)", *wald,
                             n_eval=obj.n_eval, message=f"{type(exc).__name__}: {exc}")
    if ok:
        return ParamInterval(name, x[i], wald, ratios, "linear (checked)", *wald,
                             n_eval=obj.n_eval)
    try:
        tracing = Tracing(fd_step=FD_STEP, max_points=MAX_POINTS, crossing_tol=CROSSING_TOL,
                          inner_max_nfev=10 * len(x), inner_tol=1e-6)
        pr = profile_likelihood(obj, x, i, confidence=confidence, tracing=tracing, name=name,
                                **common)
    except Exception as exc:  # noqa: BLE001 - out of budget: keep the linear interval
        return ParamInterval(name, x[i], wald, ratios, "linear (profile not finished)",
                             *wald, n_eval=obj.n_eval, message=f"{type(exc).__name__}: {exc}")
    return ParamInterval(name, x[i], wald, ratios, "profile", pr.lower, pr.upper,
                         pr.open_lower, pr.open_upper, obj.n_eval, pr.message)


def _wald(x, hw, log, scale):
    if not np.isfinite(hw):
        return (None, None)
    if log:
        return (float(x * np.exp(-hw)), float(x * np.exp(hw)))
    return (float(x - hw * scale), float(x + hw * scale))


@dataclass
class Intervals:
    """The stage's result: whose fit (``of``: a candidate label or
    "nominal") and name -> :class:`ParamInterval`."""

    of: str = ""
    params: dict = None
    skipped: str = ""

    def to_dict(self) -> dict:
        return {k: v.to_dict(self.of) for k, v in (self.params or {}).items()}


def profile_tasks(problem, cal, rk) -> tuple:
    """(label, tasks): the named cause's fit, else the nominal calibration."""
    row = rk.named
    cand, fit = (row.candidate, row.fit) if row is not None else (NOMINAL, cal.fit)
    bounds = {p.name: p for p in problem.free + cand.params}
    params = tuple(bounds[n].moved(fit.values[n]) for n in fit.names)
    dof = max(fit.n - fit.k, 1)
    disp = max(1.0, fit.cost / dof)
    pen = None
    if cand.penalty is not None:
        pen = (np.asarray(cand.penalty, float),
               np.array([abs(p.scale) or 1.0 for p in cand.params]))
    tasks = tuple(ProfileTask(problem, cand, params, i, np.asarray(fit.jacobian), disp, dof,
                              pen) for i in range(len(params)))
    return cand.label, tasks


def intervals(ctx, problem, cal, rk) -> Intervals:
    """Stage: the checked or profiled 95 % intervals (module doc)."""
    label, tasks = profile_tasks(problem, cal, rk)
    if not tasks:
        return Intervals(label, {}, "no fitted parameter")
    got = ctx.run(profile_parameter, list(tasks), "profiles", checkpoint=False)
    return Intervals(label, {r.name: r for r in got})
