"""Wall-time ratios on a shared, noisy machine."""
import time


def best_interleaved(fns, repeat, clock=time.perf_counter):
    """Best-of-``repeat`` wall time (or ``clock``: ``time.process_time`` for
    CPU time, steadier on a loaded machine for single-threaded work) of each
    function, the runs interleaved (a, b, a, b, ...) so that a change of
    machine load hits all of them alike."""
    out = [[] for _ in fns]
    for _ in range(repeat):
        for times, fn in zip(out, fns):
            t0 = clock()
            fn()
            times.append(clock() - t0)
    return [min(t) for t in out]
