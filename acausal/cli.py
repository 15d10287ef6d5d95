"""The ``acausal`` command: simulate, animate, variables, linearize, calibrate, sweep,
tolerance, diagnose, fmu.

Exit codes: 0 success, 2 a model or input error (an AcausalError, a bad
option value, a budget that refuses the work before it starts: one readable
line on stderr), 3 a solver failure or a run stopped by a limit (time and
component named; the partial result is written), 130 an interruption
(Ctrl-C, SIGTERM: the partial result is written). Any other exception is a
bug: it is not caught, so Python shows its traceback and exits with 1.

Every option value is checked before anything runs (:class:`_Number`,
:func:`_check_output`); library warnings (numpy, scipy) do not reach the
terminal: a command that succeeds ends with one line counting them
(:func:`_quiet_warnings`), and values far from the model's defaults or
declared ranges get one warning line each.
"""
import contextlib
from dataclasses import dataclass
import json
import errno
import math
import os
import signal
import sys
import time
import warnings

import click
import numpy as np

from .errors import AcausalError, Interrupted, LimitError, SolverError, UsageError


def _fail(exc):
    if isinstance(exc, Interrupted):
        code = 130
    elif isinstance(exc, (UsageError, click.BadParameter)):
        code = 2
    else:
        code = 3 if isinstance(exc, SolverError) else 2
    click.echo(f"acausal: error: {_one_line(str(exc))}", err=True)
    sys.exit(code)


def _one_line(text):
    return " ".join(str(text).split())


def _warn(text):
    click.echo(f"acausal: warning: {_one_line(text)}", err=True)


# errors of a write to standard output: a closed pipe (| head), a full device
_STDOUT_ERRNOS = (errno.EPIPE, errno.ENOSPC, errno.EIO, errno.EBADF)


class _ReaderGone(Exception):
    """Standard output's reader went away (``acausal variables m | head -1``)."""


SIGPIPE_EXIT = 128 + 13


def _reader_gone() -> bool:
    """Whether standard output is a pipe whose reader has closed it."""
    try:
        import select
        poll = select.poll()
        poll.register(1, select.POLLOUT)
        return any(ev & select.POLLERR for _, ev in poll.poll(0))
    except (OSError, ValueError, AttributeError):
        return False


def _drop_stdout():
    """Point standard output at /dev/null, so that the interpreter's own
    flush at exit does not fail again with a second message."""
    try:
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, sys.stdout.fileno())
        os.close(null)
    except (OSError, ValueError, AttributeError):
        pass


THREAD_GRACE_S = 1.0   # a model file's thread has this long to end with the command


def _end_past_model_threads(code):
    """End the command even if a thread a model file started is still
    running: Python waits at exit for every non-daemon thread, so a file
    with a ``threading.Thread(target=time.sleep, args=(300,))`` made the
    command hang after its results (and a SIGTERM then gave a traceback
    from the interpreter's shutdown). Such a thread gets a grace of
    ``THREAD_GRACE_S``, then one line, and the process ends with ``code``
    (its descendants first). Only in the command's own process."""
    from .infra import startup
    if not startup.is_command() or "acausal.modelfile" not in sys.modules:
        return
    from .modelfile import STARTED_THREADS
    deadline = time.monotonic() + THREAD_GRACE_S
    for t in STARTED_THREADS:
        t.join(max(deadline - time.monotonic(), 0.0))
    left = [t for t in STARTED_THREADS if t.is_alive()]
    if not left:
        return
    _warn(f"{len(left)} thread(s) the model file started still run(s) at the end "
          f"({left[0].name}): not waited for")
    from .infra.descendants import end
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except (OSError, ValueError, AttributeError):
            pass
    end()
    code = code if isinstance(code, int) else (0 if code is None else 1)
    os._exit(code)


class _Group(click.Group):
    """The command group, whose usage errors (an unknown option, a value of
    the wrong type) are one line, like every other error: ``acausal
    simulate: error: Invalid value for '--t-end': ...`` (exit 2)."""

    def main(self, args=None, prog_name=None, complete_var=None, standalone_mode=True,
             **extra):
        if not standalone_mode:
            return super().main(args, prog_name, complete_var, standalone_mode, **extra)
        from .infra import startup
        startup.started()
        if sys.stdout is None:      # started with stdout closed (>&-): the output is dropped
            sys.stdout = open(os.devnull, "w")
        try:
            self._main(args, prog_name, complete_var, **extra)
        except (_ReaderGone, BrokenPipeError) as exc:
            # the reader of the output has had enough (| head): quiet, as a Unix
            # tool killed by SIGPIPE is, with its status 141 (a pipeline under
            # `set -o pipefail` sees that not all the output was read)
            if isinstance(exc, BrokenPipeError) and not _reader_gone():
                raise
            _drop_stdout()
            startup.finishing()
            _end_past_model_threads(SIGPIPE_EXIT)
            sys.exit(SIGPIPE_EXIT)
        except OSError as exc:
            if exc.errno not in _STDOUT_ERRNOS:
                raise
            _drop_stdout()
            click.echo(f"acausal: error: the output could not be written to standard output: "
                       f"{exc.strerror or exc}", err=True)
            startup.finishing()
            _end_past_model_threads(2)
            sys.exit(2)
        except SystemExit as exc:
            startup.finishing()
            _end_past_model_threads(exc.code)
            raise
        startup.finishing()
        _end_past_model_threads(0)

    def invoke(self, ctx):
        try:
            return super().invoke(ctx)
        except BrokenPipeError:
            if _reader_gone():     # (click would swallow it, and exit 1)
                raise _ReaderGone() from None
            raise

    def _main(self, args, prog_name, complete_var, **extra):
        try:
            return super().main(args, prog_name, complete_var, standalone_mode=False, **extra)
        except AcausalError as exc:
            # one that a command let through (ACAUSAL_MAX_MEMORY=lots, read before
            # simulate's own catch, was a traceback): one line all the same
            _fail(exc)
        except click.exceptions.Abort:
            click.echo("acausal: interrupted", err=True)
            sys.exit(130)
        except click.ClickException as exc:
            ctx = getattr(exc, "ctx", None)
            where = ctx.command_path if ctx is not None else "acausal"
            click.echo(f"{where}: error: {_one_line(exc.format_message())} "
                       f"(see {where} --help)", err=True)
            sys.exit(exc.exit_code)


class _Number(click.ParamType):
    """A number option checked when it is parsed: ``kind`` "finite", "positive"
    (finite > 0), "fraction" (0 < x < 1), "atol" and "rtol" (within
    :data:`~acausal.modelfile.ATOL_RANGE`, ``RTOL_RANGE``) or "count" (a whole number >= 1,
    written 1000000, 1e6 or 1_000_000: the messages print counts as 1e6)."""

    def __init__(self, kind):
        self.kind = kind
        self.name = {"count": "count"}.get(kind, "number")

    def convert(self, value, param, ctx):
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            x = float(value)
        else:
            try:
                x = float(str(value).strip().replace("_", ""))
            except ValueError:
                self.fail(f"{value!r} is not a number", param, ctx)
        if not math.isfinite(x):
            self.fail(f"{value!r} is not a finite number", param, ctx)
        if self.kind == "positive" and not x > 0:
            self.fail(f"{value!r} must be > 0", param, ctx)
        if self.kind == "fraction" and not 0 < x < 1:
            self.fail(f"{value!r} must be between 0 and 1", param, ctx)
        if self.kind == "rtol" and not RTOL_RANGE[0] <= x <= RTOL_RANGE[1]:
            self.fail(f"{value!r} is outside the accepted range {RTOL_RANGE[0]:g} to "
                      f"{RTOL_RANGE[1]:g} (a relative tolerance)", param, ctx)
        if self.kind == "atol" and not ATOL_RANGE[0] <= x <= ATOL_RANGE[1]:
            self.fail(f"{value!r} is outside the accepted range {ATOL_RANGE[0]:g} to "
                      f"{ATOL_RANGE[1]:g} (SI units of the unknowns)", param, ctx)
        if self.kind == "count":
            if x != int(x) or x < 1:
                self.fail(f"{value!r} must be a whole number >= 1", param, ctx)
            if x > 1e15:
                self.fail(f"{value!r} is beyond any budget (at most 1e15)", param, ctx)
            return int(x)
        return x


# --atol, --rtol: what a tolerance can mean
from .modelfile import ATOL_RANGE, RTOL_RANGE  # noqa: E402
FINITE, POSITIVE, FRACTION, COUNT, ATOL, RTOL = (_Number(k) for k in (
    "finite", "positive", "fraction", "count", "atol", "rtol"))


def _size(ctx, param, value):
    """``--max-memory``: bytes (``4GB``, ``512MB``, ``2e9``), or None."""
    if value is None:
        return None
    from .infra.budget import parse_size
    try:
        return parse_size(value, f"--{param.name.replace('_', '-')}")
    except UsageError as exc:
        raise click.BadParameter(str(exc)) from None


# formats a CSV written under their name would pretend to be (--out o.xlsx
# wrote CSV text that a spreadsheet refuses to open)
_NOT_CSV = (".xlsx", ".xls", ".ods", ".json", ".npz", ".npy", ".parquet", ".h5", ".hdf5",
            ".mat", ".png", ".pdf", ".svg", ".gif", ".mp4", ".py", ".fmu", ".zip")


def _check_csv(path, option):
    """Refuse a CSV output named as another format."""
    ext = os.path.splitext(os.fspath(path))[1].lower() if path is not None else ""
    if ext in _NOT_CSV:
        raise UsageError(f"{option} {path}: this output is written as CSV text; name it "
                         f".csv (not {ext})")


def _check_output(path, option, *, plot=False, create=False):
    """Refuse, before anything runs, an output path that cannot be written:
    its folder missing (unless ``create``: made now) or not writable, the
    path a folder, or (``plot``) a format matplotlib cannot write. (A
    missing folder was found after the simulation, with a traceback.)"""
    if path is None:
        return
    path = os.fspath(path)
    if plot:
        from matplotlib.backend_bases import FigureCanvasBase
        formats = FigureCanvasBase.get_supported_filetypes()
        ext = os.path.splitext(path)[1].lstrip(".").lower()
        if ext not in formats:
            raise UsageError(f"{option} {path}: cannot write a figure as "
                             f"{'.' + ext if ext else 'a file without an extension'}; "
                             f"use one of {', '.join('.' + f for f in sorted(formats))}")
    if os.path.isdir(path):
        raise UsageError(f"{option} {path}: is a folder, not a file")
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        if os.path.exists(folder) or not create:
            raise UsageError(f"{option} {path}: the folder {os.path.dirname(path) or '.'} "
                             "does not exist")
        try:
            os.makedirs(folder, exist_ok=True)
        except OSError as exc:
            raise UsageError(f"{option} {path}: cannot make its folder: "
                             f"{exc.strerror or exc}") from None
    if not os.access(folder, os.W_OK) or (os.path.exists(path) and
                                          not os.access(path, os.W_OK)):
        raise UsageError(f"{option} {path}: not writable")
    _probe_write(path, option)


def _check_distinct(outputs, inputs):
    """Refuse, before anything runs, an output (``(option, path)`` pairs)
    that is one of the command's inputs (the model file, a spec, a file of
    the data folder) or the same file as another output: ``calibrate
    --json-file DATA/experiments.csv`` overwrote the measured data with the
    fit's JSON, exit 0."""
    def key(path):
        return os.path.realpath(os.fspath(path))
    read = {}
    for given in (p for p in inputs if p is not None):
        if os.path.isdir(given):
            try:
                names = os.listdir(given)
            except OSError:
                names = []
            read.update((key(os.path.join(given, n)), os.path.join(given, n)) for n in names)
        else:
            read[key(given)] = os.fspath(given)
    taken = {}
    for option, path in outputs:
        if path is None:
            continue
        k = key(path)
        if k in read:
            raise UsageError(f"{option} {path}: is an input of the command ({read[k]}): "
                             "writing it would destroy it; choose another file")
        if k in taken:
            raise UsageError(f"{option} {path}: the same file as {taken[k]}; give each "
                             "output its own file")
        taken[k] = f"{option} {path}"


def _probe_write(path, option):
    """Open ``path`` for appending, as the writer will, and leave no trace:
    ``os.access`` says yes to root where the file system says no (``/sys``,
    a read-only mount, a full disk's folder), and the run's result was then
    lost to a traceback after it had been computed."""
    existed = os.path.exists(path)
    try:
        with open(path, "a"):
            pass
    except OSError as exc:
        raise UsageError(f"{option} {path}: cannot be written: "
                         f"{exc.strerror or exc}") from None
    if not existed:
        try:
            os.remove(path)
        except OSError:
            pass


@contextlib.contextmanager
def _quiet_warnings():
    """Library warnings (numpy's overflow, scipy's LinAlgWarning, ...) are
    kept from the terminal while the block runs (24 lines of LinAlgWarning
    for a 1e30 stiffness, six RuntimeWarnings before a clean error); a block
    that ends normally prints one line counting them."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        warnings.simplefilter("ignore", DeprecationWarning)   # (old import paths: not numerical)
        warnings.simplefilter("ignore", PendingDeprecationWarning)
        with np.errstate(all="ignore"):
            yield
    own = [w for w in caught if getattr(w.category, "said_alone", False)]
    for w in own:
        _warn(str(w.message))
    caught = [w for w in caught if w not in own]
    if caught:
        kinds = {}
        for w in caught:
            kinds.setdefault(w.category.__name__, []).append(w)
        parts = [f"{len(ws)} {name}" + (f" (first: {_one_line(ws[0].message)[:120]})"
                                         if name != "DeprecationWarning" else "")
                 for name, ws in kinds.items()]
        _warn("the numerical libraries warned during the run, not shown: " + "; ".join(parts))


def _far_settings(cm, params):
    """One warning line per ``--set`` value far from its default (6 decades,
    the initialisation's own test) or of the other sign: a value in the
    wrong unit, typically."""
    from .runtime.initialize import SUSPECT_DECADES
    for name, value in params.items():
        try:
            e = cm.params[cm.param_index(name)]
        except AcausalError:
            continue
        d = e.default
        if not (d and value and math.isfinite(value) and math.isfinite(d)):
            continue
        # decades as a difference of logs: value / d underflowed to 0 for a
        # subnormal value (--set c=5e-324: log10(0), a traceback)
        decades = abs(math.log10(abs(value)) - math.log10(abs(d)))
        if decades >= SUSPECT_DECADES or (value > 0) != (d > 0):
            _warn(f"--set {name}={value:g} [{e.unit}] is far from its default {d:g} "
                  f"[{e.unit}] ({decades:.1f} decades"
                  f"{', other sign' if (value > 0) != (d > 0) else ''}): check its value "
                  "and unit")


def _parse_sets(sets):
    """``--set PATH=VALUE`` items as {path: float}; a UsageError naming the
    item if it is malformed (the model checks names, finiteness and bounds)."""
    out = {}
    for item in sets:
        if "=" not in item:
            raise UsageError(f"--set {item!r}: expected PATH=VALUE")
        k, v = item.split("=", 1)
        if not k.strip():
            raise UsageError(f"--set {item!r}: the name before '=' is missing")
        if k.strip() in out:     # (the last one silently won)
            raise UsageError(f"--set {item!r}: {k.strip()} is set twice", variable=k.strip())
        try:
            out[k.strip()] = float(v)
        except ValueError:
            raise UsageError(f"--set {item!r}: {v!r} is not a number", variable=k.strip()
                             ) from None
    return out


@click.group(cls=_Group)
@click.version_option(package_name="acausal")
@click.option("--backend", "global_backend", type=click.Choice(["sundae", "compiled"]),
              help="integrator backend of every simulation of the command, local worker "
                   "processes included (default: 'compiled' for calibrate, sweep and "
                   "diagnose, which run many simulations of each model; the library's "
                   "default, 'sundae', otherwise)")
@click.pass_context
def main(ctx, global_backend):
    """Equation-based simulation of mechanisms."""
    choice = global_backend or os.environ.get("ACAUSAL_BACKEND") or \
        ("compiled" if ctx.invoked_subcommand in MANY_RUNS else None)
    if choice:
        _set_backend(ctx, choice)


# commands that run many simulations of each model: the compiled backend's
# one-off C build per model (about 1.5-2 s of CPU, cached on disk) pays for
# itself there; it falls back to sundae without a C compiler
# (benchmarks/anchors.py, benchmarks/throughput.py, tests/backends/
# test_agreement.py). diagnose, measured on the latch with three hypotheses
# (six candidate models, each built in C on a first run): 22 against 39
# CPU-seconds with the C libraries to build, 13 against 42 with them
# cached, the same verdict. simulate (one run) keeps the reference: a C
# build costs more than the run saves (breaker: 5.1 against 3.5 CPU-seconds
# for the command on a first run, 2.9 against 3.4 once built).
# diagnose's fits also take it when called from Python (acausal/diagnose/
# problem.py FIT_BACKEND, measured in docs/diagnosis.md).
MANY_RUNS = {"calibrate", "sweep", "diagnose", "tolerance"}


def _set_backend(ctx, name):
    """ACAUSAL_BACKEND for this command (local worker processes inherit it),
    restored when the command ends."""
    old = os.environ.get("ACAUSAL_BACKEND")
    os.environ["ACAUSAL_BACKEND"] = name

    def restore():
        if old is None:
            os.environ.pop("ACAUSAL_BACKEND", None)
        else:
            os.environ["ACAUSAL_BACKEND"] = old
    ctx.call_on_close(restore)


MAX_MEMORY_HELP = ("memory limit of the command (4GB, 512MB, ...; default $ACAUSAL_MAX_MEMORY, "
                   "else 4GB or 80% of the machine's memory): estimated before the work "
                   "starts, watched while it runs")


@main.command()
@click.argument("file", type=click.Path(dir_okay=False))
@click.option("--t-end", type=FINITE, help="stop time [s] (default: the model file's)")
@click.option("--set", "sets", multiple=True, metavar="PATH=VALUE",
              help="override a parameter, e.g. --set contact.K=6.25e8")
@click.option("--out", type=click.Path(dir_okay=False), help="write all variables to CSV")
@click.option("--plot", type=click.Path(dir_okay=False), help="write a figure (PNG, PDF...)")
@click.option("--json", "as_json", is_flag=True, help="print one JSON object")
@click.option("--rtol", type=RTOL, help="relative tolerance (1e-14 to 0.1)")
@click.option("--atol", type=ATOL, help="absolute tolerance (1e-20 to 1e3, SI units)")
@click.option("--max-rows", type=COUNT, default=None, metavar="N",
              help="most output rows to store (default 1e6): a larger grid is refused")
@click.option("--max-wall", type=POSITIVE, metavar="SECONDS",
              help="stop after this wall time, keeping what was computed")
@click.option("--max-steps", type=COUNT, metavar="N",
              help="stop after this many solver steps, keeping what was computed")
@click.option("--max-memory", callback=_size, metavar="SIZE", help=MAX_MEMORY_HELP)
@click.option("--progress/--no-progress", default=None,
              help="progress bar on stderr for runs longer than 2 s "
                   "(default: when stderr is a terminal)")
@click.option("--backend", type=click.Choice(["sundae", "compiled"]),
              help="integrator backend (default: acausal.simulate.DEFAULT_BACKEND)")
def simulate(file, t_end, sets, out, plot, as_json, rtol, atol, max_rows, max_wall, max_steps,
             max_memory, progress, backend):
    """Simulate a model file. Stopped by a limit, Ctrl-C or SIGTERM, it
    writes what it computed (--out, --plot, --json) and says where it stopped."""
    from .infra.budget import Watchdog, tripped
    from .infra.budget import max_memory as memory_limit
    from .infra.executor import exit_no_sooner
    from .modelfile import compile_file, measure_values
    res = error = None
    limit = memory_limit(max_memory)
    try:
        # the whole command is watched for memory (a model file's or a measure's own
        # allocations too: 6 GB passed a 1 GB limit); --max-wall also bounds reading
        # and compiling the model file (one that never returned ignored it); the run
        # then has its own --max-wall, as before, and keeps its rows
        with _interruptible() as phase, _quiet_warnings(), \
                Watchdog(limit, max_wall, "the simulation") as watch:
            _check_output(out, "--out")
            _check_output(plot, "--plot", plot=True)
            _check_distinct([("--out", out), ("--plot", plot)], [file])
            _check_csv(out, "--out")
            params = _parse_sets(sets)
            mf, cm = compile_file(file)
            cm.param_vector(cm.split_overrides(params)[0])   # names, bounds: errors first
            _far_settings(cm, params)
            watch.max_wall = None   # the run checks its own wall time and keeps its rows
            opts = _simulate_options(mf, dict(t_end=t_end, rtol=rtol, atol=atol,
                                              max_rows=max_rows, max_wall=max_wall,
                                              max_total_steps=max_steps, backend=backend),
                                     progress, dense=bool(out or plot))
            _check_run_options(opts)
            opts["max_memory"] = limit
            with _c_stdout_to_stderr() if as_json else contextlib.nullcontext():
                res, error = _run_keeping_partial(cm, params, opts)
            phase.writing = True
            if out:
                if len(res.t) > 100_000:    # (a million rows take seconds to write)
                    click.echo(f"acausal: writing {len(res.t):,} rows to {out}", err=True)
                    # an interruption's grace covers the write (about 4 us a value)
                    phase.grace = 60.0 + WRITE_S_PER_VALUE * len(res.t) * (1 + len(res.names))
                    exit_no_sooner(phase.grace)
                _write_rows(res, out)
                if error is not None:
                    click.echo(f"acausal: partial results up to t = {res.t[-1]:.6g} s written "
                               f"to {out}", err=True)
            if plot:
                with _writing("--plot", plot):
                    _plot(mf, res, plot, partial=error is not None)
            # the measures (the model file's code) once the rows are safe, with a
            # --max-wall of their own (one that never returned ignored --max-wall)
            phase.writing = False
            watch.restart(max_wall)
            measures, missing = measure_values(mf, res) if error is None else ({}, {})
            _nonfinite_warning(res, every_row=bool(out or plot) and len(res.t) <= NAN_SCAN_ROWS)
    except (AcausalError, click.BadParameter) as exc:
        if as_json:
            click.echo(json.dumps({"error": _error_dict(exc)}, indent=1))
        _fail(exc)
    except KeyboardInterrupt:
        if res is not None:
            kept = "its results were written" if out or plot else "no --out was given"
            if tripped():
                _fail(LimitError(f"{tripped()}, while the measures were computed: {kept}"))
            click.echo(f"acausal: interrupted while the measures were computed: {kept}",
                       err=True)
            sys.exit(130)
        if tripped():
            _fail(LimitError(f"{tripped()}, before the simulation started: nothing computed"))
        click.echo("acausal: interrupted before the simulation started: nothing computed",
                   err=True)
        sys.exit(130)
    if as_json:
        click.echo(json.dumps(_result_dict(mf, res, measures, missing, error), indent=1))
    else:
        _print_run(mf, cm, res, measures, missing)
    if error is not None:
        _fail(error)
    if phase.interrupted:
        click.echo(f"acausal: interrupted ({phase.interrupted}) after the run had ended: its "
                   "results were written first", err=True)
        sys.exit(130)


def _write_rows(res, out):
    """``res.to_csv(out)``; a write that fails there (a full disk: /dev/full
    gave a traceback) is one line saying what was lost."""
    try:
        res.to_csv(out)
    except OSError as exc:
        raise AcausalError(f"--out {out}: writing the {len(res.t):,} rows failed: "
                           f"{exc.strerror or exc}; the run up to t = {res.t[-1]:.6g} s "
                           "is lost with it: free space or write elsewhere") from None


@contextlib.contextmanager
def _writing(option, path, lost=""):
    """A failed write of ``path`` (a full disk) inside the block is one line
    naming the option and the file, not 'standard output' (where the
    command's catch-all put it) nor a traceback; ``lost`` says what became
    of the work."""
    try:
        yield
    except OSError as exc:
        if exc.errno not in _STDOUT_ERRNOS + (errno.EACCES, errno.EROFS, errno.EDQUOT):
            raise
        raise AcausalError(f"{option} {path}: writing failed: {exc.strerror or exc}"
                           + (f"; {lost}" if lost else "")) from None


def _check_partial(out, option="--out"):
    """The folder beside ``out`` where finished work is kept must be a
    folder (a file there gave a FileExistsError traceback at the first
    finished point)."""
    partial = os.fspath(out) + ".partial"
    if os.path.exists(partial) and not os.path.isdir(partial):
        raise UsageError(f"{option} {out}: {partial}, where the finished work is kept, is a "
                         "file, not a folder: move it away")


def _write_json(path, obj, option, **kw):
    """``obj`` as JSON in ``path``; a failed write (a full disk) is one line."""
    try:
        with open(path, "w", encoding="utf-8") as f:
            json.dump(obj, f, indent=1, **kw)
    except OSError as exc:
        raise AcausalError(f"{option} {path}: writing failed: {exc.strerror or exc}"
                           ) from None


NAN_SCAN_ROWS = 200_000   # a result up to this long is searched for NaN row by row (~1 s)


def _nonfinite_warning(res, every_row):
    """One line when variables of the result are NaN or infinite (log of a
    negative number, 1/0 in an observed variable: the run went on, exit 0,
    and nothing said so): the first one and where. ``every_row``: every row
    is searched (a result written to CSV or plotted, up to NAN_SCAN_ROWS rows:
    the observed variables are evaluated again), else the final values only."""
    if not len(res.t):
        return
    if every_row:           # (by blocks: a large result's observed variables are not kept)
        hit = res.nonfinite()
    else:
        last = res.final()
        hit = next(((n, float(res.t[-1]), last[n]) for n in res.names
                    if n in last and not math.isfinite(last[n])), None)
    if hit is not None:
        name, t, v = hit
        where = f"from t = {t:.6g} s on" if every_row else f"at the end, t = {t:.6g} s"
        _warn(f"{name} is {v} {where}: the model computes a value outside its domain there "
              "(a log or square root of a negative number, a division by zero)")


MIN_SPAN = 1e-15   # [s] the shortest run the command accepts (a femtosecond)
WRITE_S_PER_VALUE = 20e-6   # [s] a generous time to write one CSV value (measured ~4 us)


def _check_run_options(opts):
    """The run's stop time after its start (the model file's t0), checked
    before the run (--t-end -1 gave an IndexError, nan a ValueError)."""
    t0, t_end = opts.get("t0", 0.0), opts.get("t_end")
    if t_end is not None and not t_end > t0:
        raise UsageError(f"--t-end {t_end:g}: must be after the start time t0 = {t0:g} s")
    floor = max(MIN_SPAN, 1e-12 * abs(t0))
    if t_end is not None and t_end - t0 < floor:
        raise UsageError(f"--t-end {t_end:g}: the run from t0 = {t0:g} s would last "
                         f"{t_end - t0:.3g} s, shorter than {floor:.3g} s, the shortest "
                         "run accepted")


@dataclass
class _Phase:
    """What an interrupted command is doing: ``writing`` its results (a
    signal then waits for them), ``interrupted`` by the signal named."""
    writing: bool = False
    interrupted: str = ""
    grace: float = 0.0        # [s] the write's own time budget, once sized


@contextlib.contextmanager
def _interruptible():
    """Ctrl-C, SIGTERM and SIGHUP stop a running simulation with its partial
    result (:func:`acausal.runtime.hybrid.request_stop`: the run ends at its next
    check, keeping its rows, and the command writes them); outside a run,
    or at a second signal, they interrupt at once (KeyboardInterrupt; the
    process ends within the grace period whatever it is doing)."""
    from .runtime import hybrid as sim
    from .infra.executor import exit_soon
    phase = _Phase()

    def handler(signum, frame):
        from .infra.budget import tripped
        name = signal.Signals(signum).name
        if tripped():     # the watchdog: a limit, named
            name = tripped()
        if phase.writing and not phase.interrupted:
            # the run is over: its results are being written; finish them
            # (the compiled backend's run can end between a signal and its
            # handler, and the written results were lost to a KeyboardInterrupt)
            phase.interrupted = name
            exit_soon(130, grace=max(120.0, phase.grace))
            return
        if not sim.STOP.reason and sim.request_stop(name if tripped() else
                                                    f"an interruption ({name})"):
            exit_soon(130, grace=120.0)     # time to write the partial result
            return
        exit_soon(130, grace=5.0)
        raise KeyboardInterrupt(name)

    if not _in_main_thread():
        yield phase
        return
    from .infra.signals import STOP_SIGNALS
    names = [n for n in STOP_SIGNALS if hasattr(signal, n)]
    old = {n: signal.signal(getattr(signal, n), handler) for n in names}
    sim.STOP.armed = True
    try:
        yield phase
    finally:
        sim.STOP.armed = False
        for n, h in old.items():
            signal.signal(getattr(signal, n), h)


def _in_main_thread():
    import threading
    return threading.current_thread() is threading.main_thread()


def _simulate_options(mf, given, progress, dense=False):
    """The model file's run options (its dense grid when a CSV or a plot
    needs one; measures do not), overridden by the command line's."""
    opts = mf.experiment.run_options(dense=dense)
    opts.update({k: v for k, v in given.items() if v is not None})
    opts["progress"] = sys.stderr.isatty() if progress is None else progress
    return opts


def _run_keeping_partial(cm, params, opts):
    """(result, None), or (partial result, the SolverError) when the solver
    failed or a limit stopped the run after computing something."""
    try:
        return cm.simulate(params=params, **opts), None
    except SolverError as exc:
        if exc.result is None or len(exc.result.t) == 0:
            raise
        return exc.result, exc


@contextlib.contextmanager
def _c_stdout_to_stderr():
    """Send what C code prints to stdout to stderr instead, so that stdout
    carries only the JSON (SUNDIALS' error lines, printed from Python, are
    caught by the backend and carried in the error's message)."""
    import ctypes
    import os
    sys.stdout.flush()
    saved = os.dup(1)
    os.dup2(2, 1)
    try:
        yield
    finally:
        try:
            ctypes.CDLL(None).fflush(None)   # C stdio buffers, before stdout is restored
        except (OSError, TypeError, AttributeError):  # no C library handle (Windows)
            pass
        os.dup2(saved, 1)
        os.close(saved)


def _finite(x):
    return x if x == x and abs(x) != float("inf") else None


def _error_dict(exc):
    out = {"type": type(exc).__name__, "message": str(exc)}
    for k in ("t", "component"):
        if getattr(exc, k, None) is not None:
            out[k] = getattr(exc, k)
    return out


def _result_dict(mf, res, measures, missing, error):
    """The ``--json`` object: values in SI units, named in ``units``."""
    from .modelfile import measure_unit
    final = res.final()
    return {
        "error": None if error is None else _error_dict(error),
        "status": res.status,
        "final": {k: _finite(v) for k, v in final.items()},
        "events": [{"t": t, "name": n} for t, n in res.events],
        "measures": {k: _finite(v) for k, v in measures.items()},
        "missing": missing,
        "units": {"time": "s", "final": {n: res.unit(n) for n in final},
                  "measures": {k: measure_unit(mf, k) for k in measures}},
        "stats": {k: res.stats.get(k) for k in ("nfev", "steps", "wall_s", "compile_s",
                                                "njev", "events", "backend",
                                                "backend_fallback")},
    }


def _print_run(mf, cm, res, measures, missing):
    """The summary on stdout, each measure in its display unit."""
    from .modelfile import show_measure
    click.echo(f"simulated {mf.path}: t = {res.t[0]:g} .. {res.t[-1]:g} s, "
               f"{len(res.events)} events, {res.stats['steps']} steps, "
               f"{res.stats['wall_s'] * 1e3:.1f} ms (compile {cm.compile_s:.2f} s, "
               f"backend {res.stats.get('backend')})")
    if res.stats.get("backend_fallback"):
        click.echo(f"  note: {res.stats['backend_fallback']}; ran sundae")
    for k, v in measures.items():
        if k in missing:
            click.echo(f"  {k} = missing ({missing[k]})")
        else:
            click.echo(f"  {k} = {show_measure(mf, k, v)}")


def _plot(mf, res, path, partial=False):
    """The model file's plot (or its list of variables), else the states.
    A partial result that the model file's plot function cannot draw gets
    the default plot."""
    from .modelfile import call_plot
    custom = mf.namespace.get("plot")
    if callable(custom):
        try:
            call_plot(mf, res, path)
            return
        except AcausalError:   # one line naming the file's line; a partial result: see above
            if not partial:
                raise
        custom = None
    res.plot(custom or None, path, title=mf.path.rsplit("/", 1)[-1])


@main.command()
@click.argument("file", type=click.Path(dir_okay=False))
@click.option("--out", required=True, type=click.Path(dir_okay=False),
              help="animation file: .gif (Pillow) or .mp4 (needs ffmpeg)")
@click.option("--t-end", type=FINITE, help="stop time [s] (default: the model file's)")
@click.option("--set", "sets", multiple=True, metavar="PATH=VALUE",
              help="override a parameter, e.g. --set crank_pin.w=10")
@click.option("--fps", type=COUNT, default=25, show_default=True)
@click.option("--frames", type=COUNT, default=150, show_default=True,
              help="largest number of frames (evenly spaced in time)")
@click.option("--max-wall", type=POSITIVE, metavar="SECONDS",
              help="stop the simulation after this wall time (the frames up to there are drawn)")
@click.option("--max-memory", callback=_size, metavar="SIZE", help=MAX_MEMORY_HELP)
def animate(file, out, t_end, sets, fps, frames, max_wall, max_memory):
    """Simulate a planar model file and animate its mechanism."""
    from .viz.animate import animate as write_animation
    from .infra.budget import Watchdog, tripped
    from .infra.budget import max_memory as memory_limit
    from .modelfile import compile_file
    limit, res, existed = memory_limit(max_memory), None, os.path.exists(out)
    try:
        # the whole command is watched for memory (drawing 501 frames took 899 MB
        # against --max-memory 300MB); --max-wall bounds the reading and compiling
        # of the model file, and the run has its own, as in simulate
        with _interruptible(), _quiet_warnings(), \
                Watchdog(limit, max_wall, "the animation") as watch:
            if os.path.splitext(out)[1].lower() not in (".gif", ".mp4"):
                raise UsageError(f"--out {out}: an animation is written as .gif or .mp4")
            _check_output(out, "--out")
            _check_distinct([("--out", out)], [file])
            mf, cm = compile_file(file)
            watch.max_wall = None
            opts = mf.experiment.run_options()
            if t_end is not None:
                opts["t_end"] = t_end
            _check_run_options(opts)
            opts.update(max_memory=limit,
                        **({"max_wall": max_wall} if max_wall else {}))
            res, error = _run_keeping_partial(cm, _parse_sets(sets), opts)
            ks = write_animation(res, out, fps=fps, max_frames=frames,
                                 title=mf.path.rsplit("/", 1)[-1])
    except (AcausalError, click.BadParameter) as exc:
        _fail(exc)
    except KeyboardInterrupt:
        when = "before the simulation started" if res is None else "while drawing"
        if res is not None and not existed and os.path.exists(out):
            os.remove(out)         # a half-written animation is no result
        if tripped():
            _fail(LimitError(f"{tripped()}, {when}: nothing written to {out}"))
        click.echo(f"acausal: interrupted {when}: nothing written to {out}", err=True)
        sys.exit(130)
    if error is not None:
        click.echo(f"wrote {out}: {len(ks)} frames, t = {res.t[0]:g} .. {res.t[-1]:g} s "
                   "(partial)")
        _fail(error)
    click.echo(f"wrote {out}: {len(ks)} frames, t = {res.t[0]:g} .. {res.t[-1]:g} s")


def _state_names(cm):
    """Names of the variables that are a state of the run up to sign and a
    constant offset (a joint angle that is its body's angle, a speed that
    is der(state)): the solver integrates them."""
    import sympy as sp
    y = list(cm.dae.y[:cm.dae.n_states])
    ys, params = set(y), set(cm.param_syms)
    out = {s.name for s in y}
    for name in cm.var_names:
        try:
            e = sp.sympify(cm.resolve(sp.Symbol(name)))
        except Exception:  # noqa: BLE001 - a name the compiled model cannot resolve
            continue
        hit = e.free_symbols & ys
        if len(hit) == 1 and e.free_symbols - ys <= params:
            (x,) = hit
            if e.diff(x) in (1, -1):
                out.add(name)
    return out


POSITION_UNITS = ("m", "rad", "mm", "deg")   # what an encoder or a displacement sensor gives


def _name_filter(pattern):
    """A predicate on names: a glob (``hook.*``, ``*.phi``) or, without
    wildcards, a substring; None: everything."""
    import fnmatch
    if pattern is None:
        return lambda name: True
    if any(c in pattern for c in "*?["):
        return lambda name: fnmatch.fnmatchcase(name, pattern)
    return lambda name: pattern in name


@main.command()
@click.argument("file", type=click.Path(dir_okay=False))
@click.option("--states", "only_states", is_flag=True,
              help="only the states (the unknowns the integrator carries): the usual "
                   "names of a measured trace")
@click.option("--match", "pattern", metavar="PATTERN",
              help="only names matching PATTERN: a glob ('hook.*', '*.phi') or, without "
                   "wildcards, a substring")
def variables(file, only_states, pattern):
    """List parameters and variables with units and defaults. Variables are
    marked ``state`` (integrated) and ``position`` (a length or an angle:
    what an encoder or a displacement sensor measures); a trace in the data
    names one of them as its column."""
    from .modelfile import compile_file
    try:
        with _quiet_warnings():      # a model file's own warnings: one line, counted
            mf, cm = compile_file(file)
    except AcausalError as exc:
        _fail(exc)
    keep = _name_filter(pattern)
    shown = total = 0
    if not only_states:
        click.echo("PARAMETERS (settable with --set)")
        for p in cm.params:
            if keep(p.name):
                click.echo(f"  {p.name:32s} = {p.default:<12.6g} [{p.unit}]  {p.decl.desc}")
        for name, val in cm.structural.items():
            if keep(name):
                click.echo(f"  {name:32s} = {val!r:<12} (structural)")
        for name, val in cm.bound.items():
            if keep(name):
                click.echo(f"  {name:32s} = {val} (bound)")
    click.echo("STATES (integrated; name one in a trace)" if only_states else
               "VARIABLES (a fixed start value is settable with --set; marked: state, "
               "position = a length or angle a sensor measures)")
    states = _state_names(cm)
    for name in cm.var_names:
        info = cm.flat.variables[name]
        if info.internal:
            continue
        total += 1
        if (only_states and name not in states) or not keep(name):
            continue
        shown += 1
        st = info.start
        marks = " ".join(m for m, on in (("state", name in states),
                                         ("position", info.unit in POSITION_UNITS)) if on)
        start = f"start {st.value}{' (fixed)' if st.fixed else ''}"
        click.echo(f"  {name:32s} [{info.unit}] {info.desc}; {start} {marks}".rstrip())
    if not only_states:
        for d in cm.discretes:
            if d.internal or not keep(d.symbol.name):
                continue
            click.echo(f"  {d.symbol.name:32s} [{d.unit}] {d.desc}; discrete, start "
                       f"{d.start.value}")
    if only_states or pattern is not None:
        click.echo(f"({shown} of {total} variables shown)")


@main.command()
@click.argument("file", type=click.Path(dir_okay=False))
@click.option("--json", "as_json", is_flag=True, help="print one JSON object")
def check(file, as_json):
    """Check a model file: compile it and list its states, time events and
    unconnected connectors (no error: their force/torque is zero)."""
    from .compiler.check import check_model
    from .modelfile import compile_file
    try:
        with _quiet_warnings():      # a model file's own warnings: one line, counted
            mf, cm = compile_file(file)
            report = check_model(None, compiled=cm)
    except AcausalError as exc:
        _fail(exc)
    if as_json:
        click.echo(json.dumps(dict(file=str(file), **report.as_dict())))
        return
    click.echo(f"checked {file}:")
    for line in report.lines():
        click.echo(f"  {line}")


@main.command()
@click.argument("file", type=click.Path(dir_okay=False))
@click.option("--at", "at", default="start", show_default=True,
              metavar="start|equilibrium|T|STATE=V,...",
              help="operating point: the consistent start, the static equilibrium (trim), "
                   "the state reached at time T [s], or these states' values "
                   "(e.g. rev.phi=-1.5708,rev.w=0)")
@click.option("--inputs", default="", metavar="U1,U2,...",
              help="free parameters to take as inputs (B and D columns)")
@click.option("--outputs", default="", metavar="Y1,Y2,...",
              help="variables to take as outputs (C and D rows; default: the states)")
@click.option("--set", "sets", multiple=True, metavar="PATH=VALUE",
              help="override a parameter or fixed start value, e.g. --set damper.d=0.2")
@click.option("--out", type=click.Path(dir_okay=False),
              help="write A, B, C, D, the names, the point and the eigenvalues "
                   "(.json or .npz)")
@click.option("--json", "as_json", is_flag=True, help="print one JSON object")
def linearize(file, at, inputs, outputs, sets, out, as_json):
    """Linearise a model file: A, B, C, D and the eigenvalues of A."""
    from .analysis import RunSettings, linearize as lin_
    from .modelfile import compile_file
    try:
        if out:
            if os.path.splitext(out)[1].lower() not in (".json", ".npz"):
                raise UsageError(f"--out {out}: a linearisation is written as .json or .npz")
            _check_output(out, "--out")
            _check_distinct([("--out", out)], [file])
        params = _parse_sets(sets)
        inputs = _csv_list(inputs, "--inputs", empty_ok=True)    # (a name twice: refused;
        outputs = _csv_list(outputs, "--outputs", empty_ok=True)  # an output twice passed)
        point = _parse_at(at)
        with _quiet_warnings():      # a model file's own warnings: one line, counted
            mf, cm = compile_file(file)
        if isinstance(point, float) and not (math.isfinite(point)
                                             and point >= mf.experiment.t0):
            raise UsageError(f"--at {at}: a time must be finite and at or after the model "
                             f"file's t0 = {mf.experiment.t0:g} s")
        lin = lin_(cm, at=point, inputs=inputs, outputs=outputs, params=params,
                   t=mf.experiment.t0 if not isinstance(point, float) else None,
                   run=RunSettings(rtol=mf.experiment.rtol, atol=mf.experiment.atol))
        if out:
            lin.save(out)
    except (AcausalError, click.BadParameter) as exc:
        if as_json:
            click.echo(json.dumps({"error": _error_dict(exc)}, indent=1))
        _fail(exc)
    if as_json:
        click.echo(json.dumps(lin.as_dict(), indent=1))
    else:
        click.echo(str(lin))
    if out:
        click.echo(f"wrote {out}", err=as_json)


def _parse_at(text):
    """``--at``: 'start', 'equilibrium', a time [s] or NAME=VALUE pairs."""
    text = text.strip()
    if text in ("start", "equilibrium"):
        return text
    if "=" not in text:
        try:
            return float(text)
        except ValueError:
            raise UsageError(f"--at {text!r}: expected start, equilibrium, a time [s] or "
                             "STATE=VALUE,...") from None
    out = {}
    for item in (x.strip() for x in text.split(",") if x.strip()):
        name, _, value = item.partition("=")
        if name.strip() in out:      # (the last one silently won)
            raise UsageError(f"--at {text!r}: {name.strip()} is given twice",
                             variable=name.strip())
        try:
            out[name.strip()] = float(value)
        except ValueError:
            raise UsageError(f"--at {item!r}: {value!r} is not a number",
                             variable=name.strip()) from None
    return out


@main.command()
@click.argument("file", type=click.Path(dir_okay=False))
@click.argument("data", type=click.Path(file_okay=False))
@click.option("--fit", required=True, metavar="P1,P2,...",
              help="parameters to fit; with --method report give PARAM:MEASURE pairs "
                   "in the order the report calibrates them (contact.K:contact_period,hook.bh:thrt)")
@click.option("--method", type=click.Choice(["lsq", "report"]), default="lsq", show_default=True)
@click.option("--experiments", metavar="E1,E2,...|all",
              help="fit these experiments, or 'all' (default: the rows the data marks "
                   "use=calibrate, every row without a use column); the others are "
                   "predicted and compared")
@click.option("--profile", type=click.Choice(["auto", "all", "none"]), default="auto",
              show_default=True,
              help="profile-likelihood 95% intervals (lsq): for the parameters whose "
                   "linearised interval is not trustworthy (auto), every one, or none")
@click.option("--json", "as_json", is_flag=True, help="print one JSON object")
@click.option("--json-file", "json_file", type=click.Path(dir_okay=False), metavar="FILE",
              help="also write that JSON object to FILE (as diagnose --json-file)")
@click.option("--max-wall", type=POSITIVE, metavar="SECONDS", help="stop after this wall time")
@click.option("--max-memory", callback=_size, metavar="SIZE", help=MAX_MEMORY_HELP)
def calibrate(file, data, fit, method, experiments, profile, as_json, json_file, max_wall,
              max_memory):
    """Fit parameters of a model file to a measured dataset. Warns (one line
    each) when a condition of the data lies outside the range the model
    declares, a measured value is far from what the fitted model gives (a
    unit, a sign), or a fitted value ends at a bound of its range."""
    from .studies import calibrate as cal
    from .infra.budget import Watchdog
    from .infra.budget import max_memory as memory_limit
    from .modelfile import compile_file
    try:
        if json_file:
            _check_output(json_file, "--json-file")
            _check_distinct([("--json-file", json_file)], [file, data])
        with _quiet_warnings(), _resumable(None), \
                Watchdog(memory_limit(max_memory), max_wall, "the calibration"):
            out, ds, held, mf, cm = _calibrate(cal, compile_file, file, data, fit, method,
                                               experiments, profile)
    except (AcausalError, click.BadParameter) as exc:
        _fail(exc)
    _calibration_warnings(mf, cm, ds, held, out)
    if json_file:
        try:
            _write_json(json_file, out.to_dict(), "--json-file", default=float)
        except AcausalError as exc:
            _fail(exc)
    _print_calibration(out, ds, mf, file, data, as_json)


def _calibrate(cal, compile_file, file, data, fit, method, experiments, profile):
    """The calibration's work: (result, dataset fitted, ModelFile, CompiledModel)."""
    from .data.thinning import thin_traces
    items = _csv_list(fit, "--fit")          # (the lists first: before any compiling)
    chosen = None
    if experiments is not None:
        chosen = ("all" if experiments.strip() == "all"
                  else _csv_list(experiments, "--experiments"))
    mf, cm = compile_file(file)
    ds = thin_traces(cal.model_dataset(file, data), say=True)
    _compiled_note(cm, file, "calibrate")
    _condition_bounds(cm, ds)
    _condition_warnings(mf, ds)
    _trace_span_warnings(mf, ds)
    ds, held = cal.split(ds, chosen)
    if method == "report":
        pairs = []
        for it in items:
            if ":" not in it:
                raise click.BadParameter(f"--fit {it!r}: the report method needs PARAM:MEASURE")
            p, m = it.split(":", 1)
            pairs.append((p, m))
        cal.check_names(cm, [p for p, _ in pairs])
        out = cal.report_method(file, ds, pairs)
    else:
        names = [it.split(":", 1)[0] for it in items]
        cal.check_names(cm, names)
        out = cal.least_squares(file, ds, names, profile=profile)
    out.validation = cal.validate(file, held, out.values)
    return out, ds, held, mf, cm


def _print_calibration(out, ds, mf, file, data, as_json):
    if as_json:
        click.echo(json.dumps(out.to_dict(), indent=1, default=float))
        return
    click.echo(f"calibration ({out.method}) of {file} against {data} "
               f"({', '.join(e.name for e in ds.experiments)}): {out.n_sim} simulations"
               + (f", Jacobian from {out.jacobian}" if out.method == "least_squares" else ""))
    for name, v in out.values.items():
        ci = out.ci95.get(name)
        ci_s = f"  95% CI [{ci[0]:.6g}, {ci[1]:.6g}]" if ci else ""
        click.echo(f"  {name} = {v:.6g}{ci_s}")
    for name, prof in out.profile_ci95.items():
        click.echo(f"  {name}: {_profile_line(prof)}")
    if out.correlation is not None and len(out.values) > 1:
        click.echo("  correlation:")
        for name, row in zip(out.values, out.correlation):
            click.echo(f"    {name:20s} " + " ".join(f"{x:+.3f}" for x in row))
    click.echo("  residuals (simulated - measured):")
    for exp, sig in out.residuals.items():
        click.echo(f"    {exp}: " + ", ".join(_residual(k, v, mf) for k, v in sig.items()))
    if out.validation:
        click.echo("  held back, predicted with these values (simulated - measured):")
        for exp, sig in out.validation.items():
            click.echo(f"    {exp}: " + ", ".join(_residual(k, v, mf) for k, v in sig.items()))


def _shown_unit(mf, name):
    """(factor, unit) showing a residual of measure or variable ``name``:
    a measure's display unit (thrt: 1e3, 'ms'), else its SI unit, else (1, '')."""
    from .lang.experiment import Measure
    fn = mf.measures.get(name) if mf is not None else None
    if isinstance(fn, Measure):
        factor, unit = fn.shown(1.0)
        return factor, ("" if unit == "1" else unit)
    unit = mf.measure_unit(name) if mf is not None else None
    if unit is None and mf is not None:
        try:
            from .modelfile import compile_file
            unit = compile_file(mf.path)[1].flat.variables[name].unit
        except (KeyError, AcausalError, OSError):
            unit = None
    return 1.0, ("" if unit in (None, "1") else unit)


def _residual(name, value, mf=None):
    """'thrt +0.012 ms' for a measure (in its display unit), 'hook.phi rms
    3.4e-04 rad over 40 samples' for a trace, the message for a failed prediction."""
    if name == "error":
        return f"{name} {value}"
    v = np.asarray(value, dtype=float)
    factor, unit = _shown_unit(mf, name)
    unit = f" {unit}" if unit else ""
    if v.ndim == 0:
        return f"{name} {factor * float(v):+.4g}{unit}"
    return (f"{name} rms {factor * float(np.sqrt(np.mean(v ** 2))):.4g}{unit} over "
            f"{v.size} samples")


def _condition_bounds(cm, ds):
    """A condition value outside its parameter's own bounds is an error
    naming the experiment (it was a warning about the model file's range,
    then an error that named neither the experiment nor the data)."""
    from .errors import ParameterError
    entries = {e.name: e for e in cm.params}
    for exp in ds.experiments:
        for name, v in exp.conditions.items():
            if name in entries:
                try:
                    entries[name].decl.check_bounds(v, name)
                except ParameterError as exc:
                    raise UsageError(f"experiment {exp.name} of the data: {exc}",
                                     variable=name) from None


def _condition_warnings(mf, ds):
    """One line per experiment condition outside the range the model file
    declares (``conditions``), with a hint when a unit would explain it."""
    for name, (low, high, unit) in mf.conditions.items():
        if low is None or high is None:
            continue
        margin = 0.1 * (high - low)
        out = [(e.name, e.conditions[name]) for e in ds.experiments
               if name in e.conditions and not low - margin <= e.conditions[name] <= high + margin]
        if out:
            vals = [v for _, v in out]
            which = (f"{out[0][0]}: {name} = {vals[0]:.4g} {unit}" if len(out) == 1 else
                     f"{len(out)} experiments ({out[0][0]} .. {out[-1][0]}): {name} = "
                     f"{min(vals):.4g} .. {max(vals):.4g} {unit}")
            _warn(f"{which} (in SI) outside the range {low:g}..{high:g} {unit} the model "
                  "declares: check the values and the unit in the data's header")


def _trace_span_warnings(mf, ds):
    """One line per trace with samples outside the model file's run, t0 to
    t_end: the simulation is compared there with its first or last value
    (a trace to 50 s against a 0.3 s run was fitted so, without a word)."""
    t0, t_end = mf.experiment.t0, mf.experiment.t_end
    for e in list(ds.experiments):
        tr = e.trace
        if tr is None or not len(tr.time):
            continue
        t = np.asarray(tr.time, dtype=float)
        before, after = int(np.sum(t < t0)), int(np.sum(t > t_end * (1 + 1e-9) + 1e-15))
        if before or after:
            where = tr.file.name if tr.file is not None else f"{e.name}'s trace"
            parts = ([f"{before} before t0 = {t0:g} s (from {t.min():g} s)"] if before else []) \
                + ([f"{after} after t_end = {t_end:g} s (to {t.max():g} s)"] if after else [])
            _warn(f"{where}: {' and '.join(parts)} of its {t.size:,} samples lie outside the "
                  "model file's run, where they are compared with its first or last value: "
                  "check the time column's unit, or the experiment's t0 and t_end")


def _compiled_note(cm, file, what):
    """One line on stderr when the command's backend is the compiled one and
    this model cannot be built in C (no compiler, or an expression with no
    C form): its simulations then run on sundae, 3-20 times slower, which a
    long calibration or diagnosis should not do silently (``simulate`` says
    it per run)."""
    if os.environ.get("ACAUSAL_BACKEND") != "compiled":
        return
    from .runtime.backends.compiled import Unavailable, library
    try:
        library(cm)
    except Unavailable as exc:
        click.echo(f"acausal {what}: note: {file}: compiled backend unavailable: {exc}; "
                   f"its simulations run on sundae (3-20x slower)", err=True)


def _diagnosis_data_warnings(file, data):
    """The data checks calibrate makes (a condition outside its parameter's
    bounds; trace samples outside the model file's run) before a diagnosis: it said nothing of a trace to 50 s
    against a 0.3 s run. The dataset is read here once more (the diagnosis
    reads its own); the compiled model is the process's cached one. Also
    the note when that model cannot run in C (:func:`_compiled_note`)."""
    from .modelfile import compile_file
    from .studies import calibrate as cal
    try:
        mf, cm = compile_file(file)
        ds = cal.model_dataset(file, data)
    except AcausalError:      # the diagnosis reads them again and says what is wrong
        return
    _compiled_note(cm, file, "diagnose")
    _condition_bounds(cm, ds)
    _trace_span_warnings(mf, ds)


AT_BOUND = 1e-4     # of a range: a fitted value this close to a bound is at it


def _calibration_warnings(mf, cm, ds, held, out):
    """A fitted value at a bound of its range (the data push it beyond a
    plausible value: a unit, a wrong measure), and a measured value far from
    what the fitted model gives (other sign, or a factor 10 away)."""
    for name, v in out.values.items():
        lo, hi = mf.free.get(name, (None, None))
        if lo is None:
            try:
                d = cm.params[cm.param_index(name)].decl
                lo, hi = d.min, d.max
            except (AcausalError, AttributeError):
                continue
        span = (hi - lo) if lo is not None and hi is not None else abs(v) or 1.0
        for bound, which in ((lo, "lower"), (hi, "upper")):
            if bound is not None and abs(v - bound) <= AT_BOUND * span:
                ci = out.ci95.get(name)
                _warn(f"{name} = {v:.6g} is at the {which} bound {bound:g} of its range"
                      + (" (its 95 % interval is undefined)" if ci is not None and
                         not all(math.isfinite(c) for c in ci) else "")
                      + ": the data push it out of range; check the data's values and units")
    residuals = {**(out.validation or {}), **out.residuals}
    for e in list(ds.experiments) + list(getattr(held, "experiments", None) or []):
        for k, r in residuals.get(e.name, {}).items():
            measured = e.measures.get(k)
            try:
                r = np.asarray(r, dtype=float)
            except (TypeError, ValueError):
                continue
            if measured is None or r.ndim != 0 or not math.isfinite(float(r)):
                continue
            sim = measured + float(r)
            if measured and (not sim or (sim > 0) != (measured > 0) or
                             not 0.1 <= abs(measured / sim) <= 10):
                factor, unit = _shown_unit(mf, k)
                _warn(f"{e.name}: measured {k} = {factor * measured:.4g} {unit} is far from "
                      f"the fitted model's {factor * sim:.4g} {unit}: check its value, sign "
                      "and unit")


def _profile_line(prof):
    """One line for a profile-likelihood interval (acausal.profile.Profile)."""
    ends = [("open" + (f" at bound {v:.6g}" if v is not None else "")) if opn else f"{v:.6g}"
            for v, opn in ((prof.lower, prof.open_lower), (prof.upper, prof.open_upper))]
    verdict = ("agrees with the linearised interval" if prof.trustworthy else
               "the linearised interval is not trustworthy")
    return (f"profile-likelihood 95% CI [{ends[0]}, {ends[1]}] ({verdict}; "
            f"{prof.n_evaluations} evaluations)")


def _sweep_units(mf, cm, params, measures):
    """The SI unit of each swept parameter (or fixed start value) and of each
    measure that declares one, for the sweep CSV's header."""
    units = {}
    for name in params:
        if name in {e.name for e in cm.params}:
            units[name] = cm.params[cm.param_index(name)].unit
        elif name in cm.flat.variables:
            units[name] = cm.flat.variables[name].unit
    for m in measures:
        unit = getattr(mf.measures[m], "unit", None)
        if unit:
            units[m] = unit
    return units


# a finished sweep point in the main process: its CSV cells and its returned row,
# SWEEP_POINT_BASE bytes + SWEEP_POINT_BYTES per column (parameters, measures and
# 3 more); measured at the end of a serial sweep of a Grid (peak RSS over the
# start): 1,283 B for 6 columns, 1,509 B for 8 (113 B per column) at 1e5 points;
# traced allocations at their peak grow by up to 1,724 B per point for 6 columns
# between 500 and 2,500 points (dicts doubling): 1,900 B for 6 columns covers both
SWEEP_POINT_BASE = 1000
SWEEP_POINT_BYTES = 150
TOLERANCE_RUN_BYTES = 600   # a tolerance study's run, per column (+ 400 bytes), as before
MAX_POINTS = 1_000_000      # the sweep's default work budget
SWEEP_SAY_PREPARING = 100_000   # a grid this large says so before its bar shows


@main.command()
@click.argument("file", type=click.Path(dir_okay=False))
@click.option("--param", "params", multiple=True, required=True, metavar="NAME=A:B:N",
              help="a swept parameter: start:stop:count, a list a,b,c, or one value")
@click.option("--measure", "measures", multiple=True, required=True, metavar="M1,M2,...",
              help="measure(s) to record: a list a,b or the option repeated")
@click.option("--out", type=click.Path(dir_okay=False), default="sweep.csv", show_default=True,
              help="results CSV; finished points are checkpointed in OUT.partial/ as they "
                   "finish, so running the same command again after an interruption "
                   "(even a kill) resumes")
@click.option("--plot", type=click.Path(dir_okay=False), help="plot the first measure")
@click.option("--scheduler", help="Dask scheduler address (default: local processes)")
@click.option("--workers", type=COUNT, help="local worker processes (default: all cores)")
@click.option("--max-points", type=COUNT, default=MAX_POINTS, show_default=True,
              help="most grid points: a larger grid is refused before anything runs")
@click.option("--max-wall", type=POSITIVE, metavar="SECONDS",
              help="stop after this wall time, keeping the finished points")
@click.option("--max-memory", callback=_size, metavar="SIZE", help=MAX_MEMORY_HELP)
@click.option("--no-progress", is_flag=True)
def sweep(file, params, measures, out, plot, scheduler, workers, max_points, max_wall,
          max_memory, no_progress):
    """Run a grid of simulations in parallel. Budgets, checked before anything
    runs: the grid's point count (--max-points) and its memory (points x
    bytes per point, plus each worker's output rows: --max-memory); while it
    runs: memory and wall time (--max-wall), which stop it like Ctrl-C,
    keeping the finished points."""
    import functools

    from .infra.budget import PROCESS_BYTES, Watchdog, check_estimate
    from .infra.budget import max_memory as memory_limit
    from .infra.checkpoint import source_files
    from .infra.executor import default_workers, open_executor, terminate_on_sigterm
    from .modelfile import compile_file, sweep_task
    from .studies.sweep import Journal, grid, parse_param, plot_sweep, run_sweep
    try:
        with _quiet_warnings():
            measures = _csv_list(",".join(measures), "--measure")   # (refuses an empty list)
            _check_output(out, "--out", create=True)
            _check_output(plot, "--plot", plot=True, create=True)
            _check_distinct([("--out", out), ("--plot", plot)], [file])
            _check_csv(out, "--out")
            _check_partial(out)
            specs = [parse_param(p, max_points) for p in params]
            others = [name for name, v in specs[1:] if len(v) > 1 and name != specs[0][0]]
            if plot and len(others) > 1:   # (found after the whole sweep had run)
                raise UsageError(f"--plot {plot}: draws the first measure against the first "
                                 f"parameter ({specs[0][0]}), a line per value of one other, "
                                 f"but this sweep also varies {', '.join(others)}: vary at most "
                                 "one besides the first, or plot from the CSV")
            n_points = math.prod(len(v) for _, v in specs)
            if n_points > max_points:
                raise _budget_error(f"the grid has {n_points:,} points, more than the limit "
                                    f"of {max_points:,} (--max-points): fewer values per "
                                    "parameter, or raise --max-points")
            limit = memory_limit(max_memory)
            n_workers = workers or (default_workers() if scheduler is None else 1)
            per_point = SWEEP_POINT_BASE + SWEEP_POINT_BYTES * (len(specs) + len(measures) + 3)
            main_need = PROCESS_BYTES + n_points * per_point
            check_estimate(main_need + n_workers * PROCESS_BYTES, limit,
                           f"a sweep of {n_points:,} points on {n_workers} workers",
                           "sweep fewer points")
            per_worker = (limit - main_need) / max(n_workers, 1) - PROCESS_BYTES
            mf, cm = compile_file(file)
            _check_sweep_params(cm, specs)
            for m in measures:
                if m not in mf.measures:
                    raise click.BadParameter(f"--measure {m!r}: the model file defines "
                                             f"{sorted(mf.measures) or 'no measures'}")
            task = functools.partial(sweep_task, os.path.abspath(file),
                                     max_memory=max(per_worker, 50e6))
            units = _sweep_units(mf, cm, [name for name, _ in specs], measures)
            if n_points >= SWEEP_SAY_PREPARING and not no_progress:
                # (the grid is arrays; a resumed run reads its finished points first)
                click.echo(f"sweep: preparing {n_points:,} points (the grid, the "
                           "checkpoint, what is already done)", err=True)
            points = grid(specs)
            with terminate_on_sigterm(), _resumable(out), \
                    Watchdog(limit, max_wall, "the sweep"), \
                    open_executor(scheduler, workers) as ex:
                journal = Journal(inputs=source_files(file), units=units,
                                  on_resume=_say_resumed("points"))
                with _writing("--out", out, f"the points finished before are in {out} and "
                              f"{out}.partial/: free space, then run the same command "
                              "again to resume"):
                    rows = run_sweep(task, points, out, executor=ex, measures=measures,
                                     progress=not no_progress, journal=journal)
            if plot:
                fn = mf.measures[measures[0]]
                y_unit, y_factor = units.get(measures[0]), 1.0
                if getattr(fn, "display", None) and y_unit:
                    y_factor, y_unit = fn.shown(1.0)
                with _writing("--plot", plot, f"the points are in {out}"):
                    plot_sweep(rows, specs[0][0], measures[0], plot, x_unit=units.get(specs[0][0]),
                               y_unit=y_unit, y_factor=y_factor)
    except (AcausalError, click.BadParameter) as exc:
        _fail(exc)
    failed = sum(1 for r in rows if r.get("status") != "ok")
    click.echo(f"{len(rows)} points, {failed} failed; results in {out}")


@main.command()
@click.argument("file", type=click.Path(dir_okay=False))
@click.option("--spec", required=True, type=click.Path(dir_okay=False),
              help="CSV of the toleranced parameters: name, normal|uniform, a, b, unit per "
                   "line (normal: mean, std; uniform: low, high; b as p% is relative to a; "
                   "a as 'nominal' is the model's value)")
@click.option("-n", "n", type=COUNT, default=1024, show_default=True,
              help="sets drawn (sobol: the base sample N, a power of 2; it runs N (d + 2) "
                   "simulations for d parameters)")
@click.option("--sampling", type=click.Choice(["lhs", "sobol"]), default="lhs", show_default=True,
              help="Latin hypercube (variance shares: correlation ratios, regression) or "
                   "Sobol' in Saltelli's design (first-order and total Sobol' indices)")
@click.option("--seed", type=click.IntRange(min=0), default=0, show_default=True,
              help="the sampling's seed (a whole number >= 0; -1 gave a numpy traceback)")
@click.option("--measure", "measures", multiple=True, metavar="M1,M2,...",
              help="measures to study (default: every measure of the model file)")
@click.option("--out", type=click.Path(dir_okay=False), default="tolerance.csv",
              show_default=True, help="one row per set; finished chunks are checkpointed in "
              "OUT.partial/, so running the same command again after a kill resumes")
@click.option("--plot", "plot_prefix", metavar="PREFIX",
              help="write PREFIX_<measure>_hist.png and PREFIX_<measure>_tornado.png")
@click.option("--json", "json_path", type=click.Path(dir_okay=False),
              help="write the summary as JSON")
@click.option("--scheduler", help="Dask scheduler address (default: local processes)")
@click.option("--workers", type=COUNT, help="local worker processes (default: all cores)")
@click.option("--chunk", type=COUNT, default=64, show_default=True,
              help="sets per task (each task is one batched run, journaled when it ends)")
@click.option("--max-points", type=COUNT, default=MAX_POINTS, show_default=True,
              help="most simulations: a larger study is refused before anything runs")
@click.option("--max-wall", type=POSITIVE, metavar="SECONDS",
              help="stop after this wall time, keeping the finished chunks")
@click.option("--max-memory", callback=_size, metavar="SIZE", help=MAX_MEMORY_HELP)
@click.option("--no-progress", is_flag=True)
def tolerance(file, spec, n, sampling, seed, measures, out, plot_prefix, json_path, scheduler,
              workers, chunk, max_points, max_wall, max_memory, no_progress):
    """A tolerance (Monte-Carlo) study: how the measures spread when the
    parameters spread as the spec says; their mean, standard deviation,
    percentiles and each parameter's share of the variance. Budgets as
    sweep's: the number of simulations (--max-points) and their memory are
    checked before anything runs."""
    from .infra.budget import PROCESS_BYTES, Watchdog, check_estimate
    from .infra.budget import max_memory as memory_limit
    from .infra.executor import default_workers, open_executor, terminate_on_sigterm
    from .modelfile import compile_file, show_measure
    from .studies import tolerance as tol
    try:
        with _quiet_warnings():
            for path, option in ((out, "--out"), (json_path, "--json")):
                _check_output(path, option, create=True)
            if plot_prefix:
                _check_output(plot_prefix + "_hist.png", "--plot", plot=True, create=True)
            _check_distinct([("--out", out), ("--json", json_path)], [file, spec])
            _check_csv(out, "--out")
            _check_partial(out)
            tol.check_n(n, sampling)
            mf, cm = compile_file(file)
            dists = tol.parse_spec(spec, cm)
            measures = _csv_list(",".join(measures), "--measure", empty_ok=True) or list(mf.measures)
            if not measures:
                raise UsageError(f"{file}: the model file defines no measures to study")
            for m in measures:
                if m not in mf.measures:
                    raise click.BadParameter(f"--measure {m!r}: the model file defines "
                                             f"{sorted(mf.measures)}")
            runs = n * (len(dists) + 2) if sampling == "sobol" else n
            if runs > max_points:
                raise _budget_error(f"the study needs {runs:,} simulations, more than the limit "
                                    f"of {max_points:,} (--max-points): a smaller -n, or raise "
                                    "--max-points")
            limit = memory_limit(max_memory)
            n_workers = workers or (default_workers() if scheduler is None else 1)
            main_need = PROCESS_BYTES + runs * (400 + TOLERANCE_RUN_BYTES * (
                len(dists) + len(measures) + 3))
            check_estimate(main_need + n_workers * PROCESS_BYTES, limit,
                           f"a tolerance study of {runs:,} simulations on {n_workers} workers",
                           "draw fewer sets")
            per_worker = (limit - main_need) / max(n_workers, 1) - PROCESS_BYTES
            with terminate_on_sigterm(), _resumable(out + ".partial"), \
                    Watchdog(limit, max_wall, "the tolerance study"), \
                    open_executor(scheduler, workers) as ex:
                run = tol.StudyRun(chunk=chunk, max_memory=max(per_worker, 50e6),
                                   backend=None, on_resume=_say_resumed("sets"),
                                   progress=not no_progress)
                res = tol.run_tolerance(os.path.abspath(file), dists, n, executor=ex,
                                        measures=measures,
                                        sampling=tol.Sampling(sampling, seed),
                                        out_csv=out, run=run)
            display = {m: _display(mf, m) for m in measures}
            if plot_prefix:
                tol.plot_histograms(res, plot_prefix, display)
                tol.plot_tornado(res, plot_prefix, display)
            if json_path:
                _write_json(json_path, tol.summary_json(res), "--json")
    except tol.SpecError as exc:                # one line per bad row of the spec
        for line in exc.lines:
            click.echo(f"acausal: error: {_one_line(line)}", err=True)
        sys.exit(2)
    except (AcausalError, click.BadParameter) as exc:
        _fail(exc)
    for line in tol.report_lines(res, lambda m, v: show_measure(mf, m, v)):
        click.echo(line)
    click.echo(f"results in {out} ({res.wall_s:.1f} s)")


def _display(mf, name):
    """(factor from SI, display unit) of a measure ((1, '') without a unit)."""
    fn = mf.measures.get(name)
    if getattr(fn, "unit", None):
        return fn.shown(1.0)
    return 1.0, mf.measure_unit(name) or ""


def _budget_error(message):
    from .errors import BudgetError
    return BudgetError(message)


def _check_sweep_params(cm, specs):
    """Every swept name is a parameter or a fixed start value, and every
    value of its range is within the parameter's bounds: checked before
    the sweep runs (-1:1:3 for a speed that must be > 0 ran and failed
    point by point)."""
    for name, values in specs:
        params, _ = cm.split_overrides({name: 0.0})
        if name not in params:
            continue                      # a fixed start value: no bounds
        e = cm.params[cm.param_index(name)]
        lo, hi = float(np.min(values)), float(np.max(values))
        for v in (lo, hi):
            try:
                e.decl.check_bounds(v, name)
            except AcausalError as exc:
                raise UsageError(f"--param {name}={lo:g}..{hi:g}: {exc}", variable=name
                                 ) from None


def _say_resumed(what):
    """The line a resumed command prints: 'resumed: 4,141 of 10,000 points already done'."""
    def say(done, total):
        click.echo(f"acausal: resumed: {done:,} of {total:,} {what} already done", err=True)
    return say


@contextlib.contextmanager
def _resumable(where):
    """An interruption (Ctrl-C, SIGTERM) ends with one line saying where the
    finished work is (``where``; None: the command keeps none), and exit
    code 130."""
    from .infra.budget import tripped
    from .infra.executor import exit_soon
    try:
        yield
    except KeyboardInterrupt:
        exit_soon(130)
        why = tripped()
        kept = (f"finished work is saved in {where}: run the same command again to resume"
                if where is not None else "a calibration keeps no partial result")
        if why:
            click.echo(f"acausal: error: stopped: {why}; {kept}", err=True)
            sys.exit(3)
        click.echo(f"acausal: interrupted; {kept}", err=True)
        sys.exit(130)


def unexplained_line(un):
    """The summary line of a "not explained" verdict: the located term's
    best node (and whether it beats the library's best candidate), or why
    no node could be judged ("located at the node of None" before)."""
    head = "discrepancy not explained by the library"
    if not un.get("node"):
        return f"{head}; no node located: {un.get('why') or 'no located generic term'}"
    held = un.get("heldout_rmse")
    where = f"; located at the node of {un['node']}" + (
        f" (held-out {held:.3g} floor units)" if held is not None else "")
    if not un.get("beats_library", True):
        near = un.get("nearest_heldout_rmse")
        where += (", where a generic term does not beat the library's best candidate"
                  + (f" ({near:.3g})" if near is not None else ""))
    return head + where


def _csv_list(text, option, empty_ok=False):
    """A comma-separated option value as a list (None stays None), checked
    before anything is compiled: an empty list (unless ``empty_ok``) and a
    name given twice are refused (``--fit contact.K,contact.K`` fitted one
    parameter, silently; ``--hypotheses ,`` was refused only after the
    model's C code was built)."""
    if text is None:
        return None
    items = [x.strip() for x in text.split(",") if x.strip()]
    if not items and not empty_ok:
        raise UsageError(f"{option} {text!r}: the list is empty")
    twice = sorted({x for x in items if items.count(x) > 1})
    if twice:
        raise UsageError(f"{option} {text!r}: {', '.join(twice)} named twice")
    return items


@main.command()
@click.argument("file", type=click.Path(dir_okay=False))
@click.argument("data", type=click.Path(file_okay=False))
@click.option("--json", "json_opt", is_flag=False, flag_value="-", default=None,
              metavar="", help="print the summary as one JSON object (as calibrate --json, "
                               "simulate --json); the old form --json FILE still writes FILE, "
                               "deprecated: use --json-file FILE")
@click.option("--json-file", "json_file", type=click.Path(dir_okay=False), metavar="FILE",
              help="write the summary as one JSON object to FILE")
@click.option("--report", "report_dir", type=click.Path(file_okay=False), default="diagnosis",
              show_default=True, help="folder for report.md, plots and the extended model; "
                                      "finished fits are checkpointed in REPORT/checkpoint/ as "
                                      "they finish, so running the same command again after an "
                                      "interruption (even a kill) resumes")
@click.option("--scheduler", help="Dask scheduler address (default: local processes)")
@click.option("--workers", type=COUNT, help="local worker processes (default: all cores)")
@click.option("--max-wall", type=POSITIVE, metavar="SECONDS",
              help="stop after this wall time, keeping the finished fits")
@click.option("--max-memory", callback=_size, metavar="SIZE", help=MAX_MEMORY_HELP)
@click.option("--hypotheses", metavar="ID,ID,...", help="only these hypotheses")
@click.option("--locations", metavar="PATH,PATH,...",
              help="only these locations (a path or a prefix of paths)")
@click.option("--alpha", type=FRACTION, default=0.01, show_default=True,
              help="family significance level of the discrepancy decision")
@click.option("--starts", type=click.IntRange(0, 64), default=4, show_default=True,
              help="Latin-hypercube starts per fit (besides the neutral and calibrated ones)")
@click.option("--refine", type=click.IntRange(1, 8), default=2, show_default=True,
              help="best starts refined per fit (their agreement is reported)")
@click.option("--no-progress", is_flag=True)
@click.option("--library", hidden=True, help="module standing in for the hypothesis library")
def diagnose(file, data, json_opt, json_file, report_dir, scheduler, workers, max_wall,
             max_memory, hypotheses, locations, alpha, starts, refine, no_progress, library):
    """Show what a model gets wrong against measured data, name the cause,
    extend the model and measure the gain. A long trace is thinned to what
    its instrument floor supports (said on stderr); past --max-memory or
    --max-wall, or at Ctrl-C or SIGTERM, it stops keeping its finished fits."""
    from .infra.budget import PROCESS_BYTES, Watchdog, check_estimate
    from .infra.budget import max_memory as memory_limit
    from .diagnose.problem import FitSettings
    from .diagnose.run import diagnose as run_diagnosis
    from .infra.executor import default_workers, terminate_on_sigterm
    as_json = json_opt == "-"
    json_path = json_file
    if json_opt not in (None, "-"):      # the old form: --json FILE
        click.echo(f"acausal diagnose: --json FILE is deprecated: --json alone prints the "
                   f"JSON (as calibrate --json does); use --json-file {json_opt} (writing "
                   f"{json_opt} now)", err=True)
        if json_file:
            _fail(UsageError(f"--json {json_opt} and --json-file {json_file}: give one file"))
        json_path = json_opt
    try:
        with _quiet_warnings():
            hyps = _csv_list(hypotheses, "--hypotheses")
            locs = _csv_list(locations, "--locations")
            if json_path:
                _check_output(json_path, "--json-file")
                _check_distinct([("--json-file", json_path)], [file, data])
            _check_output(os.path.join(report_dir, "report.md"), "--report", create=True)
            limit = memory_limit(max_memory)
            n_workers = workers or (default_workers() if scheduler is None else 1)
            check_estimate((n_workers + 1) * PROCESS_BYTES, limit,
                           f"a diagnosis on {n_workers} workers", "use fewer --workers")
            _diagnosis_data_warnings(file, data)
            with terminate_on_sigterm(), _resumable(f"{report_dir}/checkpoint"), \
                    Watchdog(limit, max_wall, "the diagnosis"):
                out = run_diagnosis(file, data, out_dir=report_dir, scheduler=scheduler,
                                    workers=workers, progress=not no_progress,
                                    hypotheses=hyps, locations=locs, alpha=alpha,
                                    library=library,
                                    settings=FitSettings(lhs=starts, refine=refine),
                                    on_resume=lambda n, path: click.echo(
                                        f"acausal: resumed: {n:,} fits already done "
                                        f"(from {path})", err=True))
            if json_path:
                _write_json(json_path, out, "--json-file")
    except (AcausalError, click.BadParameter) as exc:
        _fail(exc)
    if as_json:
        click.echo(json.dumps(out, indent=1))
        return
    g = out["gain"]
    if not out["discrepancy"]:
        click.echo("no significant discrepancy between the calibrated model and the data")
    elif out["unexplained"]["value"]:
        click.echo(unexplained_line(out["unexplained"]))
    elif out["cause"] is None:
        click.echo("discrepancy, but the evidence is weak: no cause named"
                   + (f" (best candidate: {out['ranking'][0]['cause']} at "
                      f"{out['ranking'][0]['location']})" if out["ranking"] else ""))
    else:
        click.echo(f"discrepancy; cause: {out['cause']} at {out['location']}")
        for c in (out.get("verdict") or {}).get("caveats", []):
            click.echo(f"  named on this ground: {c['text']}")
        for e in out["equivalent_causes"]:
            click.echo(f"  equivalent: {e['cause']} at {e['location']}")
    click.echo(f"error [instrument floor units]: train {g['before']['train']:.3g} -> "
               f"{g['after']['train']:.3g}, held-out {g['before']['heldout']:.3g} -> "
               f"{g['after']['heldout']:.3g}")
    if out["extended_model"]:
        click.echo(f"extended model: {out['extended_model']}")
    click.echo(f"report: {report_dir}/report.md" + (f"; JSON: {json_path}" if json_path else ""))


@main.command()
@click.argument("file", type=click.Path(dir_okay=False))
@click.option("-o", "--out", required=True, type=click.Path(dir_okay=False),
              help="the FMU to write (.fmu)")
@click.option("--output", "outputs", multiple=True, metavar="NAME",
              help="a variable exported as an output (repeat for more); the model file's "
                   "measures are outputs too")
@click.option("--input", "inputs", multiple=True, metavar="PARAMETER",
              help="a free parameter the importer drives as an input, held over each "
                   "communication step (repeat for more)")
@click.option("--measures/--no-measures", default=True,
              help="export the model file's measures as outputs (default: yes)")
@click.option("--fmu-backend", type=click.Choice(["sundae", "compiled"]),
              help="the integrator inside the FMU (default: the library's, or "
                   "ACAUSAL_BACKEND where it runs)")
def fmu(file, out, outputs, inputs, measures, fmu_backend):
    """Export a model file as an FMU (FMI 2.0 Co-Simulation)."""
    from .interop.fmu import export_fmu
    try:
        for option, names in (("--output", outputs), ("--input", inputs)):
            twice = sorted({x for x in names if names.count(x) > 1})
            if twice:   # (an output given twice was exported twice, silently)
                raise UsageError(f"{option} {twice[0]} is given twice", variable=twice[0])
        _check_output(out, "--out")
        _check_distinct([("--out", out)], [file])
        with _quiet_warnings():      # a model file's own warnings: one line, counted
            path = export_fmu(file, out, outputs=outputs, inputs=inputs, measures=measures,
                              backend=fmu_backend)
    except AcausalError as exc:
        _fail(exc)
    click.echo(f"wrote {path}")


if __name__ == "__main__":  # pragma: no cover
    main()
