"""Many simulations of one compiled model with different parameter sets.

:func:`simulate_batch` runs them in a pool of worker processes that each
hold the compiled model: the workers are forked from the calling process
after the model is compiled, so nothing is compiled or pickled to set them
up; only parameter dicts go out and plain arrays (or what ``reduce``
returns) come back, a chunk of parameter sets per round trip. Where
``fork`` is not available (Windows, or one worker asked for) the sets run
one after the other in the calling process.

Failed simulations (any :class:`Exception` of one parameter set) do not stop
the batch: with ``errors="return"`` their place in the output holds a
:class:`BatchItemError` naming the set and the error, with
``errors="raise"`` (default) the first one is raised once all are done.
"""
import concurrent.futures as cf
import itertools
import multiprocessing as mp
import os

from ..errors import AcausalError, UsageError

_JOBS = {}              # token -> (compiled model, reduce, simulate keywords)
_token = itertools.count()


class BatchItemError(AcausalError):
    """One parameter set of a batch failed: ``index`` in the batch,
    ``params`` the set, ``kind`` the error's class name."""

    def __init__(self, message, index=None, params=None, kind=None):
        super().__init__(message)
        self.index, self.params, self.kind = index, params, kind


def default_workers():
    """The CPUs this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except AttributeError:
        return max(1, os.cpu_count() or 1)


def _payload(res):
    """What a worker sends back for a full result (no compiled model)."""
    return dict(p=res.p, t=res.t, y=res.y, yp=res.yp, d=res.d, events=res.events,
                stats=res.stats, status=res.status, message=res.message)


def _run_chunk(token, chunk):
    """Worker side: simulate each (index, params) of ``chunk``."""
    cm, reduce, kw = _JOBS[token]
    out = []
    for index, params in chunk:
        try:
            res = cm.simulate(params=params, **kw)
            out.append(("ok", index, reduce(res) if reduce else _payload(res)))
        except Exception as exc:            # one failed set must not stop the batch
            out.append(("error", index, (type(exc).__name__, str(exc).splitlines()[0])))
    return out


def _chunks(items, size):
    for k in range(0, len(items), size):
        yield items[k:k + size]


def simulate_batch(cm, param_sets, *, workers=None, chunksize=None, reduce=None,
                   errors="raise", **simulate_kw):
    """Simulate ``cm`` once per parameter set (a dict of overrides, as
    ``simulate(params=...)``); returns a list in the order of
    ``param_sets``: :class:`acausal.result.Result` objects, or
    ``reduce(result)`` computed in the worker (cheaper to send back: a few
    measures instead of trajectories). ``workers``: processes (default: the
    CPUs this process may use); ``chunksize``: parameter sets per task
    (default: about four tasks per worker). Other keywords go to
    :meth:`CompiledModel.simulate`."""
    if errors not in ("raise", "return"):
        raise UsageError(f"errors must be 'raise' or 'return', got {errors!r}")
    sets = [dict(p or {}) for p in param_sets]
    for p in sets:
        cm.param_vector(p)                   # bad names / out-of-bounds values: fail now
    workers = min(workers or default_workers(), max(1, len(sets)))
    token = next(_token)
    _JOBS[token] = (cm, reduce, simulate_kw)
    try:
        items = list(enumerate(sets))
        if workers == 1 or "fork" not in mp.get_all_start_methods():
            raw = _run_chunk(token, items)
        else:
            size = chunksize or max(1, -(-len(items) // (4 * workers)))
            ctx = mp.get_context("fork")
            with cf.ProcessPoolExecutor(workers, mp_context=ctx) as ex:
                futures = [ex.submit(_run_chunk, token, c) for c in _chunks(items, size)]
                raw = [r for f in futures for r in f.result()]
    finally:
        del _JOBS[token]
    return _assemble(cm, sets, raw, reduce, errors)


def _assemble(cm, sets, raw, reduce, errors):
    from .result import Result
    out = [None] * len(sets)
    first = None
    for status, index, value in sorted(raw, key=lambda r: r[1]):
        if status == "ok":
            out[index] = value if reduce else Result(cm, **value)
            continue
        kind, msg = value
        err = BatchItemError(f"parameter set {index} ({sets[index]}): {kind}: {msg}",
                             index=index, params=sets[index], kind=kind)
        out[index] = err
        first = first or err
    if first is not None and errors == "raise":
        raise first
    return out
