"""Compile and simulate times of large models, and how they grow with size.

Two scalable mechanisms: a chain of N masses joined by spring-dampers, one
end fixed (``benchmarks/chains.py``), and Newton's cradle with N balls
(``models/examples/newtons_cradle.py``). For each N it prints

* compile: flatten -> ... -> codegen, with the on-disk cache off, and its
  stages (flatten, aliases, structure, causalize, codegen; ``stage_s``);
* cached: the same compile again, read back from the on-disk cache;
* first: the first simulation (initialisation, IDA set-up);
* sim: a second simulation of the same compiled model;
* dense/band: the second simulation with IDA's dense and band linear
  solvers (chain only; "auto" picks band for large narrow-banded models);

then the growth exponent b of t ~ N^b fitted over N >= 20 (the small sizes
are dominated by fixed costs). Targets (issue 10): chain N = 100 compile +
first simulation <= 10 s on 2 cores; Newton's cradle N = 50 runs; compile
and first simulation grow no faster than N^1.3 up to N = 200.

    python benchmarks/scaling.py [--sizes 5 10 20 50 100 200] [--models chain cradle]
                                 [--blas-one-thread]

Every row carries the 1-minute load average when it finished, and the CPU
time of the compile and of the first simulation (process time, all
threads): on a shared machine the wall times grow with the load, the CPU
times much less. The library limits BLAS to
one thread in its own solves (acausal/blas.py); ``--blas-one-thread``
also sets OPENBLAS_NUM_THREADS=1 for the whole process (IDA, numpy
elsewhere), to compare. The simulation modules are imported before timing,
so the first simulation does not include scipy's import.
"""
import argparse
import os
import sys
import tempfile
import time

if "--blas-one-thread" in sys.argv:        # before numpy loads OpenBLAS
    os.environ["OPENBLAS_NUM_THREADS"] = "1"

import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.join(ROOT, "benchmarks"))
sys.path.insert(0, os.path.join(ROOT, "models", "examples"))

from acausal import AcausalError, compile_model  # noqa: E402
import acausal.runtime.hybrid  # noqa: E402,F401  (its imports are not a cost of the first simulation)
from chains import chain  # noqa: E402
import newtons_cradle  # noqa: E402

RUNS = {
    # model builder, simulate options, a variable to print (sanity)
    "chain": (chain, dict(t_end=0.1, rtol=1e-6, atol=1e-9), "m0.s"),
    "cradle": (newtons_cradle.build, dict(t_end=1.5e-3, rtol=1e-6, atol=1e-10), "ball1.v"),
}


def timed(fn, cpu=None):
    """(fn(), wall time); with a list ``cpu``, appends the process's CPU time
    (all threads), which a loaded machine inflates far less than wall time."""
    t0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    if cpu is not None:
        cpu.append(time.process_time() - c0)
    return out, time.perf_counter() - t0


def measure(name, n):
    build, opts, probe = RUNS[name]
    cpu = []
    cm, t_compile = timed(lambda: compile_model(build(n)), cpu)
    _, t_cached = timed(lambda: compile_model(build(n)))
    res, t_first = timed(lambda: cm.simulate(**opts), cpu)
    _, t_sim = timed(lambda: cm.simulate(**opts))
    row = dict(model=name, n=n, unknowns=len(cm.dae.y), compile=t_compile, cached=t_cached,
               first=t_first, sim=t_sim, lin=cm.linear_solver().kind,
               events=len(res.events), probe=float(res.final()[probe]),
               stages=dict(cm.stage_s), compile_cpu=cpu[0], first_cpu=cpu[1])
    if name == "chain":
        for kind in ("dense", "band"):
            _, row[kind] = timed(lambda: cm.simulate(linsolver=kind, **opts))
    return row


def exponent(rows, key, n_min=20):
    pts = [(r["n"], r[key]) for r in rows if r["n"] >= n_min and r.get(key)]
    if len(pts) < 2:
        return float("nan")
    n, t = np.log([p[0] for p in pts]), np.log([p[1] for p in pts])
    return float(np.polyfit(n, t, 1)[0])


STAGES = ("flatten", "aliases", "structure", "causalize", "codegen")


def report(name, r):
    extra = f" {r['dense']:7.2f} {r['band']:7.2f}" if name == "chain" else ""
    stages = " ".join(f"{r['stages'].get(k, float('nan')):6.2f}" for k in STAGES)
    print(f"  N={r['n']:4d} {r['unknowns']:5d} {r['compile']:8.2f} {r['cached']:7.2f} "
          f"{r['first']:7.2f} {r['sim']:7.2f}{extra}  {r['lin']:5s} {r['events']:4d}"
          f"  ({r['compile'] + r['first']:.2f} s to the first result; load "
          f"{os.getloadavg()[0]:.1f})\n         stages: {stages}; CPU time: compile "
          f"{r['compile_cpu']:.2f}, first simulate {r['first_cpu']:.2f}", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[5, 10, 20, 50, 100, 200])
    ap.add_argument("--models", nargs="+", default=["chain", "cradle"], choices=list(RUNS))
    ap.add_argument("--blas-one-thread", action="store_true",
                    help="also set OPENBLAS_NUM_THREADS=1 for the whole process")
    args = ap.parse_args()
    print(f"OPENBLAS_NUM_THREADS={os.environ.get('OPENBLAS_NUM_THREADS', '(unset)')}; "
          f"load average at start {os.getloadavg()[0]:.1f}")
    with tempfile.TemporaryDirectory() as cache:
        os.environ["ACAUSAL_CACHE"] = cache          # measure a cold cache, then a hit
        for name in args.models:
            rows = []
            print(f"\n{name}: N, unknowns, compile, cached compile, first simulate, simulate"
                  + (", dense, band" if name == "chain" else "") + " [s]; linear solver; events"
                  + "\n         stages [s]: " + ", ".join(STAGES))
            for n in args.sizes:
                try:
                    r = measure(name, n)
                except AcausalError as exc:      # e.g. the chattering guard
                    print(f"  N={n:4d} failed: {type(exc).__name__}: "
                          f"{str(exc).splitlines()[0][:160]}", flush=True)
                    continue
                rows.append(r)
                report(name, r)
            for k in STAGES:
                for r in rows:
                    r[k] = r["stages"].get(k)
            print(f"  growth exponent (N >= 20): compile {exponent(rows, 'compile'):.2f}, "
                  f"first simulate {exponent(rows, 'first'):.2f}, simulate "
                  f"{exponent(rows, 'sim'):.2f}, cached compile {exponent(rows, 'cached'):.2f}"
                  f"\n    CPU time: compile {exponent(rows, 'compile_cpu'):.2f}, first simulate "
                  f"{exponent(rows, 'first_cpu'):.2f}"
                  "\n    stages: " + ", ".join(f"{k} {exponent(rows, k):.2f}" for k in STAGES))


if __name__ == "__main__":
    main()
