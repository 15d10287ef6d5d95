"""The breaker model file's default output (the solver's internal steps and
both sides of every event, ``output_step=0``) against the 2 us grid it used
before (``Experiment.dense_step``, still used for plots, CSV files and trace
comparisons), in the same run, at the six impact velocities of Table 2.
Prints the wall-time ratio and the THRT / contact-period differences (the
output times do not steer IDA's steps: expected 0 to round-off). For
comparison, also the per-variable absolute tolerances of
benchmarks/breaker_speed.py, which are faster still but change THRT.

    python benchmarks/breaker_output.py [--repeat N]
"""
import argparse
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.join(ROOT, "benchmarks"))

from timing import best_interleaved  # noqa: E402

from acausal.modelfile import compile_file, evaluate_measures  # noqa: E402

VELOCITIES = (3.3, 3.5, 3.8, 4.0, 4.2, 4.5)
PER_VARIABLE_ATOL = {"armature.mass.s": 1e-11, "armature.mass.v": 1e-8, "hook.phi": 1e-10,
                     "hook.body.w": 1e-7, "*": 1e-10}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    mf, cm = compile_file(os.path.join(ROOT, "models", "breaker_24kv.py"))
    variants = {"dense 2 us": mf.experiment.run_options(dense=True),
                "default": mf.experiment.run_options(),
                "per-var atol": dict(mf.experiment.run_options(), atol=PER_VARIABLE_ATOL)}
    total = dict.fromkeys(variants, 0.0)
    print(f"{'v [m/s]':>7s} " + " ".join(f"{k:>14s}" for k in variants)
          + "   dTHRT default, per-var [ms]")
    for v in VELOCITIES:
        fns = [(lambda o=o: cm.simulate(params={"v_impact": v}, **o)) for o in variants.values()]
        walls = best_interleaved(fns, args.repeat)
        m = [evaluate_measures(mf, fn()) for fn in fns]
        for k, w in zip(variants, walls):
            total[k] += w
        d = [(x["thrt"] - m[0]["thrt"]) * 1e3 for x in m[1:]]
        dc = (m[1]["contact_period"] - m[0]["contact_period"]) * 1e3
        print(f"{v:7.1f} " + " ".join(f"{w * 1e3:11.1f} ms" for w in walls)
              + f"   {d[0]:.1e}, {d[1]:.1e}  (contact period {dc:.1e})")
    base = total["dense 2 us"]
    print("wall-time ratio to the dense grid: "
          + ", ".join(f"{k} {base / t:.2f}x" for k, t in total.items()))


if __name__ == "__main__":
    main()
