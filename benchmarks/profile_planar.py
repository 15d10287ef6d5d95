"""Where a slow planar diagnosis spends its time (issue 24, item 6): the
planar breaker (models/breaker_24kv_planar.py) with a hidden Coulomb
friction in the cam pin (``cam.pin_d``, 8 floors, four impact velocities,
hook angle and armature travel at 50 kHz: the slow tier's planar blind
case), diagnosed with the command line's defaults (full library, families,
pairs when needed, located term, profiles, next experiment; no plots),
serially in this process under cProfile, on the cache ``$ACAUSAL_CACHE``
(point it at a new folder for a fresh cache).

Printed: the verdict, wall and CPU, the diagnosis's own stage times, the
simulations and wall per stage (benchmarks/diagnose_speed.py's counter),
and the profile (CPU time of this process: ``time.process_time``) split into model building (flatten to generated code:
``acausal/compiler``), the C library builds (``cc``), simulations
(``acausal/runtime``, minus their own builds), the least-squares linear
algebra and the rest; the compile-cache hits and misses.

    ACAUSAL_CACHE=/tmp/fresh PYTHONPATH=. python benchmarks/profile_planar.py --profile p.txt
"""
import argparse
import json
import os
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.join(ROOT, "benchmarks"))
from diagnose_speed import StageCounter, cpu_s  # noqa: E402

PLANAR = os.path.join(ROOT, "models", "breaker_24kv_planar.py")
SETUP = dict(hypothesis="coulomb_friction", location="cam.pin_d", effect=(8.0, 8.0),
             free_jitter=0.1, seed=7, conditions={"v_impact": [3.3, 3.8, 4.2, 4.5]},
             traces=["hook.phi", "armature.mass.s"], sample_rate=50e3,
             noise={"hook.phi": 3e-4, "armature.mass.s": 1e-5},
             resolution={"hook.phi": 3.5e-4, "armature.mass.s": 1e-5},
             units={"time": "ms", "hook.phi": "deg", "armature.mass.s": "mm"})

# profile buckets: (label, predicate on a function's file name and name)
BUCKETS = [
    ("C library builds (generate the C, wait for cc)",
     lambda f, n: f.endswith(os.path.join("backends", "compiled.py")) and n == "_build"),
    ("model building (flatten .. generated Python)",
     lambda f, n: f.endswith(os.path.join("compiler", "pipeline.py")) and n == "compile_artefact"),
    ("simulations (with their first run's C library build)",
     lambda f, n: f.endswith(os.path.join("runtime", "hybrid.py")) and n == "simulate"),
    ("least squares (scipy.optimize, with the simulations it asks for)",
     lambda f, n: "scipy/optimize" in f and n == "least_squares"),
]


def split(stats):
    """{bucket: cumulative seconds} of the outermost calls of each bucket
    (the buckets overlap where one calls another: a simulation's first run
    builds its C library; a least-squares fit runs simulations)."""
    out = {}
    for label, pred in BUCKETS:
        tot = 0.0
        for (f, _, n), (cc, nc, tt, ct, callers) in stats.stats.items():
            if pred(f, n):
                # count only calls not made from inside the same function (recursion)
                tot += ct
        out[label] = tot
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--data", default=os.path.join(tempfile.gettempdir(), "acausal_planar"))
    ap.add_argument("--profile", default=None)
    ap.add_argument("--json", default=None)
    ap.add_argument("--no-profile", action="store_true",
                    help="time only (cProfile slows sympy's model building 3-8x)")
    a = ap.parse_args(argv)
    from acausal.diagnose.run import diagnose
    from acausal.diagnose.synth import synthesize
    marker = os.path.join(a.data, "truth.json")
    if not os.path.exists(marker):
        truth = synthesize(PLANAR, a.data, **SETUP)
        with open(marker, "w") as f:
            json.dump(truth.to_dict(), f, default=float)
    truth = json.load(open(marker))
    counter = StageCounter()
    counter.install()
    import cProfile
    import pstats
    # CPU time of this process: the host is shared, and wall times under load
    # say more about the other jobs than about the diagnosis
    prof = cProfile.Profile(time.process_time)
    import resource
    ch0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    load0, c0, t0 = os.getloadavg(), cpu_s(), time.perf_counter()
    with tempfile.TemporaryDirectory() as out:
        if not a.no_profile:
            prof.enable()
        res = diagnose(PLANAR, a.data, out_dir=out, progress=False, plots=False,
                       scheduler="serial")
        if not a.no_profile:
            prof.disable()
        timing = json.loads(open(os.path.join(out, "candidates.json")).read())["timing"]
    wall, cpu, load1 = time.perf_counter() - t0, cpu_s() - c0, os.getloadavg()
    buckets = {} if a.no_profile else split(pstats.Stats(prof))
    ch1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    buckets["C compiler processes (cc, CPU of children)"] = (
        ch1.ru_utime + ch1.ru_stime - ch0.ru_utime - ch0.ru_stime)
    print(f"truth {truth['hypothesis']} at {truth['location']} ({truth['effect']:.2f} floors); "
          f"named {res['cause']} at {res['location']}; held-out "
          f"{res['gain']['before']['heldout']:.3f} -> {res['gain']['after']['heldout']:.3f}")
    print(f"wall {wall:.1f} s, CPU {cpu:.1f} s, load {load0[0]:.1f} -> {load1[0]:.1f}")
    print("diagnosis timing: " + ", ".join(f"{k} {v:.1f}" if isinstance(v, float) else
                                           f"{k} {v}" for k, v in timing.items()))
    print(counter.table())
    for k, v in buckets.items():
        print(f"{k}: {v:.1f} s")
    if a.profile and not a.no_profile:
        prof.dump_stats(a.profile + ".prof")
        with open(a.profile, "w") as f:
            s = pstats.Stats(prof, stream=f)
            s.sort_stats("cumulative").print_stats(100)
            s.sort_stats("tottime").print_stats(50)
    if a.json:
        with open(a.json, "a") as f:
            f.write(json.dumps(dict(wall_s=wall, cpu_s=cpu, load=[load0, load1], timing=timing,
                                    stages={k: [counter.sims[k], counter.wall[k]]
                                            for k in counter.wall},
                                    buckets=buckets, cause=res["cause"],
                                    location=res["location"]), default=float) + "\n")


if __name__ == "__main__":
    main()
