"""Issue 24, item 7: the diagnosis on independent mechanisms outside
``models/`` (a cam follower, a geared drive), with data from hand-written
scipy truths that share no code with acausal
(``tests/diagnose/independent/``), over the failure shapes of the issue,
effect sizes and seeds. Writes one JSON line per run to ``--log`` (a run
already there is skipped: the table resumes) and the table to ``--out``.

    PYTHONPATH=. python benchmarks/independent_cases.py --effects 30 --seeds 0
    PYTHONPATH=. python benchmarks/independent_cases.py --cases gear_null,cam_detent
    PYTHONPATH=. python benchmarks/independent_cases.py --table-only

Columns: case, truth (the hidden laws as scaled), effect (noise-free RMS
change of the data, floors), seed, verdict, named cause and location,
parameter error % (each named cause's magnitude against the truth's),
held-out error after (floors), ok (issue 24's acceptance: judge.py),
wall (s) and simulations (the fits' and the located term's: the
diagnosis's own count, ``timing.n_sim``, leaves out the located stage).
"""
import argparse
import json
import os
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
IND = HERE.parent / "tests" / "diagnose" / "independent"
sys.path.insert(0, str(IND))

import cases as C  # noqa: E402
import datawriter  # noqa: E402
import judge as J  # noqa: E402

EFFECTS = (5.0, 30.0, 300.0)
SEEDS = (0, 1, 2)
TIED = {"load": ("load", "motor"), "motor": ("motor", "load")}


def laws_of(case, effect):
    """(laws, achieved floors) of ``case`` at ``effect`` floors."""
    if not case.laws:
        return (), 0.0
    if not case.scale:
        return case.laws, datawriter.effect_floors(case.truth, case.laws)
    return datawriter.scaled(case.truth, case.laws, effect)


def _children_cpu(before):
    """CPU seconds of the worker processes ended since ``before`` (os.times)."""
    now = os.times()
    return (now.children_user - before.children_user) + \
        (now.children_system - before.children_system)


def describe(laws):
    return "; ".join(f"{l.kind}@{l.site} " + ", ".join(f"{k}={v:.4g}" for k, v in l.values.items())
                     for l in laws) or "none"


def run_one(case, effect, seed, workers=2, keep=None):
    laws, floors = laws_of(case, effect)
    from acausal.diagnose.run import diagnose
    with tempfile.TemporaryDirectory() as tmp:
        base = Path(keep) if keep else Path(tmp)
        data = base / "data"
        _, events = datawriter.write(data, case.truth, laws, seed=seed)
        t0 = time.perf_counter()
        cpu0, ch0 = time.process_time(), os.times()
        # workers 0: every task in this process (what a profiler such as
        # py-spy sees: ``py-spy record -f raw -o x.raw -- python ... --workers 0``)
        out = diagnose(case.model, data, out_dir=base / "out",
                       workers=None if workers == 0 else workers, progress=False, plots=False,
                       scheduler="serial" if workers == 0 else None)
        wall = time.perf_counter() - t0
        det = json.loads((base / "out" / "candidates.json").read_text())
    j = J.judge(case, laws, out, TIED)
    timing = det.get("timing") or {}
    return dict(case=case.name, shape=case.shape, truth=describe(laws), effect=floors,
                target=effect if case.scale and case.laws else None, seed=seed,
                verdict=J.verdict(out),
                named=[(c["cause"], c["location"]) for c in out.get("causes") or []],
                params={k: v["value"] for c in out.get("causes") or []
                        for k, v in c["parameters"].items()},
                unexplained=out.get("unexplained"), errors=j["errors"], ok=j["ok"],
                # a named cause's tied sites where the same cause was not fitted
                unfitted_tied=[(c["cause"], e["location"]) for c in out.get("causes") or []
                               for e in c.get("equivalent_sites") or []
                               if e.get("fitted") is None],
                wrong=j["wrong"], why=j["why"],
                heldout_before=out["gain"]["before"]["heldout"],
                heldout_after=out["gain"]["after"]["heldout"],
                wall_s=wall, cpu_s_main=time.process_time() - cpu0,
                cpu_s_children=_children_cpu(ch0),
                n_sim=(timing.get("n_sim") or 0) + (timing.get("located_n_sim") or 0),
                located_n_sim=timing.get("located_n_sim"), weak=det.get("weak_evidence"),
                sticks=sum(1 for ev in events.values() for e in ev if e[1] == "stick"),
                ranking=out.get("ranking", [])[:3])


def table(rows, head=""):
    lines = [head, "| case | truth | effect [floors] | seed | verdict | parameter error % "
             "| held-out before -> after | ok | wall [s] | simulations |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        err = ", ".join(f"{e:.2f}" for e in r["errors"]) or "-"
        ok = "yes" if r["ok"] else ("**WRONG NAME**" if r["wrong"] else "no")
        lines.append(f"| {r['case']} | {r['truth']} | {r['effect']:.1f} | {r['seed']} | "
                     f"{r['verdict']} | {err} | {r['heldout_before']:.3f} -> "
                     f"{r['heldout_after']:.3f} | {ok} | {r['wall_s']:.0f} | {r['n_sim']} |")
    n_ok = sum(r["ok"] for r in rows)
    n_wrong = sum(bool(r["wrong"]) for r in rows)
    lines.append("")
    lines.append(f"{n_ok} of {len(rows)} runs meet issue 24's acceptance; "
                 f"{n_wrong} name a cause the truth lacks.")
    return "\n".join(lines) + "\n"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--cases", default=",".join(C.CASES))
    ap.add_argument("--effects", default=",".join(str(e) for e in EFFECTS))
    ap.add_argument("--seeds", default=",".join(str(s) for s in SEEDS))
    ap.add_argument("--workers", type=int, default=2,
                    help="processes of each diagnosis (0: every task in this process)")
    ap.add_argument("--log", default=str(HERE.parent / "docs" / "independent_cases.jsonl"))
    ap.add_argument("--out", default=str(HERE.parent / "docs" / "independent_cases.md"))
    ap.add_argument("--label", default="", help="a heading for the table (code version)")
    ap.add_argument("--table-only", action="store_true",
                    help="only write the table from the runs already in --log")
    a = ap.parse_args(argv)
    log = Path(a.log)
    done = set()
    rows = []
    if log.exists():
        for line in log.read_text().splitlines():
            r = json.loads(line)
            if r.get("label", "") == a.label:
                done.add((r["case"], r.get("target"), r["seed"]))
                rows.append(r)
    for name in ([] if a.table_only else a.cases.split(",")):
        case = C.CASES[name]
        effects = [float(e) for e in a.effects.split(",")] if case.scale and case.laws else [None]
        for eff in effects:
            for seed in (int(s) for s in a.seeds.split(",")):
                if (name, eff, seed) in done:    # resumable: say so, not silently nothing
                    at = "" if eff is None else f" effect {eff:g}"
                    print(f"{name}{at} seed {seed}: already in {_shown(log)} under "
                          f"label {a.label!r}; not run again (another --label runs it)",
                          flush=True)
                    continue
                r = run_one(case, eff, seed, a.workers)
                r["label"] = a.label
                rows.append(r)
                with log.open("a") as fh:
                    fh.write(json.dumps(r, default=str) + "\n")
                print(f"{name} effect {r['effect']:.1f} seed {seed}: {r['verdict']}; errors "
                      f"{r['errors']}; ok {r['ok']}; held-out {r['heldout_after']:.3f}; "
                      f"{r['wall_s']:.0f} s, {r['n_sim']} simulations", flush=True)
    labels = sorted({json.loads(l).get("label", "") for l in log.read_text().splitlines()})
    every = [json.loads(l) for l in log.read_text().splitlines()]
    with open(a.out, "w") as fh:
        # the header names the log the rows came from
        fh.write(HEADER.replace("`docs/independent_cases.jsonl`", f"`{_shown(log)}`"))
        for lab in labels:
            fh.write(table([r for r in every if r.get("label", "") == lab],
                           f"\n### {lab or 'runs'}\n"))
    return 0


def _shown(path):
    """``path`` relative to the repository when inside it."""
    p = Path(path).resolve()
    try:
        return str(p.relative_to(HERE.parent))
    except ValueError:
        return str(p)


HEADER = """# Independent blind cases (issue 24, item 7)

Made by `benchmarks/independent_cases.py` (raw rows in `docs/independent_cases.jsonl`).
Mechanisms outside `models/`, written as a user would
(`tests/diagnose/independent/cam_follower.py`, `geared_drive.py`); data from
hand-written scipy truths (`cam_truth.py`, `gear_truth.py` on `truth_core.py`:
DOP853 at rtol 1e-11, dry friction by stick/slip events; no import of acausal),
written to the dataset folder by `datawriter.py` (noise and resolution as in each
truth's `NOISE`/`RESOLUTION`; effect = noise-free RMS change of every recorded
value, in floors, before any recalibration). Each truth agrees with the library's
nominal model to 7e-9 of range with the effect at zero
(`tests/diagnose/independent/test_truths.py`). "ok" is issue 24's acceptance
(`judge.py`): both causes named within 10 % when two act; "not explained" at the
right node when the cause has no hypothesis (and any cause named beside it right
within 10 %); no cause the truth lacks (**WRONG NAME**); nothing named on nulls.
Every diagnosis: `diagnose(..., workers=2, plots=False)`, the command line's defaults.
Wall times were taken on a host loaded 15-25 on 2 cores by six other sessions: they
are 5-10x a quiet host's.

What main 6fc3a0c gets wrong here (2026-11-27, seed 0, 30 floors; the run was
stopped at the deadline after 7 of the 13 shapes; effects 5 and 300 and seeds 1, 2
not run):
- dry friction + quadratic drag at the cam's bearing, in a free run-down:
  `stribeck_friction` at the *follower* named with confidence (held-out 4.68
  floors), although Coulomb friction at the cam reaches 4.26 there: a name that
  leaves the held-out data unexplained, at the wrong site (issue 24, item 1);
- the same pair at the geared drive's load: "weak", best single held-out 5.09
  against 3.48 without extension; the pair was not fitted (item 2);
- a cogging torque of the motor (several periods over the swing) and a ball
  detent in the follower's guide: "weak", never "not explained" (held-out 59 and
  44 floors left; best candidates pairs with a bilinear spring) (items 1, 3);
- right: Coulomb friction at the load (0.15 % error, held-out 1.001), and both
  nulls (no discrepancy).
A `ConstantTorque` drive (the natural choice for the geared drive) stops every
diagnosis on main with a traceback (`AttributeError: ConstantTorque has no
attribute 'quantity'`, from `position_dependent_force`'s `params`): the model
file uses `Torque(tau_m)` instead.
"""

if __name__ == "__main__":
    sys.exit(main())
