"""The dataset folder an instrument would record, written by hand (no code
of acausal): ``experiments.csv`` (name, the conditions in SI),
``instrument.csv`` (signal, resolution, noise_std in SI) and one trace file
per experiment (time and every measured signal, SI). The reading: the
truth's samples plus Gaussian noise, rounded to the resolution; the floor
of a signal is sqrt(noise^2 + resolution^2 / 12), the diagnosis's unit.

``effect_floors``: the RMS over every recorded value of (truth with the
laws - truth without) / floor, noise-free: how large a hidden effect is.
``scaled``: the laws with their magnitudes scaled together so that the
effect is a target number of floors (bisection in log of the scale).
"""
import csv
import math
from pathlib import Path

import numpy as np
from scipy.optimize import brentq


def floor(truth, signal):
    return math.sqrt(truth.NOISE[signal] ** 2 + truth.RESOLUTION[signal] ** 2 / 12.0)


def write(folder, truth, laws=(), seed=0, free=None):
    """Write the dataset of ``truth`` (a module: CONDITIONS, SIGNALS, NOISE,
    RESOLUTION, run) with the hidden ``laws`` to ``folder``; returns the
    folder and the truth's events per experiment."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(seed)
    names = [f"E{i + 1:02d}" for i in range(len(truth.CONDITIONS))]
    cond_names = list(truth.CONDITIONS[0])
    with (folder / "experiments.csv").open("w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(["name", *cond_names])
        for name, cond in zip(names, truth.CONDITIONS):
            w.writerow([name, *(repr(float(cond[k])) for k in cond_names)])
    with (folder / "instrument.csv").open("w", newline="") as fh:
        w = csv.writer(fh, lineterminator="\n")
        w.writerow(["signal", "resolution", "noise_std"])
        for s in truth.SIGNALS:
            w.writerow([s, repr(float(truth.RESOLUTION[s])), repr(float(truth.NOISE[s]))])
    events = {}
    for name, cond in zip(names, truth.CONDITIONS):
        out, ev = truth.run(cond, laws, free)
        events[name] = ev
        cols = [out["time"]]
        for s in truth.SIGNALS:
            y = out[s] + rng.normal(0.0, truth.NOISE[s], out[s].shape)
            q = truth.RESOLUTION[s]
            cols.append(q * np.round(y / q))
        with (folder / f"{name}.csv").open("w", newline="") as fh:
            w = csv.writer(fh, lineterminator="\n")
            w.writerow(["time", *truth.SIGNALS])
            for row in zip(*cols):
                w.writerow([repr(float(v)) for v in row])
    return folder, events


def effect_floors(truth, laws, free=None):
    """RMS of (with laws - without) / floor over every recorded value."""
    acc = []
    for cond in truth.CONDITIONS:
        a, _ = truth.run(cond, laws, free)
        b, _ = truth.run(cond, (), free)
        for s in truth.SIGNALS:
            acc.append((a[s] - b[s]) / floor(truth, s))
    d = np.concatenate(acc)
    return float(np.sqrt(np.mean(d * d)))


def scaled(truth, laws, target, free=None):
    """(laws scaled together, achieved effect in floors) at ``target`` floors."""
    def f(logk):
        return math.log(effect_floors(truth, [law.scaled(math.exp(logk)) for law in laws],
                                      free) / target)
    lo, hi = -1.0, 1.0
    while f(lo) > 0:
        lo -= 2.0
    while f(hi) < 0:
        hi += 2.0
    k = math.exp(brentq(f, lo, hi, xtol=1e-3))
    out = [law.scaled(k) for law in laws]
    return out, effect_floors(truth, out, free)
