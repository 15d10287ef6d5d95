"""The composed breaker model (models/breaker_24kv.py, compiled once) against
the hand-written scikit-sundae reference of the same equations
(benchmarks/handwritten/breaker_sundae.py), in the same run. Both at
rtol 1e-8 with their own absolute tolerances, both stopping at release.
Target: wall-time ratio <= 1.5.

    python benchmarks/breaker_speed.py [--repeat N]
"""
import argparse
import os
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.join(ROOT, "benchmarks", "handwritten"))
sys.path.insert(0, os.path.join(ROOT, "benchmarks"))

import breaker_sundae as ref  # noqa: E402
from timing import best_interleaved  # noqa: E402

from acausal.modelfile import compile_file, evaluate_measures  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=10)
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    mf, cm = compile_file(os.path.join(ROOT, "models", "breaker_24kv.py"))
    compile_s = time.perf_counter() - t0
    opts = mf.experiment.run_options()
    # the reference's absolute tolerances, slot by slot, and output at its
    # internal steps as the reference does
    opts.update(output_step=0, atol={
        "armature.mass.s": 1e-11, "armature.mass.v": 1e-8, "hook.phi": 1e-10,
        "hook.body.w": 1e-7, "*": 1e-10})
    params = {"contact.K": 6.25e8, "hook.bh": 0.219}

    def gen():
        return cm.simulate(params=params, **opts)

    def hand():
        return ref.simulate(v_impact=3.8, K=6.25e8, bh=0.219)

    r = gen()
    m = evaluate_measures(mf, r)
    h = hand()
    tg, th = best_interleaved([gen, hand], args.repeat)
    print(f"compile (once): {compile_s:.2f} s; states/unknowns: {cm.dae.n_states}/"
          f"{len(cm.dae.y)}")
    print(f"{'':12s} {'wall [ms]':>10s} {'nfev':>6s} {'thrt [ms]':>10s}")
    print(f"{'generated':12s} {tg * 1e3:10.2f} {r.stats['nfev']:6d} {m['thrt'] * 1e3:10.5f}")
    print(f"{'hand':12s} {th * 1e3:10.2f} {h['nfev']:6d} {h['thrt'] * 1e3:10.5f}")
    print(f"ratio generated/hand: wall {tg / th:.2f}, nfev {r.stats['nfev'] / h['nfev']:.2f}")


if __name__ == "__main__":
    main()
