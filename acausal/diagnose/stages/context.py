"""How the diagnosis's stages run: the :class:`Context` every stage takes
beside its state (``stage(ctx, state) -> state``): the executor the tasks
go to, whether progress bars are shown, the collector that keeps each
finished result (a checkpoint store), and the :class:`Clock` that records
the stages' wall times. The context holds no result: what a stage computes
goes into the state it returns."""
from __future__ import annotations

import contextlib
import itertools
import time
from dataclasses import dataclass, field
from typing import Callable


class Clock:
    """Wall times of the diagnosis: started at construction; ``times`` holds
    named durations [s] (:meth:`timing`) in the order they were recorded."""

    def __init__(self):
        self.t0 = time.perf_counter()
        self.times = {}

    def elapsed(self) -> float:
        """Seconds since the clock started."""
        return time.perf_counter() - self.t0

    @contextlib.contextmanager
    def timing(self, key: str):
        """Record the wall time of the ``with`` block under ``key`` (only when
        the block completes)."""
        t = time.perf_counter()
        yield
        self.times[key] = time.perf_counter() - t


@dataclass(frozen=True)
class Context:
    """What a stage runs with (module doc). ``executor``: an
    :mod:`acausal.infra.executor` executor (``submit``, ``as_completed``);
    ``progress``: show progress bars; ``collect(task, result)``: called as
    each checkpointed result arrives (:class:`.resume.FitStore`, whose
    ``get(task)`` also answers tasks finished in an earlier run), or None."""

    executor: object
    progress: bool = True
    collect: Callable | None = None
    clock: Clock = field(default_factory=Clock)

    def run(self, fn, tasks, desc, *, checkpoint=True, progress=None) -> list:
        """``fn(task)`` of each task on the executor, results in task order
        (:func:`run_tasks`); ``checkpoint``: pass the results to the
        collector (and take finished ones from it); ``progress``: None for
        the context's own setting."""
        show = self.progress if progress is None else progress
        return run_tasks(self.executor, fn, tasks, desc, show,
                         self.collect if checkpoint else None)


def run_tasks(ex, fn, tasks, desc, progress, collect=None):
    """Submit ``fn(task)`` for each task; results in task order. ``collect``
    (task, result) is called as each result arrives (a checkpoint store
    plugs in here: results depend only on their task); a ``collect`` with
    ``get(task)`` (:class:`.resume.FitStore`) also gives the results of
    tasks that finished in an earlier, interrupted run, which are not
    submitted again. Tasks are submitted longest first (:func:`longest_first`).
    When ``fn`` has an ``alone(task, executor)`` form (a fit whose
    Jacobians' simulations idle workers share: :func:`.tasks.fit_here`) and
    there are no more tasks than workers, the longest runs in this process
    that way while the workers run the others: the same results."""
    lookup = getattr(collect, "get", None)
    out = [lookup(t) if lookup is not None else None for t in tasks]
    todo = longest_first([i for i, r in enumerate(out) if r is None], tasks)
    alone = getattr(fn, "alone", None)
    workers = getattr(ex, "workers", None) or 1
    if not (alone is not None and 1 <= len(todo) <= workers
            and getattr(ex, "kind", "serial") != "serial" and workers > 1):
        alone = None
    # no more tasks than workers: the longest runs here and the workers the
    # others; a worker that is or falls idle runs the simulations of its
    # evaluations side by side (fn.alone, e.g. tasks.fit_here)
    here = todo[:1] if alone is not None else []
    futures = [ex.submit(fn, tasks[i]) for i in todo[len(here):]]
    index = {id(f): i for i, f in zip(todo[len(here):], futures)}
    bar = None
    if progress:
        from tqdm.auto import tqdm
        bar = tqdm(total=len(tasks), desc=desc, unit="fit", initial=len(tasks) - len(todo))
    try:
        done = itertools.chain(((i, alone(tasks[i], ex)) for i in here), (
            (index[id(fut)], fut.result()) for fut in ex.as_completed(futures)))
        for i, result in done:
            out[i] = result
            if collect is not None:
                collect(tasks[i], out[i])
            if bar is not None:
                bar.update(1)
    except BaseException:
        # stopped while a task ran here: what the workers finished is kept
        if collect is not None:
            for fut in futures:
                i = index[id(fut)]
                if out[i] is None and fut.done() and not fut.cancelled() \
                        and fut.exception() is None:
                    collect(tasks[i], fut.result())
        raise
    finally:
        if bar is not None:
            bar.close()
    return out


def longest_first(indices, tasks):
    """``indices`` of ``tasks`` ordered by decreasing expected cost (a task's
    ``cost`` attribute, 1 without one; ties keep their order): the pool
    hands tasks out in submission order, so the longest ones no longer
    start last and leave a worker idle at the end of a stage (Graham's
    longest-processing-time-first list scheduling)."""
    return sorted(indices, key=lambda i: -float(getattr(tasks[i], "cost", 1.0)))
