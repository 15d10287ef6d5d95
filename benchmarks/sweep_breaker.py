"""Sweep acceptance with the real breaker task (issue 4): a 21-point sweep on
2 cores takes at most 1.2 times the wall time of 21 sequential simulations
divided by 2, plus start-up.

The task is the one ``acausal sweep models/breaker_24kv.py --param
v_impact=3.0:5.0:21 --measure thrt ...`` runs on every point
(:func:`acausal.modelfile.sweep_task`: simulate the model file with the
point's parameters and evaluate its measures). Start-up is opening the pool
(or starting the Dask cluster) and, in every worker, compiling the model and
running it once (:func:`warm_up`: about 0.7 s of compile and 0.2-0.6 s of
one-off set-up in the first simulation of a process); the sequential
reference does the same in this process before its clock starts. A forked
process pool inherits that from this process. Each trial
is :func:`sweep_scaling.measure_scaling`; the machine is shared, so the
trials are repeated and all are printed, and the verdict uses the best
sequential and the best parallel time over the trials (noise only adds
time). On this shared 2-core machine the tasks' own CPU time grows by up to
40 % while both cores are busy, in some windows and not in others (a pure
Python loop shows the same), whereas the pool itself costs 2-6 %.

Usage (from the repository root)::

    PYTHONPATH=. python benchmarks/sweep_breaker.py [--trials 3] [--repeat 1] [--scheduler processes|dask|dask-noprofile]
"""
from __future__ import annotations

import argparse
import contextlib
import functools
import os
import statistics
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
MODEL = str(ROOT / "models" / "breaker_24kv.py")


@contextlib.contextmanager
def dask_pool(workers: int, profile: bool = True):
    """A LocalCluster of ``workers`` single-threaded processes, as an Executor
    (``profile=False``: without the workers' statistical profiler, which
    samples every worker thread's stack every 10 ms)."""
    import dask
    import distributed

    from acausal.infra.executor import open_executor

    with dask.config.set({"distributed.worker.profile.enabled": profile}):
        with distributed.LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                      dashboard_address=None) as cluster:
            with open_executor(cluster) as ex:
                yield ex


def timed_task(path: str, point: dict) -> dict:
    """:func:`acausal.modelfile.sweep_task` plus its own CPU time ``cpu_s``
    (to tell waiting for a core from computing)."""
    from acausal.modelfile import sweep_task

    cpu0 = time.process_time()
    out = dict(sweep_task(path, point))
    out["cpu_s"] = time.process_time() - cpu0
    return out


def warm_up(path: str) -> None:
    """Per-process start-up: compile the model file and run it once (the first
    simulation in a process also pays one-off set-up, about 0.2-0.6 s)."""
    from acausal.modelfile import run_file

    run_file(path)


def trial(points, workers: int, scheduler: str, repeat: int = 1) -> dict:
    from sweep_scaling import measure_scaling

    task = functools.partial(timed_task, MODEL)
    warm = functools.partial(warm_up, MODEL)
    pool = (functools.partial(dask_pool, workers, scheduler == "dask")
            if scheduler.startswith("dask") else None)
    return measure_scaling(task, points, ["thrt", "cpu_s"], workers=workers, warmup=warm, open_pool=pool,
                           repeat=repeat)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", default="v_impact=3.0:5.0:21")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--trials", type=int, default=3)
    parser.add_argument("--repeat", type=int, default=1,
                        help="time each sweep N times within a trial, keep the fastest")
    parser.add_argument("--scheduler", choices=("processes", "dask", "dask-noprofile"), default="processes")
    args = parser.parse_args(argv)

    from acausal.studies.sweep import grid, parse_param
    from sweep_scaling import report

    points = grid([parse_param(args.points)])
    print(f"breaker sweep {args.points} ({len(points)} points), {args.workers} workers, "
          f"{args.scheduler}; load average before: {os.getloadavg()[0]:.2f}")
    results = []
    for k in range(args.trials):
        t0 = time.perf_counter()
        r = trial(points, args.workers, args.scheduler, args.repeat)
        results.append(r)
        print(f"\n-- trial {k + 1} ({time.perf_counter() - t0:.1f} s, load average "
              f"{os.getloadavg()[0]:.2f})")
        print(report(r))
    ratios = [r["ratio"] for r in results]
    print("\n| trial | sequential [s] | parallel [s] | start-up [s] | ratio | task slowdown "
          "| pool (scheduling) | CPU slowdown | core share |")
    print("|---|---|---|---|---|---|---|---|---|")
    for k, r in enumerate(results, 1):
        print(f"| {k} | {r['sequential_s']:.3f} | {r['parallel_s']:.3f} | {r['startup_s']:.2f} "
              f"| {r['ratio']:.3f} | {r['task_slowdown']:.3f} | {r['scheduling_ratio']:.3f} "
              f"| {r['cpu_slowdown']:.3f} | {r['cpu_share']:.3f} |")
    print(f"\nratio: min {min(ratios):.3f}, median {statistics.median(ratios):.3f}, "
          f"max {max(ratios):.3f} (acceptance <= 1.2; whole rounds alone give "
          f"{results[0]['ideal_ratio']:.3f})")
    # noise on a shared machine only adds time: the best sequential and the
    # best parallel run of the interleaved trials estimate the noise-free
    # ratio (as benchmarks/timing.best_interleaved does for single runs)
    best = min(r["parallel_s"] for r in results) / (
        min(r["sequential_s"] for r in results) / args.workers)
    print(f"best-of-{len(results)} ratio (best parallel / (best sequential / "
          f"{args.workers})): {best:.3f} (acceptance <= 1.2)")
    return 0 if best <= 1.2 else 1


if __name__ == "__main__":
    sys.path[:0] = [str(HERE), str(ROOT)]   # sweep_scaling, and acausal/components from a checkout
    sys.exit(main())
