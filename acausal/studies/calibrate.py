"""Calibration of model parameters to measured data.

Two methods:

* :func:`report_method` — the research report's own (section 3): one
  parameter at a time, a one-dimensional root search (``scipy.optimize.brentq``
  on the logarithm of the parameter) until a simulated measure equals the
  measured one at the nominal experiment.
* :func:`least_squares` — output-error least squares over any named
  parameters (with bounds) against every measured scalar and trace sample of
  every experiment, weighted by the instrument's noise floor; 95 % confidence
  intervals from the Jacobian at the optimum (Student t) and the parameter
  correlation matrix.

The weighted residuals are :mod:`.residuals`' (the diagnosis fits the same
ones); :class:`ExperimentRuns` says how the calibration simulates each
experiment for them.
"""
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize, stats

from ..data import load_dataset
from .differences import ForwardDifferences
from ..errors import AcausalError, CalibrationError, ModelError, ModelFileError
from ..modelfile import evaluate_measures
from .profile import Confidence, Coordinates, Tracing, profiles
from .residuals import resolve, subset  # noqa: F401 (public here too, as before)
from .residuals import weighted_jacobian, weighted_residuals


# Finite-difference step of the least squares, absolute in the optimiser's
# variables (each scaled to about 1 by the parameter's typical value, or the
# logarithm of the parameter over its start value): 1e-3 of the parameter.
# The measures and traces of an adaptive, event-located simulation are not
# smooth below about 1e-6 relative, so the step must stay well above that.
# scipy's own ``diff_step`` is relative to |z| and shrinks to nothing as a
# variable nears 0 (a log-parameter at its start, an extension's parameter
# near no effect): with it the fit over the six voltages of data/report_24kv
# stopped at K = 8.86e8, S = 27.260, short of the minimum K = 9.35e8,
# S = 27.215, and the 110 V intervals came out 20 times too narrow.
FD_STEP = 1e-3




def model_dataset(path, folder):
    """Load ``folder`` checking its columns against the model file's
    parameters, measures and variables (with their units), and that it sets
    at least one of the model file's ``conditions``."""
    mf, cm = resolve(path)
    params = {p.name: p.unit for p in cm.params}
    measures = {name: _si(mf, name) for name in mf.measures}
    variables = {n: cm.flat.variables[n].unit for n in cm.var_names}
    return load_dataset(folder, parameters=params, measures=measures, variables=variables,
                        conditions=[c for c in mf.conditions if c in params])


def _si(mf, measure):
    """The SI unit of a measure declared in a model file (None if undeclared)."""
    from ..data.units import si_unit
    unit = mf.measure_unit(measure)
    try:
        return si_unit(unit)
    except Exception:  # pint raises UndefinedUnitError, TokenError, AssertionError...
        raise ModelFileError(f"{mf.path}: measure {measure!r} has unit {unit!r}, which "
                             "is not a unit expression") from None


def split(dataset, experiments=None):
    """(fitted, held back) datasets.

    ``experiments``: None for the rows the data marks ``use = calibrate``
    (every row when there is no ``use`` column), ``"all"`` for every row, or a
    list of names.  The held-back dataset has the other rows (it may be
    empty): :func:`validate` predicts them with the calibrated values."""
    import dataclasses
    if experiments == "all":
        fit = [e.name for e in dataset.experiments]
    elif experiments is None:
        fit = [e.name for e in dataset.experiments if e.use == "calibrate"]
        if not fit:
            raise CalibrationError(f"{dataset.folder}: every experiment is marked "
                                   "'validate'; nothing to calibrate to")
    else:
        fit = list(experiments)
    held = [e for e in dataset.experiments if e.name not in fit]
    return subset(dataset, fit), dataclasses.replace(dataset, experiments=held)


def validate(path, dataset, values):
    """Residuals (simulated - measured) of the measures of every experiment of
    ``dataset`` predicted with ``values``: experiment -> {measure: residual}.
    A prediction that fails records its error message instead."""
    out = {}
    for exp in dataset.experiments:
        try:
            _, meas = simulate_experiment(path, values, exp.conditions)
        except AcausalError as exc:
            out[exp.name] = {"error": str(exc)}
            continue
        out[exp.name] = {m: meas[m] - y for m, y in exp.measures.items()}
    return out


def simulate_experiment(path, params, conditions, options=None):
    """(result, measures) for one experiment with fitted ``params``;
    ``options``: further keyword arguments of ``simulate`` (``max_steps``)."""
    mf, cm = resolve(path)
    over = dict(params)
    over.update(conditions)
    opts = mf.experiment.run_options()
    opts.update(options or {})
    res = cm.simulate(params=over, **opts)
    return res, evaluate_measures(mf, res)


@dataclass
class Calibration:
    method: str
    values: dict                  # name -> value
    ci95: dict = field(default_factory=dict)      # name -> (low, high)
    correlation: np.ndarray = None
    residuals: dict = field(default_factory=dict)  # experiment -> {signal: residual}
    cost: float = None
    dof: int = None
    n_sim: int = 0
    validation: dict = field(default_factory=dict)  # held-back experiment -> residuals
    profile_ci95: dict = field(default_factory=dict)  # name -> profile.LikelihoodProfile
    jacobian: str = "finite differences"   # or "sensitivities" (see least_squares)

    def to_dict(self):
        return dict(method=self.method, values=self.values, jacobian=self.jacobian,
                    ci95={k: list(v) for k, v in self.ci95.items()},
                    profile_ci95={k: p.to_dict() for k, p in self.profile_ci95.items()},
                    correlation=None if self.correlation is None else self.correlation.tolist(),
                    residuals=_plain(self.residuals), cost=self.cost, dof=self.dof,
                    n_sim=self.n_sim, validation=_plain(self.validation))


def _plain(residuals):
    """experiment -> {signal: float, or list of floats for a trace}, for JSON."""
    return {exp: {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in sig.items()}
            for exp, sig in residuals.items()}


def report_method(path, dataset, pairs, experiment=None, brackets=None, base=None,
                  passes=2):
    """Calibrate ``pairs`` = [(parameter, measure), ...] in order, each by a
    1-D root search (``scipy.optimize.brentq``; on the logarithm of the
    parameter when its range is positive) so that the simulated measure
    equals the measured one at ``experiment`` (default: the first experiment
    that measures every one of them). ``base`` gives starting values of other
    parameters (the report starts with ``hook.bh = 0``). The sequence is
    repeated ``passes`` times, since each parameter moves the other's
    measure a little. A simulation that cannot produce the measure (the
    hook never releases, the solver fails) counts as a measure larger than
    any target, which is right for times to an event."""
    names = [m for _, m in pairs]
    exp = _nominal(dataset, names, experiment)
    values = dict(base or {})
    n_sim = [0]
    pair = resolve(path)
    history = []
    for _ in range(max(1, passes)):
        for pname, measure in pairs:
            values[pname] = _search(pair, values, pname, measure, exp,
                                    (brackets or {}).get(pname), n_sim)
        history.append(dict(values))
        if len(history) > 1 and all(abs(history[-1][k] - history[-2][k])
                                    <= 1e-6 * max(abs(history[-1][k]), 1e-300)
                                    for k in values):
            break
    _, final = simulate_experiment(path, values, exp.conditions)
    resid = {exp.name: {m: final[m] - exp.measures[m] for m in names}}
    return Calibration("report", values, residuals=resid, n_sim=n_sim[0])


def _bracket(mf, cm, pname, given):
    if given is not None:
        return tuple(map(float, given))
    if pname in mf.free:
        return mf.free[pname]
    entry = cm.params[cm.param_index(pname)]
    d = entry.default
    lo = entry.decl.min if entry.decl.min is not None else (d / 30.0 if d > 0 else -abs(d) - 1)
    hi = entry.decl.max if entry.decl.max is not None else (d * 30.0 if d > 0 else abs(d) + 1)
    return lo, hi


def _search(pair, values, pname, measure, exp, bracket, n_sim):
    """The value of ``pname`` at which ``measure`` of experiment ``exp``
    equals its measured value (:func:`report_method`)."""
    target = exp.measures[measure]
    lo, hi = _bracket(*pair, pname, bracket)
    logscale = lo > 0
    to_x = (lambda u: float(np.exp(u))) if logscale else float
    scale = max(abs(target), 1e-300)

    def f(u):
        trial = dict(values)
        trial[pname] = to_x(u)
        n_sim[0] += 1
        try:
            return (simulate_experiment(pair, trial, exp.conditions)[1][measure] - target) / scale
        except AcausalError:
            return 1e3   # no measure (no event, solver failure): beyond any target
    a, b = (np.log(lo), np.log(hi)) if logscale else (lo, hi)
    fa, fb = f(a), f(b)
    if np.sign(fa) == np.sign(fb):
        raise CalibrationError(
            f"report method: {measure} does not cross its measured value {target:.6g} "
            f"for {pname} in [{lo:.4g}, {hi:.4g}] (relative residuals {fa:.3g} and "
            f"{fb:.3g}); give other bounds in the model file's free_parameters")
    return to_x(optimize.brentq(f, a, b, xtol=1e-12, rtol=1e-10))


def _nominal(dataset, measures, name=None):
    if name is not None:
        return dataset.experiment(name)
    for e in dataset.experiments:
        if all(m in e.measures for m in measures):
            return e
    raise CalibrationError(f"no experiment measures all of {measures}")


def residual_vector(path, dataset, params, signals=None, options=None):
    """Weighted residuals (simulated - measured)/sigma over every experiment:
    measures first, then trace samples (:func:`acausal.studies.residuals.weighted_residuals`,
    each experiment run by :func:`simulate_experiment`). Returns (vector,
    labels, raw). ``options``: passed to :func:`simulate_experiment`."""
    got = weighted_residuals(path, dataset, params, ExperimentRuns(options), signals)
    return got.vector, got.labels, got.raw


def _check_finite(vec, labels, dataset):
    """A CalibrationError naming the first measured value whose weighted
    residual is not a finite number (1e308 in the data overflowed, and
    scipy stopped with a traceback)."""
    with np.errstate(all="ignore"):
        bad = np.flatnonzero(~np.isfinite(np.asarray(vec, float)))
    if not bad.size:
        return
    exp, signal = labels[int(bad[0])]
    e = dataset.experiment(exp)
    value = e.measures.get(signal)
    what = f"measured {signal} = {value:g} (SI)" if value is not None else f"trace {signal}"
    raise CalibrationError(f"{exp}: {what}: its residual weighted by the instrument floor is "
                           "not a finite number; check the value and its unit",
                           file=getattr(dataset, "folder", None), column=signal)


def residual_jacobian(path, dataset, params, names, signals=None, options=None):
    """(weighted residuals, their Jacobian d r / d x over the parameters
    ``names``), in the order of :func:`residual_vector`, from one simulation
    per experiment with forward sensitivities (:mod:`acausal.sensitivity`):
    a measure's derivative is :meth:`acausal.result.Result.measure_sensitivity`
    (the measure over the result moved along the sensitivities), a trace
    sample's ``interp(t_k, res.t, res[var])`` the same interpolation of
    ``res.sensitivity(var, p)`` (:func:`acausal.studies.residuals.weighted_jacobian`)."""
    return weighted_jacobian(path, dataset, params, names, ExperimentRuns(options), signals)


@dataclass(frozen=True)
class ExperimentRuns:
    """How the calibration simulates an experiment for its residuals:
    :func:`simulate_experiment` with the model file's run options (the dense
    output grid for an experiment with a trace) and ``options`` over them;
    every measure of the model file is evaluated."""

    options: dict | None = None

    def __call__(self, pair, params, experiment, sensitivities=None):
        dense = {} if experiment.trace is None else pair[0].experiment.run_options(dense=True)
        opts = {**dense, **(self.options or {})}
        if sensitivities is not None:
            opts["sensitivities"] = list(sensitivities)
        return simulate_experiment(pair, params, experiment.conditions, opts)


class SensitivityJacobian:
    """``jac`` for ``scipy.optimize.least_squares`` in the fit's variables
    ``z`` (``x = to_x(z)``, ``dxdz(z)`` = dx/dz) from
    :func:`residual_jacobian`; where a sensitivity run fails, the finite
    differences ``fallback`` (a :class:`ForwardDifferences`, or any object
    with a ``jac``) answer that call instead, counted in ``fallbacks``.
    ``give_up``: errors that say the sensitivities cannot serve this model
    at all (a staggered sweep refusing events): after one, the fallback
    answers every later call (``off``). ``fresh``: whether the last answer
    was a full Jacobian (the fallback's own ``fresh`` when it has one: a
    secant update is not)."""

    def __init__(self, jac_x, to_x, dxdz, fallback, give_up=()):
        self.jac_x, self.to_x, self.dxdz, self.fallback = jac_x, to_x, dxdz, fallback
        self.give_up = give_up
        self.fallbacks = self.calls = 0
        self.off = self.fresh = False

    def jac(self, z):
        self.calls += 1
        if not self.off:
            try:
                J = self.jac_x(self.to_x(z)) * self.dxdz(z)[None, :]
                self.fresh = True
                return J
            except self.give_up:
                self.off = True
            except AcausalError:
                pass
        self.fallbacks += 1
        J = self.fallback.jac(z)
        self.fresh = getattr(self.fallback, "fresh", True)
        return J


def least_squares(path, dataset, names, bounds=None, x0=None, signals=None, profile="none",
                  jacobian="auto"):
    """Output-error least squares over parameters ``names``.

    Bounds come from ``bounds``, else the model file's ``free_parameters``,
    else the parameters' declared limits. A parameter whose range is
    positive is fitted on its logarithm, so its 95 % interval is asymmetric
    and never crosses zero. Intervals use the Jacobian at the optimum, scaled
    by the reduced chi-square when it exceeds 1 (never narrower than the
    instrument model says), with Student t quantiles.

    ``profile``: "auto" adds profile-likelihood intervals
    (:mod:`acausal.profile`, ``Calibration.profile_ci95``) for the parameters
    whose linearised interval fails :func:`acausal.profile.linear_check`;
    "all" for every fitted parameter; "none" (default) for none.

    ``jacobian``: "sensitivities" (the default, "auto") takes the Jacobian
    from forward sensitivities (:func:`residual_jacobian`: one simulation per
    experiment, exact up to the solver tolerance); "differences" from
    forward differences (absolute step :data:`FD_STEP`, one simulation per
    parameter and experiment), which also answer any Jacobian the
    sensitivities cannot give (a run that fails). ``Calibration.jacobian``
    says which ran."""
    path = resolve(path)
    mf, cm = path
    entries = [cm.params[cm.param_index(n)] for n in names]
    start = np.array([(x0 or {}).get(e.name, e.default) for e in entries], float)
    sc = _Scaling.of(start, *_fit_bounds(mf, entries, bounds))
    n_sim = [0]

    def fun(z):
        n_sim[0] += len(dataset.experiments)
        params = dict(zip(names, sc.to_x(z).tolist()))
        try:
            return residual_vector(path, dataset, params, signals)[0]
        except AcausalError:
            return np.full(n_res, 1e6)

    r0, labels0, _ = residual_vector(path, dataset, dict(zip(names, start)), signals)
    _check_finite(r0, labels0, dataset)
    n_res = len(r0)
    if n_res < len(names):
        raise CalibrationError(f"{n_res} measured values cannot determine {len(names)} "
                               "parameters")
    fd = ForwardDifferences(fun, FD_STEP, sc.zhi)
    target = _Target(path, dataset, list(names), signals)
    jac, exact = _jacobian_choice(jacobian, fd, target, sc, n_sim)
    sol = optimize.least_squares(fd, sc.z0, jac=jac, bounds=(sc.zlo, sc.zhi),
                                 xtol=1e-12, ftol=1e-12, gtol=1e-12)
    kind = _jacobian_kind(exact)
    xs = sc.to_x(sol.x)
    values = dict(zip(names, xs.tolist()))
    dof = max(n_res - len(names), 0)
    ci, corr = _linear_intervals(sol, names, sc, dof)
    raw = residual_vector(path, dataset, values, signals)[2]
    out = Calibration("least_squares", values, ci, corr, raw, float(2 * sol.cost), dof,
                      n_sim[0], jacobian=kind)
    if profile != "none" and names:
        out.profile_ci95 = _profile_intervals(target, n_res, n_sim, sol, sc, dof,
                                              profile == "all")
        out.n_sim = n_sim[0]
    return out


def _jacobian_kind(exact):
    """What gave the Jacobian (``Calibration.jacobian``)."""
    if exact is None:
        return "finite differences"
    if exact.fallbacks:
        return f"sensitivities ({exact.fallbacks} of {exact.calls} by finite differences)"
    return "sensitivities"


@dataclass(frozen=True)
class _Target:
    """What :func:`least_squares` fits: the (ModelFile, CompiledModel) pair,
    the dataset, the fitted parameters' names and the signals kept (None: all)."""

    pair: tuple
    dataset: object
    names: list
    signals: object = None


def _profile_intervals(target, n_res, n_sim, sol, sc, dof, every):
    """Profile-likelihood intervals at the optimum ``sol``, in the fit's own
    variables (log for a positive range, value/scale otherwise), so that the
    profiles' Wald intervals are those of :func:`_linear_intervals`."""
    return profiles(
        _no_evidence_on_failure(target, n_res, n_sim), sc.to_x(sol.x), target.names,
        every=every, coords=Coordinates((sc.lo, sc.hi), sc.logp, sc.scale),
        confidence=Confidence(dispersion=max(2 * sol.cost / dof, 1.0) if dof > 0 else 1.0,
                              dof=dof or None),
        tracing=Tracing(fd_step=FD_STEP, inner_max_nfev=20, inner_tol=1e-6, crossing_tol=1e-2),
        jacobian=sol.jac)


def _fit_bounds(mf, entries, bounds):
    """(lo, hi) of each fitted parameter: ``bounds``, else the model file's
    ``free_parameters``, else the parameter's declared limits."""
    lo, hi = np.empty(len(entries)), np.empty(len(entries))
    for k, e in enumerate(entries):
        lo[k], hi[k] = (bounds or {}).get(e.name) or mf.free.get(e.name) or (
            e.decl.min if e.decl.min is not None else -np.inf,
            e.decl.max if e.decl.max is not None else np.inf)
    return lo, hi


@dataclass
class _Scaling:
    """The fit's variables z: log(x / ref) for a positive range (so z is
    about 0 at the start, and the finite-difference step FD_STEP, of
    max(1, |z|), is 1e-3 of the parameter, not 1e-3 of log(x) ~ 20), else
    x / scale. ``z0, zlo, zhi``: the start and the bounds in z."""
    lo: np.ndarray
    hi: np.ndarray
    logp: np.ndarray
    scale: np.ndarray
    ref: np.ndarray
    z0: np.ndarray = None
    zlo: np.ndarray = None
    zhi: np.ndarray = None

    @classmethod
    def of(cls, start, lo, hi):
        logp = lo > 0
        inside = np.clip(start, lo, hi)
        sc = cls(lo, hi, logp, np.where(start != 0, np.abs(start), 1.0),
                 np.where(logp, inside, 1.0))
        sc.zlo = np.where(np.isfinite(lo), sc.to_z(lo), -np.inf)
        sc.zhi = np.where(np.isfinite(hi), sc.to_z(hi), np.inf)
        sc.z0 = np.clip(sc.to_z(inside), sc.zlo, sc.zhi)
        return sc

    def to_x(self, z):
        return np.where(self.logp, self.ref * np.exp(z), z * self.scale)

    def to_z(self, x):
        return np.where(self.logp, np.log(np.where(self.logp, x, 1.0) / self.ref), x / self.scale)

    def dx_dz(self, z):
        return np.where(self.logp, self.to_x(z), self.scale)


def _jacobian_choice(jacobian, fd, target, sc, n_sim):
    """(the ``jac`` for scipy, the :class:`SensitivityJacobian` or None)."""
    if jacobian not in ("auto", "sensitivities", "differences"):
        raise CalibrationError(f"jacobian={jacobian!r}: choose 'auto', 'sensitivities' or "
                               "'differences'")
    if jacobian == "differences":
        return fd.jac, None

    def jac_x(x):
        n_sim[0] += len(target.dataset.experiments)
        return residual_jacobian(target.pair, target.dataset, dict(zip(target.names, x.tolist())),
                                 target.names, target.signals)[1]
    exact = SensitivityJacobian(jac_x, sc.to_x, sc.dx_dz, fd)
    return exact.jac, exact


def _linear_intervals(sol, names, sc, dof):
    """(95 % intervals, correlation) from the Jacobian at the optimum, scaled
    by the reduced chi-square when it exceeds 1, with Student t quantiles;
    mapped back through the log for positive ranges (so asymmetric)."""
    try:
        cov = np.linalg.inv(sol.jac.T @ sol.jac)
    except np.linalg.LinAlgError:
        return {n: (float("nan"), float("nan")) for n in names}, None
    s2 = 2 * sol.cost / dof if dof > 0 else 1.0
    cov = cov * max(s2, 1.0)
    sd = np.sqrt(np.diag(cov))
    tq = stats.t.ppf(0.975, dof) if dof > 0 else stats.norm.ppf(0.975)
    ci = {}
    for k, n in enumerate(names):
        zk = sol.x[k] + np.array([-1.0, 1.0]) * tq * sd[k]
        xk = sc.ref[k] * np.exp(zk) if sc.logp[k] else zk * sc.scale[k]
        ci[n] = (float(xk[0]), float(xk[1]))
    return ci, cov / np.outer(sd, sd)


def _no_evidence_on_failure(target, n_res, n_sim):
    """Residuals at parameter values x for the profile likelihood: a run that
    fails gives NaN, not the fit's penalty, since a failure is no evidence
    against x (the profile stops there and is reported open)."""
    def residuals(x):
        n_sim[0] += len(target.dataset.experiments)
        try:
            return residual_vector(target.pair, target.dataset,
                                   dict(zip(target.names, np.asarray(x).tolist())),
                                   target.signals)[0]
        except AcausalError:
            return np.full(n_res, np.nan)
    return residuals


def check_names(cm, names):
    for n in names:
        try:
            cm.param_index(n)
        except AcausalError as exc:
            raise ModelError(f"--fit: {exc}") from None
