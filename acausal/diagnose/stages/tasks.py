"""Worker-side tasks of the diagnosis: pure functions of picklable inputs
returning picklable results (no shared state beyond per-process caches of
the compiled models and the dataset, :func:`acausal.executor.worker_cache`).

:func:`fit_candidate` is the unit of work of the fit stage: one candidate
(or the nominal model) fitted from several starts. Its result depends only
on its :class:`FitTask`, so a checkpoint store can key results by the task.

Multi-start (Latin hypercube, scipy.stats.qmc): the extension's parameters
are drawn over their declared bounds (log-uniform between 1/30 of the
typical magnitude and the bound, on each side the bounds allow), each
combined with the calibrated free parameters and with the model file's own
(uncalibrated) values, so that an effect the free parameters absorbed in
the calibration can be recovered. Every start is scored once, on the first
window of the traces (where the refinement starts: :class:`Refiner`), after
a linearised re-calibration of the free parameters; the best ``refine`` are
refined by least squares through the growing windows, and the result says
how many of them reached the best point and whether the extension was
tested at all.
"""
from __future__ import annotations

import concurrent.futures as cf
import dataclasses
import functools
import os
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.stats import qmc

from ...studies.calibrate import model_dataset
from ...data import Dataset, MeasuredExperiment, Trace
from ...data.thinning import MAX_TRACE_SAMPLES, MIN_TRACE_SAMPLES, thin_traces  # noqa: F401
from ...errors import AcausalError
from ...infra.executor import worker_cache
from ...modelfile import compile_file
from ...studies.residuals import subset
from .fitting import Budget, Fit, Objective, failed_fit, finish, linear_loo, penalty_cost, \
    refine_or_keep, residuals_of, score_starts
from ..library.generic import carries_generic, members as generic_members, \
    model_for as generic_model
from ..library.loader import load_library
from ..problem import LOO_TOL, Candidate, Problem


@dataclass(frozen=True)
class FitTask:
    """Fit ``candidate`` within ``problem``; ``free`` are the free
    parameters with the calibrated values as starts (the prior kept in
    ``Param.prior``); ``absorb`` = (names, Jacobian) of the nominal fit;
    ``seed_free``: values of the free parameters (in ``free``'s order) that
    go with the candidate's seeded starts, one more start (a screened
    member's Gauss-Newton step moves both); ``floors``: points (the free
    values, then the extension's, in the fit's order) the fit must end no
    higher than: a pair's members alone, each at its own fit with the other
    member neutral (:meth:`Refiner.lowest` after the multi-start)."""

    problem: Problem
    candidate: Candidate
    free: tuple
    absorb: tuple | None = None
    budget_s: float | None = None
    seed_free: tuple | None = None   # free values that go with a seeded start (a step's)
    floors: tuple = ()               # points the fit ends no higher than (a pair's members)

    @property
    def cost(self) -> float:
        """Expected cost, for ordering: simulations per least-squares step
        (one per fitted parameter, plus one) times the model's relative cost."""
        return (len(self.free) + len(self.candidate.params) + 1) * relative_cost(
            self.problem, self.candidate)


def relative_cost(problem: Problem, candidate: Candidate) -> float:
    """A candidate model's simulation cost relative to the nominal model's:
    its hypotheses' declared ``relative_cost`` (1 when they declare none;
    the largest of a pair's)."""
    if candidate.hypothesis is None:
        return 1.0
    hyps = load_library(problem.library).HYPOTHESES
    return max(float(getattr(hyps.get(h), "relative_cost", 1.0))
               for h in candidate.hypothesis.split("+"))


@dataclass
class Starts:
    """What the multi-start did: starts scored, refined, how many refined
    fits reached the best point (S within max(0.5, 1e-3 S)), and whether
    the extension was tested (False: its parameters stayed at their
    neutral values from every start and have no local effect there)."""

    scored: int = 0
    refined: int = 0
    converged: int = 0
    tested: bool = True
    from_prior: bool = False      # the best point came from the uncalibrated free values


@dataclass
class CandidateFit:
    """The result of :func:`fit_candidate` (picklable)."""

    candidate: Candidate
    fit: Fit | None
    loo: dict = field(default_factory=dict)
    error: str | None = None
    wall_s: float = 0.0
    starts: Starts = field(default_factory=Starts)

    @property
    def ok(self):
        return self.fit is not None and self.fit.ok and np.isfinite(self.fit.cost)


# -- per-process caches ---------------------------------------------------------------
def _stamp(path):
    path = os.path.abspath(path)
    return path, os.path.getmtime(path) if os.path.exists(path) else None


def dataset_of(problem: Problem):
    key = ("diagnose-dataset", _stamp(problem.model_path),
           _stamp(os.path.join(problem.data_folder, "experiments.csv")))
    return worker_cache(key, lambda: thin_traces(model_dataset(problem.model_path,
                                                               problem.data_folder)))


def model_of(problem: Problem, candidate: Candidate):
    if candidate.hypothesis is None:
        return compile_file(problem.model_path)
    if carries_generic(candidate):           # the generic term, alone or beside a cause
        return worker_cache(("diagnose-generic", _stamp(problem.model_path), problem.library,
                             generic_members(candidate), candidate.fixed),
                            lambda: generic_model(problem.model_path, candidate,
                                                  load_library(problem.library).HYPOTHESES))
    if "+" in candidate.hypothesis:          # a pair: "h1+h2" at "l1+l2"
        pair = tuple(zip(candidate.hypothesis.split("+"), candidate.location.split("+")))
        return worker_cache(("diagnose-pair", _stamp(problem.model_path), problem.library,
                             pair), lambda: load_library(problem.library).build_pair(
                                 problem.model_path, pair))
    key = ("diagnose-model", _stamp(problem.model_path), problem.library,
           candidate.hypothesis, candidate.location)
    return worker_cache(key, lambda: load_library(problem.library).build_extended(
        problem.model_path, candidate.hypothesis, candidate.location))


def window(ds: Dataset, frac: float) -> Dataset:
    """The dataset with every trace cut to the first ``frac`` of its
    duration (measures, which need the whole run, kept only at 1)."""
    if frac >= 1.0:
        return ds
    out = []
    for e in ds.experiments:
        trace = None
        if e.trace is not None:
            t = e.trace.time
            keep = t <= t[0] + frac * (t[-1] - t[0]) * (1 + 1e-9)
            trace = Trace(t[keep], {k: v[keep] for k, v in e.trace.signals.items()})
        out.append(MeasuredExperiment(e.name, e.conditions, {}, trace, e.line, e.use))
    return Dataset(ds.folder, out, ds.instrument)


# -- a lone fit's helpers -------------------------------------------------------------------
@dataclass(frozen=True)
class PointShare:
    """Some of a lone fit's evaluations, run on a worker beside it: the
    residuals of ``candidate``'s model at each of ``points`` (parameter
    name -> value dicts) on the first ``frac`` of the traces
    (:func:`window`)."""

    problem: Problem
    candidate: Candidate
    frac: float
    points: tuple


def evaluate_points(share: PointShare) -> list:
    """[:class:`~acausal.studies.residuals.WeightedResiduals`, or None where
    the simulation failed] at each of the share's points (worker side)."""
    p = share.problem
    pair, ds = model_of(p, share.candidate), window(dataset_of(p), share.frac)
    out = []
    for params in share.points:
        try:
            out.append(residuals_of(pair, ds, params, p.settings.integrator))
        except AcausalError:
            out.append(None)
    return out


@dataclass(frozen=True)
class Helpers:
    """The idle workers beside a fit that runs alone (a round of one task:
    the located term's refits, the calibration; the longest of a round of
    no more tasks than workers). The fit runs in the calling process, and
    each of its difference Jacobians is split into contiguous shares of its
    points, two per worker (:func:`evaluate_points`), which the idle
    workers take as they come, then taken in order as if simulated one by
    one (:meth:`.fitting.Objective.many`): the same fit, bit for bit, its
    Jacobians' simulations side by side instead of on one worker while the
    others wait. ``executor``: an :mod:`acausal.infra.executor` executor
    with ``workers`` > 1."""

    executor: object
    problem: Problem
    candidate: Candidate

    def on(self, frac):
        """The ``batch`` of an :class:`.fitting.Objective` on the first
        ``frac`` of the traces."""
        return functools.partial(self._evaluate, frac)

    def _evaluate(self, frac, points):
        # two shares per worker, so that a worker busy with another task
        # (a round of two) joins in as soon as it falls idle
        n, k = len(points), 2 * max(1, int(self.executor.workers or 1))
        shares = [PointShare(self.problem, self.candidate, frac,
                             tuple(points[(n * i) // k:(n * (i + 1)) // k])) for i in range(k)]
        futures = [self.executor.submit(evaluate_points, sh) for sh in shares if sh.points]
        try:
            return [r for fut in futures for r in fut.result()]
        except (cf.BrokenExecutor, cf.CancelledError) as exc:
            raise PoolLost(str(exc)) from exc


class PoolLost(Exception):
    """The executor lost a lone fit's helpers' work (a worker died, the pool
    was shut down by an interruption): not the candidate's failure, so
    :func:`fit_candidate` raises the executor's own error (``__cause__``), as
    the round would have met it with the fit on a worker, instead of
    reporting a failed fit that a checkpoint would keep."""


def fit_here(task: FitTask, executor) -> CandidateFit:
    """:func:`fit_candidate` of a lone task, run in this process with the
    ``executor``'s workers as its :class:`Helpers` (the same result)."""
    return fit_candidate(task, Helpers(executor, task.problem, task.candidate))


def calibrate_here(task: FitTask, executor) -> CandidateFit:
    """:func:`calibrate_nominal` with :class:`Helpers` (as :func:`fit_here`)."""
    return calibrate_nominal(task, Helpers(executor, task.problem, task.candidate))


# -- starting points ----------------------------------------------------------------------
def lhs_values(params, n, seed=0):
    """``n`` Latin-hypercube points over the parameters' bounds: each
    coordinate log-uniform in [scale/30, bound] on a side the bounds allow
    (the first half of the strata on the negative side when both do)."""
    if not params or n <= 0:
        return []
    u = qmc.LatinHypercube(d=len(params), seed=seed).random(n)
    out = []
    for row in u:
        x = []
        for p, ui in zip(params, row):
            sides = [s for s, b in ((1.0, p.high), (-1.0, -p.low)) if b > 0]
            if not sides:
                x.append(p.prior)
                continue
            s = sides[0] if len(sides) == 1 else (-1.0 if ui < 0.5 else 1.0)
            w = ui if len(sides) == 1 else (2 * ui) % 1.0
            top = p.high if s > 0 else -p.low
            bot = min(abs(p.scale) / 30 or top * 1e-3, top)
            x.append(s * float(np.exp(np.log(bot) + w * (np.log(top) - np.log(bot)))))
        out.append(x)
    return out


def start_points(task: FitTask):
    """[(array, from_prior)] over the free + extension parameters."""
    free, ext = task.free, task.candidate.params
    s = task.problem.settings
    cal = [p.start for p in free]
    prior = [p.prior for p in free]
    neutral = [p.prior for p in ext]
    pts = [(np.array(cal + neutral), False)]
    seeded = [p.start for p in ext]
    if seeded != neutral:                 # a seed (a pair from its single fits)
        pts.append((np.array(cal + seeded), False))
        if task.seed_free is not None:    # ... with the free values it was predicted with
            pts.append((np.array(list(task.seed_free) + seeded), False))
    differs = any(abs(a - b) > 1e-9 * max(abs(b), 1e-300) for a, b in zip(cal, prior))
    if differs and ext:
        pts.append((np.array(prior + neutral), True))
    for i, x in enumerate(lhs_values(ext, s.lhs, s.seed)):
        pts.append((np.array(cal + x), False))
        if differs and i % 2 == 0:
            pts.append((np.array(prior + x), True))
    return pts


# -- the fit of one candidate ---------------------------------------------------------------
def bounds_of(params):
    """(lower bounds, upper bounds, scales) of ``params`` (:class:`~..problem.Param`)
    as arrays; a zero scale counts as 1."""
    lo = np.array([p.low for p in params])
    hi = np.array([p.high for p in params])
    sc = np.array([abs(p.scale) or 1.0 for p in params])
    return lo, hi, sc


def _pick(scored, n_ext, sc, n):
    """The ``n`` best scored starts, the second one the best that starts
    away from the first's extension values (so a neutral best start does
    not leave the extension untried)."""
    if not scored:
        return []
    out = [scored[0]]
    for c, x in scored[1:]:
        if len(out) >= n:
            break
        far = n_ext and np.any(np.abs(x[-n_ext:] - out[0][1][-n_ext:]) > 0.05 * sc[-n_ext:])
        if far or not n_ext:
            out.append((c, x))
    return out


def _tested(fits, ext, J_best, starts=()):
    """False when every refined fit started and ended with the extension at
    its neutral values and a move by one typical magnitude changes S by
    less than 1 at the best point: the data never saw the extension act.
    (A fit started away from neutral that comes back to it is a test: the
    data rejected the effect.)"""
    if not ext:
        return True
    k = len(ext)
    neutral = np.array([p.prior for p in ext])
    sc = np.array([abs(p.scale) or 1.0 for p in ext])
    ends = [np.array([f.values[p.name] for p in ext]) for f in fits]
    if any(np.any(np.abs(x[-k:] - neutral) > 1e-3 * sc) for x in list(starts) + ends):
        return True
    if J_best.size == 0:
        return False
    effect = np.sum((J_best[:, -k:] * sc) ** 2, axis=0)
    return bool(np.any(effect >= 1.0))


def fit_candidate(task: FitTask, helpers: Helpers | None = None) -> CandidateFit:
    """Fit one candidate from several starts (module doc); never raises.
    ``helpers``: idle workers that run the difference Jacobians'
    simulations side by side (:class:`Helpers`; the same result)."""
    t0 = time.perf_counter()
    try:
        fit, starts = _multistart(task, helpers)
        loo = linear_loo(fit, penalty_of(task.candidate)) if fit.ok else {}
        return CandidateFit(task.candidate, fit, loo, None, time.perf_counter() - t0, starts)
    except PoolLost as lost:
        raise lost.__cause__ from None
    except Exception as exc:  # noqa: BLE001 - a candidate that cannot be built is reported
        return CandidateFit(task.candidate, None, {}, f"{type(exc).__name__}: {exc}",
                            time.perf_counter() - t0)


def _windows(ds, settings):
    """The growing windows of the homotopy (only the whole record when the
    data have no trace)."""
    has_trace = any(e.trace is not None for e in ds.experiments)
    return tuple(settings.windows) if has_trace else (1.0,)


def _summary(fits, scored, ext=(), tested=True, starts=()):
    best = min(fits, key=lambda f: f.cost)
    tol = max(0.5, 1e-3 * best.cost)
    if ext:
        tested = _tested(fits, ext, best.jacobian, starts)
    return best, Starts(scored, len(fits), sum(f.cost <= best.cost + tol for f in fits), tested)


def _multistart(task: FitTask, helpers=None):
    p, cand = task.problem, task.candidate
    s = p.settings
    params = list(task.free) + list(cand.params)
    names = [q.name for q in params]
    lo, hi, sc = bounds_of(params)
    ds = dataset_of(p)
    pair = model_of(p, cand)
    # starts are scored on the whole record: scored on the first window only,
    # the stop rig's pair case lost its drag's family head (power_drag named)
    obj = Objective(pair, ds, names, budget=Budget(task.budget_s), penalty=penalty_of(cand),
                    backend=s.integrator)
    pts = start_points(task)
    scored = score_starts(obj, [x for x, _ in pts], lo, hi, task.absorb)
    if not scored:
        return failed_fit(names, pts[0][0], obj, "every starting point failed"), Starts()
    picked = _pick(scored, len(cand.params), sc, s.refine)
    refiner = Refiner(pair, ds, names, lo, hi, sc, _windows(ds, s), s, task.budget_s,
                      penalty_of(cand), helpers)
    fits = refiner.all([x for _, x in picked])
    floors = [np.asarray(x, float) for x in task.floors]
    best = min(fits, key=lambda f: f.cost)
    low, used = refiner.lowest(best, floors)
    refined = [x for _, x in picked]
    if low is not best:           # a pair ended above one of its members alone
        fits.append(low)
        refined += floors
    best, starts = _summary(fits, len(scored) + len(floors), cand.params, True, refined)
    best = dataclasses.replace(best, n_sim=obj.n_sim + used + sum(f.n_sim for f in fits))
    return best, starts


def calibrate_nominal(task: FitTask, helpers: Helpers | None = None) -> CandidateFit:
    """The nominal calibration: Latin-hypercube starts over the free
    parameters' bounds plus the model file's values, scored on the first
    window of the traces; the best ``refine`` are carried through the
    growing windows (homotopy from the start of the record to all of it).
    ``helpers``: as :func:`fit_candidate`'s."""
    t0 = time.perf_counter()
    p, s = task.problem, task.problem.settings
    params = list(task.free)
    names = [q.name for q in params]
    lo, hi, sc = bounds_of(params)
    ds = dataset_of(p)
    pair = model_of(p, task.candidate)
    windows = _windows(ds, s)
    n_lhs = s.lhs if len(windows) > 1 else 0
    pts = [np.array([q.start for q in params])] + [np.array(x) for x in lhs_values(
        params, n_lhs, s.seed)]
    obj = Objective(pair, window(ds, windows[0]), names, backend=s.integrator)
    scored = score_starts(obj, pts, lo, hi)
    if not scored:
        return CandidateFit(task.candidate, None, {}, "every starting point failed",
                            time.perf_counter() - t0)
    fits = Refiner(pair, ds, names, lo, hi, sc, windows, s, helpers=helpers).all(
        [x for _, x in scored[:max(1, s.refine if n_lhs else 1)]])
    best, starts = _summary(fits, len(scored))
    best = dataclasses.replace(best, n_sim=obj.n_sim + sum(f.n_sim for f in fits))
    loo = linear_loo(best) if best.ok else {}
    return CandidateFit(task.candidate, best, loo, None, time.perf_counter() - t0, starts)


# a round of one such task runs it here, with the idle workers as its helpers
# (.context.run_tasks)
fit_candidate.alone = fit_here
calibrate_nominal.alone = calibrate_here


def penalty_of(cand):
    """(rows P, scales) of a candidate's penalty on its last P.shape[1]
    parameters (the generic term's smoothing and pins; a term fitted beside
    a cause has the cause's parameters first), or None."""
    if cand.penalty is None:
        return None
    P = np.asarray(cand.penalty, float)
    return P, np.array([abs(p.scale) or 1.0 for p in cand.params[len(cand.params) - P.shape[1]:]])


AGREE_X = 1e-2      # two refinements meet: every parameter within this many scales,
AGREE_SE = 1.0      # ... or within this many standard errors of the earlier fit (the data
AGREE_CAP = 0.1     # ... cannot tell the points apart), but never more than this many scales;
# ... and S within max(0.5, 1e-3 S) (the converged-start rule of _summary)


class _Met(Exception):
    """A refinement reached the point of an earlier one (raised inside the optimiser)."""

    def __init__(self, index):
        super().__init__(index)
        self.index = index


def agree_tolerance(fit: Fit, names, sc, last=False):
    """Per parameter: how far a point may lie from ``fit``'s and be the same
    point: one standard error of ``fit`` (a quarter of its 95 % interval),
    at least :data:`AGREE_X` of the scale, and on a window before the
    ``last`` at most :data:`AGREE_CAP` of it (a direction such a window does
    not determine, such as an effect that acts only later in the record,
    keeps the starts apart; on the whole record no later data can)."""
    se = np.array([(fit.ci95[n][1] - fit.ci95[n][0]) / 4 if n in fit.ci95 else 0.0
                   for n in names])
    se = np.nan_to_num(se, nan=0.0, posinf=np.inf)
    tol = np.maximum(AGREE_X * sc, AGREE_SE * se)
    return tol if last else np.minimum(AGREE_CAP * sc, tol)


def same_point(x, cost, fit: Fit, names, tol) -> bool:
    """The point ``x`` with data cost ``cost`` is ``fit``'s (S within the
    converged-start tolerance, every parameter within ``tol``)."""
    if not (fit.ok and np.isfinite(fit.cost) and np.isfinite(cost)):
        return False
    if abs(cost - fit.cost) > max(0.5, 1e-3 * min(cost, fit.cost)):
        return False
    xb = np.array([fit.values[n] for n in names])
    return bool(np.all(np.abs(np.asarray(x, float) - xb) <= tol))


@dataclass
class Refiner:
    """Least-squares refinement through the growing windows (homotopy from
    the start of the record to all of it: the windows before the last get a
    third of the evaluations each), of one model on one dataset.

    :meth:`all` refines several starts. A later start whose refinement
    meets an earlier one's on a window (the same point: S within the
    converged-start tolerance, every parameter within one standard error of
    the earlier fit or :data:`AGREE_X` of its scale, at most
    :data:`AGREE_CAP` of it: :func:`agree_tolerance`) would follow it from
    there: it takes that refinement's final fit (as converged, with only its
    own simulations counted) instead of repeating the rest. The meeting is
    checked at every evaluation of the optimiser, not only at the end of a
    window, so a later start stops as soon as it reaches an earlier point.
    Refinements that do not meet are carried to the end as before."""

    pair: tuple
    ds: object
    names: list
    lo: np.ndarray
    hi: np.ndarray
    sc: np.ndarray
    windows: tuple
    settings: object
    budget_s: float | None = None
    penalty: object = None
    helpers: Helpers | None = None   # idle workers for the Jacobians' simulations

    def window_fit(self, w, x, targets=()):
        """(fit on window ``w`` from ``x``, index of the ``targets`` fit it
        met or None, simulations it ran); the fit is None when an
        evaluation met a target."""
        s = self.settings
        full = s.evals_per_param * (len(self.names) + 1)
        obj = Objective(self.pair, window(self.ds, w), self.names,
                        budget=Budget(self.budget_s, full if w >= 1.0 else max(3, full // 3)),
                        penalty=self.penalty, backend=s.integrator, jacobian=s.jacobian)
        tols = [agree_tolerance(t, self.names, self.sc, w >= 1.0) for t in targets]
        obj.watch = self._watch(targets, tols) if targets else None
        obj.batch = self.helpers.on(w) if self.helpers is not None else None
        try:
            fit = finish(obj, *refine_or_keep(obj, x, self.lo, self.hi, self.sc, s.max_nfev,
                                              s.tol), self.lo)
        except _Met as met:
            return None, met.index, obj.n_sim
        met = next((j for j, (t, tol) in enumerate(zip(targets, tols)) if same_point(
            [fit.values[n] for n in self.names], fit.cost, t, self.names, tol)), None)
        return fit, met, fit.n_sim

    def _watch(self, targets, tols):
        def watch(x, cost):
            for j, (t, tol) in enumerate(zip(targets, tols)):
                if same_point(x, cost, t, self.names, tol):
                    raise _Met(j)
        return watch

    def path(self, x, earlier=()):
        """The per-window fits from ``x`` (the last on the whole record), or
        those of an ``earlier`` path it meets. ``n_sim`` of the last fit
        counts this path's own simulations on every window. A path that
        ends above its own start on the whole record is replaced by a
        refinement of the start on the whole record (:meth:`direct`)."""
        out, n_sim, x0 = [], 0, x
        for i, w in enumerate(self.windows):
            fit, met, used = self.window_fit(w, x, [p[i] for p in earlier])
            n_sim += used
            if met is not None:
                out = list(earlier[met])
                break
            out.append(fit)
            x = np.array([fit.values[n] for n in self.names])
        else:
            out[-1], used = self.direct(x0, out[-1])
            n_sim += used
        out[-1] = dataclasses.replace(out[-1], n_sim=n_sim)
        return out

    def direct(self, x0, end):
        """(fit, simulations): ``end`` (the last window's fit of the path
        from ``x0``), or, when it ends above ``x0``'s own cost on the whole
        record (beyond the converged-start tolerance), the refinement of
        ``x0`` on the whole record if that ends lower. The growing windows
        keep an oscillating trace from wrapping its phase, but a window can
        also lead away: on a breaker case a stroke-dependent coil force ran
        to its lower bound on the first 30 % of the record, and the whole
        record's refinement stayed there, 263 above the nominal model the
        candidate nests (its start), while a refinement of the start on the
        whole record reached the truth."""
        if len(self.windows) < 2 or not np.isfinite(end.cost):
            return end, 0
        return self.lowest(end, [x0], 1e-3)

    def lowest(self, end, points, rel=0.0):
        """(fit, simulations): ``end``, or, when the lowest of ``points``
        costs less on the whole record than ``end`` by more than
        max(0.5, ``rel`` S) (a failed ``end`` costs infinity), the
        refinement of that point on the whole record if it ends lower.
        Each point is simulated once (:func:`.fitting.score_starts`)."""
        if not len(points):
            return end, 0
        obj = Objective(self.pair, self.ds, self.names, budget=Budget(self.budget_s),
                        penalty=self.penalty, backend=self.settings.integrator)
        scored = score_starts(obj, points, self.lo, self.hi)
        total = end.cost + penalty_cost(end, self.penalty) if np.isfinite(end.cost) else np.inf
        if not scored or (np.isfinite(total) and total <= scored[0][0] + max(0.5, rel * total)):
            return end, obj.n_sim
        fit, _, used = self.window_fit(1.0, scored[0][1])
        better = fit.cost + penalty_cost(fit, self.penalty) < total
        return (fit if better else end), obj.n_sim + used

    def all(self, starts):
        """The final fit of each start's path, in order."""
        paths = []
        for x in starts:
            paths.append(self.path(x, paths))
        return [p[-1] for p in paths]


# -- leave-one-experiment-out refits ------------------------------------------------------------
@dataclass(frozen=True)
class LooTask:
    problem: Problem
    candidate: Candidate
    params: tuple                 # Param with the full fit's values as starts
    held: str
    max_nfev: int
    budget_s: float | None = None

    @property
    def cost(self) -> float:
        """Expected cost, for ordering (see :attr:`FitTask.cost`)."""
        return (len(self.params) + 1) * relative_cost(self.problem, self.candidate)


@dataclass
class LooResult:
    candidate: Candidate
    held: str
    residuals: np.ndarray
    values: dict
    n_sim: int


def refit_without(task: LooTask) -> LooResult:
    """Refit without experiment ``held`` (warm start), predict it."""
    ds = dataset_of(task.problem)
    pair = model_of(task.problem, task.candidate)
    train = subset(ds, [e.name for e in ds.experiments if e.name != task.held])
    names = [q.name for q in task.params]
    lo, hi, sc = bounds_of(task.params)
    s = task.problem.settings
    obj = Objective(pair, train, names,
                    budget=Budget(task.budget_s, s.evals_per_param * (len(names) + 1) // 3),
                    backend=s.integrator, jacobian=s.jacobian)
    x0 = np.array([q.start for q in task.params])
    f = finish(obj, *refine_or_keep(obj, x0, lo, hi, sc, task.max_nfev, LOO_TOL), lo)
    r = residuals_of(pair, subset(ds, [task.held]), f.values, s.integrator).vector
    return LooResult(task.candidate, task.held, r, f.values, f.n_sim)
