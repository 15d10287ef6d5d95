"""The cost of forward sensitivities: a simulation with
``sensitivities=[...]`` against the same simulation without, on each
backend, measured in the same run (best of interleaved repeats), and the
first sensitivity run's set-up (generating the augmented model, and on the
compiled backend building its C library; both cached afterwards).

Models: the damped oscillator of tests/core/test_sensitivities.py (smooth),
the Hertz impact (models/examples/hertz_impact.py: the parameter moves two
event times) and the 24 kV breaker (models/breaker_24kv.py, its own run
options), with 1 and 2 parameters.

    python benchmarks/sensitivities.py [--repeat 5]
"""
import argparse
import os
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from timing import best_interleaved  # noqa: E402

from acausal.runtime.backends import compiled_available  # noqa: E402
from acausal.modelfile import compile_file  # noqa: E402

CASES = [
    ("oscillator", "models/examples/oscillator.py", ["spring.c"], ["spring.c", "mass.m"]),
    ("hertz impact", "models/examples/hertz_impact.py", ["contact.K"], ["contact.K", "mass.m"]),
    ("breaker 24 kV", "models/breaker_24kv.py", ["contact.K"], ["contact.K", "hook.bh"]),
]


def _row(name, path, one, two, backend, repeat):
    mf, cm = compile_file(os.path.join(ROOT, path))
    opts = dict(mf.experiment.run_options(), backend=backend)
    cm.simulate(**opts)   # the plain model's library built, callbacks warm
    setup = []
    for names in (one, two):
        t0 = time.perf_counter()
        res = cm.simulate(sensitivities=names, **opts)
        setup.append(time.perf_counter() - t0)
    plain, s1, s2 = best_interleaved([lambda: cm.simulate(**opts),
                                      lambda: cm.simulate(sensitivities=one, **opts),
                                      lambda: cm.simulate(sensitivities=two, **opts)], repeat)
    return (f"| {name} | {res.stats['backend']} | {len(cm.dae.y)} | {plain * 1e3:.1f} | "
            f"{s1 * 1e3:.1f} ({s1 / plain:.2f}x) | {s2 * 1e3:.1f} ({s2 / plain:.2f}x) | "
            f"{setup[0]:.2f} / {setup[1]:.2f} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    backends = ["sundae"] + (["compiled"] if compiled_available() is None else [])
    print("| model | backend | unknowns | plain [ms] | 1 parameter [ms] | 2 parameters [ms] "
          "| first run, 1 / 2 parameters [s] |")
    print("|---|---|---|---|---|---|---|")
    for name, path, one, two in CASES:
        for backend in backends:
            print(_row(name, path, one, two, backend, args.repeat), flush=True)


if __name__ == "__main__":
    main()
