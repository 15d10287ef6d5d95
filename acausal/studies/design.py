"""The next experiment, computed: model-discrimination design.

Given rival models that explain the data so far equally well, find the
experiment (conditions within their declared ranges, and the signal to
record) whose predicted outcomes differ most between the rivals, measured
against the instrument's noise floor (Hunter and Reiner, "Designs for
discriminating between two rival models", Technometrics 7 (1965); Box and
Hill, "Discrimination among mechanistic models", Technometrics 9 (1967)).

Criterion (Hunter-Reiner, with the rivals at their fitted parameters): for
rivals a and b and a signal with floor sigma,

    D_ab = sum over samples of ((y_a - y_b) / sigma)^2,

the rise of chi^2 that the wrong rival would show (before refitting) if the
other one were true. With more than two rivals the experiment maximises the
smallest D over the pairs (it must split every pair). The *separation in
floors* reported is sqrt(min D): the norm of the difference of predictions
in noise-floor units (10 floors: the wrong rival's chi^2 rises by 100);
``rms_floors`` is the same per sample.

Search: a Latin hypercube over the conditions' ranges
(``scipy.stats.qmc.LatinHypercube``), then a bounded Powell refinement
(``scipy.optimize.minimize``) of log(min D) from the best few points. A
rival that cannot predict an experiment (its simulation fails: it returns
None) makes that experiment unusable.

A rival is any callable conditions -> {signal: samples} (all rivals sample
at the same times); :class:`ModelRival` makes one from a model file (or a
(ModelFile, CompiledModel) pair) and a parameter set, through the public
``CompiledModel.simulate`` and ``Result`` API.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import combinations
from typing import Callable, Mapping, Sequence

import numpy as np
from scipy import optimize
from scipy.stats import qmc

from ..errors import AcausalError, UsageError
from ..modelfile import compile_file, evaluate_measures
from .residuals import principal_directions

Rival = Callable[[Mapping[str, float]], "Mapping[str, np.ndarray] | None"]


@dataclass(frozen=True)
class Condition:
    """An experiment condition the experimenter can set: a model parameter
    (an impact velocity, a start position) and its range [low, high]."""

    name: str
    low: float
    high: float
    unit: str = ""


@dataclass(frozen=True)
class Signal:
    """A signal the instrument could record, with its noise floor (per-sample
    standard deviation, the signal's units)."""

    name: str
    floor: float
    unit: str = ""


@dataclass(frozen=True)
class NextExperiment:
    """The computed next experiment.

    ``conditions``: name -> value; ``signal``: what to record;
    ``separation``: sqrt of the smallest pairwise D (noise floors, see the
    module docstring) at that experiment; ``rms_floors``: the same per
    sample; ``closest_pair``: the two rivals that are hardest to split there;
    ``pairwise``: "a | b" -> separation of every pair; ``predictions``:
    rival -> predicted samples of ``signal``; ``baseline``: the smallest
    separation at the reference conditions (``reference`` of
    :func:`design_experiment`; None if not given); ``decisive``: the
    separation reaches ``min_separation`` of :func:`design_experiment`, else
    ``message`` says that no experiment in the declared ranges splits them;
    ``times``: the sample times of the predictions, when given; ``spread``:
    the largest rival's prediction spread from its parameters' uncertainty
    there (RMS, floors; 0 for rivals without it)."""

    conditions: dict
    signal: str
    separation: float
    rms_floors: float
    closest_pair: tuple
    pairwise: dict
    predictions: dict
    n_evaluations: int
    baseline: float | None = None
    decisive: bool = True
    message: str = ""
    times: np.ndarray | None = None
    spread: float = 0.0     # the largest rival's prediction spread there (RMS, floors)

    def to_dict(self) -> dict:
        """JSON-ready (the diagnosis's ``next_experiment`` key)."""
        return dict(conditions={k: float(v) for k, v in self.conditions.items()},
                    signal=self.signal, separation_floors=float(self.separation),
                    rms_floors=float(self.rms_floors), closest_pair=list(self.closest_pair),
                    pairwise={k: float(v) for k, v in self.pairwise.items()},
                    predictions={k: np.asarray(v, float).tolist()
                                 for k, v in self.predictions.items()},
                    n_evaluations=self.n_evaluations,
                    baseline_floors=None if self.baseline is None else float(self.baseline),
                    decisive=self.decisive, message=self.message,
                    spread_floors=float(self.spread),
                    times=None if self.times is None else np.asarray(self.times).tolist())


def conditions_of(modelfile) -> list:
    """The :class:`Condition` list a model file declares (its ``conditions``)."""
    out = []
    for n, (lo, hi, unit) in modelfile.conditions.items():
        if lo is None:
            raise UsageError(f"{modelfile.path}: condition {n!r} has no range; declare "
                             f"conditions = {{{n!r}: (low, high, unit)}} to search it")
        out.append(Condition(n, lo, hi, unit))
    return out


@dataclass(frozen=True)
class _Score:
    """Separation of one experiment: the best signal's smallest pairwise D."""

    d2: float
    signal: str | None
    pairwise: dict
    predictions: dict
    spread: float = 0.0        # the largest rival spread on ``signal`` (RMS, floors)
    merit: float = -math.inf   # d2, weighed down where the spread passes MAX_SPREAD


def score(predictions: Mapping[str, Mapping[str, np.ndarray] | None],
          signals: Sequence[Signal],
          variances: Mapping[str, Mapping[str, np.ndarray]] | None = None,
          max_spread: float = math.inf) -> _Score:
    """The score of one experiment from each rival's predicted signals: for
    each signal the smallest pairwise D, and the signal where it is
    largest. D is Hunter-Reiner's sum of squared differences over floor^2;
    with ``variances`` (rival -> {signal: the variance of its prediction
    from its parameters' uncertainty, per sample}) each sample's squared
    difference is over floor^2 + both rivals' variances (Box and Hill 1967;
    Buzzi-Ferraris and Forzatti, Chem. Eng. Sci. 38 (1983)): an experiment
    whose outcome a rival predicts only loosely (a cam started just at the
    energy that carries it over its top: one standard deviation of a
    parameter decides whether it goes over) separates nothing.

    ``max_spread`` [floors]: where a rival's spread (RMS over the samples)
    exceeds it, the experiment's merit is D (max_spread / spread)^2. The
    criterion is a linearisation: it assumes each rival's prediction is
    linear in its parameters within their uncertainty, and a fit that must
    move its parameters by more than their spread to follow the new run
    travels a landscape the linearisation does not see (the cam at w0 =
    24.76: 3.5 floors of spread, and with that run added a wrong pair was
    fitted best; at w0 = 25.0, 0.95 floors, the true pair was)."""
    names = list(predictions)
    if len(names) < 2:
        raise UsageError("experiment design needs at least two rival models")
    if any(p is None for p in predictions.values()):
        return _Score(-math.inf, None, {}, {})
    var = variances or {}
    best = _Score(-math.inf, None, {}, {})
    for sig in signals:
        ys = {n: np.asarray(predictions[n][sig.name], float) for n in names}
        vs = {n: np.asarray((var.get(n) or {}).get(sig.name, 0.0), float) for n in names}
        pair = {f"{a} | {b}": float(np.sum(((ys[a] - ys[b]) / np.sqrt(
                    sig.floor ** 2 + vs[a] + vs[b])) ** 2)) for a, b in combinations(names, 2)}
        d2 = min(pair.values())
        spread = max(float(np.sqrt(np.mean(v))) / sig.floor for v in vs.values())
        merit = d2 * min(1.0, (max_spread / spread) ** 2) if spread > 0 else d2
        if np.isfinite(merit) and merit > best.merit:
            best = _Score(d2, sig.name, pair, ys, spread, merit)
    return best


MAX_SPREAD = 1.0     # floors: a rival's prediction spread beyond which an experiment is weighed down


def rival_outcome(job):
    """(prediction, variance or None) of one rival at one experiment, ``job``
    = (rival, conditions): the rival's predicted signals and, for a rival
    that gives one (a ``spread(conditions, prediction)`` method, as
    :class:`ModelRival` with its parameters' covariance), the variance of
    that prediction. A module-level function of one picklable job, so that
    a ``map_jobs`` may run the rivals in worker processes (:func:`predicted`)."""
    rival, conditions = job
    pred = rival(conditions)
    spread = getattr(rival, "spread", None)
    return pred, (spread(conditions, pred) if pred is not None and callable(spread) else None)


def serial_map(fn, jobs) -> list:
    """``[fn(job) for job in jobs]``: the design's default ``map_jobs``."""
    return [fn(job) for job in jobs]


def predicted(rivals: Mapping[str, Rival], conditions, signals,
              max_spread: float = MAX_SPREAD, map_jobs: Callable = serial_map) -> _Score:
    """:func:`score` of every rival at ``conditions``, with the variance of
    each prediction for the rivals that give one (:func:`rival_outcome`).
    ``map_jobs(fn, jobs)``: runs ``fn`` on each job, results in job order (the
    diagnosis passes its executor's, so the rivals simulate side by side;
    each rival's simulations are the same wherever they run)."""
    jobs = [(r, conditions) for r in rivals.values()]
    return _scored(rivals, map_jobs(rival_outcome, jobs), signals, max_spread)


def _scored(rivals, outcomes, signals, max_spread):
    pred = {n: o[0] for n, o in zip(rivals, outcomes)}
    var = {n: o[1] for n, o in zip(rivals, outcomes) if o[1] is not None}
    return score(pred, signals, var, max_spread)


class _Evaluator:
    """Every rival at one experiment (unit-cube coordinates), cached;
    ``map_jobs`` as :func:`predicted`'s."""

    def __init__(self, rivals, conditions, signals, fixed, map_jobs=serial_map):
        self.rivals, self.conds, self.signals = dict(rivals), list(conditions), list(signals)
        self.fixed = dict(fixed or {})
        self.lo = np.array([c.low for c in self.conds], float)
        self.span = np.array([c.high - c.low for c in self.conds], float)
        self.map_jobs = map_jobs
        self.cache, self.n = {}, 0

    def values(self, unit) -> dict:
        x = self.lo + np.clip(unit, 0.0, 1.0) * self.span
        return {**self.fixed, **{c.name: float(v) for c, v in zip(self.conds, x)}}

    @staticmethod
    def key(unit) -> tuple:
        return tuple(np.round(np.clip(unit, 0.0, 1.0), 12))

    def __call__(self, unit) -> _Score:
        self.prefetch([unit])
        return self.cache[self.key(unit)]

    def prefetch(self, units) -> None:
        """Evaluate the experiments ``units`` not in the cache, every rival
        at every one of them in one ``map_jobs`` (each counted in ``n``, in order)."""
        keys = list(dict.fromkeys(k for k in (self.key(u) for u in units)
                                  if k not in self.cache))
        conds = [self.values(np.array(k)) for k in keys]
        jobs = [(r, c) for c in conds for r in self.rivals.values()]
        outcomes = self.map_jobs(rival_outcome, jobs) if jobs else []
        m = len(self.rivals)
        for i, k in enumerate(keys):
            self.n += 1
            self.cache[k] = _scored(self.rivals, outcomes[i * m:(i + 1) * m], self.signals,
                                    MAX_SPREAD)

    def loss(self, unit) -> float:
        """-log(1 + min D): smooth enough for Powell, finite where a rival fails."""
        s = self(unit)
        return -math.log1p(s.merit) if np.isfinite(s.merit) else 1e3


@dataclass(frozen=True)
class Search:
    """How the conditions' ranges are searched: a Latin hypercube of
    ``n_initial`` points (default 8 per condition, at least 12), then a
    bounded Powell search from the ``n_refine`` best, each of at most
    ``max_refine_evals`` evaluations; ``seed`` of the hypercube;
    ``map_jobs(fn, jobs)``: how the rivals' predictions are computed
    (:func:`predicted`; the hypercube's points all in one call)."""

    n_initial: int | None = None
    n_refine: int = 3
    max_refine_evals: int = 60
    seed: int = 0
    map_jobs: Callable = serial_map


def design_experiment(rivals: Mapping[str, Rival], conditions: Sequence[Condition],
                      signals: Sequence[Signal], *, fixed: Mapping[str, float] | None = None,
                      reference: Mapping[str, float] | None = None, search: Search = Search(),
                      min_separation: float = 3.0, times=None) -> NextExperiment:
    """The experiment within the conditions' ranges whose predicted outcomes
    differ most between ``rivals`` (name -> callable conditions -> {signal:
    samples}, or None when it cannot predict), in noise floors of the best of
    ``signals``. ``fixed``: further parameter settings passed to every rival
    unchanged. ``reference``: the conditions of the data so far (its
    separation is reported as ``baseline``). ``search``: :class:`Search`.
    ``min_separation`` [floors]: below it the result is not ``decisive``
    (3 floors: the wrong rival's chi^2 rises by 9, p = 0.003 for one degree
    of freedom). ``times``: the rivals' sample times, kept in the result for
    its plot."""
    conds = list(conditions)
    if not conds:
        raise UsageError("no experiment conditions to search (declare `conditions` "
                         "with their ranges in the model file)")
    ev = _Evaluator(rivals, conds, signals, fixed, search.map_jobs)
    n0 = search.n_initial or max(12, 8 * len(conds))
    pts = qmc.LatinHypercube(d=len(conds), seed=search.seed).random(n0)
    pts = np.vstack([np.full(len(conds), 0.5), pts])
    ev.prefetch(pts)
    scored = sorted(pts, key=ev.loss)
    for start in scored[:search.n_refine]:
        if not np.isfinite(ev(start).d2):
            continue
        optimize.minimize(ev.loss, start, method="Powell", bounds=[(0.0, 1.0)] * len(conds),
                          options=dict(maxfev=search.max_refine_evals, xtol=1e-3, ftol=1e-4))
    best_key = max(ev.cache, key=lambda k: ev.cache[k].merit)
    best = ev.cache[best_key]
    if best.signal is None:
        raise AcausalError("experiment design: no experiment in the declared ranges could be "
                           "predicted by every rival model")
    base = None
    if reference is not None:
        ref = predicted(ev.rivals, {**ev.fixed, **reference}, ev.signals,
                        map_jobs=search.map_jobs)
        base = math.sqrt(max(ref.d2, 0.0)) if np.isfinite(ref.d2) else None
    return _result(ev, best_key, best, base, min_separation, times)


def _result(ev: _Evaluator, key, best: _Score, base, min_separation, times) -> NextExperiment:
    pair = min(best.pairwise, key=best.pairwise.get)
    n_samples = max(np.asarray(next(iter(best.predictions.values()))).size, 1)
    vals = ev.values(np.array(key))
    cond = {c.name: vals[c.name] for c in ev.conds}
    sep = math.sqrt(best.d2)
    decisive = sep >= min_separation
    message = "" if decisive else (
        f"no experiment within the declared ranges of {', '.join(c.name for c in ev.conds)} "
        f"separates {pair} by more than {sep:.3g} noise floors (needs {min_separation:g}): "
        "declare other conditions (a start state, a load, a reversal of the motion)")
    return NextExperiment(cond, best.signal, sep, math.sqrt(best.d2 / n_samples),
                          tuple(pair.split(" | ")),
                          {k: math.sqrt(v) for k, v in best.pairwise.items()},
                          best.predictions, ev.n, base, decisive, message,
                          None if times is None else np.asarray(times, float), best.spread)


def plot_next_experiment(nxt: NextExperiment, path=None, title=None):
    """Each rival's predicted signal at the computed experiment (against the
    sample times when known, else the sample index), with the separation in
    the title. Returns the matplotlib figure; writes it to ``path`` if given."""
    from matplotlib.figure import Figure
    fig = Figure(figsize=(7, 3.2))
    ax = fig.subplots()
    for name, y in nxt.predictions.items():
        y = np.asarray(y, float)
        x = nxt.times if nxt.times is not None and len(nxt.times) == y.size else np.arange(y.size)
        ax.plot(x, y, lw=1.2, marker="o" if y.size < 3 else None, label=name)
    ax.set_xlabel("time [s]" if nxt.times is not None else "sample")
    ax.set_ylabel(nxt.signal)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    cond = ", ".join(f"{k} = {v:.4g}" for k, v in nxt.conditions.items())
    ax.set_title(title or f"next experiment: {cond}; {nxt.separation:.3g} floors apart",
                 fontsize=9)
    fig.tight_layout()
    if path:
        fig.savefig(path, dpi=120)
    return fig


def signals_of(dataset, names: Sequence[str]) -> list:
    """:class:`Signal` list for ``names`` with the floors of a dataset's
    instrument (``acausal.data.Dataset``; a signal it does not describe is
    an error: its floor would be a guess)."""
    out = []
    for n in names:
        inst = dataset.instrument.get(n)
        if inst is None or not inst.floor() > 0:
            raise AcausalError(f"experiment design: the instrument description has no noise "
                               f"floor for {n!r} (instrument.csv)")
        out.append(Signal(n, float(inst.floor())))
    return out


class ModelRival:
    """A rival from a model file (path or (ModelFile, CompiledModel) pair)
    and its fitted parameters: conditions -> {signal: samples at ``times``}
    by ``CompiledModel.simulate`` (the model file's run options, ``t_end``
    at least the last sample time) and linear interpolation of the
    ``Result``; a signal that is one of the model file's ``measures`` (a
    response time) is that scalar, one sample. A run that fails (an
    AcausalError) predicts nothing (None)."""

    def __init__(self, model, params: Mapping[str, float], signals: Sequence[str],
                 times: np.ndarray, options: Mapping | None = None, steps=()):
        self.mf, self.cm = model if isinstance(model, tuple) else compile_file(model)
        self.params, self.signals = dict(params), list(signals)
        self.times = np.asarray(times, float)
        self.options = dict(options or {})
        self.steps = [dict(s) for s in steps]

    def spread(self, conditions: Mapping[str, float], prediction) -> dict | None:
        """{signal: variance per sample} of the prediction at ``conditions``
        from the parameters' uncertainty: the sum over ``steps`` (one
        standard deviation along each principal direction of the
        parameters' covariance: {name: change}; :func:`covariance_steps`)
        of the squared change of the prediction, a one-sided sigma-point
        estimate that stays finite where the prediction is not linear in
        the parameters. A step whose simulation fails is retried at a
        quarter, its change scaled back by 4 (linear); None without steps."""
        if not self.steps:
            return None
        out = {s: np.zeros_like(np.asarray(prediction[s], float)) for s in self.signals}
        for step in self.steps:
            for frac in (1.0, 0.25):
                moved = {k: self.params[k] + frac * dv for k, dv in step.items()}
                y = self._run(conditions, {**self.params, **moved})
                if y is not None:
                    break
            if y is None:
                continue
            for s in self.signals:
                out[s] += ((np.asarray(y[s], float) - np.asarray(prediction[s], float))
                           / frac) ** 2
        return out

    def __call__(self, conditions: Mapping[str, float]):
        return self._run(conditions, self.params)

    def _run(self, conditions, params):
        opts = self.mf.experiment.run_options()
        opts.update(self.options)
        opts["t_end"] = max(float(opts.get("t_end") or 0.0), float(self.times[-1]))
        try:
            res = self.cm.simulate(params={**params, **conditions}, **opts)
            measures = [s for s in self.signals if s in self.mf.measures]
            scalars = evaluate_measures(self.mf, res) if measures else {}
            return {s: np.atleast_1d(scalars[s]) if s in scalars
                    else np.interp(self.times, res.t, res[s]) for s in self.signals}
        except AcausalError:
            return None


def covariance_steps(names, values, jacobian, cost) -> list:
    """One standard deviation along each principal direction of a
    least-squares fit's parameter covariance, as {name: change}: the
    covariance is (J'J)^-1 scaled by max(1, cost/(n-k)), J the weighted
    residuals' Jacobian (n x k) in parameter units, computed per relative
    change of each parameter (``values``). Directions the data do not
    determine (eigenvalue below 1e-12 of the largest) are left out: the
    fit bounds nothing along them (:func:`.residuals.principal_directions`)."""
    J = np.asarray(jacobian, float)
    n, k = J.shape
    if k == 0 or n <= k:
        return []
    v = np.array([values[nm] for nm in names], float)
    sc = np.where(v != 0, np.abs(v), 1.0)
    w, V, good = principal_directions(J * sc)
    s2 = max(cost / (n - k), 1.0)
    return [{nm: float(V[i, j] * math.sqrt(s2 / w[j]) * sc[i])
             for i, nm in enumerate(names)} for j in np.argsort(w) if good[j]]
