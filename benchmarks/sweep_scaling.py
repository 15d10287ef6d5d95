"""Parallel efficiency of a sweep on this machine.

Runs the same points once sequentially (``"serial"`` executor) and once on a
local process pool, both through :func:`acausal.sweep.run_sweep`, and prints::

    ratio = parallel_wall / (sequential_wall / workers)

where ``parallel_wall`` excludes pool start-up (opening the pool and running
``warmup`` once on every worker, e.g. loading and compiling a model into
:func:`acausal.executor.worker_cache`), which is reported separately. The
project's acceptance: a 21-point sweep on 2 cores has ratio <= 1.2 (plus
start-up). Note that 21 points on 2 workers take 11 rounds, so even a perfect
pool gives ratio 11/10.5 = 1.048 for equal-cost points.

Usage (from the repository root)::

    python benchmarks/sweep_scaling.py --points 21 --seconds 0.2 --workers 2

To benchmark the real simulation, call :func:`measure_scaling` with its task,
points, measures and a ``warmup`` that builds the per-worker cache.
"""

from __future__ import annotations

import argparse
import functools
import math
import os
import sys
import tempfile
import time
from collections.abc import Callable, Mapping, Sequence
from pathlib import Path

_HOLD_S = 0.1  # warm-up tasks linger this long so each worker gets one


def spin(point: Mapping[str, float], *, loops: int) -> dict[str, float]:
    """A CPU-bound task: ``loops`` iterations of pure-Python arithmetic."""
    acc = point.get("x", 0.0)
    for i in range(loops):
        acc = (acc * 1.000001 + i) % 1000.0
    return {"value": acc}


def calibrate_loops(seconds: float) -> int:
    """Loops of :func:`spin` that take about ``seconds`` on this machine."""
    loops = 200_000
    start = time.perf_counter()
    spin({}, loops=loops)
    return max(1, int(loops * seconds / (time.perf_counter() - start)))


def _noop() -> None:
    """Default warm-up: nothing to build."""


def _warm_worker(warmup: Callable[[], object]) -> int:
    """Run ``warmup`` on a worker, linger so peers get their own, return the pid."""
    warmup()
    time.sleep(_HOLD_S)
    return os.getpid()


def _warm_all(executor, warmup: Callable[[], object], workers: int) -> None:
    """Run ``warmup`` once on each worker (best effort: retried a few times)."""
    seen: set[int] = set()
    for _ in range(3):
        futures = [executor.submit(_warm_worker, warmup) for _ in range(workers)]
        seen |= {f.result() for f in executor.as_completed(futures)}
        if len(seen) >= workers:
            return


def _timed_sweep(task, points, measures, executor, csv_path: Path) -> tuple[float, float, float]:
    """(wall time of the sweep, summed per-point task time measured on the workers,
    summed ``cpu_s`` measure if the task reports one, else nan)."""
    from acausal.studies.sweep import run_sweep

    start = time.perf_counter()
    rows = run_sweep(task, points, csv_path, executor=executor, measures=measures, progress=False)
    wall = time.perf_counter() - start
    failed = sum(r["status"] != "ok" for r in rows)
    if failed:
        print(f"warning: {failed} point(s) failed; timings are suspect", file=sys.stderr)
    cpu = sum(r["cpu_s"] for r in rows) if "cpu_s" in measures else math.nan
    return wall, sum(r["wall_s"] for r in rows), cpu


def _best_sweep(task, points, measures, executor, tmp: str, name: str, repeat: int) -> tuple[float, float, float]:
    """Fastest of ``repeat`` timed sweeps (least disturbed by other load)."""
    runs = [_timed_sweep(task, points, measures, executor, Path(tmp, f"{name}{i}.csv")) for i in range(repeat)]
    return min(runs)


def measure_scaling(
    task: Callable[[dict], Mapping],
    points: Sequence[Mapping[str, float]],
    measures: Sequence[str],
    *,
    workers: int = 2,
    warmup: Callable[[], object] = _noop,
    repeat: int = 1,
    open_pool: Callable[[], object] | None = None,
) -> dict[str, float]:
    """Time ``points`` sequentially and on a ``workers``-process pool.

    ``open_pool`` (default ``lambda: open_executor(workers=workers)``) opens
    the parallel executor as a context manager, e.g. a Dask cluster of
    ``workers`` single-threaded processes; its opening counts as start-up.

    ``task`` and ``warmup`` must be picklable. ``warmup`` runs once in this
    process before the sequential run and once per worker before the parallel
    run, so one-off set-up is not counted as sweep time in either. With
    ``repeat`` > 1 each sweep is timed that many times and the fastest is kept.

    Returns ``sequential_s``, ``startup_s`` (open pool + warm every worker, minus
    the fixed linger of the warm-up tasks), ``parallel_s`` (sweep only),
    ``shutdown_s`` and ``ratio = parallel_s / (sequential_s / workers)``.
    To tell pool overhead from hardware contention it also returns
    ``ideal_ratio`` (whole rounds of equal points: ceil(n/w) / (n/w)),
    ``task_slowdown`` (summed per-point task time, parallel / sequential: > 1
    when concurrent tasks slow each other, e.g. shared cores or memory
    bandwidth) and ``scheduling_ratio`` (parallel_s over the summed parallel
    task time / workers: what the pool itself costs). If the task returns a
    ``cpu_s`` measure (its own CPU time) and ``measures`` lists it, also
    ``cpu_slowdown`` (summed CPU time, parallel / sequential: ~1 unless the
    workers slow each other's computation) and ``cpu_share`` (summed parallel
    CPU time / (workers * parallel_s): the share of the ``workers`` cores the
    tasks got; < 1 when other processes use them); else these are nan.
    """
    from acausal.infra.executor import open_executor

    with tempfile.TemporaryDirectory() as tmp:
        warmup()
        with open_executor("serial") as ex:
            sequential, seq_task, seq_cpu = _best_sweep(task, points, measures, ex, tmp, "seq", repeat)
        t0 = time.perf_counter()
        with (open_pool or functools.partial(open_executor, workers=workers))() as ex:
            _warm_all(ex, warmup, workers)
            t1 = time.perf_counter()
            parallel, par_task, par_cpu = _best_sweep(task, points, measures, ex, tmp, "par", repeat)
            t2 = time.perf_counter()
        t3 = time.perf_counter()
    return {
        "points": len(points),
        "workers": workers,
        "sequential_s": sequential,
        "startup_s": max(0.0, t1 - t0 - _HOLD_S),
        "parallel_s": parallel,
        "shutdown_s": t3 - t2,
        "ratio": parallel / (sequential / workers),
        "ideal_ratio": math.ceil(len(points) / workers) / (len(points) / workers),
        "task_slowdown": par_task / seq_task,
        "scheduling_ratio": parallel / (par_task / workers),
        "cpu_slowdown": par_cpu / seq_cpu,
        "cpu_share": par_cpu / (workers * parallel),
    }


def report(result: Mapping[str, float]) -> str:
    """Human-readable summary of :func:`measure_scaling`'s result."""
    w = result["workers"]
    return "\n".join([
        f"points: {result['points']}, workers: {w}",
        f"sequential wall: {result['sequential_s']:.3f} s ({result['sequential_s'] / result['points']:.3f} s/point)",
        f"parallel wall:   {result['parallel_s']:.3f} s (sweep only)",
        f"start-up:        {result['startup_s']:.3f} s (pool + warm-up), shutdown {result['shutdown_s']:.3f} s",
        f"ratio parallel/(sequential/{w}): {result['ratio']:.3f}  (acceptance <= 1.2: "
        f"{'PASS' if result['ratio'] <= 1.2 else 'FAIL'})",
        f"  per-point task time, parallel/sequential: {result['task_slowdown']:.3f} (contention between workers)",
        f"  pool: parallel wall / (summed task time / {w}): {result['scheduling_ratio']:.3f} "
        f"(whole rounds alone give {result['ideal_ratio']:.3f})",
    ] + ([] if math.isnan(result.get("cpu_share", math.nan)) else [
        f"  task CPU time, parallel/sequential: {result['cpu_slowdown']:.3f}; share of the {w} "
        f"cores the tasks got: {result['cpu_share']:.3f}",
    ]))


def main(argv: Sequence[str] | None = None) -> int:
    """Benchmark :func:`spin` calibrated to ``--seconds`` per point."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=21)
    parser.add_argument("--seconds", type=float, default=0.2, help="target CPU time per point")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--repeat", type=int, default=1, help="time each sweep N times, keep the fastest")
    args = parser.parse_args(argv)

    from acausal.studies.sweep import grid

    loops = calibrate_loops(args.seconds)
    points = grid([("x", [float(i) for i in range(args.points)])])
    result = measure_scaling(functools.partial(spin, loops=loops), points, ["value"], workers=args.workers,
                             repeat=args.repeat)
    print(report(result))
    return 0


if __name__ == "__main__":
    sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # run from a checkout
    sys.exit(main())
