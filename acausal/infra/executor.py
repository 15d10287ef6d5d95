"""One small executor abstraction for embarrassingly parallel work.

Used by parameter sweeps (:mod:`acausal.sweep`) and, later, by parallel
model-diagnosis fits. Every backend is driven through the same three calls::

    with open_executor() as ex:                 # local process pool
        futures = [ex.submit(task, p) for p in points]
        for fut in ex.as_completed(futures):
            fut.result()

Backends, chosen by ``scheduler``:

* ``None`` or ``"processes"`` -- a local :class:`~concurrent.futures.ProcessPoolExecutor`
  (``workers`` defaults to the CPUs this process may use).
* ``"serial"`` -- in-process, one task at a time, run lazily when its future is
  waited on (by ``as_completed`` or ``result()``); handy for debugging and tests.
* an address such as ``"tcp://127.0.0.1:8786"`` -- a Dask ``distributed.Client``.
* an existing ``distributed.Client`` or cluster (e.g. ``LocalCluster``) object.
* an existing :class:`concurrent.futures.Executor`.

Dask is imported only when asked for (install it with ``pip install acausal[dask]``).

Tasks that run in worker processes must be picklable: a module-level function
or a :func:`functools.partial` of one. Expensive per-process set-up (loading and
compiling a model) belongs in :func:`worker_cache`, which keeps one value per key
per process, so a compiled model is reused by every task that lands on that worker.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import ctypes
import functools
import os
import re
import signal
import sys
import threading
import time
from collections.abc import Callable, Hashable, Iterable, Iterator
from typing import Any
from ..errors import UsageError

__all__ = ["Executor", "open_executor", "worker_cache", "clear_worker_cache", "terminate_on_sigterm"]

_ADDRESS = re.compile(r"^([a-z][a-z0-9+.-]*://\S+|[\w.-]+:\d+)$", re.IGNORECASE)

# ---------------------------------------------------------------------------
# Per-process cache (the only module-level mutable state, by design)
# ---------------------------------------------------------------------------

_CACHE: dict[Hashable, Any] = {}
_CACHE_STATE = {"pid": None, "lock": None, "key_locks": {}}


def _cache_locks() -> tuple[threading.Lock, dict]:
    """Return the cache locks, recreating them in a freshly forked child.

    A lock copied by ``fork`` while another parent thread held it would stay
    locked forever in the child, so locks are per pid. Cached values are kept
    across ``fork`` (the child's copy is independent).
    """
    if _CACHE_STATE["pid"] != os.getpid():
        _CACHE_STATE.update(pid=os.getpid(), lock=threading.Lock(), key_locks={})
    return _CACHE_STATE["lock"], _CACHE_STATE["key_locks"]


def worker_cache(key: Hashable, factory: Callable[[], Any]) -> Any:
    """Return the value cached under ``key`` in this process, building it once.

    ``factory()`` is called the first time ``key`` is asked for in a process;
    later calls in the same process (later sweep points that land on the same
    worker) get the same object back. Typical use inside a task::

        def simulate_point(point, model_path):
            model = worker_cache(("model", model_path), lambda: compile_model(model_path))
            return model.run(point)

    Notes:

    * The cache is per process: each pool worker or Dask worker process builds
      its own value; Dask threads in one process share it. Thread-safe: for a
      given key, ``factory`` runs once even under concurrent callers.
    * The key should identify everything the value depends on (e.g. the model
      path *and* a content hash or mtime if the file may change between runs).
    * If ``factory`` raises, nothing is cached and the error propagates.
    * Entries live until the process ends or :func:`clear_worker_cache` is called.
    """
    lock, key_locks = _cache_locks()
    with lock:
        if key in _CACHE:
            return _CACHE[key]
        key_lock = key_locks.setdefault(key, threading.Lock())
    with key_lock:
        with lock:
            if key in _CACHE:
                return _CACHE[key]
        value = factory()
        with lock:
            _CACHE[key] = value
            key_locks.pop(key, None)
        return value


def clear_worker_cache() -> None:
    """Forget every value cached by :func:`worker_cache` in this process."""
    lock, _ = _cache_locks()
    with lock:
        _CACHE.clear()


# ---------------------------------------------------------------------------
# Executor wrapper
# ---------------------------------------------------------------------------


class _DeferredFuture(cf.Future):
    """A future whose call runs in the calling thread when first waited on."""

    def __init__(self, fn: Callable, args: tuple, kw: dict):
        super().__init__()
        self._call = functools.partial(fn, *args, **kw)

    def run(self) -> None:
        """Run the call now (once); Exceptions are stored, others propagate."""
        if not self.set_running_or_notify_cancel():
            return
        try:
            result = self._call()
        except Exception as exc:
            self.set_exception(exc)
        except BaseException as exc:  # KeyboardInterrupt etc.: store, then propagate
            self.set_exception(exc)
            raise
        else:
            self.set_result(result)
        finally:
            self._call = None

    def result(self, timeout=None):  # noqa: D102 - same as Future.result
        if not self.done():
            self.run()
        return super().result(timeout)

    def exception(self, timeout=None):  # noqa: D102 - same as Future.exception
        if not self.done():
            self.run()
        return super().exception(timeout)


class Executor:
    """Uniform ``submit`` / ``as_completed`` / ``cancel`` over one backend.

    Obtain one with :func:`open_executor`. Attributes: ``kind`` (``"serial"``,
    ``"processes"``, ``"dask"`` or ``"executor"``), ``workers`` (int, or None when
    unknown) and ``needs_pickle`` (tasks cross a process boundary via pickle).
    """

    def __init__(self, kind: str, backend: Any = None, workers: int | None = None):
        self.kind = kind
        self.workers = workers
        self._backend = backend

    @property
    def needs_pickle(self) -> bool:
        """True if tasks are sent to other processes with the stdlib pickle."""
        return isinstance(self._backend, cf.ProcessPoolExecutor)

    def submit(self, fn: Callable, *args: Any, **kw: Any):
        """Schedule ``fn(*args, **kw)`` and return a future.

        The future has ``result()``, ``exception()``, ``done()`` and ``cancel()``.
        """
        if self.kind == "serial":
            return _DeferredFuture(fn, args, kw)
        if self.kind == "dask":
            # Bind everything into one callable: no clash with Client.submit's own
            # keywords (key, workers, retries, ...); pure=False gives every call its
            # own key, so repeated identical calls are really repeated.
            return self._backend.submit(functools.partial(fn, *args, **kw), pure=False)
        return self._backend.submit(fn, *args, **kw)

    def as_completed(self, futures: Iterable) -> Iterator:
        """Yield ``futures`` as they finish (serial: in submission order)."""
        futures = list(futures)
        if self.kind == "serial":
            return self._serial_as_completed(futures)
        if self.kind == "dask":
            import distributed

            return iter(distributed.as_completed(futures))
        return cf.as_completed(futures)

    def wait_any(self, futures: Iterable) -> list:
        """Block until at least one of ``futures`` is done; return the done
        ones (serial: runs the first not yet run)."""
        futures = list(futures)
        if self.kind == "serial":
            for fut in futures:
                if isinstance(fut, _DeferredFuture) and not fut.done():
                    fut.run()
                    break
            return [f for f in futures if f.done()]
        if self.kind == "dask":
            import distributed

            done, _ = distributed.wait(futures, return_when="FIRST_COMPLETED")
            return list(done)
        done, _ = cf.wait(futures, return_when=cf.FIRST_COMPLETED)
        return list(done)

    @staticmethod
    def _serial_as_completed(futures: list) -> Iterator:
        for fut in futures:
            if isinstance(fut, _DeferredFuture) and not fut.done():
                fut.run()
            yield fut

    def cancel(self, futures: Iterable) -> None:
        """Cancel futures that have not started (running ones may finish)."""
        futures = list(futures)
        if self.kind == "dask":
            self._backend.cancel(futures)
            return
        for fut in futures:
            fut.cancel()

    def __repr__(self) -> str:
        return f"Executor(kind={self.kind!r}, workers={self.workers!r})"


def default_workers() -> int:
    """CPUs this process may run on (affinity-aware ``os.cpu_count()``)."""
    if hasattr(os, "process_cpu_count"):  # Python >= 3.13
        return os.process_cpu_count() or 1
    if hasattr(os, "sched_getaffinity"):
        return len(os.sched_getaffinity(0)) or 1
    return os.cpu_count() or 1


def _import_distributed():
    """Import ``distributed`` or fail with an install hint."""
    try:
        import distributed
    except ImportError as exc:
        raise UsageError(
            "A Dask scheduler was requested but dask.distributed is not installed; "
            "install it with: pip install 'acausal[dask]'"
        ) from exc
    return distributed


def _is_dask_object(obj: Any) -> bool:
    """True for objects from the ``distributed`` package (without importing it)."""
    return type(obj).__module__.split(".")[0] == "distributed"


# ---------------------------------------------------------------------------
# Workers die with their parent
# ---------------------------------------------------------------------------

WATCH_S = 0.5  # how often a worker checks that its parent is alive [s]
_PR_SET_PDEATHSIG = 1  # from <linux/prctl.h>


def _die_with_parent(parent: int) -> None:
    """Pool-worker initializer: end this process when its parent ends.

    On Linux the kernel sends SIGKILL when the parent dies
    (``prctl(PR_SET_PDEATHSIG)``, through ctypes); everywhere, a daemon
    thread checks every ``WATCH_S`` seconds that the parent is still the
    parent (an orphan is re-parented) and ends the worker if not. So a
    sweep or diagnosis killed by SIGKILL leaves no worker computing on.
    """
    # The command's process handles the interruption: a worker ignores
    # Ctrl-C (the terminal sends it to the whole process group) and ends at
    # once, quietly, on SIGTERM (the parent's handler, inherited through
    # fork, printed two worker tracebacks on a killed sweep)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    import warnings
    warnings.simplefilter("ignore")   # numpy/scipy warnings: not a wall on the terminal
    from .signals import STOP_SIGNALS
    for name in (n for n in STOP_SIGNALS if n not in ("SIGINT", "SIGTERM")):   # as SIGTERM
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), signal.SIG_DFL)
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(_PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        except (OSError, AttributeError):  # no prctl: the watchdog alone
            pass
    if os.getppid() != parent:  # the parent died before prctl took effect
        os._exit(1)
    threading.Thread(target=_watch_parent, args=(parent,), daemon=True,
                     name="acausal-parent-watchdog").start()


def _watch_parent(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(WATCH_S)
    os._exit(1)


def _terminate_workers(pool: cf.ProcessPoolExecutor) -> None:
    """Stop the pool's workers now, running tasks included (after an
    interruption: their results would be thrown away anyway)."""
    if hasattr(pool, "terminate_workers"):  # Python >= 3.14
        pool.terminate_workers()
        return
    # Before 3.14 the pool does not expose its processes: this module is the
    # one place that reaches into concurrent.futures' private state.
    procs = list((getattr(pool, "_processes", None) or {}).values())
    pool.shutdown(wait=False, cancel_futures=True)
    for proc in procs:
        if proc.is_alive():
            proc.terminate()
    for proc in procs:
        proc.join(timeout=5.0)


def _quiet_broken_pool() -> None:
    """Before 3.12 the pool's manager thread, finding its workers gone,
    sets an exception on every pending future, cancelled ones included, and
    dies of InvalidStateError (a thread traceback on the terminal of a large
    sweep ended by SIGTERM: 'CANCELLED: <Future ...>'). That error, in that
    thread, is expected here and not printed; every other thread error is."""
    if getattr(threading.excepthook, "_acausal", False):
        return
    previous = threading.excepthook

    def hook(args):
        if isinstance(args.exc_value, cf.InvalidStateError) and \
                type(args.thread).__name__ == "_ExecutorManagerThread":
            return
        previous(args)
    hook._acausal = True
    threading.excepthook = hook


def _quiet_exit_wakeup(pool: cf.ProcessPoolExecutor) -> None:
    """A signal while the pool starts its workers can leave the pipe that
    wakes its manager thread closed underneath it; at exit the interpreter
    wakes that thread once more and printed 'Exception ignored ... OSError:
    [Errno 9] Bad file descriptor' with a traceback (2 sweeps in 20 given
    SIGTERM 1.6-1.8 s after their start). That last wake-up of a pool already
    stopped may fail quietly. (Private state of concurrent.futures, as in
    :func:`_terminate_workers`.)"""
    wake = getattr(pool, "_executor_manager_thread_wakeup", None)
    if wake is None or not hasattr(wake, "wakeup"):
        return
    real = wake.wakeup

    def wakeup():
        try:
            real()
        except OSError:
            pass
    wake.wakeup = wakeup


@contextlib.contextmanager
def _process_pool(workers: int | None):
    """A local pool whose workers die with this process (see
    :func:`_die_with_parent`); on an exception (an interruption, SIGTERM
    turned into one by the CLI) the workers are terminated, not waited for."""
    n = default_workers() if workers is None else workers
    _quiet_broken_pool()     # (before the workers can die: a group's SIGTERM reaches them first)
    pool = cf.ProcessPoolExecutor(max_workers=n, initializer=_die_with_parent,
                                  initargs=(os.getpid(),))
    _quiet_exit_wakeup(pool)
    try:
        yield Executor("processes", pool, n)
    except BaseException:
        _terminate_workers(pool)
        raise
    else:
        # Pending tasks are dropped; running ones finish (at most one per worker).
        pool.shutdown(wait=True, cancel_futures=True)


@contextlib.contextmanager
def terminate_on_sigterm():
    """Turn SIGTERM into :class:`KeyboardInterrupt` in the main thread while
    the block runs, so that a killed command unwinds: its process pool is
    terminated and its finished work saved (restores the old handler)."""
    if threading.current_thread() is not threading.main_thread():
        yield
        return

    def handler(signum, frame):
        exit_soon()   # whatever the unwinding meets, the process ends
        _PENDING["signal"] = signum
        if _swallowing(frame):
            return    # raised at the caller's next check (:func:`check_interrupted`)
        raise KeyboardInterrupt(f"terminated by signal {signum}")

    from .signals import STOP_SIGNALS
    names = [n for n in STOP_SIGNALS if n != "SIGINT" and hasattr(signal, n)]
    old = {n: signal.signal(getattr(signal, n), handler) for n in names}
    _PENDING["signal"] = None
    try:
        yield
    finally:
        _PENDING["signal"] = None
        for n, h in old.items():
            signal.signal(getattr(signal, n), h)


DASK_CONNECT_S = 20.0  # a Dask scheduler that does not answer within this is refused
EXIT_GRACE_S = 20.0   # an interrupted command has this long to save its work and end
EXIT_SOON = True      # False where commands run inside another program (the tests' CliRunner)


def exit_soon(code: int = 130, grace: float = EXIT_GRACE_S) -> None:
    """After an interruption: end this process ``grace`` seconds from now
    if it has not ended by then (a cleanup that blocks, an interpreter
    shutdown joining a stuck thread, a C call that does not return), with
    ``code``; its pool workers follow it (:func:`_die_with_parent`). A
    later call can only bring the deadline closer. (A diagnosis stopped by
    SIGTERM printed 'interrupted' and went on computing.)"""
    if not EXIT_SOON:
        return
    deadline = time.monotonic() + grace
    if _EXITING["deadline"] is not None:
        _EXITING["deadline"] = min(_EXITING["deadline"], deadline)
        return
    _EXITING["deadline"], _EXITING["code"] = deadline, code

    def later():
        while time.monotonic() < _EXITING["deadline"]:
            time.sleep(0.05)
        try:
            sys.stderr.write(f"acausal: the command did not end within {grace:g} s of its "
                             "interruption: ended\n")
            sys.stderr.flush()
        finally:
            from .descendants import end
            end(grace=1.0)     # os._exit skips atexit: the model file's processes too
            os._exit(_EXITING["code"])
    threading.Thread(target=later, daemon=True, name="acausal-exit-soon").start()


_EXITING = {"deadline": None, "code": 130}
_PENDING = {"signal": None}   # a stop signal whose KeyboardInterrupt may have been lost
# code where Python reports an exception and goes on ('Exception ignored'):
# the interpreter's at-fork hooks of logging, run while a pool forks its workers
_SWALLOWING = (os.path.join("logging", "__init__.py"),)


def _swallowing(frame) -> bool:
    """Whether a KeyboardInterrupt raised in ``frame`` would be printed and
    dropped (a SIGTERM while a sweep's pool forked its workers: 'Exception
    ignored in _releaseLock', then the sweep ran on until the 20 s hard
    exit)."""
    f = frame
    while f is not None:
        if f.f_code.co_filename.endswith(_SWALLOWING):
            return True
        f = f.f_back
    return False


def check_interrupted() -> None:
    """Raise the KeyboardInterrupt of a stop signal that arrived where it
    could not be raised (see :func:`terminate_on_sigterm`); a loop that
    waits on workers calls this between waits."""
    sig = _PENDING["signal"]
    if sig is not None:
        _PENDING["signal"] = None
        raise KeyboardInterrupt(f"terminated by signal {sig}")


def exit_no_sooner(grace: float) -> None:
    """Move a pending :func:`exit_soon` deadline to at least ``grace``
    seconds from now: for bounded work sized in advance that keeps what was
    computed (an interrupted run's rows being written: 5.4 M rows took
    about 120 s, the whole first grace). No pending deadline: nothing."""
    if _EXITING["deadline"] is not None:
        _EXITING["deadline"] = max(_EXITING["deadline"], time.monotonic() + grace)


@contextlib.contextmanager
def _dask_client(scheduler: Any):
    distributed = _import_distributed()
    if isinstance(scheduler, distributed.Client):
        client, owned = scheduler, False  # caller's client: leave it open
    elif isinstance(scheduler, (str, distributed.deploy.Cluster)):
        try:
            client, owned = distributed.Client(scheduler, timeout=DASK_CONNECT_S), True
        except (OSError, TimeoutError) as exc:
            raise UsageError(f"cannot reach the Dask scheduler {scheduler!r} within "
                             f"{DASK_CONNECT_S:g} s: {' '.join(str(exc).split())[:200]}"
                             ) from None
    else:
        raise TypeError(f"unsupported Dask object of type {type(scheduler).__name__}")
    try:
        n = len(client.scheduler_info().get("workers", {})) or None
        yield Executor("dask", client, n)
    finally:
        if owned:
            client.close()


def open_executor(scheduler: Any = None, workers: int | None = None):
    """Open an executor; use as ``with open_executor(...) as ex:``.

    Args:
        scheduler: ``None`` or ``"processes"`` (local process pool), ``"serial"``
            (in-process), a Dask scheduler address (``"tcp://host:8786"``), a
            ``distributed.Client``, a Dask cluster object (``LocalCluster`` ...),
            or a ``concurrent.futures.Executor``. Objects passed in are not shut
            down on exit (a Client created for a cluster object is closed).
        workers: number of processes for the local pool (default: the CPUs this
            process may use). Meaningless, and rejected, for other schedulers.

    Returns:
        A context manager yielding an :class:`Executor`.
    """
    if workers is not None:
        if scheduler not in (None, "processes"):
            raise UsageError(f"workers= applies only to the local process pool, not to {scheduler!r}")
        if isinstance(workers, bool) or not isinstance(workers, int) or workers < 1:
            raise UsageError(f"workers must be an integer >= 1, got {workers!r}")
    if scheduler is None or scheduler == "processes":
        return _process_pool(workers)
    if scheduler == "serial":
        return contextlib.nullcontext(Executor("serial", None, 1))
    if isinstance(scheduler, str):
        if not _ADDRESS.match(scheduler):
            raise UsageError(
                f"unknown scheduler {scheduler!r}: expected None, 'processes', 'serial' "
                "or a Dask scheduler address such as 'tcp://127.0.0.1:8786'"
            )
        return _dask_client(scheduler)
    if _is_dask_object(scheduler):
        return _dask_client(scheduler)
    if isinstance(scheduler, cf.Executor):
        n = getattr(scheduler, "_max_workers", None)
        return contextlib.nullcontext(Executor("executor", scheduler, n))
    raise TypeError(f"unsupported scheduler object of type {type(scheduler).__name__}")
