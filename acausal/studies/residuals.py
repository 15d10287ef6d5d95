"""Weighted residuals of a model against measured data: the one definition
the calibration (:mod:`.calibrate`) and the diagnosis
(:mod:`acausal.diagnose.stages.fitting`) fit with.

A residual is (simulated - measured) / sigma, sigma the instrument floor of
the signal (:func:`sigma`), so every weighted residual is in units of the
noise floor (1 = what the instrument alone explains). Per experiment, in
the dataset's order: its measured scalars (measures) in their order, then
every sample of every traced signal (the simulation interpolated linearly at
the sample times).

How an experiment is simulated is the caller's (the calibration's run
options, or the diagnosis's windowed runs on its integrator): a
``simulate(pair, params, experiment, sensitivities)`` callable returning
``(result, measures)``, ``measures`` the model file's measures evaluated on
the result (name -> value; at least those the experiment measures).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..data import Dataset
from ..errors import AcausalError, CalibrationError, ModelFileError
from ..modelfile import compile_file

__all__ = ["WeightedResiduals", "measure_derivative", "resolve", "sigma", "subset",
           "weighted_jacobian", "weighted_residuals", "principal_directions"]


def resolve(model):
    """(ModelFile, CompiledModel) for a model file path, or the pair itself
    (e.g. the model file extended with a hypothesis by :mod:`acausal.diagnose`)."""
    if isinstance(model, tuple) and len(model) == 2:
        return model
    return compile_file(model)


def sigma(dataset: Dataset, signal: str, values) -> float:
    """The weight of ``signal``'s residuals: its instrument floor
    (:meth:`acausal.data.Instrument.floor`), or, without an instrument entry
    (or a zero floor), 1e-3 of the largest measured magnitude ``values``."""
    inst = dataset.instrument.get(signal)
    s = inst.floor() if inst is not None else 0.0
    if s <= 0:
        s = 1e-3 * max(float(np.max(np.abs(values))), 1e-12)
    return s


def measure_derivative(mf, res, measure: str, param: str) -> float:
    """d measure / d ``param`` on a result with forward sensitivities
    (:meth:`acausal.runtime.result.Result.measure_sensitivity`); a measure
    that fails on the moved result raises a ModelFileError naming it."""
    try:
        return float(res.measure_sensitivity(mf.measures[measure], param))
    except AcausalError:
        raise
    except Exception as exc:  # a measure's own failure on the moved result
        raise ModelFileError(f"{mf.path}: measure {measure!r} failed on the result moved "
                             f"along d/d{param}: {type(exc).__name__}: {exc}") from None


def subset(dataset: Dataset, names) -> Dataset:
    """The dataset restricted to the experiments ``names``, in that order
    (same folder and instrument). An unknown name is a CalibrationError
    naming it and the experiments the dataset has."""
    names = list(names)
    known = [e.name for e in dataset.experiments]
    bad = [n for n in names if n not in known]
    if bad:
        raise CalibrationError(f"{dataset.folder}: no experiment {bad[0]!r}; the dataset has "
                               + ", ".join(known))
    return dataclasses.replace(dataset, experiments=[dataset.experiment(n) for n in names])


@dataclass(frozen=True)
class WeightedResiduals:
    """The residuals of one parameter set over a dataset. ``vector``: the
    weighted residuals; ``groups`` / ``signals``: the experiment and the
    signal of each entry; ``raw``: experiment -> signal -> simulated -
    measured in SI (a float for a measure, an array for a trace)."""

    vector: np.ndarray
    groups: list
    signals: list
    raw: dict

    @property
    def labels(self) -> list:
        """(experiment, signal) of each entry."""
        return list(zip(self.groups, self.signals))


def _kept(signals, name):
    return not signals or name in signals


def weighted_residuals(model, dataset: Dataset, params: dict, simulate,
                       signals=None) -> WeightedResiduals:
    """The weighted residuals at ``params`` (module doc): one
    ``simulate(pair, params, experiment, None)`` per experiment; ``signals``
    (None: all) keeps only those measures and traced signals. A failed
    simulation raises its AcausalError."""
    pair = resolve(model)
    vec, groups, names, raw = [], [], [], {}
    for e in dataset.experiments:
        res, meas = simulate(pair, params, e, None)
        raw[e.name] = {}
        for m, y in e.measures.items():
            if not _kept(signals, m):
                continue
            r = meas[m] - y
            raw[e.name][m] = r
            vec.append(np.atleast_1d(np.asarray(r / sigma(dataset, m, y), float)))
            groups.append(e.name)
            names.append(m)
        if e.trace is None:
            continue
        for var, ys in e.trace.signals.items():
            if not _kept(signals, var):
                continue
            r = np.interp(e.trace.time, res.t, res[var]) - ys
            raw[e.name][var] = r
            vec.append(np.asarray(r / sigma(dataset, var, ys), float).ravel())
            groups += [e.name] * len(ys)
            names += [var] * len(ys)
    return WeightedResiduals(np.concatenate(vec) if vec else np.zeros(0), groups, names, raw)


def weighted_jacobian(model, dataset: Dataset, params: dict, names, simulate,
                      signals=None):
    """(weighted residuals, their Jacobian d r / d p over the parameters
    ``names``), in the order of :func:`weighted_residuals`, from one
    ``simulate(pair, params, experiment, names)`` per experiment with forward
    sensitivities (:mod:`acausal.runtime.sensitivity`): a measure's row is
    :func:`measure_derivative`, a trace sample's the interpolated
    sensitivity ``interp(t_k, res.t, res.sensitivity(var, p))``, each over
    its sigma. A failed simulation raises its AcausalError."""
    pair = resolve(model)
    mf = pair[0]
    names = list(names)
    vec, rows = [], []
    for e in dataset.experiments:
        res, meas = simulate(pair, params, e, names)
        for m, y in e.measures.items():
            if not _kept(signals, m):
                continue
            s = sigma(dataset, m, y)
            vec.append((meas[m] - y) / s)
            rows.append([measure_derivative(mf, res, m, n) / s for n in names])
        if e.trace is None:
            continue
        for var, ys in e.trace.signals.items():
            if not _kept(signals, var):
                continue
            s = sigma(dataset, var, ys)
            vec.extend((np.interp(e.trace.time, res.t, res[var]) - ys) / s)
            rows.extend(np.column_stack([np.interp(e.trace.time, res.t,
                                                   res.sensitivity(var, n)) / s
                                         for n in names]))
    return np.asarray(vec, float), np.asarray(rows, float).reshape(len(vec), len(names))


def principal_directions(jacobian):
    """(w, V, good) of a least-squares Jacobian J (n x k): the eigenvalues
    and eigenvectors of J'J, and which directions the data determine
    (eigenvalue above 1e-12 of the largest). Over those, (J'J)^-1 is
    V diag(1/w) V'; a direction outside them is one the data cannot see.
    Shared by the Wald intervals (:func:`.profile.wald_halfwidths`), the
    diagnosis's fits and the design's parameter steps."""
    J = np.asarray(jacobian, float)
    w, V = np.linalg.eigh(J.T @ J)
    good = w > 1e-12 * max(w.max(initial=0.0), 1e-300)
    return w, V, good
