"""Long traces thinned to what their instrument floor supports.

A trace sampled far faster than its signal moves by one instrument floor
carries no more information per extra sample (the quantisation error of a
slow signal is correlated), while every fit simulates and compares each
sample. :func:`thin_traces` keeps about one sample per floor the signal
travels; the diagnosis and the calibration both fit the thinned dataset,
and the thinning is kept in the dataset's notes.
"""
from __future__ import annotations

import dataclasses
import sys

import numpy as np

from .records import Dataset

__all__ = ["MAX_TRACE_SAMPLES", "MIN_TRACE_SAMPLES", "thin_traces"]

MAX_TRACE_SAMPLES = 4000   # samples of one trace a diagnosis fits (each fit simulates them all)
MIN_TRACE_SAMPLES = 200    # ... and at least this many, when the trace has them


def thin_traces(ds: Dataset, max_samples=MAX_TRACE_SAMPLES, say=False) -> Dataset:
    """The dataset with each long trace thinned to what its instrument
    floor supports, evenly (every k-th sample, the last one kept): about
    one sample per floor the signal travels (its total variation over the
    floor, the largest over its signals; independent noise makes every
    sample count), at least ``MIN_TRACE_SAMPLES`` and at most
    ``max_samples``. Samples closer than the floor are not independent
    (the quantisation error of a slow signal is correlated:
    :mod:`acausal.diagnose.stages.stats`)
    and a fit's cost grows with them (a 5 M-sample trace). Each thinning is
    kept in the dataset's ``notes`` (and said on stderr with ``say``: once,
    where a study loads its data; a diagnosis's workers thin their copies
    alike and silently)."""
    notes = list(ds.notes)
    experiments = []
    for e in ds.experiments:
        tr = e.trace
        n = 0 if tr is None else len(tr.time)
        if n <= MIN_TRACE_SAMPLES:
            experiments.append(e)
            continue
        supported = 0
        for name, y in tr.signals.items():
            inst = ds.instrument.get(name)
            floor = inst.floor() if inst is not None else 0.0
            if not floor > 0:
                supported = n
                break
            travel = float(np.sum(np.abs(np.diff(y))))
            supported = max(supported, int(min(travel / floor, 1e15)) + 1)
        keep = min(n, max(supported, MIN_TRACE_SAMPLES), max_samples)
        if keep >= n:
            experiments.append(e)
            continue
        step = -(-n // keep)
        idx = np.arange(0, n, step)
        if idx[-1] != n - 1:
            idx = np.append(idx, n - 1)
        why = ("the limit of "
               f"{max_samples:,} samples per trace" if supported > max_samples else
               "what the instrument floor supports (about one sample per floor the signal "
               "travels)")
        note = (f"{e.name}: trace thinned from {n:,} to {len(idx):,} samples (every "
                f"{step:,}th): {why}")
        notes.append(note)
        if say:
            print(f"acausal: note: {note}", file=sys.stderr, flush=True)
        trace = dataclasses.replace(tr, time=tr.time[idx],
                                    signals={k: v[idx] for k, v in tr.signals.items()})
        experiments.append(dataclasses.replace(e, trace=trace))
    return dataclasses.replace(ds, experiments=experiments, notes=notes)
