"""No process outlives the command.

A model file is a Python script: it may start processes of its own
(``subprocess.Popen(["sleep", "300"])`` at import, a shell that puts a job in
the background and exits). Such a process went on running after the command
ended, normally or by a signal. The command (only the ``acausal`` process,
:func:`acausal.infra.startup.guard`) therefore

* becomes its descendants' subreaper on Linux
  (``prctl(PR_SET_CHILD_SUBREAPER)``): an orphan whose parent ended is
  re-parented to the command, not to init, so it stays among its
  descendants;
* ends every descendant still alive when it exits (:func:`end`: SIGTERM,
  then SIGKILL after a grace), from ``atexit`` (normal exit, an error, an
  interruption turned into exit 130) and before the hard exit of an
  interruption that did not unwind (:func:`acausal.infra.executor.exit_soon`).

Spared: Python's multiprocessing helpers (the resource tracker, the fork
server), which end by themselves when the command's end closes their pipe,
after releasing what they track (killing the tracker first would leak the
pool's semaphores). The process pool's workers and a local Dask cluster are
shut down by their own code before ``atexit`` reaches :func:`end`.
Descendants are read from ``/proc``; elsewhere nothing is done.
"""
import os
import signal
import time

_PR_SET_CHILD_SUBREAPER = 36   # from <linux/prctl.h>
_SPARED = ("multiprocessing.resource_tracker", "multiprocessing.forkserver")
GRACE_S = 2.0   # a descendant has this long to end after SIGTERM


def adopt():
    """Make this process its descendants' subreaper (Linux; else nothing)."""
    if not os.path.isdir("/proc/self"):
        return
    try:
        import ctypes
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0)
    except (OSError, AttributeError):
        pass


def _parents():
    """pid -> parent pid of every process ``/proc`` lists."""
    out = {}
    for name in os.listdir("/proc"):
        if not name.isdigit():
            continue
        try:
            with open(f"/proc/{name}/stat", "rb") as f:
                stat = f.read()
        except OSError:     # ended meanwhile
            continue
        # pid (comm) state ppid ...: comm may hold spaces and parentheses
        fields = stat[stat.rfind(b")") + 2:].split()
        if len(fields) > 1 and fields[0] != b"Z":
            out[int(name)] = int(fields[1])
    return out


def _cmdline(pid):
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            return f.read().replace(b"\0", b" ").decode(errors="replace")
    except OSError:
        return ""


def living(root=None):
    """The living descendants of ``root`` (default: this process), minus the
    spared multiprocessing helpers; [] where there is no ``/proc``."""
    if not os.path.isdir("/proc/self"):
        return []
    root = os.getpid() if root is None else root
    children = {}
    for pid, ppid in _parents().items():
        children.setdefault(ppid, []).append(pid)
    out, todo = [], list(children.get(root, []))
    while todo:
        pid = todo.pop()
        out.append(pid)
        todo.extend(children.get(pid, []))
    return [p for p in out if not any(s in _cmdline(p) for s in _SPARED)]


def _reap(pids):
    """Collect the exit status of those of ``pids`` that are this process's
    children (a killed child is a zombie until then)."""
    for pid in pids:
        try:
            os.waitpid(pid, os.WNOHANG)
        except (ChildProcessError, OSError):
            pass


def end(grace=GRACE_S):
    """End every living descendant: SIGTERM, then SIGKILL to those still
    alive after ``grace`` seconds. Never raises."""
    try:
        pids = living()
        if not pids:
            return
        for pid in pids:
            _signal(pid, signal.SIGTERM)
        deadline = time.monotonic() + grace
        while True:
            _reap(pids)
            alive = living()
            for pid in alive:
                if pid not in pids:    # an orphan adopted meanwhile
                    _signal(pid, signal.SIGTERM)
            pids = alive
            if not pids or time.monotonic() > deadline:
                break
            time.sleep(0.02)
        for pid in pids:
            _signal(pid, signal.SIGKILL)
        _reap(pids)
    except Exception:   # noqa: BLE001 - the command is ending: never a traceback from here
        pass


def _signal(pid, sig):
    try:
        os.kill(pid, sig)
    except OSError:
        pass
