"""One BLAS thread for the library's own dense solves (an adapter around
threadpoolctl, the one module that touches BLAS threading).

The initialisation's least squares, rank tests and re-initialisations solve
systems of tens to a few hundred unknowns, many times per simulation.
OpenBLAS splits such solves over its threads, which spin while they wait;
on a loaded 2-core machine that made the initialisation of a 50-mass chain
50-80 times slower, and the first simulation of a 200-mass chain 24 s
instead of 2.3 s (benchmarks/scaling.py). :func:`single_threaded` limits
BLAS to one thread for the duration of a block, and restores the caller's
setting after it. Nothing happens at import: the thread-pool controller is
created at the first use, and without threadpoolctl the block runs as is.
Systems below :data:`MIN_SIZE` unknowns are left alone (OpenBLAS does not
thread them, and the limit costs ~0.1 ms).
"""
import contextlib
import functools

MIN_SIZE = 32       # unknowns from which the BLAS thread limit is applied


@functools.lru_cache(maxsize=None)
def _get_controller():
    """The process's ThreadpoolController (made at the first use, ~7 ms), or
    None without threadpoolctl."""
    try:
        from threadpoolctl import ThreadpoolController
    except ImportError:
        return None
    return ThreadpoolController()


def single_threaded(size):
    """A context manager: BLAS limited to one thread inside it when the
    system has ``size`` >= MIN_SIZE unknowns and threadpoolctl is
    installed; otherwise nothing."""
    if size < MIN_SIZE:
        return contextlib.nullcontext()
    ctl = _get_controller()
    if ctl is None:
        return contextlib.nullcontext()
    return ctl.limit(limits=1, user_api="blas")
