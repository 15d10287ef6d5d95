"""The diagnosis report: ``report.md`` and its plots, a pure view of a
:class:`~acausal.diagnose.report.result.Diagnosis` (it simulates nothing: the
traces it shows were computed by the views stage, :mod:`.views`)."""
from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np

from ..stages import stats as st
from ..stages.fingerprints import EXPECTED, describe
from ..library.loader import load_library
from .result import summary


def fmt(x, digits=4):
    if x is None:
        return "n/a"
    if isinstance(x, float) and not math.isfinite(x):
        return "inf" if x > 0 else "nan"
    return f"{x:.{digits}g}"


def _rel(path):
    """``path`` relative to the working directory when it lies below it."""
    rel = os.path.relpath(path)
    return path if rel.startswith("..") else rel


def _rms(r):
    if r is None:
        return None
    r = np.atleast_1d(r)
    return float(np.sqrt(np.mean(r ** 2))) if r.size else None


def write_report(out_dir: Path, d, plots: bool = True) -> Path:
    """Write ``report.md`` (and, with ``plots``, its figures) for ``d``."""
    out_dir = Path(out_dir)
    figs = {}
    if plots and d.views is not None:
        from .plots import write_plots
        figs = write_plots(out_dir, d)
    path = out_dir / "report.md"
    path.write_text(markdown(d, figs))
    return path


def markdown(d, figs=None) -> str:
    figs = figs or {}
    s = summary(d)
    parts = [_header(d), "## Verdict\n", verdict(d, s) + "\n", _section_residuals(d, figs),
             _section_fingerprints(d), _section_hypotheses(d, figs),
             "## 4. Cause, evidence and equivalent causes\n", "\n".join(evidence(d)) + "\n",
             _section_located(d, figs), _section_gain(d, s, figs), _section_extended(d, s),
             _section_next(d, s, figs), _section_profiles(d, s), _section_cost(d)]
    return "\n".join(parts) + "\n"


def _header(d):
    p, f0 = d.problem, d.calibration.fit
    return (f"# Diagnosis of `{os.path.basename(p.model_path)}` against "
            f"`{os.path.basename(p.data_folder)}`\n\n"
            f"Model file: `{_rel(p.model_path)}`  \nData: `{_rel(p.data_folder)}` "
            f"({len(d.dataset.experiments)} experiments, {f0.n} measured values)  \n"
            f"Errors are RMS of (simulated - measured) / instrument floor: 1 is what the "
            f"instrument's noise and resolution alone explain.\n")


def _free_lines(d):
    f0, cal = d.calibration.fit, d.calibration
    if not f0.names:
        return ["The model file declares no free parameters: the nominal model is "
                "compared as it is.\n"]
    L = ["Free parameters calibrated by weighted output error (95 % intervals; "
         f"{cal.nominal.starts.converged} of {cal.nominal.starts.refined} refined starts "
         f"reached the best point):\n"]
    for x in cal.drift:
        lo, hi = f0.ci95.get(x.name, (float("nan"),) * 2)
        flag = (f" — **moved {x.relative:+.0%} from the model file's {fmt(x.prior)}**: it may "
                f"stand in for a missing effect" if x.far else "")
        L.append(f"- `{x.name}` = {fmt(x.calibrated)}  [{fmt(lo)}, {fmt(hi)}]{flag}")
    return L + [""]


def _residual_table(d):
    ds, f0, raw0 = d.dataset, d.calibration.fit, d.views.raw0 if d.views else {}
    L = ["Residuals per experiment and signal (SI units; floor = instrument floor):\n",
         "| experiment | conditions | signal | n | residual (RMS, SI) | RMS / floor | "
         "max abs / floor |", "|---|---|---|---|---|---|---|"]
    groups, sigs = np.asarray(f0.groups), np.asarray(f0.signals)
    for e in ds.experiments:
        cond = ", ".join(f"{k}={fmt(v)}" for k, v in e.conditions.items())
        for sg in dict.fromkeys(sigs[groups == e.name]):
            r = f0.residuals[(groups == e.name) & (sigs == sg)]
            raw = raw0.get(e.name, {}).get(sg)
            L.append(f"| {e.name} | {cond} | {sg} | {r.size} | {fmt(_rms(raw))} | "
                     f"{fmt(_rms(r), 3)} | {fmt(float(np.max(np.abs(r))), 3)} |")
    return L + [""]


def _section_residuals(d, figs):
    ds, dec = d.dataset, d.decision.decision
    L = ["## 1. What the calibrated model gets wrong\n"] + _free_lines(d) + _residual_table(d)
    if d.views is not None:
        L.append("Instrument floors: " + ", ".join(
            f"`{sg}` {fmt(v)} (resolution "
            f"{fmt(ds.instrument[sg].resolution) if sg in ds.instrument else 'n/a'}, noise "
            f"{fmt(ds.instrument[sg].noise_std) if sg in ds.instrument else 'n/a'})"
            for sg, v in d.views.floors.items()) + "\n")
    L += [f"**Is there a discrepancy?** Family significance level alpha = {dec['alpha']:g}, "
          f"split equally between the tests (Bonferroni); see `acausal/diagnose/stats.py` "
          f"for why this bounds the false-positive rate.\n",
          "| test | detail | p-value (adjusted) | threshold | discrepancy |",
          "|---|---|---|---|---|"]
    for p in dec["parts"]:
        L.append(f"| {p['name']} | {p['detail']} | {fmt(p['p_value'], 3)} | "
                 f"{fmt(p['threshold'], 3)} | {'yes' if p['reject'] else 'no'} |")
    word = "discrepancy" if dec["discrepancy"] else "no significant discrepancy"
    L += ["", f"Result: **{word}**.\n"]
    if "residuals" in figs:
        L.append(f"![residuals before and after]({figs['residuals']})\n")
    return "\n".join(L)


def _section_fingerprints(d):
    lines = describe(d.views.fingerprints) if d.views is not None else []
    L = ["## 2. Residual fingerprints\n"]
    L += [f"- {x}" for x in lines] if lines else ["- none stands out"]
    L += ["", "Expected fingerprint of each hypothesis: " + "; ".join(
        f"{k}: {v}" for k, v in EXPECTED.items()) + ".\n"]
    return "\n".join(L)


def _ranking_table(d):
    rows = d.ranking.rows
    w = st.akaike_weights([r.aicc for r in rows])
    L = ["| rank | cause | location | k | S | AICc | dAICc | weight | LR p | held-out RMS | "
         "train RMS | starts (conv./refined) | parameters |",
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    a_best = rows[0].aicc
    for i, (r, wi) in enumerate(zip(rows, w)):
        ps = ", ".join(f"{nm} = {fmt(r.fit.values[nm], 3)}" for nm in r.own)
        tested = "" if r.starts.tested else " **not tested**"
        L.append(f"| {i + 1} | {r.candidate.hypothesis} | {r.candidate.location} | {r.k} | "
                 f"{fmt(r.S)} | {fmt(r.aicc)} | {fmt(r.aicc - a_best, 3)} | {wi:.2g} | "
                 f"{fmt(r.lr_p, 2)} | {fmt(r.heldout_rmse, 3)} "
                 f"({'e' if r.heldout_exact else 'l'}) | {fmt(r.train_rmse, 3)} | "
                 f"{r.starts.converged}/{r.starts.refined}{tested} | {ps} |")
    return L + [""]


def _section_hypotheses(d, figs):
    dec, f0 = d.decision, d.calibration.fit
    L = ["## 3. Hypotheses fitted\n",
         f"{len(dec.rows)} candidates (hypothesis x location from the model graph), each "
         f"fitted with the free parameters by weighted output error from several starts "
         f"(Latin hypercube over the extension's bounds, from the calibrated and from the "
         f"model file's free values). AICc = S/c + 2k + 2k(k+1)/(n-k-1), n = {f0.n}, "
         f"c = {dec.c_hat:.3g} (over-dispersion of the best fit; 1 = it reaches the "
         f"instrument floor). No extension: k = {f0.k}, S = {fmt(f0.cost)}, AICc = "
         f"{fmt(dec.a0)}. Held-out: leave-one-experiment-out RMS, by exact refits where "
         f"marked (e), else linearised from the Jacobian at the full fit (l). LR p: "
         f"likelihood ratio against no extension, unadjusted. Not tested: the "
         f"extension's parameter stayed neutral from every start with no local effect.\n"]
    if dec.rows:
        L += _ranking_table(d)
    for r in dec.failed:
        why = r.error or (r.fit.message if r.fit is not None else "")
        L.append(f"- not fitted: {r.candidate.label}: {why}")
    if dec.failed:
        L.append("")
    if "ranking" in figs:
        L.append(f"![hypothesis ranking]({figs['ranking']})\n")
    return "\n".join(L)


def _section_located(d, figs):
    loc = d.location
    L = ["## 4b. Where the library falls short (located generic term)\n"]
    if loc is None or not loc.terms:
        L.append(f"Not run: {loc.skipped if loc is not None else 'not requested'}.\n")
        return "\n".join(L)
    L.append("A generic, smooth, regularised force (linear splines in the body's position and "
             "velocity, `acausal/diagnose/generic.py`) fitted at each body's node with the "
             "free parameters; the node whose term removes most of the misfit locates the "
             "discrepancy in the mechanism.\n")
    L += ["Nodes by held-out error (best first; a node whose linearised score was not "
          "within reach of the best is not fitted in full):\n",
          "| node (body) | components on the node | knots (x, v) | fitted | S | AICc | "
          "held-out RMS |", "|---|---|---|---|---|---|---|"]
    L += [f"| {t.node} | {', '.join(t.members)} | {t.resolution[0]}, {t.resolution[1]} | "
          f"{t.fitted} | {fmt(t.S)} | {fmt(t.aicc)} | {fmt(t.heldout_rmse, 3)} |"
          for t in loc.terms]
    verdict_line = (f"**Not explained by the library**: {loc.reason}." if loc.unexplained
                    else f"The library is not ruled out: {loc.reason}.")
    L += ["", verdict_line]
    if loc.nearest_why:
        L.append(f"Nearest library hypothesis: {loc.nearest}; why it does not fit: "
                 f"{loc.nearest_why}.")
    L.append("")
    if "located" in figs:
        L.append(f"![the located term against position and velocity]({figs['located']})\n")
    return "\n".join(L)


def _section_gain(d, s, figs):
    rk, g = d.ranking, s["gain"]
    which = ("the named cause" if rk.named is not None else
             "the best candidate (no cause named)" if rk.best is not None else "no extension")
    cv = ("exact leave-one-experiment-out refits" if d.cv.exact else
          "linearised leave-one-experiment-out")
    L = ["## 5. Gain\n",
         f"RMS error in floor units (1 = instrument floor); after = {which}; held-out = "
         f"{cv}.\n", "| | train | held-out |", "|---|---|---|",
         f"| before (calibrated model) | {fmt(g['before']['train'], 3)} | "
         f"{fmt(g['before']['heldout'], 3)} |",
         f"| after | {fmt(g['after']['train'], 3)} | {fmt(g['after']['heldout'], 3)} |",
         "| instrument floor | 1 | 1 |", ""]
    if d.cv.exact:
        before = d.cv.exact.get((None, None), {})
        aft = d.cv.exact.get(rk.best.candidate.key, {}) if rk.best is not None else {}
        L += ["Held-out residual per experiment (RMS, floor units):\n",
              "| experiment | before | after |", "|---|---|---|"]
        L += [f"| {e.name} | {fmt(_rms(before.get(e.name)), 3)} | "
              f"{fmt(_rms(aft.get(e.name)), 3)} |" for e in d.dataset.experiments]
        L.append("")
    if "traces" in figs:
        L.append(f"![fitted against measured]({figs['traces']})\n")
    return "\n".join(L)


def _section_extended(d, s):
    L = ["## 6. Extended model\n"]
    named = d.ranking.named
    if s["extended_model"]:
        L.append(f"`{s['extended_model']}` imports the original model file and adds "
                 f"{named.candidate.hypothesis} at `{named.candidate.location}` with the "
                 f"fitted values; run it with `acausal simulate "
                 f"{os.path.basename(s['extended_model'])}`.\n")
    else:
        L.append("None written (no cause named).\n")
    return "\n".join(L)


def _section_next(d, s, figs):
    nx = s["next_experiment"]
    L = ["## 7. The next experiment\n"]
    if nx is None:
        return "\n".join(L + ["Not computed (design=False).\n"])
    members = ", ".join(nx["members"]) or "none"
    if not nx["computed"]:
        return "\n".join(L + [f"Rivals: {members}. Not computed: {nx['message']}.\n"])
    cond = ", ".join(f"`{k}` = {fmt(v)}" for k, v in nx["conditions"].items()) or "as run"
    L += [f"Rivals (the best candidate's class, one per cause class): {members}. The "
          f"experiment whose predictions differ most between them (Hunter-Reiner, in "
          f"instrument floors: sqrt of the rise of chi^2 the wrong rival would show), the "
          f"other conditions as in experiment `{nx['reference_experiment']}`:\n",
          f"- conditions: {cond}; record `{nx['signal']}`",
          f"- predicted separation: **{fmt(nx['separation_floors'], 3)} floors** "
          f"({fmt(nx['rms_floors'], 3)} per sample; at the experiment already run: "
          f"{fmt(nx['baseline_floors'], 3)}); closest pair: {' vs '.join(nx['closest_pair'])}",
          f"- {'decisive' if nx['decisive'] else 'not decisive'}"
          + (f": {nx['message']}" if nx["message"] else ""), ""]
    if "next" in figs:
        L.append(f"![each rival's predicted signal]({figs['next']})\n")
    return "\n".join(L)


def _section_profiles(d, s):
    pr = s["profile_ci95"]
    L = ["## 8. Profile-likelihood intervals\n"]
    if not pr:
        return "\n".join(L + ["Not computed.\n"])
    of = next(iter(pr.values()))["of"]
    L += [f"For the fit of {of}: each parameter's linearised (Wald) interval is checked "
          f"first (the rise of chi^2 at its ends, 1 for a linear model); where the check "
          f"fails, the profile is traced (`acausal/profile.py`).\n",
          "| parameter | value | 95 % interval | method | Wald | check ratios |",
          "|---|---|---|---|---|---|"]
    for name, p in pr.items():
        lo, hi = p["ci95"]
        lo_s = f"{fmt(lo)}{' (open)' if p['open_lower'] else ''}"
        hi_s = f"{fmt(hi)}{' (open)' if p['open_upper'] else ''}"
        L.append(f"| `{name}` | {fmt(p['value'])} | [{lo_s}, {hi_s}] | {p['method']} | "
                 f"[{fmt(p['wald'][0])}, {fmt(p['wald'][1])}] | "
                 f"{', '.join(fmt(q, 3) for q in p['check_ratios'])} |")
    return "\n".join(L + [""])


def _section_cost(d):
    t = d.timing
    return ("## Method and cost\n\n"
            f"{t['n_candidates']} candidate fits + the nominal fit in {t['fit_s']:.1f} s, "
            f"then {t['cv_s']:.1f} s for the later stages (leave-one-out, located term, "
            f"profiles {t.get('profile_s', 0.0):.1f} s, next experiment "
            f"{t.get('design_s', 0.0):.1f} s; family members "
            f"{t.get('families_s', 0.0):.1f} s); {t['n_sim']} simulations for the fits. "
            f"Hypothesis library: `{d.problem.library}`.\n")


def _candidates_sentence(v) -> str:
    """The best candidates of each kind with their held-out errors."""
    cs = v.get("candidates") or []
    if not cs:
        return ""
    return " Best candidates (held-out RMS, floors): " + "; ".join(
        f"{c['kind']} {c['cause']} at `{c['location']}` {fmt(c['heldout_rmse'], 4)}"
        for c in cs) + "."


def _threshold_sentence(v) -> str:
    t = v.get("heldout_threshold")
    if not t:
        return ""
    return (f" Held-out threshold {fmt(t['rms'], 4)} floors: the most a held-out RMS error "
            f"reaches on noise alone at {t['level']:.0%} ({t['n']} values, {t['k']} fitted "
            f"parameters, {t['experiments']} experiments; {t['sentence']}).")


def verdict(d, s) -> str:
    g, v = s["gain"], s["verdict"]
    if v["kind"] == "no_discrepancy":
        return ("**No significant discrepancy.** The calibrated model explains the data "
                "within the instrument model at the stated significance level; no cause is "
                "named and no extended model is written. (This does not prove the model "
                "right: an effect smaller than the noise, or one the free parameters absorb, "
                "would pass.)")
    held = (f"held-out error {fmt(g['before']['heldout'], 3)} -> "
            f"{fmt(g['after']['heldout'], 3)} floor units")
    if v["kind"] == "not_explained":
        where = _where_sentence(s["unexplained"])
        laws = "".join(f" **A mixture of laws?** {x['text']}." for x in v["laws"])
        return ("**Discrepancy not explained by the library.** "
                + "; ".join(r["text"] for r in v["reasons"]) + "." + where + laws
                + _candidates_sentence(v) + _threshold_sentence(v)
                + _class_sentence(s["cause_class"]))
    if v["kind"] == "weak" or s["cause"] is None:
        best = d.ranking.best
        kinds = sorted({r["code"] for r in v["reasons"]})
        reasons = "; ".join(r["text"] for r in v["reasons"]) or "no candidate could be fitted"
        txt = (f"**Discrepancy, but the evidence is weak: no cause is named** (the data "
               f"cannot decide: {', '.join(kinds)}). {reasons}.")
        if v.get("partial"):
            txt = (f"**Discrepancy; named in part** (the data cannot decide the rest: "
                   f"{', '.join(kinds)}): {d.verdict.partial.sentence()}."
                   + (" The next experiment below splits them."
                      if (s.get("next_experiment") or {}).get("computed") else "")
                   + f" {reasons[0].upper()}{reasons[1:]}.")
        if best is not None:
            txt += (f" The best candidate, {best.candidate.label}, explains the held-out "
                    f"data ({held}).")
        return (txt + _threshold_sentence(v) + _tied_sentence(d)
                + _class_sentence(s["cause_class"]))
    # a name whose plain held-out error exceeds the threshold rests on the
    # whitened and directional parts (verdict.rescued): say so, with its numbers
    rescue = [c for c in v.get("caveats") or () if c["code"] == "heldout_one_experiment"]
    judged = f"; {rescue[0]['text']}." if rescue else ", within the held-out threshold."
    txt = (f"**Discrepancy; cause: {s['cause']} at `{s['location']}`.** {held[0].upper()}"
           f"{held[1:]} (train {fmt(g['before']['train'], 3)} -> "
           f"{fmt(g['after']['train'], 3)}){judged}")
    if v["undetermined"]:
        txt += " Undetermined (flagged, consistent with the law without it): " + "; ".join(
            f"`{c['name']}` = {fmt(c['value'])} [{fmt(c['ci95'][0])}, {fmt(c['ci95'][1])}]"
            f" (neutral {fmt(c['neutral'])})" for c in v["undetermined"]) + "."
    if s["equivalent_causes"]:
        txt += " The data cannot tell it from: " + ", ".join(
            f"{e['cause']} at `{e['location']}`" for e in s["equivalent_causes"]) + "."
    return (txt + _threshold_sentence(v) + _tied_sentence(d)
            + _class_sentence(s["cause_class"]))


def _where_sentence(un) -> str:
    """Where the located generic term puts what the library leaves: its
    best node with its held-out error against the other nodes', or why no
    node could be judged."""
    if not un["node"]:
        return f" No node could be judged: {un['why'] or 'no located generic term'}."
    others = ", ".join(f"`{x['node']}` {fmt(x['heldout_rmse'], 3)}"
                       for x in un["nodes"][1:4])
    tied = ("; the held-out data cannot tell it from "
            + ", ".join(f"`{n}`" for n in un["tied_nodes"]) if un["tied_nodes"] else "")
    head = (f" A generic term at the node of `{un['node']}` removes most of the misfit"
            if un["beats_library"] else
            f" The located generic term fits best at the node of `{un['node']}`")
    tail = ("" if un["beats_library"] else
            f", but it does not beat the library's best candidate (held-out "
            f"{fmt(un['nearest_heldout_rmse'], 3)})")
    bs = un.get("beside")
    beside = "" if not bs else (
        f" Fitted beside {bs['cause']} at `{bs['location']}`, the term at `{bs['node']}` "
        f"{'leaves' if bs['second_force'] else 'does not leave'} a second force (held-out "
        f"{fmt(bs['alone_heldout_rmse'], 3)} for the cause alone -> "
        f"{fmt(bs['heldout_rmse'], 3)} with the term; "
        + ", ".join(f"`{k}` = {fmt(v)}" for k, v in bs["values"].items()) + ").")
    return (f"{head} (held-out {fmt(un['heldout_rmse'], 3)} floor units"
            + (f"; other nodes: {others}" if others else "") + tied
            + f"){tail}; section 4b shows its shape." + beside)


def _tied_sentence(d) -> str:
    """The sites kinematically tied to the shown cause's, the cause's
    parameters at each, and why its own site is the one shown
    (:mod:`.kinematics`)."""
    parts = []
    for t in d.tied:
        for x in t.sites:
            vals = ", ".join(f"`{k}` = {fmt(v)}" for k, v in x.values if v is not None)
            own = "" if not x.fitted else (
                " (fitted there: " + ", ".join(f"{fmt(v)}" for _, v in x.fitted)
                + f", dAICc {x.daicc:+.3g})")
            parts.append(f"`{x.location}` moves {fmt(x.ratio, 3)} times as fast as "
                         f"`{t.location}` (a constant ratio within {x.spread:.1%} over every "
                         f"experiment): {t.cause} there is {vals or 'not convertible'}{own}.")
        parts.append(t.reason)
    return (" **Kinematically equivalent sites.** " + " ".join(parts)) if parts else ""


def _class_sentence(cc):
    """The cause class of the best candidate with the misfit its best law
    leaves (said even when no cause is named)."""
    if cc is None:
        return ""
    laws = ", ".join(f"{m['member']} (dAICc {fmt(m['daicc'], 3)})" for m in cc["members"])
    left = (f"it reaches the instrument floor ({fmt(cc['leftover_floors'], 3)}x RMS)"
            if cc["within_floor"] else
            f"**its best law still leaves {fmt(cc['leftover_floors'], 3)}x the floor (RMS)**: "
            "the effect belongs to this class but follows none of its laws exactly")
    return (f" Cause class: **{cc['family']} at `{cc['location']}`**, best law "
            f"{cc['member']}; {left}. Laws fitted there: {laws}.")


def evidence(d) -> list:
    dec, rk = d.decision, d.ranking
    if not dec.discrepancy:
        L = ["No discrepancy: nothing to explain."]
        if dec.rows:
            r = dec.rows[0]
            L.append(f"For information, the best candidate ({r.candidate.label}) lowers S "
                     f"from {fmt(d.calibration.fit.cost)} to {fmt(r.S)}, LR p = "
                     f"{fmt(r.lr_p, 2)} before the correction for the {len(dec.rows)} "
                     f"candidates tried.")
        return L
    if rk.best is None:
        return ["No candidate could be fitted."]
    return _best_lines(d) + _class_lines(d)


def _best_lines(d):
    dec, rk, best = d.decision, d.ranking, d.ranking.best
    lib = load_library(d.problem.library)
    head = ("Named cause" if rk.named is not None else
             "Best candidate (not named: it does not explain the held-out data)"
             if d.verdict.kind == "not_explained" else
             "Best candidate (not named: evidence weak)")
    L = [f"**{head}: {best.candidate.label}**\n"]
    for h, loc, _ in best.candidate.members():
        hyp = lib.HYPOTHESES[h]
        L.append(f"- {h} at `{loc}` — {hyp.title}. {hyp.explanation}")
    L += ["", "Parameters (95 % intervals, covariance scaled by max(1, S/(n-k))):\n"]
    for nm in best.fit.names:
        lo, hi = best.fit.ci95.get(nm, (float("nan"),) * 2)
        L.append(f"- `{nm}` = {fmt(best.fit.values[nm])}  [{fmt(lo)}, {fmt(hi)}]")
    f0 = d.calibration.fit
    n_c = len(dec.rows)
    L += ["", f"- against no extension: dAICc = {dec.a0 - best.aicc:.1f}, likelihood ratio "
          f"2 dlnL = {f0.cost - best.S:.1f} on {best.k - f0.k} dof, p = {fmt(best.lr_p, 2)} "
          f"(x {n_c} candidates = {fmt(min(1.0, best.lr_p * n_c), 2)})",
          f"- {best.starts.converged} of {best.starts.refined} refined starts reached the "
          f"best point ({best.starts.scored} scored)"]
    runner = rk.row(rk.runner)
    if runner is not None:
        dd = runner.aicc - best.aicc
        L.append(f"- against the runner-up outside its class ({runner.candidate.label}): "
                 f"dAICc = {dd:.1f}, evidence ratio exp(dAICc/2) = "
                 f"{fmt(math.exp(min(dd, 1400) / 2), 3)}")
    return L


def _class_lines(d):
    rk, best = d.ranking, d.ranking.best
    lib = load_library(d.problem.library)
    others = [rk.rows[i] for i in (rk.classes[0] if rk.classes else []) if rk.rows[i] is not best]
    L = []
    if others:
        L.append(f"- equivalent within {st.EQUIVALENCE:g} AICc units (one class; the data "
                 f"cannot tell them apart):")
        L += [f"  - {r.candidate.label} (dAICc {r.aicc - best.aicc:.2f}, held-out "
              f"{fmt(r.heldout_rmse, 3)})" for r in others]
        L.append("- the experiments that would tell them apart:")
        for hid in dict.fromkeys(h for r in [best] + others for h, _, _ in r.candidate.members()):
            L.append(f"  - {hid}: {lib.HYPOTHESES[hid].distinguishing_experiment}")
    v = d.verdict
    if v.kind == "named" and v.caveats:
        L.append("- **named, on this ground**:")
        L += [f"  - {r.text} [`{r.code}`]" for r in v.caveats]
    if v.kind == "weak" and v.partial is not None:
        L.append("- **named in part**: " + v.partial.sentence())
    if v.kind == "weak" and v.reasons:
        L.append("- **evidence is weak** (the data cannot decide):")
        L += [f"  - {r.text} [`{r.code}`]" for r in v.reasons]
    elif v.kind == "not_explained":
        L.append("- **not explained by the library** (never \"weak\" in this case):")
        L += [f"  - {r.text} [`{r.code}`]" for r in v.reasons]
        L += [f"  - a mixture of laws? {x.text}" for x in v.laws if x.text not in
              " ".join(r.text for r in v.reasons)]
    if v.threshold is not None:
        L.append(f"- held-out threshold: {fmt(v.threshold.rms, 4)} floors "
                 f"({v.threshold.sentence()})")
    return L
