"""The diagnosis driver: from a model file and measured data to a named
cause, an extended model and the measured gain.

:func:`diagnose` does, in order:

1. calibrate the model file's ``free_parameters`` by weighted output error
   (the nominal fit) and compute its residuals per experiment and signal;
2. fit every hypothesis of the library at every candidate location the model
   graph offers (its parameters together with the free parameters, output
   error with the event-correct simulation, no differentiated data), in
   parallel through :func:`acausal.executor.open_executor`;
3. decide whether there is a discrepancy (:func:`stats.discrepancy_decision`:
   chi-square, runs, and the likelihood ratio of the best candidate, at a
   family level ``alpha``);
4. rank the candidates by AICc (QAICc when even the best leaves misfit),
   with their leave-one-experiment-out error; group the ones the data cannot
   tell apart; name the winner unless the evidence is weak
   (:func:`stats.weak_evidence`);
5. measure the gain before/after on the fitted and on held-out experiments
   (exact leave-one-out refits of the nominal and of the best model);
6. write the extended model file, a Markdown report and plots into
   ``out_dir``, and return the JSON-able summary.

Errors are in units of the instrument floor throughout (RMS of
(simulated - measured)/floor): 1.0 is what the instrument's noise and
resolution alone explain.
"""
from __future__ import annotations

import json
import math
import os
import time
from pathlib import Path

import numpy as np

from ..calibrate import model_dataset
from ..data import DataError
from ..errors import DiagnosisError
from ..executor import open_executor, worker_cache
from ..modelfile import compile_file
from . import stats as st
from .fitting import fit, heldout_rms, linear_loo, subset, weighted_residuals
from .library import load_library

__all__ = ["diagnose", "DiagnosisError"]

FIT_TOL = 1e-6   # ftol/xtol of the candidate fits (S to about 1e-6 relative)
LOO_TOL = 1e-4   # of the warm-started leave-one-out refits (predictions only)
EVALS_PER_PARAM = 25  # a fit stops after 25 (k + 1) residual evaluations (best point kept)
BUDGET_FACTOR = 12.0  # and, a last resort, when it takes this many times the nominal fit
BUDGET_MIN_S = 60.0   # ... but at least this long [s] (machine-dependent: rarely reached)
SMALL_N = 100         # at most this many values and ...
SMALL_EXPERIMENTS = 12  # ... experiments: exact leave-one-out for the SMALL_TOP ...
SMALL_TOP = 6         # ... best candidates (the linearised shortcut is poor on few data)


# ---------------------------------------------------------------------------
# Worker tasks (module level: picklable)
# ---------------------------------------------------------------------------


def _stamp(path):
    path = os.path.abspath(path)
    return path, os.path.getmtime(path) if os.path.exists(path) else None


def _dataset(model_path, folder):
    key = ("diagnose-dataset", _stamp(model_path), _stamp(os.path.join(folder,
                                                                      "experiments.csv")))
    return worker_cache(key, lambda: model_dataset(model_path, folder))


def _model(model_path, library, hyp_id, location):
    if hyp_id is None:
        return compile_file(model_path)
    key = ("diagnose-model", _stamp(model_path), library, hyp_id, location)
    return worker_cache(key, lambda: load_library(library).build_extended(
        model_path, hyp_id, location))


def _starts(spec_rows):
    """Extra starting points along the first extension parameter: its scale
    times 0.1, 0.5 and 2.5, both signs where the bounds allow (a parameter
    starting where it has no effect may sit on a bound or a flat spot)."""
    if not spec_rows:
        return []
    name, initial, low, high, scale = spec_rows[0][:5]
    out = []
    for f in (0.1, 0.5, 2.5):
        for s in (1.0, -1.0):
            v = s * f * abs(scale)
            if low <= v <= high and v != initial:
                out.append({name: v})
    return out


def fit_task(model_path, folder, library, hyp_id, location, spec_rows, free, max_nfev,
             budget_s=None, absorb=None):
    """Fit one candidate (``hyp_id`` None: the nominal model). ``spec_rows``:
    (name, initial, low, high, scale) of the extension's parameters;
    ``free``: name -> (start, low, high, scale) of the free parameters."""
    t0 = time.perf_counter()
    try:
        ds = _dataset(model_path, folder)
        pair = _model(model_path, library, hyp_id, location)
        names = list(free) + [r[0] for r in spec_rows]
        x0 = {n: v[0] for n, v in free.items()} | {r[0]: r[1] for r in spec_rows}
        lo = {n: v[1] for n, v in free.items()} | {r[0]: r[2] for r in spec_rows}
        hi = {n: v[2] for n, v in free.items()} | {r[0]: r[3] for r in spec_rows}
        sc = {n: v[3] for n, v in free.items()} | {r[0]: r[4] for r in spec_rows}
        f = fit(pair, ds, names, x0, lo, hi, sc, starts=_starts(spec_rows),
                max_nfev=max_nfev, tol=FIT_TOL, budget_s=budget_s, absorb=absorb,
                max_evals=EVALS_PER_PARAM * (len(names) + 1))
        return dict(hyp=hyp_id, location=location, fit=f, loo=linear_loo(f) if f.ok else {},
                    error=None, wall_s=time.perf_counter() - t0)
    except Exception as exc:  # noqa: BLE001 - a candidate that cannot be built is reported
        return dict(hyp=hyp_id, location=location, fit=None, loo={},
                    error=f"{type(exc).__name__}: {exc}", wall_s=time.perf_counter() - t0)


def loo_task(model_path, folder, library, hyp_id, location, names, start, low, high, scale,
             held, max_nfev, budget_s=None):
    """Refit without experiment ``held`` (warm start), predict it."""
    ds = _dataset(model_path, folder)
    pair = _model(model_path, library, hyp_id, location)
    train = subset(ds, [e.name for e in ds.experiments if e.name != held])
    test = subset(ds, [held])
    f = fit(pair, train, names, start, low, high, scale, max_nfev=max_nfev, tol=LOO_TOL,
            budget_s=budget_s, max_evals=EVALS_PER_PARAM * (len(names) + 1) // 3)
    r = weighted_residuals(pair, test, f.values)[0]
    return dict(hyp=hyp_id, location=location, held=held, residuals=r, values=f.values,
                n_sim=f.n_sim)


# ---------------------------------------------------------------------------
# The driver
# ---------------------------------------------------------------------------


def _progress(total, desc, enabled):
    if not enabled:
        return None
    from tqdm.auto import tqdm
    return tqdm(total=total, desc=desc, unit="fit")


def _run_tasks(ex, calls, desc, progress, store=None, keys=None):
    """Submit (fn, args) calls; return results in submission order.

    With a ``store`` (:class:`acausal.checkpoint.Checkpoint`) and one key per
    call, a result found in the store is taken from there instead of being
    recomputed, and every new result is appended to it as soon as it
    arrives: an interrupted diagnosis keeps its finished fits."""
    saved = store.load() if store is not None else {}
    out = [saved.get(k) for k in keys] if store is not None else [None] * len(calls)
    todo = [i for i, r in enumerate(out) if r is None]
    futures = [ex.submit(fn, *args) for fn, args in (calls[i] for i in todo)]
    index = {id(f): i for i, f in zip(todo, futures)}
    bar = _progress(len(calls), desc, progress)
    if bar is not None:
        bar.update(len(calls) - len(todo))
    try:
        for fut in ex.as_completed(futures):
            i = index[id(fut)]
            out[i] = fut.result()
            if store is not None:
                store.append(keys[i], out[i])
            if bar is not None:
                bar.update(1)
    finally:
        if bar is not None:
            bar.close()
    return out


def _checkpoint(out_dir, model_path, data_folder, options):
    """The diagnosis's checkpoint, ``<out_dir>/checkpoint/<hash>.jsonl``,
    the hash of the model file (and its neighbours), the data and the
    options: one record per finished fit."""
    from ..checkpoint import Checkpoint, input_key, source_files
    from .fitting import Fit
    key = input_key(source_files(model_path), Path(data_folder), options)
    return Checkpoint(Path(out_dir) / "checkpoint", key, types=(Fit,))


def _select(items, wanted, what):
    if wanted is None:
        return list(items)
    wanted = [wanted] if isinstance(wanted, str) else list(wanted)
    unknown = [w for w in wanted if w not in items]
    if unknown:
        raise DiagnosisError(f"unknown {what} {', '.join(map(repr, unknown))}; "
                             f"known: {', '.join(items)}")
    return [i for i in items if i in wanted]


def candidates(model_path, library=None, hypotheses=None, locations=None):
    """[(hyp_id, location, [ParamSpec...])] the graph of the model offers.
    ``locations``: a list of paths (exact, or a prefix followed by '.') to
    keep."""
    lib = load_library(library)
    graph = lib.graph_of(model_path)
    out = []
    for hid in _select(lib.HYPOTHESES, hypotheses, "hypothesis"):
        hyp = lib.HYPOTHESES[hid]
        for loc in hyp.candidates(graph):
            if locations is not None and not any(
                    loc == w or loc.startswith(w + ".") for w in locations):
                continue
            out.append((hid, loc, list(hyp.params(graph, loc))))
    return lib, graph, out


def diagnose(model_path, data_folder, *, out_dir, scheduler=None, workers=None,
             progress=True, hypotheses=None, locations=None, alpha=st.ALPHA,
             exact_cv=True, library=None, plots=True, max_nfev=60) -> dict:
    """Diagnose ``model_path`` against the dataset folder ``data_folder``.

    Writes ``report.md``, ``diagnosis.json``, plots and (when a cause is
    named) the extended model file into ``out_dir``; returns the summary dict
    (keys: discrepancy, cause, location, equivalent_causes, parameters,
    ranking, gain, extended_model). ``hypotheses``/``locations`` restrict the
    candidates; ``alpha`` is the family significance level of the discrepancy
    decision; ``exact_cv`` refits the nominal and best models without each
    experiment (else the linearised leave-one-out); ``library`` names a
    module standing in for :mod:`acausal.diagnose.hypotheses`.
    """
    t_start = time.perf_counter()
    model_path = os.path.abspath(model_path)
    data_folder = os.path.abspath(data_folder)
    out_dir = Path(out_dir)
    mf, cm = compile_file(model_path)
    try:
        ds = model_dataset(model_path, data_folder)
    except DataError as exc:
        raise DiagnosisError(exc.message, file=exc.file, line=exc.line,
                             column=exc.column) from None
    if not ds.experiments:
        raise DiagnosisError(f"{data_folder}: no experiments")
    if not any(e.measures or e.trace is not None for e in ds.experiments):
        raise DiagnosisError(f"{data_folder}: no measured values (no measures, no traces)")
    free = {}
    for name, (lo, hi) in mf.free.items():
        default = cm.params[cm.param_index(name)].default
        free[name] = (float(np.clip(default, lo, hi)), lo, hi, abs(default) or
                      (hi - lo if math.isfinite(hi - lo) else 1.0))
    lib, graph, cands = candidates(model_path, library, hypotheses, locations)
    spec_rows = {(h, l): [(s.name, float(s.initial), float(s.low), float(s.high),
                           float(s.scale) or 1.0) for s in specs] for h, l, specs in cands}
    specs_by = {(h, l): specs for h, l, specs in cands}
    lib_name = lib.name
    store = _checkpoint(out_dir, model_path, data_folder, dict(
        library=lib_name, candidates=[[h, l] for h, l, _ in cands], free=free,
        max_nfev=max_nfev, exact_cv=exact_cv))

    with open_executor(scheduler, workers) as ex:
        # the nominal fit first: the candidates start from its calibrated values
        nominal = _run_tasks(ex, [(fit_task, (model_path, data_folder, lib_name, None, None,
                                              [], free, max_nfev))],
                             "calibrating", progress, store, ["nominal"])[0]
        if nominal["fit"] is None or not nominal["fit"].ok:
            raise DiagnosisError(f"the nominal model could not be fitted: "
                                 f"{nominal['error'] or nominal['fit'].message}")
        f0 = nominal["fit"]
        warm = {n: (f0.values[n],) + v[1:] for n, v in free.items()}
        budget = max(BUDGET_MIN_S, BUDGET_FACTOR * nominal["wall_s"])
        absorb = (list(f0.names), f0.jacobian)
        calls = [(fit_task, (model_path, data_folder, lib_name, h, l, spec_rows[(h, l)],
                             warm, max_nfev, budget, absorb)) for h, l, _ in cands]
        results = [nominal] + _run_tasks(ex, calls, "fitting candidates", progress, store,
                                         [f"fit {h} {l}" for h, l, _ in cands])
        t_fit = time.perf_counter() - t_start
        n = f0.n
        fitted = [r for r in results[1:] if r["fit"] is not None and r["fit"].ok
                  and math.isfinite(r["fit"].cost)]
        failed = [r for r in results[1:] if r not in fitted]
        c_hat = st.overdispersion([(f0.cost, n, f0.k)] +
                                  [(r["fit"].cost, n, r["fit"].k) for r in fitted])
        a0 = st.aicc(f0.cost, n, f0.k, c_hat)
        rows = []
        for r in fitted:
            f = r["fit"]
            rows.append(dict(cause=r["hyp"], location=r["location"], k=f.k, S=f.cost,
                             aicc=st.aicc(f.cost, n, f.k, c_hat),
                             heldout_rmse=heldout_rms(r["loo"]), train_rmse=f.rms(),
                             lr_p=st.lr_test(f0.cost, f.cost, f.k - f0.k), fit=f,
                             loo=r["loo"]))
        rows.sort(key=lambda r: (r["aicc"], r["heldout_rmse"]))

        # -- the discrepancy decision ------------------------------------------------
        chi2 = st.chi2_test(f0.cost, n, f0.k, alpha / 3)
        runs = _runs(ds, f0)
        lr = None
        if rows:
            lr = dict(p_value=min(r["lr_p"] for r in rows), m=len(rows))
        decision = st.discrepancy_decision(chi2, runs, lr, alpha)
        discrepancy = decision["discrepancy"]

        # -- exact leave-one-out: the nominal model and the best candidate (the
        # SMALL_TOP best when the dataset is small: the linearised shortcut is then poor)
        loo_exact = {}
        small = n <= SMALL_N and len(ds.experiments) <= SMALL_EXPERIMENTS
        if exact_cv and len(ds.experiments) > 1:
            jobs = [(None, None, f0)]
            if small:
                jobs += [(r["cause"], r["location"], r["fit"]) for r in rows[:SMALL_TOP]]
            elif discrepancy and rows:
                jobs.append((rows[0]["cause"], rows[0]["location"], rows[0]["fit"]))
            calls = []
            for h, l, f in jobs:
                lo = {nm: v[1] for nm, v in free.items()}
                hi = {nm: v[2] for nm, v in free.items()}
                sc = {nm: v[3] for nm, v in free.items()}
                for sp_ in (spec_rows.get((h, l)) or []):
                    lo[sp_[0]], hi[sp_[0]], sc[sp_[0]] = sp_[2], sp_[3], sp_[4]
                for e in ds.experiments:
                    calls.append((loo_task, (model_path, data_folder, lib_name, h, l,
                                             f.names, f.values, lo, hi, sc, e.name,
                                             max(5, max_nfev // 4), budget / 3)))
            keys = [f"loo {c[1][3]} {c[1][4]} {c[1][10]}" for c in calls]
            for r in _run_tasks(ex, calls, "leave-one-out", progress, store, keys):
                loo_exact.setdefault((r["hyp"], r["location"]), {})[r["held"]] = r["residuals"]
        for r in rows:
            got = loo_exact.get((r["cause"], r["location"]))
            r["heldout_exact"] = got is not None
            if got is not None:
                r["heldout_rmse"] = heldout_rms(got)
        held0 = heldout_rms(loo_exact.get((None, None)) or nominal["loo"])

        # -- ranking, classes, evidence ---------------------------------------------
        classes = st.equivalence_classes(rows) if rows else []
        best = rows[0] if rows else None
        cls = [rows[i] for i in classes[0]] if classes else []
        runner = rows[classes[1][0]] if len(classes) > 1 else None
        weak = []
        if discrepancy and best is not None:
            weak = st.weak_evidence(
                n=n, k=best["k"], d_null=a0 - best["aicc"],
                d_runner=None if runner is None else runner["aicc"] - best["aicc"],
                heldout_nominal=held0, heldout_best=best["heldout_rmse"],
                ci_rel=_ci_rel(best, specs_by), c_hat=c_hat, coarse=_coarse(ds, f0))
        cause = best if (discrepancy and best is not None and not weak) else None
        after = cause or (best if discrepancy else None)
    t_cv = time.perf_counter() - t_start - t_fit

    def held(h, l, linear):
        got = loo_exact.get((h, l))
        return heldout_rms(got) if got else heldout_rms(linear)

    gain_before = dict(train=f0.rms(), heldout=held(None, None, nominal["loo"]))
    if after is not None:
        gain_after = dict(train=after["fit"].rms(),
                          heldout=held(after["cause"], after["location"], after["loo"]))
    else:
        gain_after = dict(gain_before)
    if after is not None and (after["cause"], after["location"]) in loo_exact:
        after["heldout_exact"] = gain_after["heldout"]

    out_dir.mkdir(parents=True, exist_ok=True)
    extended = None
    parameters = {}
    if after is not None:
        for name in after["fit"].names:
            ci = after["fit"].ci95.get(name, (float("nan"),) * 2)
            parameters[name] = dict(value=after["fit"].values[name], ci95=[_num(ci[0]), _num(ci[1])])
    if cause is not None:
        stem = Path(model_path).stem
        target = out_dir / f"{stem}_{cause['cause']}.py"
        extended = write_extended(lib, model_path, cause, target, list(free))

    if discrepancy:
        equivalent = [dict(cause=r["cause"], location=r["location"]) for r in cls
                      if cause is None or r is not cause]
    else:
        equivalent = []
    summary = dict(
        discrepancy=bool(discrepancy),
        cause=None if cause is None else cause["cause"],
        location=None if cause is None else cause["location"],
        equivalent_causes=equivalent,
        parameters=parameters if cause is not None else {},
        ranking=[dict(cause=r["cause"], location=r["location"], aicc=_num(r["aicc"]),
                      heldout_rmse=_num(r["heldout_rmse"])) for r in rows],
        gain=dict(before={k: _num(v) for k, v in gain_before.items()},
                  after={k: _num(v) for k, v in gain_after.items()}),
        extended_model=extended,
    )
    # -- report --------------------------------------------------------------------------
    ctx = dict(model_path=model_path, data_folder=data_folder, ds=ds, f0=f0, nominal=nominal,
               rows=rows, classes=classes, decision=decision, chi2=chi2, runs=runs,
               c_hat=c_hat, a0=a0, weak=weak, cause=cause, after=after, runner=runner,
               summary=summary, failed=failed, lib=lib, graph=graph, free=free,
               parameters_after=parameters, loo_exact=loo_exact, alpha=alpha,
               timing=dict(fit_s=t_fit, cv_s=t_cv, n_candidates=len(cands),
                           n_sim=sum(r["fit"].n_sim for r in results if r["fit"])),
               specs_by=specs_by, library=library)
    try:
        from .report import write_report
        write_report(out_dir, ctx, plots=plots)
    finally:
        ctx["timing"]["total_s"] = time.perf_counter() - t_start
    (out_dir / "diagnosis.json").write_text(json.dumps(summary, indent=1))
    (out_dir / "candidates.json").write_text(json.dumps(_clean(_details(ctx)), indent=1))
    store.discard()  # complete: the fits are in the report
    return summary


def write_extended(lib, model_path, row, target, free_names):
    """Write the extended model file: the library writes the original plus
    the hypothesis with its fitted values; the calibrated values of the free
    parameters are set on the model before the hypothesis is applied (a
    hypothesis may rebind a parameter of the component it extends)."""
    values = row["fit"].values
    own = {k: v for k, v in values.items() if k not in free_names}
    path = str(lib.write_extended_model(model_path, row["cause"], row["location"], own,
                                        str(target)))
    if not free_names:
        return path
    lines = ["# calibrated free parameters (acausal diagnose)"]
    for name in free_names:
        comp, _, pname = name.rpartition(".")
        target_expr = f"model.find({comp!r})" if comp else "model"
        lines.append(f"{target_expr}.set({pname}={float(values[name])!r})")
    block = "\n".join(lines) + "\n\n"
    text = Path(path).read_text()
    marker = "\n# hypothesis "
    i = text.find(marker)
    if i < 0:
        raise DiagnosisError(f"{path}: cannot place the calibrated values (no "
                             f"'# hypothesis' line written by the library)")
    Path(path).write_text(text[:i + 1] + block + text[i + 1:])
    return path


def _details(ctx):
    """Every fit in full (for scripts and tests): the nominal model, then the
    candidates in rank order, and the decision."""
    def one(label, f, extra):
        return dict(label, k=f.k, S=_num(f.cost), train_rmse=_num(f.rms()),
                    values=f.values, ci95={k: [_num(a), _num(b)] for k, (a, b) in
                                           f.ci95.items()},
                    n_sim=f.n_sim, wall_s=f.wall_s, message=f.message, **extra)
    f0 = ctx["f0"]
    out = dict(nominal=one(dict(cause=None, location=None), f0,
                           dict(aicc=_num(ctx["a0"]))),
               candidates=[one(dict(cause=r["cause"], location=r["location"]), r["fit"],
                               dict(aicc=_num(r["aicc"]), heldout_rmse=_num(r["heldout_rmse"]),
                                    lr_p=_num(r["lr_p"])))
                           for r in ctx["rows"]],
               failed=[dict(cause=r["hyp"], location=r["location"], error=r["error"] or
                            (r["fit"].message if r["fit"] is not None else ""),
                            wall_s=r["wall_s"])
                       for r in ctx["failed"]],
               decision=ctx["decision"], overdispersion=ctx["c_hat"],
               weak_evidence=ctx["weak"], timing=ctx["timing"])
    return out


def _clean(obj):
    """JSON-safe copy: non-finite floats -> None, numpy scalars -> Python."""
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_clean(v) for v in obj]
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return _num(obj)
    return obj


def _num(x):
    x = float(x)
    return x if math.isfinite(x) else None


def _runs(ds, f0):
    """Runs tests of the nominal residuals: one per (experiment, trace signal)."""
    groups = np.asarray(f0.groups)
    sigs = np.asarray(f0.signals)
    out = []
    for e in ds.experiments:
        if e.trace is None:
            continue
        for var in e.trace.signals:
            m = (groups == e.name) & (sigs == var)
            if np.sum(m) >= 20:
                d = st.runs_test(f0.residuals[m])
                d.update(experiment=e.name, signal=var)
                out.append(d)
    return out


def _ci_rel(row, specs_by):
    """Relative 95 % half-width of the extension's first parameter."""
    specs = specs_by.get((row["cause"], row["location"])) or []
    if not specs:
        return None
    name = specs[0].name
    v = row["fit"].values.get(name)
    lo, hi = row["fit"].ci95.get(name, (float("nan"), float("nan")))
    if v is None or not math.isfinite(lo) or v == 0:
        return float("inf")
    return float((hi - lo) / 2 / abs(v))


def _coarse(ds, f0):
    """The nominal misfit's RMS in resolution steps, over signals that have a
    resolution (the largest such ratio: the most finely read signal); None if none has one."""
    ratios = []
    sigs = np.asarray(f0.signals)
    for s, inst in ds.instrument.items():
        m = sigs == s
        if inst.resolution > 0 and np.any(m):
            rms_floor = float(np.sqrt(np.mean(f0.residuals[m] ** 2)))
            ratios.append(rms_floor * inst.floor() / inst.resolution)
    return max(ratios) if ratios else None
