"""What a diagnosis pays per model build (issue 24, item 6): the first N
candidate models of a model file (the nominal plus one hypothesis each, as
the diagnosis's workers build them), each compiled and run once on the
compiled backend, on a fresh store, in one process.

Printed: wall time, the process's CPU in the compile (model file, flatten
... the iteration matrix's sparsity), in the C generation and in the first
run (initialisation), and the CPU of the C compiler's processes. Compare
two versions of the code by running this from each checkout, alternately,
on the same host (the figures move 10-20 % with the host's load).

    PYTHONPATH=. python benchmarks/builds.py models/breaker_24kv_planar.py 26
    PYTHONPATH=. python benchmarks/builds.py models/breaker_24kv.py 16 --dump DIR

``--dump DIR`` writes each model's generated C and Python source (to check
that a change to the compiler leaves them the same text: ``cmp``).
"""
from __future__ import annotations

import argparse
import os
import resource
import sys
import tempfile
import time
from collections import Counter

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)


def _cpu():
    own = resource.getrusage(resource.RUSAGE_SELF)
    kids = resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime, kids.ru_utime + kids.ru_stime


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("model")
    ap.add_argument("n", type=int, nargs="?", default=16, help="candidate models to build")
    ap.add_argument("--dump", default=None, help="write each model's C and Python here")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as store:
        os.environ["ACAUSAL_CACHE"] = store            # a fresh store
        run(args.model, args.n, args.dump)


def run(model, n, dump):
    from acausal.diagnose.problem import Problem
    from acausal.diagnose.stages.chain import candidates
    from acausal.diagnose.stages.tasks import model_of
    import acausal.runtime.backends.compiled as compiled

    problem = Problem(model, "", "acausal.diagnose.library.hypotheses", ())
    chosen = candidates(problem)[:n]
    spent = Counter()
    generate_c = compiled.generate_c

    def timed_generate_c(cm):
        t = _cpu()[0]
        out = generate_c(cm)
        spent["C generation"] += _cpu()[0] - t
        return out
    compiled.generate_c = timed_generate_c
    try:
        t0, c0 = time.perf_counter(), _cpu()
        for k, cand in enumerate(chosen):
            t = _cpu()[0]
            _, cm = model_of(problem, cand)
            spent["compile"] += _cpu()[0] - t
            own, kids = _cpu()
            cm.simulate(t_end=0.01, backend="compiled")
            own2, kids2 = _cpu()
            spent["first run"] += own2 - own
            spent["cc (its processes)"] += kids2 - kids
            if dump:
                os.makedirs(dump, exist_ok=True)
                with open(os.path.join(dump, f"{k:03d}.c"), "w") as fh:
                    fh.write(generate_c(cm).text)
                with open(os.path.join(dump, f"{k:03d}.py.txt"), "w") as fh:
                    fh.write(cm.source)
        wall, c1 = time.perf_counter() - t0, _cpu()
    finally:
        compiled.generate_c = generate_c
    spent["first run"] -= spent["C generation"]
    print(f"{len(chosen)} models of {os.path.basename(model)}: wall {wall:.2f} s, "
          f"CPU {c1[0] - c0[0]:.2f} s here + {c1[1] - c0[1]:.2f} s in cc; "
          + ", ".join(f"{k} {v:.2f} s" for k, v in spent.items())
          + f"; peak memory {resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024:.0f} MB")


if __name__ == "__main__":
    main()
