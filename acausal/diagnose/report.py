"""The diagnosis report: a Markdown file and its plots, written from the
context :func:`acausal.diagnose.run.diagnose` assembles."""
from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ..errors import AcausalError
from . import stats as st
from .fingerprints import EXPECTED, describe, fingerprints


def _simulate_all(pair, ds, values):
    """experiment -> result (None where the simulation fails)."""
    mf, cm = pair
    out = {}
    for e in ds.experiments:
        try:
            out[e.name] = cm.simulate(params={**values, **e.conditions},
                                      **mf.experiment.run_options(dense=True))
        except AcausalError:
            out[e.name] = None
    return out


def _raw(f, ds):
    """experiment -> signal -> residual in SI (weighted residual x floor)."""
    from ..calibrate import _sigma
    raw = {}
    groups = np.asarray(f.groups)
    sigs = np.asarray(f.signals)
    for e in ds.experiments:
        raw[e.name] = {}
        for s in dict.fromkeys(sigs[groups == e.name]):
            m = (groups == e.name) & (sigs == s)
            vals = (e.trace.signals[s] if e.trace is not None and s in e.trace.signals
                    else np.atleast_1d(e.measures.get(s, 1.0)))
            r = f.residuals[m] * _sigma(ds, s, vals)
            raw[e.name][s] = float(r[0]) if s in e.measures and r.size == 1 else r
    return raw


def _fmt(x, digits=4):
    if x is None:
        return "n/a"
    if isinstance(x, float) and not math.isfinite(x):
        return "inf" if x > 0 else "nan"
    return f"{x:.{digits}g}"


def write_report(out_dir: Path, ctx: dict, plots: bool = True) -> Path:
    from ..calibrate import _sigma
    from .run import _model

    ds, f0, rows = ctx["ds"], ctx["f0"], ctx["rows"]
    lib, graph = ctx["lib"], ctx["graph"]
    nominal_pair = _model(ctx["model_path"], lib.name, None, None)
    sims0 = _simulate_all(nominal_pair, ds, f0.values)
    after = ctx["after"]
    sims1 = {}
    if after is not None:
        pair1 = _model(ctx["model_path"], lib.name, after["cause"], after["location"])
        sims1 = _simulate_all(pair1, ds, after["fit"].values)
    raw0 = _raw(f0, ds)
    raw1 = _raw(after["fit"], ds) if after is not None else {}
    try:
        bodies = [s.path for s in graph.sites("bodies")]
    except Exception:  # noqa: BLE001 - a graph without bodies
        bodies = []
    fp = fingerprints(ds, raw0, {k: v for k, v in sims0.items() if v is not None}, bodies)
    floors = {s: _sigma(ds, s, np.atleast_1d(_values_of(ds, s)))
              for s in dict.fromkeys(f0.signals)}
    figs = {}
    if plots:
        figs = _plots(out_dir, ctx, sims0, sims1, raw0, raw1, floors)
    text = _markdown(ctx, fp, floors, raw0, raw1, figs)
    path = out_dir / "report.md"
    path.write_text(text)
    return path


def _values_of(ds, s):
    for e in ds.experiments:
        if s in e.measures:
            return e.measures[s]
        if e.trace is not None and s in e.trace.signals:
            return e.trace.signals[s]
    return 1.0


# ---------------------------------------------------------------------------
# Markdown
# ---------------------------------------------------------------------------


def _markdown(ctx, fp, floors, raw0, raw1, figs):
    ds, f0, rows, summary = ctx["ds"], ctx["f0"], ctx["rows"], ctx["summary"]
    decision, cause, after, weak = ctx["decision"], ctx["cause"], ctx["after"], ctx["weak"]
    lib = ctx["lib"]
    L = []
    L.append(f"# Diagnosis of `{os.path.basename(ctx['model_path'])}` against "
             f"`{os.path.basename(ctx['data_folder'])}`\n")
    L.append(f"Model file: `{_rel(ctx['model_path'])}`  \nData: `{_rel(ctx['data_folder'])}` "
             f"({len(ds.experiments)} experiments, {f0.n} measured values)  \n"
             f"Errors are RMS of (simulated - measured) / instrument floor: 1 is what the "
             f"instrument's noise and resolution alone explain.\n")
    L.append("## Verdict\n")
    L.append(_verdict(ctx) + "\n")

    # 1 ------------------------------------------------------------------------
    L.append("## 1. What the calibrated model gets wrong\n")
    if f0.names:
        L.append("Free parameters calibrated by weighted output error (95 % intervals):\n")
        for nm in f0.names:
            lo, hi = f0.ci95.get(nm, (float("nan"),) * 2)
            L.append(f"- `{nm}` = {_fmt(f0.values[nm])}  [{_fmt(lo)}, {_fmt(hi)}]")
        L.append("")
    else:
        L.append("The model file declares no free parameters: the nominal model is "
                 "compared as it is.\n")
    L.append("Residuals per experiment and signal (SI units; floor = instrument "
             "floor):\n")
    L.append("| experiment | conditions | signal | n | residual (RMS, SI) | RMS / floor | "
             "max abs / floor |")
    L.append("|---|---|---|---|---|---|---|")
    groups, sigs = np.asarray(f0.groups), np.asarray(f0.signals)
    for e in ds.experiments:
        cond = ", ".join(f"{k}={_fmt(v)}" for k, v in e.conditions.items())
        for s in dict.fromkeys(sigs[groups == e.name]):
            m = (groups == e.name) & (sigs == s)
            r = f0.residuals[m]
            raw = np.atleast_1d(raw0[e.name][s])
            L.append(f"| {e.name} | {cond} | {s} | {r.size} | "
                     f"{_fmt(float(np.sqrt(np.mean(raw ** 2))))} | "
                     f"{_fmt(float(np.sqrt(np.mean(r ** 2))), 3)} | "
                     f"{_fmt(float(np.max(np.abs(r))), 3)} |")
    L.append("")
    L.append("Instrument floors: " + ", ".join(
        f"`{s}` {_fmt(v)} (resolution {_fmt(ds.instrument[s].resolution) if s in ds.instrument else 'n/a'}, "
        f"noise {_fmt(ds.instrument[s].noise_std) if s in ds.instrument else 'n/a'})"
        for s, v in floors.items()) + "\n")
    L.append(f"**Is there a discrepancy?** Family significance level alpha = "
             f"{decision['alpha']:g}, split equally between the tests (Bonferroni); see "
             f"`acausal/diagnose/stats.py` for why this bounds the false-positive rate.\n")
    L.append("| test | detail | p-value (adjusted) | threshold | discrepancy |")
    L.append("|---|---|---|---|---|")
    for p in decision["parts"]:
        L.append(f"| {p['name']} | {p['detail']} | {_fmt(p['p_value'], 3)} | "
                 f"{_fmt(p['threshold'], 3)} | {'yes' if p['reject'] else 'no'} |")
    L.append("")
    L.append(f"Result: **{'discrepancy' if decision['discrepancy'] else 'no significant discrepancy'}**.\n")
    if "residuals" in figs:
        L.append(f"![residuals before and after]({figs['residuals']})\n")

    # 2 ------------------------------------------------------------------------
    L.append("## 2. Residual fingerprints\n")
    lines = describe(fp)
    if lines:
        L.extend(f"- {x}" for x in lines)
    else:
        L.append("- none stands out")
    L.append("")
    L.append("Expected fingerprint of each hypothesis: " + "; ".join(
        f"{k}: {v}" for k, v in EXPECTED.items()) + ".\n")

    # 3 ------------------------------------------------------------------------
    L.append("## 3. Hypotheses fitted\n")
    c_hat = ctx["c_hat"]
    L.append(f"{len(rows)} candidates (hypothesis x location from the model graph), each "
             f"fitted with the free parameters by weighted output error. AICc = S/c + 2k + "
             f"2k(k+1)/(n-k-1), n = {f0.n}, c = {c_hat:.3g} (over-dispersion of the best "
             f"fit; 1 = it reaches the instrument floor). No extension: k = {f0.k}, "
             f"S = {_fmt(f0.cost)}, AICc = {_fmt(ctx['a0'])}. Held-out: "
             f"leave-one-experiment-out RMS, by exact refits where marked (e), "
             f"else linearised from the Jacobian at the full fit (l). LR p: "
             f"likelihood ratio against no extension, unadjusted.\n")
    if rows:
        w = st.akaike_weights([r["aicc"] for r in rows])
        L.append("| rank | cause | location | k | S | AICc | dAICc | weight | LR p | "
                 "held-out RMS | train RMS | parameters |")
        L.append("|---|---|---|---|---|---|---|---|---|---|---|---|")
        a_best = rows[0]["aicc"]
        specs_by = ctx["specs_by"]
        for i, (r, wi) in enumerate(zip(rows, w)):
            own = [s.name for s in specs_by.get((r["cause"], r["location"]), [])]
            ps = ", ".join(f"{nm} = {_fmt(r['fit'].values[nm], 3)}" for nm in own)
            L.append(f"| {i + 1} | {r['cause']} | {r['location']} | {r['k']} | "
                     f"{_fmt(r['S'])} | {_fmt(r['aicc'])} | {_fmt(r['aicc'] - a_best, 3)} | "
                     f"{wi:.2g} | {_fmt(r['lr_p'], 2)} | {_fmt(r['heldout_rmse'], 3)} "
                     f"({'e' if r.get('heldout_exact') else 'l'}) | "
                     f"{_fmt(r['train_rmse'], 3)} | {ps} |")
        L.append("")
    for r in ctx["failed"]:
        why = r["error"] or (r["fit"].message if r["fit"] is not None else "")
        L.append(f"- not fitted: {r['hyp']} at {r['location']}: {why}")
    if ctx["failed"]:
        L.append("")
    if "ranking" in figs:
        L.append(f"![hypothesis ranking]({figs['ranking']})\n")

    # 4 ------------------------------------------------------------------------
    L.append("## 4. Cause, evidence and equivalent causes\n")
    L.extend(_evidence(ctx))
    L.append("")

    # 5 ------------------------------------------------------------------------
    L.append("## 5. Gain\n")
    g = summary["gain"]
    which = ("the named cause" if cause is not None else
             "the best candidate (no cause named)" if after is not None else
             "no extension")
    cv = "exact leave-one-experiment-out refits" if ctx["loo_exact"] else \
        "linearised leave-one-experiment-out"
    L.append(f"RMS error in floor units (1 = instrument floor); after = {which}; held-out "
             f"= {cv}.\n")
    L.append("| | train | held-out |")
    L.append("|---|---|---|")
    L.append(f"| before (calibrated model) | {_fmt(g['before']['train'], 3)} | "
             f"{_fmt(g['before']['heldout'], 3)} |")
    L.append(f"| after | {_fmt(g['after']['train'], 3)} | {_fmt(g['after']['heldout'], 3)} |")
    L.append("| instrument floor | 1 | 1 |")
    L.append("")
    if ctx["loo_exact"]:
        L.append("Held-out residual per experiment (RMS, floor units):\n")
        L.append("| experiment | before | after |")
        L.append("|---|---|---|")
        before = ctx["loo_exact"].get((None, None), {})
        aft = ctx["loo_exact"].get((after["cause"], after["location"]), {}) if after else {}
        for e in ds.experiments:
            b = before.get(e.name)
            a = aft.get(e.name)
            L.append(f"| {e.name} | {_fmt(_rms(b), 3)} | {_fmt(_rms(a), 3)} |")
        L.append("")
    if "traces" in figs:
        L.append(f"![fitted against measured]({figs['traces']})\n")

    # 6 ------------------------------------------------------------------------
    L.append("## 6. Extended model\n")
    if summary["extended_model"]:
        L.append(f"`{summary['extended_model']}` imports the original model file and adds "
                 f"{cause['cause']} at `{cause['location']}` with the fitted values; run it "
                 f"with `acausal simulate {os.path.basename(summary['extended_model'])}`.\n")
    else:
        L.append("None written (no cause named).\n")
    t = ctx["timing"]
    L.append("## Method and cost\n")
    L.append(f"{t['n_candidates']} candidate fits + the nominal fit in "
             f"{t['fit_s']:.1f} s, leave-one-out in {t['cv_s']:.1f} s; "
             f"{t['n_sim']} simulations for the candidate fits. Hypothesis library: "
             f"`{lib.name}`.\n")
    return "\n".join(L) + "\n"


def _rel(path):
    """``path`` relative to the working directory when it lies below it."""
    rel = os.path.relpath(path)
    return path if rel.startswith("..") else rel


def _rms(r):
    if r is None:
        return None
    r = np.atleast_1d(r)
    return float(np.sqrt(np.mean(r ** 2))) if r.size else None


def _verdict(ctx):
    s, decision = ctx["summary"], ctx["decision"]
    g = s["gain"]
    if not decision["discrepancy"]:
        return ("**No significant discrepancy.** The calibrated model explains the data "
                "within the instrument model at the stated significance level; no cause is "
                "named and no extended model is written. (This does not prove the model "
                "right: an effect smaller than the noise, or one the free parameters absorb, "
                "would pass.)")
    if s["cause"] is None:
        best = ctx["after"]
        reasons = "; ".join(ctx["weak"]) if ctx["weak"] else "no candidate could be fitted"
        txt = (f"**Discrepancy, but the evidence is weak: no cause is named.** {reasons}.")
        if best is not None:
            txt += (f" The best candidate would be {best['cause']} at `{best['location']}` "
                    f"(held-out error {_fmt(g['before']['heldout'], 3)} -> "
                    f"{_fmt(g['after']['heldout'], 3)} floor units).")
        return txt
    txt = (f"**Discrepancy; cause: {s['cause']} at `{s['location']}`.** Held-out error "
           f"{_fmt(g['before']['heldout'], 3)} -> {_fmt(g['after']['heldout'], 3)} floor units "
           f"(train {_fmt(g['before']['train'], 3)} -> {_fmt(g['after']['train'], 3)}).")
    if s["equivalent_causes"]:
        txt += " The data cannot tell it from: " + ", ".join(
            f"{e['cause']} at `{e['location']}`" for e in s["equivalent_causes"]) + "."
    return txt


def _evidence(ctx):
    L = []
    rows, cause, after, lib = ctx["rows"], ctx["cause"], ctx["after"], ctx["lib"]
    if not ctx["decision"]["discrepancy"]:
        L.append("No discrepancy: nothing to explain.")
        if rows:
            r = rows[0]
            L.append(f"For information, the best candidate ({r['cause']} at "
                     f"`{r['location']}`) lowers S from {_fmt(ctx['f0'].cost)} to "
                     f"{_fmt(r['S'])}, LR p = {_fmt(r['lr_p'], 2)} before the correction "
                     f"for the {len(rows)} candidates tried.")
        return L
    if after is None:
        L.append("No candidate could be fitted.")
        return L
    f = after["fit"]
    hyp = lib.HYPOTHESES[after["cause"]]
    head = "Named cause" if cause is not None else "Best candidate (not named: evidence weak)"
    L.append(f"**{head}: {after['cause']} at `{after['location']}`** — {hyp.title}. "
             f"{hyp.explanation}\n")
    L.append("Parameters (95 % intervals, covariance scaled by max(1, S/(n-k))):\n")
    for nm in f.names:
        lo, hi = f.ci95.get(nm, (float("nan"),) * 2)
        L.append(f"- `{nm}` = {_fmt(f.values[nm])}  [{_fmt(lo)}, {_fmt(hi)}]")
    L.append("")
    d_null = ctx["a0"] - after["aicc"]
    L.append(f"- against no extension: dAICc = {d_null:.1f}, likelihood ratio "
             f"2 dlnL = {ctx['f0'].cost - after['S']:.1f} on {after['k'] - ctx['f0'].k} "
             f"dof, p = {_fmt(after['lr_p'], 2)} (x {len(rows)} candidates = "
             f"{_fmt(min(1.0, after['lr_p'] * len(rows)), 2)})")
    runner = ctx["runner"]
    if runner is not None:
        d = runner["aicc"] - after["aicc"]
        L.append(f"- against the runner-up outside its class ({runner['cause']} at "
                 f"`{runner['location']}`): dAICc = {d:.1f}, evidence ratio "
                 f"exp(dAICc/2) = {_fmt(math.exp(min(d, 1400) / 2), 3)}")
    cls = ctx["classes"][0] if ctx["classes"] else []
    members = [rows[i] for i in cls]
    others = [r for r in members if r is not after]
    if others:
        L.append(f"- equivalent within {st.EQUIVALENCE:g} AICc units (one class; the data "
                 f"cannot tell them apart):")
        for r in others:
            L.append(f"  - {r['cause']} at `{r['location']}` (dAICc "
                     f"{r['aicc'] - after['aicc']:.2f}, held-out "
                     f"{_fmt(r['heldout_rmse'], 3)})")
        L.append("- the experiments that would tell them apart:")
        for hid in dict.fromkeys([after["cause"]] + [r["cause"] for r in others]):
            L.append(f"  - {hid}: {lib.HYPOTHESES[hid].distinguishing_experiment}")
    if ctx["weak"]:
        L.append("- **evidence is weak**:")
        L.extend(f"  - {w}" for w in ctx["weak"])
    return L


# ---------------------------------------------------------------------------
# Plots
# ---------------------------------------------------------------------------


def _plots(out_dir, ctx, sims0, sims1, raw0, raw1, floors):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    ds, rows = ctx["ds"], ctx["rows"]
    figs = {}
    trace_sigs = list(dict.fromkeys(s for e in ds.experiments if e.trace is not None
                                    for s in e.trace.signals))
    meas = ds.measure_names
    panels = trace_sigs + meas
    cond = ds.condition_names[0] if ds.condition_names else None
    label1 = (f"with {ctx['after']['cause']} at {ctx['after']['location']}"
              if ctx["after"] is not None else None)
    # residuals before / after with the instrument band
    fig, axes = plt.subplots(len(panels), 1, figsize=(8, 2.8 * len(panels)), squeeze=False)
    for ax, s in zip(axes[:, 0], panels):
        fl = floors.get(s, 0.0)
        if s in trace_sigs:
            tmax = 0.0
            for i, e in enumerate(ds.experiments):
                if e.trace is None or s not in e.trace.signals:
                    continue
                t = e.trace.time * 1e3
                tmax = max(tmax, t[-1])
                ax.plot(t, raw0[e.name][s], color=f"C{i % 10}", lw=0.8,
                        label=f"{e.name} before")
                if raw1:
                    ax.plot(t, raw1[e.name][s], color=f"C{i % 10}", lw=0.8, ls="--")
            ax.fill_between([0, tmax], -fl, fl, color="0.8", alpha=0.6, lw=0,
                            label="instrument floor")
            ax.axhline(2 * fl, color="0.5", lw=0.5, ls=":")
            ax.axhline(-2 * fl, color="0.5", lw=0.5, ls=":")
            ax.set_xlabel("time [ms]")
        else:
            xs, y0, y1 = [], [], []
            for e in ds.experiments:
                if s in raw0.get(e.name, {}) and s in e.measures:
                    xs.append(e.conditions.get(cond, len(xs)))
                    y0.append(raw0[e.name][s])
                    y1.append(raw1[e.name][s] if raw1 else np.nan)
            xs = np.asarray(xs)
            if xs.size:
                pad = 0.05 * (np.ptp(xs) or 1.0)
                ax.fill_between([xs.min() - pad, xs.max() + pad], -fl, fl, color="0.8",
                                alpha=0.6, lw=0, label="instrument floor")
                ax.errorbar(xs, y0, yerr=fl, fmt="o", color="C0", label="before")
                if raw1:
                    ax.plot(xs, y1, "x", color="C3", ms=8, label="after")
            ax.set_xlabel(cond or "experiment")
        ax.axhline(0, color="k", lw=0.5)
        ax.set_ylabel(f"{s}\nresidual [SI]")
        ax.legend(fontsize=7, ncol=3)
    axes[0, 0].set_title("residuals (simulated - measured): solid/o before, "
                         f"dashed/x after" + (f" ({label1})" if label1 else ""), fontsize=9)
    fig.tight_layout()
    fig.savefig(out_dir / "residuals.png", dpi=110)
    plt.close(fig)
    figs["residuals"] = "residuals.png"

    # ranking
    if rows:
        top = rows[:20]
        a0 = rows[0]["aicc"]
        fig, ax = plt.subplots(figsize=(8, 0.35 * len(top) + 1.5))
        labels = [f"{r['cause']} @ {r['location']}" for r in top]
        d = [r["aicc"] - a0 for r in top]
        y = np.arange(len(top))[::-1]
        ax.barh(y, np.maximum(d, 1e-2), color=["C3" if i == 0 else "C0" for i in range(len(top))])
        ax.set_yticks(y)
        ax.set_yticklabels(labels, fontsize=7)
        ax.set_xscale("symlog", linthresh=2.0)
        ax.axvline(st.EQUIVALENCE, color="k", ls=":", lw=0.8)
        d_nom = ctx["a0"] - a0
        ax.axvline(d_nom, color="C2", ls="--", lw=1, label=f"no extension ({d_nom:.3g})")
        ax.set_xlabel("dAICc to the best (dotted: equivalence threshold)")
        ax2 = ax.twiny()
        ax2.plot([r["heldout_rmse"] for r in top], y, "k.", label="held-out RMS")
        ax2.set_xlabel("held-out RMS [floor units] (dots)")
        ax.legend(fontsize=7, loc="lower right")
        fig.tight_layout()
        fig.savefig(out_dir / "ranking.png", dpi=110)
        plt.close(fig)
        figs["ranking"] = "ranking.png"

    # fitted against measured
    exps = ds.experiments
    fig, axes = plt.subplots(len(panels), 1, figsize=(8, 3 * len(panels)), squeeze=False)
    for ax, s in zip(axes[:, 0], panels):
        if s in trace_sigs:
            for i, e in enumerate(exps):
                if e.trace is None or s not in e.trace.signals:
                    continue
                c = f"C{i % 10}"
                ax.plot(e.trace.time * 1e3, e.trace.signals[s], ".", ms=2, color=c,
                        label=f"{e.name} measured")
                r0 = sims0.get(e.name)
                if r0 is not None:
                    ax.plot(r0.t * 1e3, r0[s], color=c, lw=0.6, alpha=0.6)
                r1 = sims1.get(e.name)
                if r1 is not None:
                    ax.plot(r1.t * 1e3, r1[s], color=c, lw=1.0, ls="--")
            ax.set_xlabel("time [ms]")
        else:
            xs, ym, y0, y1 = [], [], [], []
            for e in exps:
                if s in e.measures:
                    xs.append(e.conditions.get(cond, len(xs)))
                    ym.append(e.measures[s])
                    y0.append(e.measures[s] + raw0[e.name][s])
                    y1.append(e.measures[s] + raw1[e.name][s] if raw1 else np.nan)
            ax.errorbar(xs, ym, yerr=floors.get(s, 0.0), fmt="ko", label="measured")
            ax.plot(xs, y0, "s", color="C0", mfc="none", label="calibrated model")
            if raw1:
                ax.plot(xs, y1, "x", color="C3", ms=8, label=label1)
            ax.set_xlabel(cond or "experiment")
        ax.set_ylabel(f"{s} [SI]")
        ax.legend(fontsize=7, ncol=2)
    axes[0, 0].set_title("measured (dots) against the calibrated model (solid) and "
                         "the extended one (dashed)", fontsize=9)
    fig.tight_layout()
    fig.savefig(out_dir / "fitted.png", dpi=110)
    plt.close(fig)
    figs["traces"] = "fitted.png"
    return figs
