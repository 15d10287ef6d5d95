"""The command's first second: a signal while it is still importing.

``python -m acausal.cli`` and the ``acausal`` script spend about a second
importing numpy, scipy and sympy before the command's own handlers exist. A
Ctrl-C then printed a KeyboardInterrupt traceback from inside scipy, and a
SIGTERM or SIGHUP ended it silently (exit -15). :func:`guard` (called by
``acausal/__init__`` first thing, only in that process) makes such a signal
one line and exit 130; once the command starts (:func:`started`) a signal
interrupts as Ctrl-C does (KeyboardInterrupt: the command's one-line
'interrupted'), SIGTERM and SIGHUP included, with the process's end armed
(:func:`acausal.infra.executor.exit_soon`). Commands that save work install
their own handlers over these while they run. A signal the process was
started ignoring (``nohup``: SIGHUP) stays ignored. No process the command
started outlives it, even when it is SIGKILLed (:mod:`acausal.infra.descendants`).
"""
import os
import signal
import sys

from .signals import STOP_SIGNALS

_STATE = {"starting": False}


def is_command(argv=None, orig_argv=None) -> bool:
    """True when this process is the acausal command: the ``acausal``
    script, or ``python -m acausal.cli`` (``sys.orig_argv``: while the package
    is imported, ``sys.argv[0]`` is only '-m')."""
    argv = sys.argv if argv is None else argv
    orig = getattr(sys, "orig_argv", None) if orig_argv is None else orig_argv
    if argv and os.path.basename(str(argv[0])) == "acausal":
        return True
    orig = list(orig or [])
    return any(a == "-m" and b in ("acausal.cli", "acausal") for a, b in zip(orig, orig[1:]))


def _handler(signum, frame):
    name = signal.Signals(signum).name
    if _STATE["starting"]:
        os.write(2, f"acausal: interrupted ({name}) while starting: nothing done\n".encode())
        os._exit(130)
    if signum != signal.SIGINT:
        try:
            from .executor import exit_soon
        except ImportError:
            # the signal came while executor itself was being imported (a
            # sweep's first seconds): its half-made module has no exit_soon,
            # and the ImportError was a traceback; the process ends anyway
            import threading
            timer = threading.Timer(20.0, os._exit, (130,))
            timer.daemon = True
            timer.start()
        else:
            exit_soon(130)      # whatever the unwinding meets, the process ends
    raise KeyboardInterrupt(name)


def guard() -> None:
    """Install the handlers (where a signal has its default action); make
    the command end its model file's own processes when it ends
    (:mod:`acausal.infra.descendants`)."""
    import atexit
    from . import descendants
    descendants.adopt()
    descendants.watch()    # before any thread: it forks
    if hasattr(os, "register_at_fork"):
        os.register_at_fork(after_in_child=_child_defaults)
    atexit.register(_ignore_stop_signals)   # registered first: runs last
    atexit.register(descendants.end)       # ... after this one
    defaults = {"SIGINT": signal.default_int_handler}
    _STATE["starting"] = True
    for name in STOP_SIGNALS:
        sig = getattr(signal, name, None)
        if sig is None:
            continue
        if signal.getsignal(sig) == defaults.get(name, signal.SIG_DFL):
            signal.signal(sig, _handler)


def started() -> None:
    """The imports are over: from now on a signal interrupts the command."""
    _STATE["starting"] = False


def finishing() -> None:
    """The command's work is over (its results written or its error said):
    from now on a stop signal is one line and changes nothing; the process
    ends as it was ending, its descendants ended
    (:mod:`acausal.infra.descendants`). A SIGTERM then raised a
    KeyboardInterrupt inside an atexit function (a traceback); one landing
    after the interpreter had put back the default handlers killed it with
    no word (exit 143, seen in ``fmu``): the last atexit function has the
    stop signals ignored from then on (:func:`_ignore_stop_signals`)."""
    for name in STOP_SIGNALS:
        sig = getattr(signal, name, None)
        if sig is not None and signal.getsignal(sig) is _handler:
            signal.signal(sig, _late)


def _late(signum, frame):
    name = signal.Signals(signum).name
    try:
        os.write(2, f"acausal: {name} while the command was ending, its work done: its "
                    "results are kept\n".encode())
    except OSError:
        pass
    try:
        from .executor import exit_soon
        exit_soon(130)    # whatever the end is waiting for, the process ends
    except Exception:     # noqa: BLE001 - never a traceback at the command's end
        pass


def _child_defaults() -> None:
    """A process forked by the command (a model file's multiprocessing pool)
    does not inherit the command's stop handlers: they raised
    KeyboardInterrupt in it, and ending such a process (the command's end,
    its watchdog) printed its traceback on the command's stderr. It ends
    as a plain process does; one that wants handlers sets its own (the
    command's own pool workers do)."""
    for name in STOP_SIGNALS:
        sig = getattr(signal, name, None)
        try:
            if sig is not None and callable(signal.getsignal(sig)):
                signal.signal(sig, signal.SIG_DFL)
        except (OSError, ValueError):
            pass


def _ignore_stop_signals() -> None:
    """The command's last act before the interpreter's own end: the stop
    signals are ignored (for the whole process: blocking them in one thread
    leaves them to the others, numpy's among them), instead of killing it
    silently once Python has put back their default action (it leaves an
    ignored signal ignored)."""
    for name in STOP_SIGNALS:
        try:
            signal.signal(getattr(signal, name), signal.SIG_IGN)
        except (OSError, ValueError, AttributeError):
            pass
