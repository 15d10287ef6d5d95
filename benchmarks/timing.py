"""Wall-time ratios on a shared, noisy machine."""
import time


def best_interleaved(fns, repeat):
    """Best-of-``repeat`` wall time of each function, the runs interleaved
    (a, b, a, b, ...) so that a change of machine load hits all of them alike."""
    out = [[] for _ in fns]
    for _ in range(repeat):
        for times, fn in zip(out, fns):
            t0 = time.perf_counter()
            fn()
            times.append(time.perf_counter() - t0)
    return [min(t) for t in out]
