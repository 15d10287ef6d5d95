"""Detection power of ``acausal diagnose``: for every hypothesis of the
library and every effect size, the rate at which blind diagnoses name the
right cause at the right location (or a class containing it), and the
false-positive rate on noise-only data.

Each case: a truth = the model file + one hidden extension at a location
drawn at random among the hypothesis's candidates, with its magnitude solved
for so that it changes the data by ``effect`` times the instrument floor
(RMS, before recalibration: :func:`acausal.diagnose.synth.synthesize`);
traces sampled like an instrument; then a full diagnosis of the nominal
model against the data (every hypothesis x location of the library).

    PYTHONPATH=. python benchmarks/detection_power.py --model latch \\
        --effects 1,3,10 --seeds 3 --nulls 10 --workers 2 --out docs/detection_power.md

Columns: right = right cause at the right location named or in the named
class (or a member of its family there to which the truth's law reduces,
e.g. Stribeck friction drawn with no static excess is Coulomb friction:
:func:`acausal.diagnose.synth.same_law_members`); named = named exactly;
weak = a discrepancy found but no cause named (evidence weak); missed = no
discrepancy found; capped = cases whose location cannot reach the requested
effect within the library's bounds on the parameter (the achieved effect is
below 0.9 times the requested one; e.g. a cubic term on a spring that
barely deflects): they are counted in
their cell, with the achieved effect shown. The table is printed as Markdown
and, with ``--out``, written to a file, with every case's outcome beside it
as JSON (``--out`` with ``.json``).
"""
from __future__ import annotations

import argparse
import concurrent.futures as cf
import os
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

SETUPS = {
    "latch": dict(path=os.path.join(ROOT, "models", "latch_striker.py"),
                  conditions={"F_coil": [20.0, 28.0, 36.0, 45.0]}, traces=["latch.s"],
                  sample_rate=20e3, noise={"latch.s": 5e-6}, resolution={"latch.s": 5e-6},
                  units={"time": "ms", "latch.s": "mm"}),
    "breaker": dict(path=os.path.join(ROOT, "models", "breaker_24kv.py"),
                    conditions={"v_impact": [3.3, 3.5, 3.8, 4.0, 4.2, 4.5]},
                    traces=["hook.phi"], sample_rate=50e3,
                    noise={"hook.phi": 3e-4}, resolution={"hook.phi": 3.5e-4},
                    units={"time": "ms", "hook.phi": "deg"}),
}


def run_case(model, hyp, effect, seed, library, quick):
    """One blind diagnosis; returns a dict of outcomes (runs in a worker)."""
    from acausal.diagnose.run import candidates, diagnose
    from acausal.diagnose.synth import same_law_members, synthesize

    setup = SETUPS[model]
    rng = np.random.default_rng(seed)
    loc = None
    if hyp is not None:
        _, _, cands = candidates(setup["path"], library, [hyp])
        locs = [l for h, l, _ in cands]
        loc = locs[int(rng.integers(len(locs)))]
    t0, c0 = time.perf_counter(), time.process_time()
    with tempfile.TemporaryDirectory() as tmp:
        kw = {k: v for k, v in setup.items() if k != "path"}
        truth = synthesize(setup["path"], os.path.join(tmp, "data"), hypothesis=hyp,
                           location=loc, effect=None if hyp is None else (effect, effect),
                           free_jitter=0.1, seed=seed, library=library, **kw)
        out = diagnose(setup["path"], os.path.join(tmp, "data"),
                       out_dir=os.path.join(tmp, "out"), scheduler="serial",
                       progress=False, exact_cv=False, plots=False, library=library,
                       max_nfev=30 if quick else 60)
        read = {k: v for k, v in kw.items() if k != "units"}
        same = same_law_members(setup["path"], truth, library=library, **read) if hyp else []
    members = [(out["cause"], out["location"])] + [(e["cause"], e["location"])
                                                  for e in out["equivalent_causes"]]
    right = hyp is not None and any(m in members for m in [(hyp, loc)] + same)
    return dict(hyp=hyp, effect=effect, seed=seed, location=loc,
                achieved=truth.effect, discrepancy=out["discrepancy"],
                named=hyp is not None and out["cause"] == hyp and out["location"] == loc,
                right=bool(right and out["discrepancy"]),
                weak=out["discrepancy"] and out["cause"] is None,
                verdict=(out.get("verdict") or {}).get("kind"),
                cause=out["cause"], cause_location=out["location"],
                same_law=[f"{h} at {l}" for h, l in same],
                left=_left_after_calibration(out["gain"]["before"]["train"]),
                wall_s=time.perf_counter() - t0,
                cpu_s=time.process_time() - c0)


def _left_after_calibration(train_rms):
    """The effect the calibrated nominal model leaves in the data (floors,
    RMS): sqrt(rms^2 - 1) of its weighted residuals, the noise's unit share
    taken out. Near 0 when the free parameters absorb the truth's extension
    (viscous damping at a body whose damping is a free parameter): no
    method can see such a cause in these data, whatever its effect before
    calibration (the table's "achieved")."""
    if train_rms is None or not np.isfinite(train_rms):
        return None
    return float(np.sqrt(max(train_rms ** 2 - 1.0, 0.0)))


def job_list(args, hyps, effects):
    """Every case, seed-major (every hypothesis and effect at the first seed,
    then the next seed, ...) with the null datasets spread among them, so
    that a run stopped early has covered every cell as evenly as it could."""
    per_seed = [[(args.model, h, e, 1000 * i + s, args.library, args.quick)
                 for i, h in enumerate(hyps) for e in effects] for s in range(args.seeds)]
    nulls = [(args.model, None, 0.0, 90000 + s, args.library, args.quick)
             for s in range(args.nulls)]
    jobs = []
    for k, block in enumerate(per_seed):
        share = nulls[k * len(nulls) // max(args.seeds, 1):(k + 1) * len(nulls)
                      // max(args.seeds, 1)]
        step = max(1, len(block) // max(len(share), 1))
        for j, job in enumerate(block):
            jobs.append(job)
            if share and (j + 1) % step == 0:
                jobs.append(share.pop(0))
        jobs += share
    return jobs if args.seeds else nulls


def _sited(model, hyps, library):
    """The hypotheses with at least one site on the model, and the others."""
    from acausal.diagnose.run import candidates
    path = SETUPS[model]["path"]
    have = [h for h in hyps if candidates(path, library, [h])[2]]
    return have, [h for h in hyps if h not in have]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--model", choices=sorted(SETUPS), default="latch")
    ap.add_argument("--effects", default="1,3,10")
    ap.add_argument("--seeds", type=int, default=3)
    ap.add_argument("--nulls", type=int, default=10)
    ap.add_argument("--hypotheses", default=None, help="comma-separated subset")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--library", default=None)
    ap.add_argument("--quick", action="store_true", help="fewer optimiser steps")
    ap.add_argument("--resume", action="store_true", help="keep the cases already in the "
                    "--out .json and run only the others (the table says so)")
    ap.add_argument("--out", default=None, help="the Markdown table (rewritten after every "
                    "case, marked partial until all are done; every case's outcome in "
                    "the .json beside it)")
    args = ap.parse_args(argv)

    from acausal.diagnose.library.loader import load_library
    lib = load_library(args.library)
    hyps = args.hypotheses.split(",") if args.hypotheses else list(lib.HYPOTHESES)
    hyps, unsited = _sited(args.model, hyps, args.library)
    effects = [float(x) for x in args.effects.split(",")]
    jobs = job_list(args, hyps, effects)
    n_all = len(jobs)
    results, wall0 = _done(args) if args.resume else ([], 0.0)
    done = {(r["hyp"], r["effect"], r["seed"]) for r in results}
    jobs = [j for j in jobs if (j[1], j[2], j[3]) not in done]
    t0 = time.perf_counter() - wall0
    commit = _commit()
    with cf.ProcessPoolExecutor(args.workers) as ex:
        futs = [ex.submit(run_case, *j) for j in jobs]
        for k, f in enumerate(cf.as_completed(futs)):
            try:
                r = f.result()
            except Exception as exc:  # noqa: BLE001 - report and go on
                print(f"case failed: {type(exc).__name__}: {exc}", file=sys.stderr)
                continue
            r["commit"] = commit
            results.append(r)
            print(f"[{len(results)}/{n_all}] {r['hyp']} effect {r['effect']:g} seed {r['seed']}"
                  f" at {r['location']} (achieved {r['achieved']:.2f}): right={r['right']} "
                  f"named={r['named']} "
                  f"cause={r['cause']} ({r['wall_s']:.0f} s)", file=sys.stderr)
            _write(args, results, hyps, effects, time.perf_counter() - t0, n_all, unsited)
    table = _write(args, results, hyps, effects, time.perf_counter() - t0, n_all, unsited)
    print(table)


def _commit():
    import subprocess
    try:
        return subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"],
                              capture_output=True, text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return ""


def _done(args):
    """(cases, wall time) already in the --out .json (resumed runs add up
    their wall times; the cases may come from earlier code: the table's
    JSON keeps each case's commit when it was recorded)."""
    import json
    path = os.path.splitext(args.out or "")[0] + ".json"
    if not args.out or not os.path.exists(path):
        return [], 0.0
    with open(path) as f:
        d = json.load(f)
    return list(d["cases"]), float(d.get("wall_s", 0.0))


def _write(args, results, hyps, effects, wall, n_jobs, unsited=()):
    """The table (and, with ``--out``, the files) of the cases done so far."""
    table = render(results, hyps, effects, args, wall, n_jobs, unsited)
    if args.out:
        with open(args.out, "w") as f:
            f.write(table)
        import json
        with open(os.path.splitext(args.out)[0] + ".json", "w") as f:
            json.dump(dict(args=vars(args), wall_s=wall, n_cases=n_jobs, cases=results), f,
                      indent=1, default=float)
    return table


def _cpu_note(results):
    """The cases' CPU time (this process; the diagnosis runs serially in it),
    which a busy or niced run's wall time does not show."""
    cpu = [r["cpu_s"] for r in results if r.get("cpu_s") is not None]
    if not cpu:
        return ""
    return f"; CPU per case {np.mean(cpu):.0f} s (total {sum(cpu) / 60:.0f} min)"


ABSORBED = 0.2   # floors left after calibration under which a missed case was absorbed
# (rms^2 - 1 = 0.04: within three standard deviations of pure noise, sqrt(2/n), for n < 11000)


def render(results, hyps, effects, args, wall, n_jobs=None, unsited=()):
    n_jobs = len(results) if n_jobs is None else n_jobs
    L = [f"Detection power on `{args.model}` ({args.seeds} seeds per cell, "
         f"{args.nulls} null datasets; {wall / 60:.0f} min with {args.workers} workers).",
         "Cell: right-cause rate (right cause at the right location, named or in the "
         "named class) / named exactly / weak (discrepancy, no cause named) / missed.", ""]
    if len(results) < n_jobs:
        done = max(len(results), 1)
        L[1:1] = ["", f"**PARTIAL: {len(results)} of {n_jobs} cases done after "
                  f"{wall / 60:.0f} min** ({wall / done:.0f} s of wall per case with "
                  f"{args.workers} workers; all {n_jobs} would take about "
                  f"{wall / done * n_jobs / 60:.0f} min at that rate). Cells show the cases "
                  "done so far (n/a: none yet)."]
    if unsited:
        L.insert(1, f"Not run (no site for them on this model): {', '.join(unsited)}.")
    load = os.getloadavg()
    L.insert(1, f"Machine load (1/5/15 min) when written: {load[0]:.1f}/{load[1]:.1f}/"
             f"{load[2]:.1f} on {os.cpu_count()} CPUs; mean wall per case "
             f"{np.mean([r['wall_s'] for r in results]) if results else float('nan'):.0f} s"
             + _cpu_note(results) + ".")
    L.append("| hypothesis | " + " | ".join(f"effect {e:g}" for e in effects) + " |")
    L.append("|---|" + "---|" * len(effects))
    for h in hyps:
        cells = []
        for e in effects:
            rs = [r for r in results if r["hyp"] == h and r["effect"] == e]
            if not rs:
                cells.append("n/a")
                continue
            n = len(rs)
            capped = [r for r in rs if r["achieved"] < 0.9 * e]
            cap = ""
            if capped:
                cap = (f"; {len(capped)} capped (achieved "
                       + ", ".join(f"{r['achieved']:.2g}" for r in capped) + ")")
            cells.append(f"{sum(r['right'] for r in rs)}/{n} right, "
                         f"{sum(r['named'] for r in rs)} named, "
                         f"{sum(r['weak'] for r in rs)} weak, "
                         f"{sum(not r['discrepancy'] for r in rs)} missed{cap}")
        L.append(f"| {h} | " + " | ".join(cells) + " |")
    missed = [r for r in results if r["hyp"] is not None and not r["discrepancy"]
              and r.get("left") is not None]
    if missed:
        gone = [r for r in missed if r["left"] < ABSORBED]
        L.append("")
        L.append(f"Missed cases the calibration absorbed (the calibrated nominal leaves under "
                 f"{ABSORBED:g} floor, sqrt(rms^2 - 1) of its residuals): {len(gone)} of "
                 f"{len(missed)} missed with that figure recorded"
                 + (" (" + ", ".join(sorted({f"{r['hyp']} at {r['location']}" for r in gone}))
                    + ")" if gone else "") + ".")
    nulls = [r for r in results if r["hyp"] is None]
    if nulls:
        fp = sum(r["discrepancy"] for r in nulls)
        L.append("")
        L.append(f"False positives (discrepancy declared on noise-only data): {fp}/{len(nulls)}"
                 f" ({fp / len(nulls):.0%}); causes named on noise: "
                 f"{sum(r['cause'] is not None for r in nulls)}.")
    return "\n".join(L) + "\n"


if __name__ == "__main__":
    main()
