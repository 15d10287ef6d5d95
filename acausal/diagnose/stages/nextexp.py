"""Stage: the next experiment, computed (:mod:`acausal.design`).

When the data cannot tell the members of the best candidate's class apart
(two or more cause classes in the class of :func:`.stages.rank`), each member
at its fitted parameters becomes a rival, and the experiment within the
conditions the model file declares (``conditions = {name: (low, high,
unit)}``), with the signal to record, whose predictions differ most
between them is searched (Hunter and Reiner 1965; Box and Hill 1967: the
separation is in instrument floors). The other conditions stay those of the
reference experiment (the first with a trace). When the model file declares
no conditions, the separation at the reference experiment is reported
(the numbers, not a null) with a message saying what to declare.

The stage simulates, on the diagnosis's workers (the design's
``Search.map_jobs``; each rival a picklable :class:`CandidateRival`); the
report only draws what it stored (each member's predicted signal).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import AcausalError

MAX_RIVALS = 4        # the best members of the class taken as rivals
N_REFINE = 1          # Powell refinements of the design search (acausal.design)
MAX_REFINE_EVALS = 16


@dataclass
class NextStep:
    """``members``: the class's candidate labels (rivals); ``result``: the
    :class:`acausal.design.NextExperiment` (None when not computed, with
    ``message`` saying why)."""

    members: tuple = ()
    result: object = None
    message: str = ""
    wall_s: float = 0.0
    reference: str = ""           # the experiment whose conditions are kept fixed

    def to_dict(self) -> dict:
        base = dict(computed=self.result is not None, members=list(self.members),
                    reference_experiment=self.reference)
        if self.result is None:
            return dict(base, conditions=None, signal=None, separation_floors=None,
                        message=self.message)
        out = dict(base, **self.result.to_dict())
        if self.message and not out.get("message"):
            out["message"] = self.message
        return out


def class_rows(dec, rk, index=None) -> list:
    """The rows of the best candidate's class, best first, one per set of
    cause classes (families) and sites (a pair: its two members' families
    and sites, in any order): members of one family are nested (Coulomb
    friction is Stribeck friction without its static excess), so at their
    fits they predict alike everywhere and would leave nothing to split
    (Coulomb + drag at the cam and stick-slip + drag at the cam are one
    rival; until 2026-11-28 a pair was keyed by its hypothesis ids, so such
    variants filled the four places and the drag at the follower was never
    a rival); at most MAX_RIVALS."""
    if not dec.discrepancy or rk.best is None or not rk.classes:
        return []
    first = next((c for c in rk.classes if rk.after in c), rk.classes[0])
    out, seen = [], set()
    fam = index.family if index is not None else (lambda h: h)
    for i in [rk.after] + sorted(i for i in first if i != rk.after):
        c = rk.rows[i].candidate
        key = frozenset((fam(h), loc) for h, loc, _ in c.members())
        if key not in seen:
            seen.add(key)
            out.append(rk.rows[i])
    return out[:MAX_RIVALS]


def _reference(ds):
    return next((e for e in ds.experiments if e.trace is not None), ds.experiments[0])


def _signals(ds, ref):
    from ...studies.design import signals_of
    names = list(ref.trace.signals) if ref.trace is not None else []
    names += [m for m in dict.fromkeys(k for e in ds.experiments for k in e.measures)]
    return signals_of(ds, names)


@dataclass(frozen=True, eq=False)
class CandidateRival:
    """One member of the class as a rival of the design: the
    :class:`acausal.studies.design.ModelRival` of its fitted model, made
    where it runs (the model once per process, :func:`.tasks.model_of`),
    so that the design's ``map_jobs`` can send it to the diagnosis's workers
    (it pickles without a compiled model)."""

    problem: object
    candidate: object
    params: dict
    signals: tuple
    times: np.ndarray
    options: dict
    steps: tuple

    def _rival(self):
        from ...studies.design import ModelRival
        from .tasks import model_of
        return ModelRival(model_of(self.problem, self.candidate), self.params, self.signals,
                          self.times, self.options, self.steps)

    def __call__(self, conditions):
        return self._rival()(conditions)

    def spread(self, conditions, prediction):
        return self._rival().spread(conditions, prediction)


def rivals(problem, rows, ref, signals):
    """label -> :class:`CandidateRival` of each row's fitted model, with one
    step per principal direction of its parameters' covariance
    (:func:`acausal.studies.design.covariance_steps`): the design weighs
    each rival's predictions by how well its fit determines them."""
    from ...studies.design import covariance_steps
    times = ref.trace.time if ref.trace is not None else np.array([0.0])
    opts = dict(backend=problem.settings.integrator)     # the fits' integrator
    return {r.candidate.label: CandidateRival(
        problem, r.candidate, dict(r.fit.values), tuple(s.name for s in signals), times, opts,
        tuple(covariance_steps(r.fit.names, r.fit.values, r.fit.jacobian, r.fit.cost)))
        for r in rows}


def _fixed_only(rv, signals, ref, times, map_jobs=None):
    """The class at the reference experiment alone (no condition declared);
    ``map_jobs`` as :func:`next_experiment`'s."""
    from ...studies.design import NextExperiment, predicted, serial_map
    sc = predicted(rv, dict(ref.conditions), signals, map_jobs=map_jobs or serial_map)
    sep = math.sqrt(max(sc.d2, 0.0)) if np.isfinite(sc.d2) else float("nan")
    pair = min(sc.pairwise, key=sc.pairwise.get) if sc.pairwise else " | "
    n = max(np.asarray(next(iter(sc.predictions.values()), [0.0])).size, 1)
    msg = (f"the model file declares no conditions (conditions = {{name: (low, high, unit)}}): "
           f"no experiment to search; at the experiment already run ({ref.name}) the "
           f"members are {sep:.3g} noise floors apart")
    return NextExperiment({}, sc.signal or "", sep, sep / math.sqrt(n),
                          tuple(pair.split(" | ")),
                          {k: math.sqrt(v) for k, v in sc.pairwise.items()}, sc.predictions,
                          1, sep, False, msg, times)


def next_experiment(problem, ds, dec, rk, index=None, map_jobs=None) -> NextStep:
    """Stage: the experiment that splits the best candidate's class (module
    doc). ``map_jobs(fn, jobs)``: how the rivals' simulations run (None: one
    after another here; the diagnosis passes its executor's, the same
    predictions side by side, :func:`acausal.studies.design.predicted`)."""
    import time
    from ...studies.design import Search, conditions_of, design_experiment, serial_map
    map_jobs = map_jobs or serial_map
    from ...modelfile import compile_file
    t0 = time.perf_counter()
    rows = class_rows(dec, rk, index)
    labels = tuple(r.candidate.label for r in rows)
    if len(rows) < 2:
        why = ("no discrepancy: nothing to split" if not dec.discrepancy else
               "the best candidate's class has one member: nothing to split")
        return NextStep(labels, None, why)
    ref = _reference(ds)
    try:
        signals = _signals(ds, ref)
        rv = rivals(problem, rows, ref, signals)
        times = ref.trace.time if ref.trace is not None else None
        conds = conditions_of(compile_file(problem.model_path)[0])
        if not conds:
            res = _fixed_only(rv, signals, ref, times, map_jobs)
        else:
            search = Search(n_initial=max(8, 4 * len(conds)), n_refine=N_REFINE,
                            max_refine_evals=MAX_REFINE_EVALS, map_jobs=map_jobs)
            res = design_experiment(rv, conds, signals, fixed=dict(ref.conditions),
                                    reference=dict(ref.conditions), search=search, times=times)
    except AcausalError as exc:
        return NextStep(labels, None, f"not computed: {exc}", time.perf_counter() - t0,
                        ref.name)
    return NextStep(labels, res, "", time.perf_counter() - t0, ref.name)
