"""Speed of ``acausal diagnose`` end to end on the breaker (issue #10's
target: a 6-experiment breaker diagnosis in <= 20 s on 2 cores).

The case is the slow tier's first blind case (tests/diagnose/test_diagnose.py
SLOW_CASES[0]): hidden Coulomb friction at ``hook.body``, 8 noise floors,
hook-angle and armature traces at six impact velocities, seed 100. The data
are synthesized once into ``--data`` (kept between runs); the diagnosis
then runs with everything the command line runs by default (families,
pairs, located term, profiles, next experiment; no plots). ``--case pair``
is instead the slow tier's blind pair case (issue #11's timing case: two
causes, data from the independent tests/diagnose/breaker_scipy.py).

Printed: the verdict, held-out errors, wall and CPU time (this process and
its finished workers), the diagnosis's own stage times, the load average
before and after, and -- with ``--serial`` -- the simulations and wall time
per stage (counted in this process: every task runs here), optionally with
a cProfile of the whole run (``--profile FILE``).

    PYTHONPATH=. python benchmarks/diagnose_speed.py            # 2 workers
    PYTHONPATH=. python benchmarks/diagnose_speed.py --serial --profile prof.txt
    PYTHONPATH=. python benchmarks/diagnose_speed.py --case pair --serial
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import sys
import tempfile
import time
from collections import Counter

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
BREAKER = os.path.join(ROOT, "models", "breaker_24kv.py")
SETUP = dict(conditions={"v_impact": [3.3, 3.5, 3.8, 4.0, 4.2, 4.5]},
             traces=["hook.phi", "armature.mass.s"], sample_rate=50e3,
             noise={"hook.phi": 3e-4, "armature.mass.s": 1e-5},
             resolution={"hook.phi": 3.5e-4, "armature.mass.s": 1e-5},
             units={"time": "ms", "hook.phi": "deg", "armature.mass.s": "mm"})
CASES = {  # name -> (hypothesis, location, effect [floors], seed): the slow tier's
    "coulomb": ("coulomb_friction", "hook.body", 8.0, 100),
    "damping_law": ("contact_damping_law", "contact", 8.0, 107),
    "flexible": ("flexible_link", "hook.body:hook.arm3", 5.0, 105),
    "null": (None, None, 0.0, 500),
}
# the slow tier's blind pair case (tests/diagnose/test_blind_breaker.py): dry
# friction at the hook (1 N*m) and a coil force rising with the stroke (20 kN/m),
# 47 floors, data from the independent scipy simulator (breaker_scipy.py), seed 7
BLIND = {"pair": ({"hook_coulomb": 1.0, "coil_slope": 2e4}, 7,
                  "coulomb_friction+position_dependent_force", "hook.body+armature.coil")}


def data_folder(case, root):
    """The case's dataset (synthesized on first use); returns (folder, truth)."""
    from acausal.diagnose.synth import synthesize
    folder = os.path.join(root, f"breaker_{case}")
    marker = os.path.join(folder, "truth.json")
    if os.path.exists(marker):
        with open(marker) as f:
            return folder, json.load(f)
    if case in BLIND:
        return blind_folder(case, folder, marker)
    hyp, loc, effect, seed = CASES[case]
    truth = synthesize(BREAKER, folder, hypothesis=hyp, location=loc,
                       effect=None if hyp is None else (effect, effect), free_jitter=0.1,
                       seed=seed, **SETUP)
    with open(marker, "w") as f:
        json.dump(truth.to_dict(), f, default=float)
    return folder, truth.to_dict()


def blind_folder(case, folder, marker):
    """A blind case's dataset, written by tests/diagnose/breaker_scipy.py."""
    sys.path.insert(0, os.path.join(ROOT, "tests", "diagnose"))
    import breaker_scipy
    effect, seed, hyp, loc = BLIND[case]
    breaker_scipy.write(folder, effect, seed=seed)
    truth = dict(hypothesis=hyp, location=loc)
    with open(marker, "w") as f:
        json.dump(truth, f)
    return folder, truth


class StageCounter:
    """Simulations, model builds (flatten to generated code, not read from
    the compile cache; the C library's ``cc`` is not in them) and wall time
    per diagnosis stage (serial runs only: every task then runs in this
    process)."""

    STAGES = {"stages": ("calibrate", "fit", "search_pairs", "cross_validate"),
              "run": ("fit_members", "locate", "intervals", "next_experiment")}

    def __init__(self):
        self.sims, self.wall, self.calls = Counter(), Counter(), Counter()
        self.builds, self.build_s = Counter(), Counter()
        self.current = "load/other"

    def install(self):
        from acausal.diagnose import run
        from acausal.diagnose.stages import chain as stages
        from acausal.runtime import model as comp
        inner = comp.CompiledModel.simulate
        me = self

        def counted(cm, *a, **k):
            me.sims[me.current] += 1
            return inner(cm, *a, **k)
        comp.CompiledModel.simulate = counted
        build = comp.compile_artefact

        def built(*a, **k):
            art = build(*a, **k)
            if not art.build.cache_hit:
                me.builds[me.current] += 1
                me.build_s[me.current] += art.build.compile_s
            return art
        comp.compile_artefact = built
        for modname, names in self.STAGES.items():
            mod = run if modname == "run" else stages
            for name in names:
                setattr(mod, name, self._wrap(name, getattr(mod, name)))

    def _wrap(self, name, fn):
        me = self

        def wrapped(*a, **k):
            me.calls[name] += 1
            label = name if not (name == "fit" and me.calls[name] > 1) else "fit (pairs)"
            before, me.current = me.current, label
            t = time.perf_counter()
            try:
                return fn(*a, **k)
            finally:
                me.wall[label] += time.perf_counter() - t
                me.current = before
        return wrapped

    def table(self):
        rows = ["| stage | simulations | models built | their build [s] | wall [s] |",
                "|---|---|---|---|---|"]
        for k in list(dict.fromkeys(list(self.wall) + list(self.sims) + list(self.builds))):
            rows.append(f"| {k} | {self.sims[k]} | {self.builds[k]} | {self.build_s[k]:.1f} "
                        f"| {self.wall[k]:.1f} |")
        rows.append(f"| total | {sum(self.sims.values())} | {sum(self.builds.values())} "
                    f"| {sum(self.build_s.values()):.1f} | |")
        return "\n".join(rows)


def cpu_s():
    me, ch = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return me.ru_utime + me.ru_stime + ch.ru_utime + ch.ru_stime


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--case", choices=sorted(CASES) + sorted(BLIND), default="coulomb")
    ap.add_argument("--data", default=os.path.join(tempfile.gettempdir(), "acausal_dspeed"))
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--serial", action="store_true", help="run every task in this process "
                    "(per-stage simulation counts)")
    ap.add_argument("--profile", default=None, help="write a cProfile (cumulative) here")
    ap.add_argument("--json", default=None, help="append the result as one JSON line here")
    args = ap.parse_args(argv)
    from acausal.diagnose.run import diagnose
    folder, truth = data_folder(args.case, args.data)
    counter = None
    if args.serial:
        counter = StageCounter()
        counter.install()
    prof = None
    if args.profile:
        import cProfile
        prof = cProfile.Profile()
    load0, c0, t0 = os.getloadavg(), cpu_s(), time.perf_counter()
    with tempfile.TemporaryDirectory() as out:
        if prof:
            prof.enable()
        res = diagnose(BREAKER, folder, out_dir=out, progress=False,
                       workers=None if args.serial else args.workers,
                       plots=False, scheduler="serial" if args.serial else None)
        if prof:
            prof.disable()
        timing = json.loads(open(os.path.join(out, "candidates.json")).read())["timing"]
    wall, cpu, load1 = time.perf_counter() - t0, cpu_s() - c0, os.getloadavg()
    g = res["gain"]
    line = dict(case=args.case, truth=[truth["hypothesis"], truth["location"]],
                cause=res["cause"], location=res["location"],
                heldout=[g["before"]["heldout"], g["after"]["heldout"]],
                wall_s=wall, cpu_s=cpu, load_before=load0, load_after=load1,
                serial=args.serial, timing=timing)
    print(f"case {args.case}: truth {truth['hypothesis']} at {truth['location']}; named "
          f"{res['cause']} at {res['location']}; held-out {g['before']['heldout']:.3f} -> "
          f"{g['after']['heldout']:.3f}")
    print(f"wall {wall:.1f} s, CPU {cpu:.1f} s, load {load0[0]:.1f} -> {load1[0]:.1f}")
    print("diagnosis timing: " + ", ".join(f"{k} {v:.1f}" if isinstance(v, float) else
                                           f"{k} {v}" for k, v in timing.items()))
    if counter:
        print(counter.table())
        line["stages"] = {k: [counter.sims[k], counter.wall[k]] for k in counter.wall}
    if prof:
        import pstats
        prof.dump_stats(args.profile + ".prof")
        with open(args.profile, "w") as f:
            st = pstats.Stats(prof, stream=f)
            st.sort_stats("cumulative").print_stats(80)
            st.sort_stats("tottime").print_stats(40)
    if args.json:
        with open(args.json, "a") as f:
            f.write(json.dumps(line, default=float) + "\n")


if __name__ == "__main__":
    main()
