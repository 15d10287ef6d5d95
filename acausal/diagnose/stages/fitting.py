"""Output-error fits used by the diagnosis: one model (a model file, or a
model file extended with a hypothesis) fitted to a dataset by weighted least
squares with the event-correct simulation, plus its leave-one-experiment-out
errors (exact refits, or the linearised shortcut from the Jacobian).

Residuals are the calibration's (:mod:`acausal.studies.residuals`):
(simulated - measured) / sigma, sigma the instrument floor of the signal, so
every number here is in units of the noise floor (1 = what the instrument
alone explains); each experiment is simulated as :class:`FitRuns` says.
"""
from __future__ import annotations

import time
from collections import OrderedDict
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize, stats

from ...studies.calibrate import FD_STEP, SensitivityJacobian
from ...runtime import staggered
from ...runtime.staggered import SweepUnavailable
from ...studies.differences import ForwardDifferences, SecantDifferences
from ...studies.residuals import WeightedResiduals, principal_directions, resolve, \
    weighted_jacobian, weighted_residuals
from ...errors import AcausalError
from ...modelfile import evaluate_measures

PENALTY = 1e3   # weighted residual given to every sample of a failed simulation
RECENT = 16     # evaluations an Objective remembers (the optimum's residuals reused)
MAX_STEPS = 5000  # solver steps between two outputs beyond which a run counts as failed
# Finite differences (FD_STEP of each parameter's scale, absolute; see
# acausal.calibrate): the residuals of an adaptive, event-located simulation
# are not smooth below about 1e-6 relative. On the breaker, dS/d(bh) from
# forward differences changes sign between steps 1e-6 and 1e-5 and settles
# only from 1e-4 (within 2 % from 1e-4 to 1e-2). With scipy's relative step
# of 1e-5 the trust region collapsed on that noise and a quadratic-drag fit
# stopped at a tenth of its true value.


@dataclass
class Fit:
    """The result of one output-error fit (picklable, plain arrays)."""

    names: list                       # fitted parameters, in order
    values: dict                      # name -> value
    cost: float                       # S = sum of squared weighted residuals
    residuals: np.ndarray             # weighted residual vector at the optimum
    jacobian: np.ndarray              # d residual / d parameter (parameter units)
    groups: list                      # experiment name of each residual
    signals: list                     # signal name of each residual
    ci95: dict = field(default_factory=dict)
    n_sim: int = 0
    wall_s: float = 0.0               # wall time of the last least-squares run (Objective)
    cpu_s: float = 0.0                # ... and its CPU time in this process
    ok: bool = True
    message: str = ""

    @property
    def n(self):
        return int(self.residuals.size)

    @property
    def k(self):
        return len(self.names)

    def rms(self, mask=None):
        r = self.residuals if mask is None else self.residuals[mask]
        return float(np.sqrt(np.mean(r ** 2))) if r.size else float("nan")


def run_options(mf, e):
    """The simulation options of experiment ``e``: the model file's. An
    experiment with a trace and no measures is simulated only up to its
    last sample (a growing-window fit then pays only for its window), with
    output at the trace's own sample times (IDA's interpolant there, in
    place of the dense grid the samples were interpolated from: the same
    values where the samples lie on that grid, and cheaper: about a third
    of a breaker simulation went into storing its 950 dense rows for 100
    samples). With measures, the dense grid (measures need every event
    row; the samples are interpolated from it)."""
    opts = {**mf.experiment.run_options(dense=e.trace is not None), "max_steps": MAX_STEPS}
    if not e.measures and e.trace is not None and e.trace.time.size:
        opts["t_end"] = min(opts["t_end"], float(e.trace.time[-1]) * (1 + 1e-9) + 1e-12)
        opts["output_step"] = None
        opts["output_times"] = e.trace.time
    return opts


@dataclass(frozen=True)
class FitRuns:
    """How the diagnosis simulates an experiment for its residuals
    (:func:`acausal.studies.residuals.weighted_residuals`): with
    :func:`run_options` (an experiment without measures only up to its last
    trace sample, output at the sample times: a growing-window fit then pays
    only for its window), on the integrator ``backend``
    (:func:`acausal.runtime.hybrid.simulate`; None: the library's); the
    measures are evaluated only on an experiment that measures some."""

    backend: str | None = None
    staggered: bool = False   # sensitivities staggered along the run (runtime.staggered)
    scales: tuple | None = None   # the parameters' typical magnitudes (the sweep's steps)

    def __call__(self, pair, params, experiment, sensitivities=None):
        mf, cm = pair
        values = {**params, **experiment.conditions}
        if sensitivities is not None and self.staggered:
            if experiment.measures:
                raise SweepUnavailable("a measure's sensitivity needs the augmented model")
            res = staggered.simulate(cm, values, sensitivities, self.scales,
                                     backend=self.backend, **run_options(mf, experiment))
            return res, {}
        extra = {} if sensitivities is None else {"sensitivities": list(sensitivities)}
        res = cm.simulate(params=values, backend=self.backend, **extra,
                          **run_options(mf, experiment))
        return res, (evaluate_measures(mf, res) if experiment.measures else {})


def residuals_of(model, dataset, params, backend=None) -> WeightedResiduals:
    """The weighted residuals of ``model`` at ``params`` as the diagnosis's
    fits see them (:class:`FitRuns` on ``backend``). A failed run raises its
    AcausalError."""
    return weighted_residuals(model, dataset, params, FitRuns(backend))


def scaled_columns(model, dataset, base, params, step, backend=None, r0=None, inside=True):
    """(residuals at ``base``, forward-difference columns of ``params`` per
    unit of each one's scale): one simulation of every experiment per column
    (and one for ``r0`` unless given). The step is ``step`` of the scale,
    taken backwards where it would pass the parameter's upper bound when
    ``inside``. A failed run raises its AcausalError."""
    if r0 is None:
        r0 = residuals_of(model, dataset, base, backend).vector
    cols = []
    for q in params:
        scale = abs(q.scale) or 1.0
        h = step * scale
        if inside and base[q.name] + h > q.high:
            h = -h
        r = residuals_of(model, dataset, {**base, q.name: base[q.name] + h}, backend).vector
        cols.append((r - r0) / (h / scale))
    return r0, (np.array(cols).T if cols else np.zeros((r0.size, 0)))


class _OutOfTime(Exception):
    """The fit's time budget is spent (raised inside the optimiser)."""


@dataclass(frozen=True)
class Budget:
    """When an :class:`Objective` stops (:class:`_OutOfTime`): after
    ``seconds`` of wall time or ``evals`` evaluations (None: no limit)."""

    seconds: float | None = None
    evals: int | None = None


class Objective:
    """The weighted residuals of one model on one dataset as a function of
    the fitted parameters, counting simulations, keeping the best point
    seen, and stopping (:class:`_OutOfTime`) when its :class:`Budget` is
    spent. A failed simulation gives :data:`PENALTY` residuals (after a
    first success, which sets the size). ``penalty``: (rows P, scales) on the
    last P.shape[1] parameters; ``jacobian``: see :func:`refine`;
    ``backend``: the integrator (:class:`FitRuns`).
    """

    def __init__(self, model, dataset, names, fixed=None, budget=None, penalty=None,
                 jacobian="differences", backend=None):
        budget = budget or Budget()
        budget_s, max_evals = budget.seconds, budget.evals
        self.pair = resolve(model)
        self.jacobian = jacobian      # "differences", "sensitivities", ... (see refine)
        self.backend = backend
        self.penalty = penalty        # (rows P, scales) on the last P.shape[1] parameters
        self.dataset = dataset
        self.names = list(names)
        self.fixed = dict(fixed or {})
        self.budget_s, self.max_evals = budget_s, max_evals
        self.t0, self.c0 = time.perf_counter(), time.process_time()
        self.n_eval = self.n_sim = 0
        self.size = None
        self.best_cost, self.best_x = np.inf, None
        self.timed = True
        self.recent = OrderedDict()   # x bytes -> WeightedResiduals (the RECENT last)
        self.watch = None             # watch(x, data cost) after each evaluation (may raise)
        self.batch = None             # simulations of several points side by side (many)

    def params(self, x):
        return {**self.fixed, **dict(zip(self.names, np.asarray(x, float).tolist()))}

    def _check(self):
        if not self.timed:
            return
        if self.budget_s is not None and time.perf_counter() - self.t0 > self.budget_s:
            raise _OutOfTime(f"stopped at the time budget ({self.budget_s:.0f} s)")
        if self.max_evals is not None and self.n_eval >= self.max_evals:
            raise _OutOfTime(f"stopped after {self.max_evals} evaluations")

    def __call__(self, x):
        self._check()
        self.n_eval += 1
        self.n_sim += len(self.dataset.experiments)
        return self._take(x, self._simulate(x))

    def many(self, xs):
        """``[self(x) for x in xs]``: the same vectors, counts, budget stops
        and callbacks, in the same order. With ``batch`` (a callable from a
        list of parameter dicts to their :func:`residuals_of`, None where a
        simulation failed: :class:`acausal.diagnose.stages.tasks.Helpers`)
        the simulations of the points the evaluation budget allows run side
        by side first and are then taken in order, as if run one by one
        (the simulations are deterministic); so only once a first
        evaluation has set the residuals' size (a failure before it is
        raised, as :meth:`__call__` does)."""
        if self.batch is None or self.size is None or len(xs) < 2:
            return [self(x) for x in xs]
        room = len(xs)
        if self.timed and self.max_evals is not None:
            room = max(0, min(room, self.max_evals - self.n_eval))
        got = list(self.batch([self.params(x) for x in xs[:room]])) if room else []
        out = []
        for x, g in zip(xs, got + [None] * (len(xs) - room)):
            self._check()      # stops where one by one would have stopped
            self.n_eval += 1
            self.n_sim += len(self.dataset.experiments)
            out.append(self._take(x, g))
        return out

    def _simulate(self, x):
        """:func:`residuals_of` at ``x``, or the AcausalError it raised."""
        try:
            return residuals_of(self.pair, self.dataset, self.params(x), self.backend)
        except AcausalError as exc:
            return exc

    def _take(self, x, got):
        """The vector of one evaluation whose simulation gave ``got`` (a
        :class:`WeightedResiduals`, or the error / None where it failed):
        remembered, the failures as :data:`PENALTY` (raised before a first
        success sets the size), the watch called, the penalty rows added,
        the best point kept."""
        if got is None or isinstance(got, AcausalError):
            if self.size is None:
                raise got if got is not None else AcausalError("the simulation failed")
            vec = np.full(self.size, PENALTY)
        else:
            vec = self._remember(x, got).vector
            self.size = vec.size
            if not np.all(np.isfinite(vec)):
                vec = np.nan_to_num(vec, nan=PENALTY, posinf=PENALTY, neginf=-PENALTY)
        if self.watch is not None:
            self.watch(np.asarray(x, float), float(vec @ vec))
        if self.penalty is not None:
            P, sc = self.penalty
            vec = np.concatenate([vec, P @ (np.asarray(x, float)[-P.shape[1]:] / sc)])
        c = float(vec @ vec)
        if c < self.best_cost:
            self.best_cost, self.best_x = c, np.array(x, float)
        return vec

    def _remember(self, x, out):
        self.recent[np.asarray(x, float).tobytes()] = out
        while len(self.recent) > RECENT:
            self.recent.popitem(last=False)
        return out

    def residuals_at(self, x):
        """:func:`residuals_of` at ``x``: an evaluation's own output when
        ``x`` is one of the last :data:`RECENT` evaluated (the simulations are
        deterministic), else simulated (and counted)."""
        got = self.recent.get(np.asarray(x, float).tobytes())
        if got is None:
            got = residuals_of(self.pair, self.dataset, self.params(x), self.backend)
            self.n_sim += len(self.dataset.experiments)
        return got

    def jac_x(self, x, scales=None):
        """d residuals / d x from forward sensitivities
        (:func:`acausal.studies.residuals.weighted_jacobian` with :class:`FitRuns`),
        penalty rows included; a failed run raises its AcausalError. It
        spends the evaluations of the differences it stands for (one per
        parameter), so a fit's budget allows it the same iterations either way.
        ``scales``: the parameters' typical magnitudes (a staggered sweep's
        difference steps)."""
        self._check()
        self.n_eval += len(self.names)
        self.n_sim += len(self.dataset.experiments)
        J = weighted_jacobian(self.pair, self.dataset, self.params(x), self.names,
                              FitRuns(self.backend, self.jacobian.startswith("staggered"),
                                      None if scales is None else tuple(scales)))[1]
        if not np.all(np.isfinite(J)):
            from ...errors import SolverError
            raise SolverError("non-finite sensitivities")
        if self.penalty is not None:
            P, sc = self.penalty
            Jp = np.zeros((P.shape[0], len(self.names)))
            Jp[:, len(self.names) - P.shape[1]:] = P / sc
            J = np.vstack([J, Jp])
        return J


def score_starts(obj, starts, lo, hi, absorb=None):
    """Evaluate each start (an array over ``obj.names``) once; with
    ``absorb`` = (names, jacobian) of parameters calibrated beforehand, each
    start is scored after a linearised re-calibration of those parameters
    and moved there (so that a start is not rejected because a free
    parameter currently absorbs the effect). Returns [(cost, x)] sorted by
    cost (starts that fail to simulate are left out)."""
    a_idx = a_jac = None
    if absorb is not None and absorb[0]:
        a_idx = np.array([obj.names.index(n) for n in absorb[0]])
        a_jac = np.asarray(absorb[1], float)
    out = []
    for x in starts:
        x = np.clip(np.asarray(x, float), lo, hi)
        try:
            r = obj(x)
        except AcausalError:
            continue
        except _OutOfTime:
            break
        c = float(r @ r)
        m = a_jac.shape[0] if a_jac is not None else 0
        if a_jac is not None and m <= r.size:
            d = np.linalg.lstsq(a_jac, -r[:m], rcond=None)[0]
            moved = np.clip(x[a_idx] + d, lo[a_idx], hi[a_idx])
            rr = r[:m] + a_jac @ (moved - x[a_idx])
            c = float(rr @ rr) + float(r[m:] @ r[m:])   # a penalty's rows kept
            x = x.copy()
            x[a_idx] = moved
        out.append((c, x))
    return sorted(out, key=lambda cx: cx[0])


def refine(obj, x_start, lo, hi, sc, max_nfev, tol):
    """Trust-region least squares (scipy, bounded, on value/scale) from
    ``x_start`` with forward differences of a step FD_STEP of each scale,
    or with the Jacobian from forward sensitivities when ``obj.jacobian`` is
    "sensitivities" (:class:`acausal.calibrate.SensitivityJacobian`: the
    differences answer where a sensitivity run fails), from Broyden updates
    between difference Jacobians when "secant"
    (:class:`~acausal.studies.differences.SecantDifferences`), from staggered
    sensitivities when "staggered" (the same :class:`SensitivityJacobian`
    on :class:`FitRuns` with ``staggered``, giving up on the sweep where it
    cannot serve the model: the forward differences from then on) or
    "staggered_secant" (the secant differences there).
    Returns (x, jacobian in parameter units, ok, message); when the budget
    runs out the best point seen is kept and the Jacobian taken there."""
    fd = ForwardDifferences(lambda z: obj(z * sc), FD_STEP, hi / sc,
                            many=lambda zs: obj.many([z * sc for z in zs]))
    jac, kept = fd.jac, None      # kept: whose ``fresh`` says if the last Jacobian was full
    kind = getattr(obj, "jacobian", "differences")
    if kind == "sensitivities":
        jac = SensitivityJacobian(obj.jac_x, lambda z: z * sc, lambda z: sc, fd).jac
    elif kind == "secant":
        kept = SecantDifferences(fd)
        jac = kept.jac
    elif kind in ("staggered", "staggered_secant"):
        # the sweep's difference steps follow each parameter's scale; where it
        # refuses the model (events), the fallback answers from then on
        kept = SensitivityJacobian(lambda x: obj.jac_x(x, sc), lambda z: z * sc,
                                   lambda z: sc, SecantDifferences(fd)
                                   if kind == "staggered_secant" else fd,
                                   give_up=SweepUnavailable)
        jac = kept.jac
    obj.best_cost, obj.best_x = np.inf, None
    try:
        sol = optimize.least_squares(fd, x_start / sc, jac=jac, bounds=(lo / sc, hi / sc),
                                     x_scale=1.0, xtol=tol, ftol=tol, gtol=tol,
                                     max_nfev=max_nfev)
        J = sol.jac if kept is None or kept.fresh else fd.jac(sol.x)
        return sol.x * sc, J / sc, sol.status >= 0, str(sol.message)
    except _OutOfTime as stop:
        obj.timed = False
        x = obj.best_x if obj.best_x is not None else x_start
        staggered_kind = isinstance(kept, SensitivityJacobian)
        J = (kept.jac(x / sc) if staggered_kind else fd.jac(x / sc)) / sc
        if staggered_kind and not kept.fresh:
            J = fd.jac(x / sc) / sc
        obj.timed = True
        return x, J, True, f"{stop}; best point kept"


@dataclass(frozen=True)
class Refinement:
    """How :func:`fit` refines its best start: at most ``max_nfev``
    least-squares iterations, ``tol`` their xtol/ftol/gtol, the Jacobian by
    ``jacobian`` ("differences", "sensitivities", "secant", "staggered" or
    "staggered_secant": see :func:`refine`)."""

    max_nfev: int = 60
    tol: float = 1e-8
    jacobian: str = "differences"


def fit(model, dataset, params, *, fixed=None, starts=None, absorb=None, budget=None,
        refinement=Refinement()) -> Fit:
    """Weighted output-error least squares over ``params`` from the best of
    the starting points.

    ``params``: the fitted parameters, each with ``name``, ``start``,
    ``low``, ``high`` and ``scale`` (a typical magnitude: the optimiser
    works on value/scale), e.g. :class:`acausal.diagnose.problem.Param`.
    ``fixed``: other parameter overrides. ``starts``: extra starting points
    (dicts name -> value, merged into the starts), scored by
    :func:`score_starts` (with ``absorb``); the best is refined by
    :func:`refine` as ``refinement`` says. ``budget``: a :class:`Budget`
    (wall time, evaluations; the best point is kept).
    """
    names = [p.name for p in params]
    x0 = np.array([float(p.start) for p in params])
    lo = np.array([float(p.low) for p in params])
    hi = np.array([float(p.high) for p in params])
    sc = np.array([abs(float(p.scale)) or 1.0 for p in params])
    obj = Objective(model, dataset, names, fixed, budget, jacobian=refinement.jacobian)
    cands = [x0]
    for st in starts or []:
        cands.append(np.array([float(st.get(n, v)) for n, v in zip(names, x0)]))
    scored = score_starts(obj, cands, lo, hi, absorb)
    if not scored:
        return failed_fit(names, x0, obj, "every starting point failed to simulate")
    return finish(obj, *refine_or_keep(obj, scored[0][1], lo, hi, sc, refinement.max_nfev,
                                       refinement.tol), lo)


def refine_or_keep(obj, x, lo, hi, sc, max_nfev, tol):
    """:func:`refine` when there is something to fit, else the start."""
    if not obj.names:
        return x, np.zeros((0, 0)), True, ""
    return refine(obj, x, lo, hi, sc, max_nfev, tol)


def failed_fit(names, x0, obj, message):
    return Fit(list(names), dict(zip(names, np.asarray(x0, float).tolist())), float("inf"),
               np.zeros(0), np.zeros((0, len(names))), [], [], n_sim=obj.n_sim,
               wall_s=time.perf_counter() - obj.t0, cpu_s=time.process_time() - obj.c0,
               ok=False, message=message)


def finish(obj, x, J, ok, message, lo):
    """The :class:`Fit` at ``x``: residuals there (:meth:`Objective.residuals_at`:
    the optimiser's own evaluation of ``x``, or a new one), the Jacobian
    reshaped, intervals (log intervals for positive parameters)."""
    got = obj.residuals_at(x)
    r, groups, signals = got.vector, got.groups, got.signals
    names = obj.names
    J = np.asarray(J)[:r.size].reshape(r.size, len(names)) if names else np.zeros((r.size, 0))
    out = Fit(names, dict(zip(names, np.asarray(x, float).tolist())), float(r @ r), r, J,
              groups, signals, n_sim=obj.n_sim, wall_s=time.perf_counter() - obj.t0,
              cpu_s=time.process_time() - obj.c0, ok=bool(ok), message=str(message))
    out.ci95 = confidence(out, positive=[n for n, low in zip(names, lo) if low > 0])
    return out


def confidence(f: Fit, level=0.95, positive=()) -> dict:
    """Intervals from the Jacobian at the optimum (Student t), the covariance
    scaled by max(1, S/(n-k)): never narrower than the instrument model says,
    wider when the fit leaves misfit beyond the noise. A parameter in
    ``positive`` (its lower bound is above zero: a stiffness, a mass) gets its
    interval on the logarithm, as :func:`acausal.calibrate.least_squares`
    does: asymmetric, never crossing zero."""
    n, k = f.n, f.k
    if k == 0:
        return {}
    dof = n - k
    v = np.array([f.values[nm] for nm in f.names], float)
    sc = np.where(v != 0, np.abs(v), 1.0)
    Js = f.jacobian * sc                     # columns per relative change
    norms = np.linalg.norm(Js, axis=0)
    live = norms > 1e-9 * max(norms.max(initial=0.0), 1e-300)
    cov = np.full((k, k), np.inf)
    if np.any(live):
        w, V, good = principal_directions(Js[:, live])
        inv = (V[:, good] / w[good]) @ V[:, good].T
        sub = np.full(inv.shape, np.inf)
        # a parameter that loads on an unidentifiable direction gets no interval
        blind = np.abs(V[:, ~good]).max(axis=1) > 1e-3 if np.any(~good) else \
            np.zeros(len(w), bool)
        ok = ~blind
        sub[np.ix_(ok, ok)] = inv[np.ix_(ok, ok)]
        cov[np.ix_(live, live)] = sub
    s2 = f.cost / dof if dof > 0 else 1.0
    sd = np.sqrt(np.clip(np.diag(cov), 0, None) * max(s2, 1.0)) * sc
    q = stats.t.ppf(0.5 + level / 2, dof) if dof > 0 else stats.norm.ppf(0.5 + level / 2)
    out = {}
    for name, s, scale in zip(f.names, sd, sc):
        v = f.values[name]
        if name in positive and v > 0:
            # the columns of Js are derivatives per relative change, i.e. per
            # unit of log(value): s / scale is the standard deviation of log(value)
            w = min(q * s / scale, 700.0)    # exp(700) ~ 1e304: open above, not an overflow
            out[name] = (float(v * np.exp(-w)), float(v * np.exp(w)) if w < 700 else np.inf)
        else:
            out[name] = (float(v - q * s), float(v + q * s))
    return out


def linear_loo(f: Fit, penalty=None) -> dict:
    """Leave-one-experiment-out residuals predicted from the full fit.

    For experiment G, one Gauss-Newton step from the optimum without G's
    rows: delta = -lstsq(J[-G], r[-G]); predicted held-out residuals
    r[G] + J[G] delta. Exact for a model linear in its parameters (the
    classical PRESS residuals); a first-order estimate otherwise, and free
    (no simulation). ``penalty`` = (rows P, scales) of a penalised fit
    (:class:`Objective`) on its last P.shape[1] parameters: the step keeps
    the penalty rows, as the refit would (the PRESS residuals of a
    penalised fit). Returns experiment -> residual vector.
    """
    groups = np.asarray(f.groups)
    Jp, rp = _penalty_rows(f, penalty)
    out = {}
    for g in dict.fromkeys(f.groups):
        m = groups == g
        if f.k == 0 or not np.any(~m):
            out[g] = f.residuals[m]
            continue
        A = np.vstack([f.jacobian[~m], Jp])
        delta = np.linalg.lstsq(A, -np.concatenate([f.residuals[~m], rp]), rcond=None)[0]
        out[g] = f.residuals[m] + f.jacobian[m] @ delta
    return out


def _penalty_rows(f: Fit, penalty):
    """(Jacobian rows, residuals) of the penalty at the fit, in parameter units."""
    if penalty is None or f.k == 0:
        return np.zeros((0, f.k)), np.zeros(0)
    P, sc = penalty
    q = P.shape[1]
    x = np.array([f.values[n] for n in f.names[-q:]], float)
    J = np.zeros((P.shape[0], f.k))
    J[:, -q:] = P / sc
    return J, P @ (x / sc)


def penalty_cost(f: Fit, penalty) -> float:
    """The penalty rows' share of the cost at the fit (0 without a penalty)."""
    rp = _penalty_rows(f, penalty)[1]
    return float(rp @ rp)


def effective_k(f: Fit, penalty=None) -> float:
    """The number of parameters a (penalised) fit spends: the trace of its
    hat matrix, tr[J (J'J + Jp'Jp)^+ J'] (the effective degrees of freedom of
    a penalised least-squares fit; Hastie & Tibshirani, Generalized Additive
    Models, 1990, sec. 3.5). It is ``f.k`` for an unpenalised fit of full
    rank; a direction pinned by a stiff penalty row counts about zero, and a
    smoothing penalty counts a fraction of each weight it ties."""
    if f.k == 0 or f.jacobian.size == 0:
        return 0.0
    Jp, _ = _penalty_rows(f, penalty)
    J = f.jacobian
    # with [J; Jp] = U S V' the data rows of the hat matrix are U_J U_J'
    # (U_J = U's first n rows): its trace is |U_J|^2, with no normal equations
    # to square a stiff pin row's condition number
    U, s, _ = np.linalg.svd(np.vstack([J, Jp]), full_matrices=False)
    keep = s > s[0] * max(U.shape) * np.finfo(float).eps
    return float(np.sum(U[:J.shape[0], keep] ** 2))


def _scaled_information(f: Fit, penalty=None):
    """(groups, J / scale, A^-1) of a fit: its Jacobian's columns scaled to
    unit norm over the data and penalty rows, and the inverse of their
    information A = J'J (+ the penalty's rows), shared by the whitened
    held-out error and its directional part."""
    J = np.asarray(f.jacobian, float)
    Jp, _ = _penalty_rows(f, penalty)
    A_rows = np.vstack([J, Jp])
    scale = np.linalg.norm(A_rows, axis=0)
    scale[scale == 0] = 1.0
    A = (A_rows / scale).T @ (A_rows / scale)
    return np.asarray(f.groups), J / scale, np.linalg.pinv(A, rcond=1e-12, hermitian=True)


def whitened_heldout(f: Fit, loo: dict, penalty=None) -> float:
    """The held-out RMS error (noise-floor units) beyond what the parameters'
    uncertainty without each experiment allows: with ``r_h`` experiment
    h's held-out residuals (``loo``: exact refits or :func:`linear_loo`),
    ``J_h`` its rows of the full fit's Jacobian, ``g_h = J_h' r_h`` and
    ``A = J'J`` (+ the penalty's rows, a prior the refits keep)::

        sqrt( sum_h (r_h' r_h - g_h' A^-1 g_h) / n )

    For a model linear in its parameters with unit Gaussian noise the
    held-out residuals of experiment h are ``N(0, I + J_h A_-h^-1 J_h')``
    (``A_-h`` the information without h), whose inverse is ``I - J_h A^-1
    J_h'`` (Woodbury, ``A = A_-h + A_h``): each term is chi2(n_h), mean
    n_h, whatever the design. The plain held-out RMS (:func:`heldout_rms`)
    has mean ``n + sum_h tr(A_-h^-1 A_h)``, k E/(E-1) only when each
    experiment carries an equal share of the information: when one
    experiment alone determines a parameter (the fastest run a drag, the
    run without a stop the bearing's viscous loss), the others predict it
    with a parameter they do not know and its held-out error grows with
    no fault of the model's form (cam follower, dry friction + drag, the
    truth's own parameters on that run: 0.99 floors; refitted without it:
    7.4, whitened 0.99). An error the model's form leaves, in directions
    the other experiments determine, is kept whole. Judged with its
    directional part (:func:`directional_heldout`) only where the plain
    error fails (:func:`.verdict.rescued` says why). NaN without a
    Jacobian or residuals."""
    if not loo or f is None or f.jacobian is None or f.jacobian.size == 0:
        return float("nan")
    groups, Js, A_inv = _scaled_information(f, penalty)
    total, count = 0.0, 0
    for g, r in loo.items():
        r = np.atleast_1d(np.asarray(r, float))
        m = groups == g
        if m.sum() != r.size:
            return float("nan")
        gv = Js[m].T @ r
        total += float(r @ r) - float(gv @ A_inv @ gv)
        count += r.size
    return float(np.sqrt(max(total, 0.0) / count)) if count else float("nan")


@dataclass(frozen=True)
class DirectionalHeldout:
    """Per held-out experiment, the part of its residuals that the model's
    own parameters reach (:func:`directional_heldout`): ``stats[h]`` ~
    chi2(``dofs[h]``) for a right model. ``p``: the smallest experiment's
    upper tail, Bonferroni-corrected over the experiments (the folds'
    residuals are correlated through their shared data: summed, they
    exceed chi2(sum dof) at 1 % on 2-3 % of linear nulls; the corrected
    minimum keeps the level, 0.6-1.0 % measured)."""

    stats: dict = field(default_factory=dict)
    dofs: dict = field(default_factory=dict)

    def fold_p(self, h) -> float:
        d = self.dofs.get(h, 0)
        x = self.stats.get(h, float("nan"))
        return float(stats.chi2.sf(x, d)) if d > 0 and np.isfinite(x) else float("nan")

    @property
    def worst(self):
        ps = {h: self.fold_p(h) for h in self.stats}
        ps = {h: p for h, p in ps.items() if np.isfinite(p)}
        return min(ps, key=ps.get) if ps else None

    @property
    def p(self) -> float:
        h = self.worst
        return float("nan") if h is None else min(1.0, len(self.stats) * self.fold_p(h))


DIRECTION_RCOND = 1e-8   # singular values of J_h below this x the largest: no direction


def directional_heldout(f: Fit, loo: dict, penalty=None) -> DirectionalHeldout:
    """The whitened held-out residuals of each held-out experiment h within
    the span of its Jacobian rows' columns::

        T_h = r_h' P_h r_h - g_h' A^-1 g_h,   g_h = J_h' r_h

    with ``P_h`` the projector onto the columns of ``J_h`` and ``A = J'J``
    (+ the penalty's rows). For a model linear in its parameters with unit
    Gaussian noise, ``r_h ~ N(0, I + M_h)``, ``M_h = J_h A_-h^-1 J_h'``,
    whose range is that of ``J_h``: the whitened residuals
    (:func:`whitened_heldout`) split into independent parts inside and
    outside it, and the inside part is chi2(rank J_h). The whitened error
    pools it with the n_h - rank J_h values outside, where a few dozen
    floors^2 that a wrong law leaves in its parameters' directions vanish
    into thousands of degrees of freedom; here they stand against rank
    J_h. A right law whose parameter one experiment alone determines
    passes (its plain excess is the predictive spread ``M_h`` allows); a
    law that fits every run only by taking other values without each one
    does not."""
    if not loo or f is None or f.jacobian is None or f.jacobian.size == 0:
        return DirectionalHeldout()
    groups, Js, A_inv = _scaled_information(f, penalty)
    out, dofs = {}, {}
    for g, r in loo.items():
        r = np.atleast_1d(np.asarray(r, float))
        m = groups == g
        if m.sum() != r.size:
            return DirectionalHeldout()
        U, sv, _ = np.linalg.svd(Js[m], full_matrices=False)
        keep = sv > DIRECTION_RCOND * sv[0] if sv.size and sv[0] > 0 else np.zeros(0, bool)
        ur = U[:, keep].T @ r
        gv = Js[m].T @ r
        out[g] = max(float(ur @ ur) - float(gv @ A_inv @ gv), 0.0)
        dofs[g] = int(keep.sum())
    return DirectionalHeldout(out, dofs)


def heldout_rms(loo: dict) -> float:
    """RMS of all held-out residuals (noise-floor units)."""
    r = np.concatenate([np.atleast_1d(v) for v in loo.values()]) if loo else np.zeros(0)
    return float(np.sqrt(np.mean(r ** 2))) if r.size else float("nan")
