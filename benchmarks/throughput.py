"""Simulations per second on the 24 kV breaker, measured in one run:

* calibrate: output-error least squares of contact.K and hook.bh over the
  report's six voltages (data/report_24kv), end to end (compile excluded:
  the model is compiled before the clock starts, as a second run with the
  on-disk cache would be);
* one-by-one: ``cm.simulate`` over a list of parameter sets, measures
  computed after each;
* batched: ``cm.simulate_batch`` over the same sets on ``--workers``
  processes that hold the compiled model, measures computed in the workers;

with the ratio batched / one-by-one (the sets and the measures are the
same; the THRT values are checked to agree). All on ``--backend`` (default
``compiled``, the default of ``acausal calibrate`` and ``sweep``; the
calibration gets it as the CLI passes it, through ``ACAUSAL_BACKEND``).
Every figure is printed with the load average when it was measured: the
machine may be shared. Targets (issue 10): calibration >= 50 simulations
per second, a batched sweep >= 500 per second.

    python benchmarks/throughput.py [--sets 200] [--workers 2] [--backend compiled]
                                    [--no-calibrate]
"""
import argparse
import functools
import os
import resource
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")   # see benchmarks/scaling.py

import numpy as np  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)

from acausal.studies import calibrate as cal  # noqa: E402
from acausal.runtime.batch import default_workers  # noqa: E402
from acausal.modelfile import compile_file, evaluate_measures  # noqa: E402

MODEL = os.path.join(ROOT, "models", "breaker_24kv.py")
DATA = os.path.join(ROOT, "data", "report_24kv")


def param_sets(n, seed=1):
    rng = np.random.default_rng(seed)
    return [{"contact.K": float(k), "hook.bh": float(b)}
            for k, b in zip(rng.uniform(4e8, 9e8, n), rng.uniform(0.15, 0.30, n))]


def calibrate_rate():
    path = cal.resolve(MODEL)
    ds = cal.model_dataset(MODEL, DATA)
    t0 = time.perf_counter()
    out = cal.least_squares(path, ds, ["contact.K", "hook.bh"])
    wall = time.perf_counter() - t0
    return out.n_sim, wall


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sets", type=int, default=200)
    ap.add_argument("--backend", choices=["sundae", "compiled"], default="compiled")
    ap.add_argument("--workers", type=int, default=default_workers())
    ap.add_argument("--no-calibrate", action="store_true")
    args = ap.parse_args()
    os.environ["ACAUSAL_BACKEND"] = args.backend   # as `acausal --backend` does
    mf, cm = compile_file(MODEL)
    opts = dict(mf.experiment.run_options(), backend=args.backend)
    measures = functools.partial(evaluate_measures, mf)
    sets = param_sets(args.sets)
    cm.simulate(**opts)                                        # warm-up
    c0, t0 = _cpu(), time.perf_counter()
    one = [measures(cm.simulate(params=p, **opts)) for p in sets]
    t_one, load_one, cpu_one = time.perf_counter() - t0, os.getloadavg()[0], _cpu() - c0
    c0, t0 = _cpu(), time.perf_counter()
    batch = cm.simulate_batch(sets, workers=args.workers, reduce=measures, **opts)
    t_batch, load_batch, cpu_batch = time.perf_counter() - t0, os.getloadavg()[0], _cpu() - c0
    agree = max(abs(a["thrt"] - b["thrt"]) for a, b in zip(one, batch))
    n = len(sets)
    print(f"breaker on {args.backend}, {n} parameter sets, {args.workers} workers "
          f"({os.cpu_count()} CPUs); per CPU-second: what one idle core would do")
    print(f"  one-by-one : {n / t_one:7.1f} simulations/s  (load {load_one:.1f}; "
          f"{n / cpu_one:.0f} per CPU-second)")
    print(f"  batched    : {n / t_batch:7.1f} simulations/s  (load {load_batch:.1f}; "
          f"{n / cpu_batch:.0f} per CPU-second, workers included; x{t_one / t_batch:.2f} "
          f"in wall time; THRT agrees to {agree:.1e} s)")
    if not args.no_calibrate:
        c0 = _cpu()
        n_sim, wall = calibrate_rate()
        print(f"  calibrate  : {n_sim / wall:7.1f} simulations/s  (load "
              f"{os.getloadavg()[0]:.1f}; {n_sim / (_cpu() - c0):.0f} per CPU-second; "
              f"{n_sim} simulations in {wall:.1f} s, least squares over 6 voltages)")


def _cpu():
    """CPU seconds of this process and of its finished child processes."""
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime

if __name__ == "__main__":
    main()
