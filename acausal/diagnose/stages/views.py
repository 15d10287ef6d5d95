"""Stage 8: what the report shows that needs simulations, computed once and
stored in the result (the report re-simulates nothing): the calibrated and
the extended model's traces, the residuals in SI units, the instrument
floors and the residual fingerprints."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...studies.residuals import sigma
from ...errors import AcausalError
from .fingerprints import fingerprints
from ..library.loader import load_library
from .tasks import dataset_of, model_of


@dataclass
class Views:
    """``raw0``/``raw1``: experiment -> signal -> residual (simulated -
    measured, SI) of the calibrated / the extended model; ``sim0``/``sim1``:
    experiment -> signal -> (t, y) of their simulated traces; ``floors``:
    signal -> instrument floor (SI); ``fingerprints``: see
    :func:`.fingerprints.fingerprints`."""

    raw0: dict
    raw1: dict
    sim0: dict
    sim1: dict
    floors: dict
    fingerprints: dict = field(default_factory=dict)


def simulate_all(pair, ds, values, backend=None):
    """experiment -> result (None where the simulation fails); ``backend``:
    the integrator (the fits' own, :attr:`.problem.FitSettings.integrator`)."""
    mf, cm = pair
    out = {}
    for e in ds.experiments:
        try:
            out[e.name] = cm.simulate(params={**values, **e.conditions}, backend=backend,
                                      **mf.experiment.run_options(dense=True))
        except AcausalError:
            out[e.name] = None
    return out


def raw_residuals(f, ds):
    """experiment -> signal -> residual in SI (weighted residual x floor)."""
    raw = {}
    groups, sigs = np.asarray(f.groups), np.asarray(f.signals)
    for e in ds.experiments:
        raw[e.name] = {}
        for s in dict.fromkeys(sigs[groups == e.name]):
            m = (groups == e.name) & (sigs == s)
            vals = (e.trace.signals[s] if e.trace is not None and s in e.trace.signals
                    else np.atleast_1d(e.measures.get(s, 1.0)))
            r = f.residuals[m] * sigma(ds, s, vals)
            raw[e.name][s] = float(r[0]) if s in e.measures and r.size == 1 else r
    return raw


def _values_of(ds, s):
    for e in ds.experiments:
        if s in e.measures:
            return e.measures[s]
        if e.trace is not None and s in e.trace.signals:
            return e.trace.signals[s]
    return 1.0


def _traces(ds, sims):
    out = {}
    for e in ds.experiments:
        res = sims.get(e.name)
        if res is None or e.trace is None:
            continue
        out[e.name] = {s: (np.asarray(res.t), np.asarray(res[s])) for s in e.trace.signals}
    return out


def views(problem, cal, ranking) -> Views:
    """The report's simulated material (module doc)."""
    ds = dataset_of(problem)
    from ..problem import NOMINAL
    f0 = cal.fit
    backend = problem.settings.integrator
    sims0 = simulate_all(model_of(problem, NOMINAL), ds, f0.values, backend)
    best = ranking.best
    sims1, raw1 = {}, {}
    if best is not None:
        sims1 = simulate_all(model_of(problem, best.candidate), ds, best.fit.values, backend)
        raw1 = raw_residuals(best.fit, ds)
    raw0 = raw_residuals(f0, ds)
    lib = load_library(problem.library)
    try:
        bodies = [s.path for s in lib.graph_of(problem.model_path).sites("bodies")]
    except Exception:  # noqa: BLE001 - a stand-in graph without bodies
        bodies = []
    fp = fingerprints(ds, raw0, {k: v for k, v in sims0.items() if v is not None}, bodies)
    floors = {s: sigma(ds, s, np.atleast_1d(_values_of(ds, s)))
              for s in dict.fromkeys(f0.signals)}
    return Views(raw0, raw1, _traces(ds, sims0), _traces(ds, sims1), floors, fp)
