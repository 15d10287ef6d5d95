"""Residual fingerprints: features of the calibrated model's residuals that
point at a kind of cause and explain the choice in the report.

* traces: correlation of the residual with the sign of a body's velocity
  (dry friction, or a constant load while the body does not reverse), with
  its velocity (viscous), with v|v| (drag), with its displacement (a force
  varying with position) and its cube (a hardening spring); the shift in
  time of the whole measured trace against the simulated one (a gap or a
  delay); the spectral peak of the residual (an unmodelled compliance rings
  at its frequency);
* measures: the slope and correlation of each measure's residual against
  each experimental condition (for the report's data: THRT residual against
  impact velocity), a trend a velocity-dependent law leaves.

Nothing here decides anything: the candidates are ranked by their fits
(:mod:`acausal.diagnose.run`).
"""
from __future__ import annotations

import numpy as np
from scipy import signal as sps
from scipy import stats

# which fingerprint each hypothesis is expected to leave (shown in the report)
EXPECTED = {
    "coulomb_friction": "sign(v)",
    "quadratic_damping": "v|v|",
    "constant_load": "sign(v)",     # same as friction while the body never reverses
    "hardening_spring": "x^3",
    "clearance": "time shift",
    "flexible_link": "spectral peak",
    "position_dependent_force": "x",
    "contact_damping_law": "measure vs impact velocity",
}

REGRESSORS = ("sign(v)", "v", "v|v|", "x", "x^3")


def body_kinematics(res, path):
    """(position, velocity) arrays of the body at ``path`` in a result, trying
    translational (``s``/``v``) then rotational (``phi``/``w``) names; None
    if the result has neither."""
    for x, v in (("s", "v"), ("phi", "w")):
        if f"{path}.{x}" in res and f"{path}.{v}" in res:
            return np.asarray(res[f"{path}.{x}"], float), np.asarray(res[f"{path}.{v}"], float)
    return None


def _corr(a, b):
    a = np.asarray(a, float) - np.mean(a)
    b = np.asarray(b, float) - np.mean(b)
    d = np.sqrt((a @ a) * (b @ b))
    return float(a @ b / d) if d > 0 else 0.0


def regressor_correlations(time, resid, res, bodies):
    """body -> {regressor: correlation with the residual} on the samples."""
    out = {}
    for path in bodies:
        kin = body_kinematics(res, path)
        if kin is None:
            continue
        x, v = (np.interp(time, res.t, k) for k in kin)
        x = x - x[0]
        feats = {"sign(v)": np.sign(v), "v": v, "v|v|": v * np.abs(v), "x": x, "x^3": x ** 3}
        out[path] = {k: _corr(resid, f) for k, f in feats.items()}
    return out


def time_shift(time, measured, res, var, max_shift=None):
    """The shift tau (s) of the simulated trace y(t - tau) that best matches
    the measured one (cross-correlation: least squares over a grid of shifts
    of up to ``max_shift``, default a tenth of the record, refined by a
    parabola), and the share of the residual's sum of squares it removes."""
    time = np.asarray(time, float)
    y = np.asarray(res[var], float)
    span = time[-1] - time[0]
    if span <= 0 or time.size < 5:
        return dict(shift=0.0, explained=0.0)
    max_shift = span / 10 if max_shift is None else max_shift
    dt = span / (time.size - 1)
    taus = np.arange(-max_shift, max_shift + dt / 4, dt / 4)

    def sse(tau):
        return float(np.sum((np.interp(time - tau, res.t, y) - measured) ** 2))

    costs = np.array([sse(t) for t in taus])
    i = int(np.argmin(costs))
    tau = taus[i]
    if 0 < i < len(taus) - 1:
        c0, c1, c2 = costs[i - 1], costs[i], costs[i + 1]
        den = c0 - 2 * c1 + c2
        if den > 0:
            tau = tau + 0.5 * (c0 - c2) / den * (taus[1] - taus[0])
    s0 = sse(0.0)
    return dict(shift=float(tau), explained=float(1 - sse(tau) / s0) if s0 > 0 else 0.0)


def spectral_peak(time, resid):
    """Frequency (Hz) of the largest periodogram peak of the residual after
    removing a cubic trend, its share of the residual power, and the share
    white noise would give one bin on average (1/number of bins)."""
    time = np.asarray(time, float)
    r = np.asarray(resid, float)
    if r.size < 16:
        return dict(frequency=float("nan"), share=0.0, white_share=float("nan"))
    tn = (time - time[0]) / max(time[-1] - time[0], 1e-300)
    r = r - np.polyval(np.polyfit(tn, r, 3), tn)
    fs = 1.0 / np.median(np.diff(time))
    f, p = sps.periodogram(r, fs=fs, detrend=False)
    if p.size < 3 or not np.any(p[1:] > 0):
        return dict(frequency=float("nan"), share=0.0, white_share=float("nan"))
    i = 1 + int(np.argmax(p[1:]))
    return dict(frequency=float(f[i]), share=float(p[i] / np.sum(p[1:])),
                white_share=float(1.0 / (p.size - 1)))


def measure_trends(dataset, raw):
    """measure -> condition -> {slope, r, p_value, n}: the residual of a
    measure (simulated - measured, SI) regressed on each condition over the
    experiments that measured it (at least 3 with distinct conditions)."""
    out = {}
    for m in dataset.measure_names:
        for c in dataset.condition_names:
            xs, ys = [], []
            for e in dataset.experiments:
                if m in raw.get(e.name, {}) and c in e.conditions:
                    xs.append(e.conditions[c])
                    ys.append(raw[e.name][m])
            if len(xs) < 3 or np.ptp(xs) == 0:
                continue
            lr = stats.linregress(xs, ys)
            out.setdefault(m, {})[c] = dict(slope=float(lr.slope), r=float(lr.rvalue),
                                            p_value=float(lr.pvalue), n=len(xs))
    return out


def fingerprints(dataset, raw, results, bodies):
    """All fingerprints of the calibrated nominal model.

    ``raw``: experiment -> signal -> residual (simulated - measured, SI) as
    :func:`acausal.calibrate.residual_vector` returns; ``results``:
    experiment -> simulation result at the calibrated values; ``bodies``:
    paths of the bodies whose motion the regressors use.
    Returns a dict: ``traces`` (list of per experiment/signal dicts),
    ``measures`` (:func:`measure_trends`) and ``summary`` (pooled regressor
    correlations over every trace sample, per body)."""
    traces = []
    pooled = {}
    for e in dataset.experiments:
        if e.trace is None or e.name not in results:
            continue
        res = results[e.name]
        for var, ys in e.trace.signals.items():
            r = raw[e.name].get(var)
            if r is None:
                continue
            corr = regressor_correlations(e.trace.time, r, res, bodies)
            traces.append(dict(experiment=e.name, signal=var,
                               correlations=corr,
                               shift=time_shift(e.trace.time, ys, res, var),
                               spectrum=spectral_peak(e.trace.time, r)))
            for path in bodies:
                kin = body_kinematics(res, path)
                if kin is None:
                    continue
                x, v = (np.interp(e.trace.time, res.t, k) for k in kin)
                x = x - x[0]
                feats = {"sign(v)": np.sign(v), "v": v, "v|v|": v * np.abs(v), "x": x,
                         "x^3": x ** 3}
                acc = pooled.setdefault(path, {k: ([], []) for k in feats})
                for k, f in feats.items():
                    acc[k][0].append(r / max(np.std(r), 1e-300))
                    acc[k][1].append((f - f.mean()) / max(np.std(f), 1e-300))
    summary = {path: {k: _corr(np.concatenate(a), np.concatenate(b)) if a else 0.0
                      for k, (a, b) in feats.items()}
               for path, feats in pooled.items()}
    return dict(traces=traces, measures=measure_trends(dataset, raw), summary=summary)


def describe(fp, limit=6) -> list:
    """Short sentences naming the strongest fingerprints."""
    lines = []
    best = []
    for path, feats in fp.get("summary", {}).items():
        for k, c in feats.items():
            best.append((abs(c), path, k, c))
    for _, path, k, c in sorted(best, reverse=True)[:3]:
        lines.append(f"trace residuals correlate with {k} of {path}: r = {c:+.2f}")
    shifts = [t for t in fp.get("traces", []) if t["shift"]["explained"] > 0.5]
    for t in shifts[:limit]:
        lines.append(f"{t['experiment']}/{t['signal']}: a time shift of "
                     f"{t['shift']['shift'] * 1e3:+.4g} ms removes "
                     f"{t['shift']['explained']:.0%} of the residual")
    peaks = [t for t in fp.get("traces", [])
             if t["spectrum"]["share"] > 10 * (t["spectrum"]["white_share"] or 1)]
    for t in peaks[:limit]:
        lines.append(f"{t['experiment']}/{t['signal']}: spectral peak at "
                     f"{t['spectrum']['frequency']:.4g} Hz "
                     f"({t['spectrum']['share']:.0%} of the residual power)")
    for m, conds in fp.get("measures", {}).items():
        for c, d in conds.items():
            lines.append(f"{m} residual against {c}: slope {d['slope']:+.3g} per unit, "
                         f"r = {d['r']:+.2f}, p = {d['p_value']:.2g} ({d['n']} experiments)")
    return lines
