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
"""
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize, stats

from .data import load_dataset
from .errors import AcausalError, ModelError
from .modelfile import compile_file, evaluate_measures


class CalibrationError(AcausalError):
    """The calibration could not be carried out (no bracket, no data...)."""


def resolve(model):
    """(ModelFile, CompiledModel) for a model file path, or the pair itself.

    Every function here taking ``path`` also accepts such a pair, e.g. the
    model file extended with a hypothesis by :mod:`acausal.diagnose`."""
    if isinstance(model, tuple) and len(model) == 2:
        return model
    return compile_file(model)


def model_dataset(path, folder):
    """Load ``folder`` checking its columns against the model file's
    parameters, measures and variables (with their units)."""
    mf, cm = resolve(path)
    params = {p.name: p.unit for p in cm.params}
    measures = {name: None for name in mf.measures}
    variables = {n: cm.flat.variables[n].unit for n in cm.var_names}
    return load_dataset(folder, parameters=params, measures=measures, variables=variables)


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

    def to_dict(self):
        return dict(method=self.method, values=self.values,
                    ci95={k: list(v) for k, v in self.ci95.items()},
                    correlation=None if self.correlation is None else self.correlation.tolist(),
                    residuals=self.residuals, cost=self.cost, dof=self.dof, n_sim=self.n_sim)


def report_method(path, dataset, pairs, experiment=None, brackets=None, base=None):
    """Calibrate ``pairs`` = [(parameter, measure), ...] in order, each by a
    1-D root search so that the simulated measure equals the measured one at
    ``experiment`` (default: the first experiment that has every measure)."""
    names = [m for _, m in pairs]
    exp = _nominal(dataset, names, experiment)
    values = dict(base or {})
    n_sim = [0]
    _, cm = compile_file(path)
    for pname, measure in pairs:
        target = exp.measures[measure]
        default = cm.params[cm.param_index(pname)].default
        lo, hi = (brackets or {}).get(pname, (default / 30.0 if default > 0 else 1e-3,
                                                default * 30.0 if default > 0 else 10.0))

        def f(logx, pname=pname, measure=measure, target=target):
            trial = dict(values)
            trial[pname] = float(np.exp(logx))
            n_sim[0] += 1
            return simulate_experiment(path, trial, exp.conditions)[1][measure] - target

        a, b = np.log(lo), np.log(hi)
        fa, fb = f(a), f(b)
        if np.sign(fa) == np.sign(fb):
            raise CalibrationError(
                f"report method: {measure} does not cross its measured value "
                f"{target:.6g} for {pname} in [{lo:.4g}, {hi:.4g}] "
                f"(residuals {fa:.3g} and {fb:.3g}); give a bracket")
        values[pname] = float(np.exp(optimize.brentq(f, a, b, xtol=1e-10, rtol=1e-10)))
    _, final = simulate_experiment(path, values, exp.conditions)
    resid = {exp.name: {m: final[m] - exp.measures[m] for m in names}}
    return Calibration("report", values, residuals=resid, n_sim=n_sim[0])


def _nominal(dataset, measures, name=None):
    if name is not None:
        return dataset.experiment(name)
    for e in dataset.experiments:
        if all(m in e.measures for m in measures):
            return e
    raise CalibrationError(f"no experiment measures all of {measures}")


def residual_vector(path, dataset, params, signals=None, options=None):
    """Weighted residuals (simulated - measured)/sigma over every experiment:
    measures first, then trace samples. Returns (vector, labels, raw).
    ``options``: passed to :func:`simulate_experiment`."""
    path = resolve(path)
    vec, labels, raw = [], [], {}
    for exp in dataset.experiments:
        res, meas = simulate_experiment(path, params, exp.conditions, options)
        raw[exp.name] = {}
        for m, y in exp.measures.items():
            if signals and m not in signals:
                continue
            sigma = _sigma(dataset, m, y)
            r = meas[m] - y
            raw[exp.name][m] = r
            vec.append(r / sigma)
            labels.append((exp.name, m))
        if exp.trace is not None:
            for var, ys in exp.trace.signals.items():
                if signals and var not in signals:
                    continue
                sim = np.interp(exp.trace.time, res.t, res[var])
                sigma = _sigma(dataset, var, ys)
                raw[exp.name][var] = sim - ys
                vec.extend((sim - ys) / sigma)
                labels.extend((exp.name, var) for _ in ys)
    return np.asarray(vec), labels, raw


def _sigma(dataset, signal, values):
    inst = dataset.instrument.get(signal)
    s = inst.floor() if inst is not None else 0.0
    if s <= 0:
        s = 1e-3 * max(float(np.max(np.abs(values))), 1e-12)
    return s


def least_squares(path, dataset, names, bounds=None, x0=None, signals=None):
    """Output-error least squares over parameters ``names``."""
    path = resolve(path)
    _, cm = path
    entries = [cm.params[cm.param_index(n)] for n in names]
    start = np.array([(x0 or {}).get(e.name, e.default) for e in entries], float)
    lo = np.array([(bounds or {}).get(e.name, (e.decl.min if e.decl.min is not None
                                               else -np.inf, None))[0] for e in entries], float)
    hi = np.array([(bounds or {}).get(e.name, (None, e.decl.max if e.decl.max is not None
                                               else np.inf))[1] for e in entries], float)
    scale = np.where(start != 0, np.abs(start), 1.0)
    n_sim = [0]

    def fun(z):
        n_sim[0] += len(dataset.experiments)
        params = dict(zip(names, z * scale))
        try:
            return residual_vector(path, dataset, params, signals)[0]
        except AcausalError:
            return np.full(n_res, 1e6)

    n_res = len(residual_vector(path, dataset, dict(zip(names, start)), signals)[0])
    if n_res < len(names):
        raise CalibrationError(f"{n_res} measured values cannot determine {len(names)} "
                               "parameters")
    z0 = np.clip(start / scale, lo / scale, hi / scale)
    sol = optimize.least_squares(fun, z0, bounds=(lo / scale, hi / scale), x_scale=1.0,
                                 diff_step=1e-6, xtol=1e-12, ftol=1e-12, gtol=1e-12)
    values = dict(zip(names, (sol.x * scale).tolist()))
    dof = max(n_res - len(names), 0)
    J = sol.jac / scale  # d r / d param
    ci, corr = {}, None
    try:
        cov = np.linalg.inv(J.T @ J)
        s2 = 2 * sol.cost / dof if dof > 0 else 1.0
        cov = cov * max(s2, 1.0)  # never narrower than the instrument model says
        sd = np.sqrt(np.diag(cov))
        tq = stats.t.ppf(0.975, dof) if dof > 0 else stats.norm.ppf(0.975)
        ci = {n: (v - tq * s, v + tq * s) for (n, v), s in zip(values.items(), sd)}
        corr = cov / np.outer(sd, sd)
    except np.linalg.LinAlgError:
        ci = {n: (float("nan"), float("nan")) for n in names}
    raw = residual_vector(path, dataset, values, signals)[2]
    return Calibration("least_squares", values, ci, corr, raw, float(2 * sol.cost), dof,
                       n_sim[0])


def check_names(cm, names):
    for n in names:
        try:
            cm.param_index(n)
        except AcausalError as exc:
            raise ModelError(f"--fit: {exc}") from None
