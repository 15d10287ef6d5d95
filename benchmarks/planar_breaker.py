"""The planar breaker (models/breaker_24kv_planar.py: the cam-and-roller
four-bar from planar bodies and joints) against the 1-D breaker
(models/breaker_24kv.py: the closed-form FourBar), in the same run:
compile time (each compiled ``--compiles`` times, fresh, interleaved; best)
and simulation wall time (best of ``--repeat`` interleaved runs), as ratios
planar / 1-D. Target: each ratio <= 3.

    python benchmarks/planar_breaker.py [--repeat N] [--compiles N]
"""
import argparse
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.join(ROOT, "benchmarks"))

from timing import best_interleaved  # noqa: E402

from acausal import compile_model  # noqa: E402
from acausal.modelfile import evaluate_measures, load_model_file  # noqa: E402

FILES = {"planar": os.path.join(ROOT, "models", "breaker_24kv_planar.py"),
         "1-D": os.path.join(ROOT, "models", "breaker_24kv.py")}


def _compile(path):
    """Load and compile a model file without the per-process cache and
    without the disk cache (``cache=False``: a hit would time loading a
    stored model, not compiling it)."""
    mf = load_model_file(path)
    if mf.experiment.stop is not None:
        mf.model.event(mf.experiment.stop.event(mf.model))
    return mf, compile_model(mf.model, cache=False)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--compiles", type=int, default=2)
    args = ap.parse_args(argv)
    built = {}

    def compiler(name):
        def fn():
            built[name] = _compile(FILES[name])
        return fn

    c_planar, c_1d = best_interleaved([compiler("planar"), compiler("1-D")], args.compiles)
    runs = {}

    def runner(name):
        mf, cm = built[name]

        def fn():
            runs[name] = cm.simulate(**mf.experiment.run_options())
        return fn

    s_planar, s_1d = best_interleaved([runner("planar"), runner("1-D")], args.repeat)
    m = {k: evaluate_measures(built[k][0], runs[k]) for k in FILES}
    print(f"{'':8s} {'compile [s]':>12s} {'simulate [ms]':>14s} {'unknowns':>9s} "
          f"{'thrt [ms]':>12s}")
    for name, c, s in (("planar", c_planar, s_planar), ("1-D", c_1d, s_1d)):
        cm = built[name][1]
        print(f"{name:8s} {c:12.2f} {s * 1e3:14.1f} {len(cm.dae.y):9d} "
              f"{m[name]['thrt'] * 1e3:12.7f}")
    print(f"ratio planar/1-D: compile {c_planar / c_1d:.2f}, simulate {s_planar / s_1d:.2f} "
          f"(target <= 3); |THRT difference| {abs(m['planar']['thrt'] - m['1-D']['thrt']):.2e} s")


if __name__ == "__main__":
    main()
