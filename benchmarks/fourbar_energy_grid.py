"""The frictionless planar crank-rocker (models/examples/fourbar_planar.py)
over 3 s from neighbouring starts and tolerances: how many runs drift in
energy over 1e-8, the worst drift and the steps, on one backend.

Whether IDA falls into the step and order cycle of docs/planar.md ("The
generic four-bar's energy over three turns") is decided by the last bits
of the arithmetic, so a single run proves nothing either way; a grid of
neighbouring runs gives the fraction that does. Measured 2026-11-26:

===========  ==========================  ==================  ===============
geometry     grid                        main (a99cca4)      statesel9
===========  ==========================  ==================  ===============
generic      rtol 0.8-1.2e-10 x theta1_0  sundae 4/81,        0/81, 1.6e-9
             2.3-2.7 (9 x 9)              compiled 3/81       0/81, 1.85e-9
vertical     rtol 0.9-1.1e-10 x theta1_0  sundae 10/15,       1/15 (IDA stops
             0.5-2.5 (3 x 5)              compiled 9/15       at 0.5), 2/15
===========  ==========================  ==================  ===============

Usage: ``python benchmarks/fourbar_energy_grid.py [sundae|compiled]
[generic|vertical]``.
"""
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "models", "examples"))

GEOMETRIES = {
    # tests/models/test_planar_examples.py GENERIC and OTHER
    "generic": (dict(e=0.04, f=0.1, r1=0.08, r2=0.03, r3=0.06),
                np.linspace(0.8e-10, 1.2e-10, 9), np.linspace(2.3, 2.7, 9)),
    "vertical": (dict(e=0.05, f=0.12, r1=0.09, r2=0.04, r3=0.06),
                 (0.9e-10, 1e-10, 1.1e-10), np.linspace(0.5, 2.5, 5)),
}


def run(cm, geometry, rtol, theta1_0, backend):
    """(energy drift, steps) of one 3 s run; drift 1.0 when IDA fails."""
    import fourbar_planar as fp
    from acausal.errors import SolverError
    try:
        res = cm.simulate(t_end=3.0, rtol=rtol, atol=1e-12, output_step=1e-3, backend=backend,
                          params={**geometry, "theta1_0": theta1_0, "w1_0": 5.0,
                                  "spring.c": 0.0})
    except SolverError:
        return 1.0, -1
    E = 0.5 * fp.JH * res["hook.w"]**2 + 0.5 * fp.JS * res["shaft.w"]**2
    return float(np.max(np.abs(E / E[0] - 1))), res.stats["steps"]


def main(backend="sundae", which="generic"):
    from acausal.modelfile import compile_file
    _, cm = compile_file(os.path.join(ROOT, "models", "examples", "fourbar_planar.py"))
    geometry, rtols, starts = GEOMETRIES[which]
    t0 = time.perf_counter()
    runs = [run(cm, geometry, r, th, backend) for r in rtols for th in starts]
    drift = np.array([d for d, _ in runs])
    steps = [s for _, s in runs if s > 0]
    print(f"{which} on {backend}: {int(np.sum(drift > 1e-8))}/{len(runs)} runs over 1e-8 "
          f"({int(np.sum(drift >= 1.0))} IDA failures); worst finished drift "
          f"{np.max(drift[drift < 1.0], initial=0.0):.2e}; mean steps {np.mean(steps):.0f}; "
          f"{time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main(*sys.argv[1:3])
