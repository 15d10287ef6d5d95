"""Budgets of long commands: memory estimated before the work starts and
watched while it runs, wall time, and counts of work.

Every long command (``simulate``, ``calibrate``, ``sweep``, ``diagnose``,
``animate``) has a memory limit: ``--max-memory`` (``4GB``, ``512MB``...),
else the environment variable ``ACAUSAL_MAX_MEMORY``, else
:data:`DEFAULT_MAX_MEMORY` (never more than 80 % of the machine's memory).
Its need is estimated up front (for a sweep, points x bytes per point plus
each worker's output rows; for ``simulate``, rows x bytes per row) and a
command whose estimate exceeds the limit is refused with one line before
anything runs (:func:`check_estimate`). While it runs, a
:class:`Watchdog` thread reads the resident memory of the command and of
its worker processes every :data:`WATCH_S` seconds; past the limit (or past
``--max-wall``) it interrupts the command as Ctrl-C would, so that what was
computed is saved, and says which limit stopped it; a command that has not
ended :data:`executor.EXIT_GRACE_S` seconds later is ended.
"""
from __future__ import annotations

import _thread
import os
import re
import signal
import sys
import threading
import time

from ..errors import BudgetError, UsageError

GB = 1e9
DEFAULT_MAX_MEMORY = 4 * GB
WATCH_S = 0.25
PROCESS_BYTES = 250e6     # one Python process with the model compiled (measured 150-220 MB)

_SIZE = re.compile(r"^\s*([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)\s*([kKmMgGtT]?)(i?)[bB]?\s*$")


def parse_size(text, option="--max-memory") -> float:
    """``'4GB'``, ``'512MB'``, ``'2.5e9'``, ``'1GiB'`` as bytes; a UsageError
    naming ``option`` otherwise."""
    if isinstance(text, (int, float)):
        value = float(text)
    else:
        m = _SIZE.match(str(text))
        if m is None:
            raise UsageError(f"{option} {text!r}: expected a size such as 4GB, 512MB or 2e9 "
                             "(bytes)")
        base = 1024.0 if m.group(3) else 1000.0
        power = "kmgt".find(m.group(2).lower()) + 1 if m.group(2) else 0
        value = float(m.group(1)) * base ** power
    if not (value > 0 and value != float("inf")):
        raise UsageError(f"{option} {text!r}: must be a positive size")
    return value


def physical_memory() -> float | None:
    """Bytes of memory of this machine (None if unknown)."""
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):
        return None


def max_memory(given=None) -> float:
    """The command's memory limit in bytes: ``given`` (text or bytes), else
    ``$ACAUSAL_MAX_MEMORY``, else :data:`DEFAULT_MAX_MEMORY` capped at 80 %
    of the machine's memory."""
    if given is not None:
        return parse_size(given)
    env = os.environ.get("ACAUSAL_MAX_MEMORY")
    if env:
        return parse_size(env, "ACAUSAL_MAX_MEMORY")
    phys = physical_memory()
    return min(DEFAULT_MAX_MEMORY, 0.8 * phys) if phys else DEFAULT_MAX_MEMORY


def show(nbytes: float) -> str:
    """Bytes as '1.2 GB', '340 MB'."""
    for unit, f in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if nbytes >= f:
            return f"{nbytes / f:.3g} {unit}"
    return f"{nbytes:.0f} B"


def check_estimate(need: float, limit: float, what: str, advice: str) -> None:
    """Refuse ``what`` (a sentence) whose estimated memory ``need`` exceeds ``limit``."""
    if need > limit:
        raise BudgetError(f"{what} needs about {show(need)}, more than the memory limit "
                          f"{show(limit)}: {advice}, or raise the limit (--max-memory or "
                          "ACAUSAL_MAX_MEMORY)")


# ---------------------------------------------------------------------------
# Resident memory of this process and its descendants (Linux /proc)
# ---------------------------------------------------------------------------

_PAGE = os.sysconf("SC_PAGE_SIZE") if hasattr(os, "sysconf") else 4096


def _children(pid: int) -> list[int]:
    out = []
    try:
        for tid in os.listdir(f"/proc/{pid}/task"):
            with open(f"/proc/{pid}/task/{tid}/children") as f:
                out += [int(x) for x in f.read().split()]
    except OSError:
        pass
    return out


def _rss(pid: int) -> float:
    try:
        with open(f"/proc/{pid}/statm") as f:
            return int(f.read().split()[1]) * _PAGE
    except (OSError, ValueError, IndexError):
        return 0.0


def tree_rss(pid: int | None = None) -> float | None:
    """Resident bytes of process ``pid`` (default: this one) and all its
    descendants; None where /proc is not available."""
    pid = os.getpid() if pid is None else pid
    if not os.path.exists(f"/proc/{pid}/statm"):
        return None
    from .descendants import watchdog_pid
    total, todo, seen = 0.0, [pid], {watchdog_pid()}    # the watchdog is not the work
    while todo:
        p = todo.pop()
        if p in seen:
            continue
        seen.add(p)
        total += _rss(p)
        todo += _children(p)
    return total


# ---------------------------------------------------------------------------
# The watchdog
# ---------------------------------------------------------------------------


class Watchdog:
    """``with Watchdog(max_memory=..., max_wall=...) as wd:`` watches the
    command while the block runs; past a limit it sets ``wd.reason`` (one
    sentence) and interrupts the main thread as Ctrl-C does (the command's
    own handling saves its work), then ends the process if it has not ended
    within the grace period. ``wd.peak`` is the largest resident memory seen."""

    def __init__(self, max_memory: float | None = None, max_wall: float | None = None,
                 what: str = "the command"):
        self.max_memory, self.max_wall, self.what = max_memory, max_wall, what
        self.reason = None
        self.peak = 0.0
        self._stop = threading.Event()
        self._lock = threading.Lock()      # no trip once the block has ended
        self._t0 = time.monotonic()

    def __enter__(self):
        self._ignored = False
        if threading.current_thread() is threading.main_thread() and (
                self.max_memory or self.max_wall):
            if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
                # started in the background (`nohup cmd &`: the shell ignores SIGINT
                # for it), where neither a signal nor interrupt_main reaches Python:
                # the watchdog's stop would end in the hard exit, its rows lost
                signal.signal(signal.SIGINT, signal.default_int_handler)
                self._ignored = True
            threading.Thread(target=self._watch, daemon=True, name="acausal-watchdog").start()
        _LAST["reason"] = None
        return self

    def __exit__(self, *exc):
        with self._lock:
            self._stop.set()
        if self._ignored:
            signal.signal(signal.SIGINT, signal.SIG_IGN)
        return False

    def restart(self, max_wall=None):
        """Watch the wall time afresh from now, against ``max_wall`` (None:
        memory only), for the next part of the command."""
        self._t0, self.max_wall = time.monotonic(), max_wall

    def _watch(self):
        while not self._stop.wait(WATCH_S):
            rss = tree_rss()
            if rss is not None:
                self.peak = max(self.peak, rss)
            wall = time.monotonic() - self._t0
            if self.max_memory and rss is not None and rss > self.max_memory:
                self._trip(f"{self.what} used {show(rss)} of memory, more than the limit "
                           f"{show(self.max_memory)} (--max-memory)")
                return
            if self.max_wall and wall > self.max_wall:
                self._trip(f"{self.what} ran for {wall:.3g} s, more than the limit "
                           f"--max-wall {self.max_wall:g} s")
                return

    def _trip(self, reason):
        """Stop the command: Ctrl-C in its main thread, and its end armed
        (whatever it is doing then: executor.exit_soon); nothing once the
        watched block has ended (the signal would reach whatever runs next)."""
        with self._lock:
            if not self._stop.is_set():
                self._interrupt(reason)

    def _interrupt(self, reason):
        self.reason = _LAST["reason"] = reason
        if callable(signal.getsignal(signal.SIGINT)):
            # a real signal to the main thread, as Ctrl-C is: it also wakes a blocking
            # call (a model file that slept ignored interrupt_main until the grace ended)
            signal.pthread_kill(threading.main_thread().ident, signal.SIGINT)
        else:
            _thread.interrupt_main(signal.SIGINT)
        from .executor import exit_soon
        exit_soon(3)


_LAST = {"reason": None}


def tripped() -> str | None:
    """Why the last watchdog stopped the command (one sentence), or None."""
    return _LAST["reason"]


def stderr_line(text: str) -> None:
    sys.stderr.write(text.rstrip("\n") + "\n")
    sys.stderr.flush()
