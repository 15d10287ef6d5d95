"""The report's figures, drawn from a :class:`~.result.Diagnosis` and its
stored views (no simulation here)."""
from __future__ import annotations

import numpy as np

from ..stages import stats as st


def write_plots(out_dir, d) -> dict:
    """name -> file of each figure written into ``out_dir``."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    figs = {"residuals": _save(plt, _residuals(plt, d), out_dir, "residuals.png")}
    if d.ranking.rows:
        figs["ranking"] = _save(plt, _ranking(plt, d), out_dir, "ranking.png")
    figs["traces"] = _save(plt, _fitted(plt, d), out_dir, "fitted.png")
    if d.location is not None and d.location.terms:
        figs["located"] = _save(plt, _located(plt, d), out_dir, "located.png")
    nxt = getattr(d.next_experiment, "result", None)
    if nxt is not None and nxt.predictions:
        from ...studies.design import plot_next_experiment
        plot_next_experiment(nxt, out_dir / "next_experiment.png")
        figs["next"] = "next_experiment.png"
    return figs


def _located(plt, d):
    """The generic term's shape against position and against velocity (best
    3 nodes; the best node with its +-2 standard deviation band, from the
    fit's covariance, and the term beside the named cause when fitted)."""
    fig, axes = plt.subplots(1, 2, figsize=(9.5, 3.6))
    loc = d.location
    shown = list(loc.terms[:3]) + ([loc.beside] if loc.beside is not None else [])
    for i, t in enumerate(shown):
        best = i == 0
        label = (f"{t.node} beside {t.beside}" if t.beside else t.node) + \
            f" ({t.resolution[0]}x{t.resolution[1]} knots, held-out {t.heldout_rmse:.3g})"
        ls = "--" if t.beside else "-"
        for ax, z, f, sd in ((axes[0], "x", "f_x", "f_x_sd"), (axes[1], "v", "f_v", "f_v_sd")):
            line = ax.plot(t.shape[z], t.shape[f], lw=2.0 if best else 0.8, ls=ls,
                           label=label)[0]
            if (best or t.beside) and sd in t.shape:
                ax.fill_between(t.shape[z], t.shape[f] - 2 * t.shape[sd],
                                t.shape[f] + 2 * t.shape[sd], color=line.get_color(),
                                alpha=0.25, lw=0)
    axes[0].set_xlabel("position of the node's body [m, or rad for a rotating body]")
    axes[1].set_xlabel("velocity of the node's body [m/s, or rad/s]")
    for ax in axes:
        ax.axhline(0, color="k", lw=0.5)
        ax.set_ylabel("generic force [N, or N*m]")
        ax.legend(fontsize=6)
    axes[0].set_title("located generic term (thick: the best node; band: +-2 sd the data "
                      "support)", fontsize=8)
    return fig


def _save(plt, fig, out_dir, name):
    fig.tight_layout()
    fig.savefig(out_dir / name, dpi=110)
    plt.close(fig)
    return name


def _panels(ds):
    traces = list(dict.fromkeys(s for e in ds.experiments if e.trace is not None
                                for s in e.trace.signals))
    return traces, traces + ds.measure_names


def _label(d):
    best = d.ranking.best
    return None if best is None else f"with {best.candidate.label}"


def _residual_trace(ax, d, s):
    v, fl, tmax = d.views, d.views.floors.get(s, 0.0), 0.0
    for i, e in enumerate(d.dataset.experiments):
        if e.trace is None or s not in e.trace.signals:
            continue
        t = e.trace.time * 1e3
        tmax = max(tmax, t[-1])
        ax.plot(t, v.raw0[e.name][s], color=f"C{i % 10}", lw=0.8, label=f"{e.name} before")
        if v.raw1:
            ax.plot(t, v.raw1[e.name][s], color=f"C{i % 10}", lw=0.8, ls="--")
    ax.fill_between([0, tmax], -fl, fl, color="0.8", alpha=0.6, lw=0, label="instrument floor")
    for y in (2 * fl, -2 * fl):
        ax.axhline(y, color="0.5", lw=0.5, ls=":")
    ax.set_xlabel("time [ms]")


def _residual_measure(ax, d, s, cond):
    v, fl = d.views, d.views.floors.get(s, 0.0)
    xs, y0, y1 = [], [], []
    for e in d.dataset.experiments:
        if s in v.raw0.get(e.name, {}) and s in e.measures:
            xs.append(e.conditions.get(cond, len(xs)))
            y0.append(v.raw0[e.name][s])
            y1.append(v.raw1[e.name][s] if v.raw1 else np.nan)
    xs = np.asarray(xs)
    if xs.size:
        pad = 0.05 * (np.ptp(xs) or 1.0)
        ax.fill_between([xs.min() - pad, xs.max() + pad], -fl, fl, color="0.8", alpha=0.6,
                        lw=0, label="instrument floor")
        ax.errorbar(xs, y0, yerr=fl, fmt="o", color="C0", label="before")
        if v.raw1:
            ax.plot(xs, y1, "x", color="C3", ms=8, label="after")
    ax.set_xlabel(cond or "experiment")


def _panel_figure(plt, d, height, on_trace, on_measure):
    """One panel per signal of the dataset (:func:`_panels`): ``on_trace(ax,
    d, s)`` or ``on_measure(ax, d, s, condition)`` draws it."""
    ds = d.dataset
    traces, panels = _panels(ds)
    cond = ds.condition_names[0] if ds.condition_names else None
    fig, axes = plt.subplots(len(panels), 1, figsize=(8, height * len(panels)), squeeze=False)
    for ax, s in zip(axes[:, 0], panels):
        if s in traces:
            on_trace(ax, d, s)
        else:
            on_measure(ax, d, s, cond)
    return fig, axes, panels


def _shown(d, s):
    """(factor, unit) a signal's values are shown in: a measure's display
    unit (thrt in ms), else the SI unit of the measure or variable
    (the axes said only "[SI]")."""
    try:
        from ...lang.experiment import Measure
        from ...modelfile import compile_file
        mf, cm = compile_file(d.problem.model_path)
    except Exception:  # noqa: BLE001 - a figure without units rather than none
        return 1.0, "SI"
    fn = mf.measures.get(s)
    if isinstance(fn, Measure):
        factor, unit = fn.shown(1.0)
        return factor, unit
    unit = mf.measure_unit(s)
    if unit is None and s in cm.flat.variables:
        unit = cm.flat.variables[s].unit
    if unit is None:
        for e in cm.params:
            if e.name == s:
                unit = e.unit
    return 1.0, unit or "SI"


def _in_unit(ax, factor, axis="y"):
    """Tick labels of ``ax`` showing SI values multiplied by ``factor``."""
    if factor == 1.0:
        return
    from matplotlib.ticker import FuncFormatter
    fmt = FuncFormatter(lambda v, _: f"{v * factor:.6g}")
    (ax.yaxis if axis == "y" else ax.xaxis).set_major_formatter(fmt)


def _condition_label(ax, d, cond):
    if cond:
        factor, unit = _shown(d, cond)
        ax.set_xlabel(f"{cond} [{unit}]")
        _in_unit(ax, factor, "x")


def _residuals(plt, d):
    fig, axes, panels = _panel_figure(plt, d, 2.8, _residual_trace, _residual_measure)
    cond = d.dataset.condition_names[0] if d.dataset.condition_names else None
    traces, _ = _panels(d.dataset)
    for ax, s in zip(axes[:, 0], panels):
        ax.axhline(0, color="k", lw=0.5)
        factor, unit = _shown(d, s)
        ax.set_ylabel(f"{s}\nresidual [{unit}]")
        _in_unit(ax, factor)
        if s not in traces:
            _condition_label(ax, d, cond)
        ax.legend(fontsize=7, ncol=3)
    label = _label(d)
    axes[0, 0].set_title("residuals (simulated - measured): solid/o before, dashed/x after"
                         + (f" ({label})" if label else ""), fontsize=9)
    return fig


def _ranking(plt, d):
    top = d.ranking.rows[:20]
    a0 = top[0].aicc
    fig, ax = plt.subplots(figsize=(8, 0.35 * len(top) + 1.5))
    y = np.arange(len(top))[::-1]
    dd = [r.aicc - a0 for r in top]
    ax.barh(y, np.maximum(dd, 1e-2), color=["C3" if i == 0 else "C0" for i in range(len(top))])
    ax.set_yticks(y)
    ax.set_yticklabels([f"{r.candidate.hypothesis} @ {r.candidate.location}" for r in top],
                       fontsize=7)
    ax.set_xscale("symlog", linthresh=2.0)
    ax.axvline(st.EQUIVALENCE, color="k", ls=":", lw=0.8)
    d_nom = d.decision.a0 - a0
    ax.axvline(d_nom, color="C2", ls="--", lw=1, label=f"no extension ({d_nom:.3g})")
    ax.set_xlabel("dAICc to the best (dotted: equivalence threshold)")
    ax2 = ax.twiny()
    ax2.plot([r.heldout_rmse for r in top], y, "k.", label="held-out RMS")
    ax2.set_xlabel("held-out RMS [floor units] (dots)")
    ax.legend(fontsize=7, loc="lower right")
    return fig


def _fitted_trace(ax, d, s):
    v = d.views
    for i, e in enumerate(d.dataset.experiments):
        if e.trace is None or s not in e.trace.signals:
            continue
        c = f"C{i % 10}"
        ax.plot(e.trace.time * 1e3, e.trace.signals[s], ".", ms=2, color=c,
                label=f"{e.name} measured")
        if s in v.sim0.get(e.name, {}):
            t, y = v.sim0[e.name][s]
            ax.plot(t * 1e3, y, color=c, lw=0.6, alpha=0.6)
        if s in v.sim1.get(e.name, {}):
            t, y = v.sim1[e.name][s]
            ax.plot(t * 1e3, y, color=c, lw=1.0, ls="--")
    ax.set_xlabel("time [ms]")


def _fitted_measure(ax, d, s, cond):
    v = d.views
    xs, ym, y0, y1 = [], [], [], []
    for e in d.dataset.experiments:
        if s in e.measures:
            xs.append(e.conditions.get(cond, len(xs)))
            ym.append(e.measures[s])
            y0.append(e.measures[s] + v.raw0[e.name][s])
            y1.append(e.measures[s] + v.raw1[e.name][s] if v.raw1 else np.nan)
    ax.errorbar(xs, ym, yerr=v.floors.get(s, 0.0), fmt="ko", label="measured")
    ax.plot(xs, y0, "s", color="C0", mfc="none", label="calibrated model")
    if v.raw1:
        ax.plot(xs, y1, "x", color="C3", ms=8, label=_label(d))
    ax.set_xlabel(cond or "experiment")


def _fitted(plt, d):
    fig, axes, panels = _panel_figure(plt, d, 3, _fitted_trace, _fitted_measure)
    cond = d.dataset.condition_names[0] if d.dataset.condition_names else None
    traces, _ = _panels(d.dataset)
    for ax, s in zip(axes[:, 0], panels):
        factor, unit = _shown(d, s)
        ax.set_ylabel(f"{s} [{unit}]")
        _in_unit(ax, factor)
        if s not in traces:
            _condition_label(ax, d, cond)
        ax.legend(fontsize=7, ncol=2)
    axes[0, 0].set_title("measured (dots) against the calibrated model (solid) and "
                         "the extended one (dashed)", fontsize=9)
    return fig
