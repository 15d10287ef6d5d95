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

SIGKILL (or ``os._exit``, a crash) runs none of that; for those a watchdog
(:func:`watch`), a small process forked first thing (before any thread is
started), records the command's descendants every :data:`POLL_S` seconds,
each by pid and start time, and learns of the command's end at once
(``prctl(PR_SET_PDEATHSIG)``; its parent pid changing, else). It then ends
those of them still alive (SIGTERM, then SIGKILL after :data:`WATCH_GRACE_S`),
never a pid since given to another process, and never a process group:
the command may share its group with a shell or a test harness. It ignores
the stop signals (in its own process group, it outlives a group kill to
clean up after it), holds none of the command's files, and ends itself as
soon as its work is done. A process started and orphaned in the last
:data:`POLL_S` seconds before a SIGKILL can escape it.

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
POLL_S = 0.1    # the watchdog reads the command's descendants this often
WATCH_GRACE_S = 1.0   # after the command was killed, its leftovers' grace
WATCHDOG_NAME = b"acausal-watch"   # its name in ps (comm)
_PR_SET_NAME = 15
_PR_SET_PDEATHSIG = 1
_WATCHDOG = {"pid": None}


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
    return [p for p in out if p != _WATCHDOG["pid"] and not _spared(p)]


def _spared(pid):
    return any(s in _cmdline(pid) for s in _SPARED)


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


# ---------------------------------------------------------------------------
# The watchdog: the command's descendants ended even when it is SIGKILLed
# ---------------------------------------------------------------------------

def watchdog_pid():
    """The pid of this command's watchdog (None: there is none)."""
    return _WATCHDOG["pid"]


def watch(poll=POLL_S):
    """Fork the watchdog (Linux with /proc; call before any thread starts:
    the child runs Python code, not a new program). Never raises."""
    if not os.path.isdir("/proc/self") or not hasattr(os, "fork"):
        return
    parent = os.getpid()
    try:
        pid = os.fork()
    except OSError:
        return
    if pid:
        _WATCHDOG["pid"] = pid
        return
    code = 0
    try:    # the child: never back into the command's code
        _watchdog(parent, poll)
    except BaseException:   # noqa: BLE001 - nothing may escape into a second command
        code = 1
    os._exit(code)


def _detach():
    """The watchdog holds none of the command's files (a harness reading the
    command's output waits for every holder of its pipe) and ignores the
    stop signals; in a process group of its own (never the command's, a
    terminal's Ctrl-C is for the command) it outlives a group kill."""
    null = os.open(os.devnull, os.O_RDWR)
    for fd in (0, 1, 2):
        os.dup2(null, fd)
    for name in os.listdir("/proc/self/fd"):
        fd = int(name)
        if fd > 2:
            try:
                os.close(fd)
            except OSError:
                pass
    for name in ("SIGINT", "SIGTERM", "SIGHUP", "SIGUSR1", "SIGXCPU", "SIGPIPE", "SIGQUIT",
                 "SIGTSTP", "SIGTTIN", "SIGTTOU"):
        sig = getattr(signal, name, None)
        if sig is not None:
            signal.signal(sig, signal.SIG_IGN)
    try:
        os.setpgid(0, 0)
    except OSError:
        pass


def _watchdog(parent, poll):
    """Record ``parent``'s descendants until it ends, then end them."""
    _detach()
    wake = signal.SIGUSR2
    signal.pthread_sigmask(signal.SIG_BLOCK, [wake])
    try:
        import ctypes
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(_PR_SET_NAME, ctypes.c_char_p(WATCHDOG_NAME), 0, 0, 0)
        libc.prctl(_PR_SET_PDEATHSIG, int(wake), 0, 0, 0)
    except (OSError, AttributeError):
        pass    # no prctl: the parent pid, read every poll, tells
    me = os.getpid()
    known = {}    # pid -> start time of every descendant seen
    while os.getppid() == parent:
        for pid in _tree(parent):
            if pid != me and pid not in known:
                start = _start_time(pid)
                if start is not None:
                    known[pid] = start
        if len(known) > 4096:     # forget the ended ones
            known = {p: s for p, s in known.items() if _start_time(p) == s}
        signal.sigtimedwait([wake], poll)
    _finish(known, me)


def _finish(known, me):
    """End the recorded processes still alive (same pid, same start time)
    and their own descendants: SIGTERM, then SIGKILL after the grace."""
    def alive():
        found = {p: s for p, s in known.items() if _start_time(p) == s}
        todo = list(found)
        while todo:     # their children born since the last poll
            for child in _tree(todo.pop(), deep=False):
                if child != me and child not in found:
                    start = _start_time(child)
                    if start is not None:
                        found[child] = start
                        todo.append(child)
        known.update(found)
        return [p for p in found if not _spared(p)]

    deadline = time.monotonic() + WATCH_GRACE_S
    sig = signal.SIGTERM
    told = set()
    while True:
        pids = alive()
        if not pids:
            return
        for pid in pids:
            if sig == signal.SIGKILL or pid not in told:
                _signal_if(pid, known[pid], sig)
                told.add(pid)
        if sig == signal.SIGKILL:
            return
        time.sleep(0.02)
        if time.monotonic() > deadline:
            sig = signal.SIGKILL


def _signal_if(pid, start, sig):
    """Signal ``pid`` unless it is no longer the process recorded."""
    if _start_time(pid) == start:
        _signal(pid, sig)


def _start_time(pid):
    """The start time of a living ``pid`` (clock ticks since boot), None if
    it has ended or is a zombie."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as f:
            stat = f.read()
    except OSError:
        return None
    fields = stat[stat.rfind(b")") + 2:].split()
    if len(fields) < 20 or fields[0] in (b"Z", b"X"):
        return None
    return int(fields[19])


def _kids(pid):
    """``pid``'s children, from /proc/PID/task/*/children."""
    out = []
    try:
        tasks = os.listdir(f"/proc/{pid}/task")
    except OSError:
        return out
    for tid in tasks:
        try:
            with open(f"/proc/{pid}/task/{tid}/children", "rb") as f:
                out += [int(x) for x in f.read().split()]
        except OSError:     # the thread ended meanwhile
            pass
    return out


def _tree(root, deep=True):
    """``root``'s living descendants (only its children if not ``deep``)."""
    if os.path.exists("/proc/self/task/%d/children" % os.getpid()):
        get = _kids
    else:   # a kernel without the children files: the whole /proc
        children = {}
        for pid, ppid in _parents().items():
            children.setdefault(ppid, []).append(pid)
        get = lambda p: children.get(p, [])   # noqa: E731
    out, todo = [], list(get(root))
    while todo:
        pid = todo.pop()
        out.append(pid)
        if deep:
            todo.extend(get(pid))
    return out
