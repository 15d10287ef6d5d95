"""Model files: plain Python scripts that build a model.

A model file binds a :class:`~acausal.Model` to the module-level name
``model``; it may define ``experiment`` (an :class:`~acausal.Experiment`),
``measures``, a dict of name -> function(result) -> float (a scalar
computed from a result, such as a response time, in SI units; a
:class:`~acausal.Measure` also gives its unit and the unit it is printed
in; ``measure_units``, a dict of measure -> SI unit, may give the units of
plain functions), ``conditions``, the parameters an experiment sets: a dict
of parameter -> (low, high) or (low, high, unit), their ranges, which
:mod:`acausal.design` searches for the next experiment, or a plain list of
names (a dataset must give at least one of them), ``free_parameters``, a
dict of parameter -> (low, high) that calibration and diagnosis may fit,
and ``plot(result, path)``. A model file can import
another one (``from breaker_24kv import build``): its folder, ``$ACAUSAL_MODEL_PATH``,
the current folder's ``models/`` and the bundled ``models/`` are on the path
(:func:`model_path`).
"""
import contextlib
import io
import math
import os
import re
import runpy
import sys
import threading
import traceback
from dataclasses import dataclass, field

from .runtime.model import compile_model
from .lang.component import Model
from .errors import AcausalError, ModelFileError
from .lang.experiment import Experiment, Measure, Stop


@dataclass
class ModelFile:
    path: str
    model: Model
    experiment: Experiment
    measures: dict = field(default_factory=dict)
    namespace: dict = field(default_factory=dict)
    free: dict = field(default_factory=dict)   # parameter -> (low, high) bounds
    measure_units: dict = field(default_factory=dict)  # measure -> SI unit (None: unknown)
    conditions: dict = field(default_factory=dict)  # parameter -> (low, high, unit)

    def measure_unit(self, name):
        """The SI unit of measure ``name``, or None if the file declares none."""
        return self.measure_units.get(name)


def _line(exc, path):
    """Line of the deepest frame of ``exc`` inside ``path`` (None if none)."""
    line = None
    for fr in traceback.extract_tb(exc.__traceback__):
        if os.path.abspath(fr.filename) == path:
            line = fr.lineno
    return line


def _error(path, line, message):
    """A ModelFileError 'path:line: message' carrying ``file`` and ``line``."""
    where = f"{path}:{line}" if line else path
    return ModelFileError(f"{where}: {message}", file=path, line=line)


class HardExit(BaseException):
    """``os._exit(code)`` called by a model file's code while the command
    runs it (see :func:`no_hard_exit`); a BaseException, so that the file's
    own ``except Exception`` does not swallow it."""

    def __init__(self, code):
        super().__init__(f"os._exit({code!r})")
        self.code = code


@contextlib.contextmanager
def no_hard_exit():
    """While the block runs the model file's code (its reading, a measure,
    its plot), ``os._exit`` called from this thread of this process raises
    :class:`HardExit`: ``os._exit(7)`` ended the command with exit 7 and no
    word, results unsaid. A process the file forks, or another thread,
    still exits as it asked (multiprocessing's children end by
    ``os._exit``)."""
    real, pid, thread = os._exit, os.getpid(), threading.get_ident()

    def _exit(code):
        if os.getpid() == pid and threading.get_ident() == thread:
            raise HardExit(code)
        real(code)
    os._exit = _exit
    try:
        yield
    finally:
        if os._exit is _exit:
            os._exit = real


@contextlib.contextmanager
def _guarded_exit_functions(path):
    """A function the model file registers with ``atexit`` while it is read
    runs at the command's end under :func:`no_hard_exit`: its ``os._exit(7)``
    ended the command silently with 7 (the command's own end skipped), its
    exception printed a traceback; each is now one line naming the file and
    the function's line, and the command ends as it was ending."""
    import atexit
    real_register, real_unregister = atexit.register, atexit.unregister
    guards = {}

    def register(fn, *args, **kw):
        code = getattr(fn, "__code__", None)
        where = f"{path}:{code.co_firstlineno}" if code is not None else path
        name = getattr(fn, "__name__", repr(fn))

        def guarded():
            try:
                with no_hard_exit():
                    fn(*args, **kw)
            except BaseException as exc:   # noqa: BLE001 - the command is ending: one line
                if isinstance(exc, SystemExit):
                    what = f"called sys.exit({exc.code!r})"
                elif isinstance(exc, HardExit):
                    what = f"called {exc}"
                else:
                    what = f"failed: {type(exc).__name__}: {' '.join(str(exc).split())}"
                try:
                    sys.stderr.write(f"acausal: warning: {where}: the model file's exit "
                                     f"function {name}() {what}: ignored\n")
                    sys.stderr.flush()
                except (OSError, ValueError, AttributeError):
                    pass
        guards[fn] = guarded
        real_register(guarded)
        return fn

    def unregister(fn):
        real_unregister(guards.pop(fn, fn))
    atexit.register, atexit.unregister = register, unregister
    try:
        yield
    finally:
        if atexit.register is register:
            atexit.register, atexit.unregister = real_register, real_unregister


STARTED_THREADS = []   # non-daemon threads model files started while read (see the CLI's end)


@contextlib.contextmanager
def _command_state():
    """The command's own state as it was before the model file ran: its
    working folder (an ``os.chdir`` in the file sent ``--out rel.csv`` to
    ``/rel.csv``), its standard streams (a file that closed stdout ended the
    command with a traceback), its signal handlers (one that ignored SIGINT
    made Ctrl-C do nothing), numpy's error handling, the recursion limit,
    the umask and no timer (the command sets none). What the file does
    for itself while it is read is its own affair. In the command, the file
    reads an empty standard input: ``input()`` in a model file waited
    forever for a harness's open pipe (a hang); it is now an EOFError
    naming its line. (A library call keeps the caller's stdin.)"""
    import signal

    import numpy as np
    cwd = os.getcwd()
    streams = (sys.stdin, sys.stdout, sys.stderr)
    from .infra.signals import STOP_SIGNALS
    names = [n for n in STOP_SIGNALS if hasattr(signal, n)]
    main = threading.current_thread() is threading.main_thread()
    handlers = {n: signal.getsignal(getattr(signal, n)) for n in names} if main else {}
    errs = np.geterr()
    before = set(threading.enumerate())
    depth = sys.getrecursionlimit()
    mask = os.umask(0o022)
    os.umask(mask)
    from .infra.startup import is_command
    if is_command():
        sys.stdin = io.StringIO("")
    try:
        yield
    finally:
        # a recursion limit of 30 (a traceback from the next import), a umask of
        # 0o777 (the results written unreadable), an alarm set (SIGALRM ended
        # the command a second later: exit 142 and no word) were the file's
        sys.setrecursionlimit(depth)
        os.umask(mask)
        if main and hasattr(signal, "setitimer"):
            for timer in (signal.ITIMER_REAL, signal.ITIMER_VIRTUAL, signal.ITIMER_PROF):
                signal.setitimer(timer, 0)
        STARTED_THREADS.extend(t for t in threading.enumerate()
                               if t not in before and not t.daemon)
        if os.getcwd() != cwd:
            os.chdir(cwd)
        sys.stdin, sys.stdout, sys.stderr = streams
        for name, fd in (("stdout", 1), ("stderr", 2)):
            stream = getattr(sys, name)
            if stream is not None and stream.closed:   # closed by the file: a new one on its fd
                setattr(sys, name, open(fd, "w", buffering=1, closefd=False,
                                        encoding=stream.encoding, errors=stream.errors))
        for n, h in handlers.items():
            if h is not None and signal.getsignal(getattr(signal, n)) is not h:
                signal.signal(getattr(signal, n), h)
        np.seterr(**errs)


def _run(path):
    """The namespace of the model file ``path`` after running it; any
    exception it raises becomes a ModelFileError naming its line."""
    try:
        with no_hard_exit(), _command_state(), _guarded_exit_functions(path):
            return runpy.run_path(path, run_name="__acausal_model__")
    except HardExit as exc:
        raise _error(path, _line(exc, path), f"the model file called {exc} while it was "
                     "being read: a model file binds 'model', it does not end the "
                     "command") from None
    except SyntaxError as exc:  # also a bad encoding or a NUL byte
        line = exc.lineno if os.path.abspath(exc.filename or path) == path else None
        raise _error(path, line or _bad_byte_line(path), f"syntax error: {exc.msg}") from None
    except AcausalError as exc:
        raise _error(path, _line(exc, path), str(exc)) from None
    except SystemExit as exc:  # sys.exit() in the script: the command went on with nothing
        raise _error(path, _line(exc, path), f"the model file called sys.exit({exc.code!r}) "
                     "while it was being read: a model file binds 'model', it does not end "
                     "the command") from None
    except Exception as exc:  # a bug in the script: say where
        line = _line(exc, path) or _bad_byte_line(path)
        hint = ""
        if isinstance(exc, EOFError):
            hint = (" (a model file is read with no standard input: it cannot ask for "
                    "input; give values as parameters and --set)")
        elif isinstance(exc, ModuleNotFoundError):
            hint = (" (a model file's imports are searched in " + ", ".join(model_path(path))
                    + " and ACAUSAL_MODEL_PATH)")
        elif isinstance(exc, TypeError) and "convert expression to" in str(exc):
            hint = (" (a model parameter is a sympy symbol, not a number: a start value or "
                    "guess that depends on one, such as a loop's assembly at a release angle "
                    "that is a condition, is written with sympy functions, e.g. "
                    "sympy.asin(r*sympy.sin(theta0)/l), not math.asin or float(); "
                    "docs/planar.md, 'Writing a planar model file')")
        raise _error(path, line, f"{type(exc).__name__}: {exc}{hint}") from None


def _bad_byte_line(path):
    """Line of the first NUL byte or byte that is not UTF-8 in the file
    (what Python refuses before it can name a line), or None."""
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError:
        return None
    bad = data.find(b"\0")
    try:
        data.decode("utf-8")
    except UnicodeDecodeError as exc:
        bad = exc.start if bad < 0 else min(bad, exc.start)
    return data.count(b"\n", 0, bad) + 1 if bad >= 0 else None


def model_path(path):
    """The folders a model file's imports are searched in, first to last:
    its own folder, the folders of ``$ACAUSAL_MODEL_PATH`` (separated like
    PATH), the current folder's ``models/``, and the ``models/`` folder
    beside the acausal package (its bundled models). So a variant written
    anywhere imports its base (``from breaker_24kv import build``) without
    PYTHONPATH=models."""
    here = os.path.dirname(os.path.abspath(path))
    env = [p for p in os.environ.get("ACAUSAL_MODEL_PATH", "").split(os.pathsep) if p]
    bundled = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                           "models")
    out = []
    for folder in [here, *env, os.path.join(os.getcwd(), "models"), bundled]:
        folder = os.path.abspath(folder)
        if os.path.isdir(folder) and folder not in out:
            out.append(folder)
    return out


def load_model_file(path):
    """Run a model file and collect ``model``, ``experiment`` and ``measures``
    (its imports searched in :func:`model_path`)."""
    path = os.path.abspath(path)
    if not os.path.isfile(path):
        what = "no such model file" if not os.path.exists(path) else \
            "not a regular file (a model file is a Python script)"
        raise ModelFileError(f"{path}: {what}", file=path)
    added = [f for f in model_path(path) if f not in sys.path]
    sys.path[0:0] = added
    try:
        ns = _run(path)
    finally:
        for f in added:
            if f in sys.path:
                sys.path.remove(f)
    return _collect(ns, path)


def _binding_line(path, name):
    """Line of the last top-level assignment to ``name`` in the file: the
    binding the file ends with (a rebinding was reported at the first one)."""
    found = None
    try:
        with open(path, encoding="utf-8", errors="replace") as f:
            for k, text in enumerate(f, start=1):
                if re.match(rf"{name}\s*(:[^=]*)?=(?!=)", text):
                    found = k
    except OSError:
        pass
    return found


def _bad(path, name, message):
    """A ModelFileError at the line that binds ``name``."""
    return _error(path, _binding_line(path, name), message)


def _collect(ns, path):
    """The ModelFile of a model file's namespace, every name checked."""
    model = ns.get("model")
    if not isinstance(model, Model):
        raise _bad(path, "model", "a model file must bind a Model to the name 'model'"
                   + (f" (found {type(model).__name__})" if model is not None else ""))
    if not model.children() and not model.equations():   # it "simulated": 500 steps of nothing
        raise _bad(path, "model", "'model' has no components and no equations: nothing to "
                   "simulate (add components: model.body = Mass(m=1.0))")
    exp = ns.get("experiment") or Experiment()
    if not isinstance(exp, Experiment):
        raise _bad(path, "experiment", "'experiment' must be an acausal.Experiment")
    _check_experiment(exp, path)
    measures = ns.get("measures") or {}
    if not isinstance(measures, dict) or not all(callable(f) for f in measures.values()):
        raise _bad(path, "measures", "'measures' must be a dict of name -> function(result)")
    units, conditions = _measure_units(ns, measures, path), _conditions(ns, path)
    return ModelFile(path, model, exp, dict(measures), ns, _free(ns, path), units, conditions)


def _number(v):
    """``v`` as a float, or None if it is not a real number (a text is not
    one: ``t_end="1"`` passed the checks and failed later with a traceback)."""
    if isinstance(v, (bool, str, bytes)):
        return None
    try:
        return float(v)
    except (TypeError, ValueError):
        return None


def _positive(value):
    """True for a finite number > 0."""
    v = _number(value)
    return v is not None and math.isfinite(v) and v > 0


# an absolute tolerance in SI units can mean something between these: above 1e3
# every position, speed and force of a mechanism counts as zero; below 1e-20 no
# solution gets closer than the relative tolerance makes it (the command line's
# --atol and a model file's Experiment(atol=...) alike; the library's own calls
# take any positive value)
ATOL_RANGE = (1e-20, 1e3)
# a relative tolerance can mean something between these: below 1e-14 no step's
# local error test can pass in double precision (unit roundoff 2.2e-16, a few
# digits of margin); above 0.1 a step may carry a tenth of its value as error
# (rtol 0.9 ran silently, 8 % off at the end). The command line's --rtol and
# Experiment(rtol=...) alike; the library's own calls take any value in (0, 1).
RTOL_RANGE = (1e-14, 0.1)


def _check_experiment(exp, path):
    """The Experiment's times and tolerances are numbers in range (``atol``
    may also be a dict of tolerances by variable)."""
    bad = None
    t0, t_end = _number(getattr(exp, "t0", 0.0)), _number(getattr(exp, "t_end", None))
    if t0 is None or not math.isfinite(t0):
        bad = f"t0 = {exp.t0!r} must be a finite number"
    elif t_end is None or not math.isfinite(t_end) or not t_end > t0:
        bad = f"t_end = {exp.t_end!r} must be a finite number after t0 = {exp.t0!r}"
    atol = getattr(exp, "atol", None)
    tolerances = list(atol.values()) if isinstance(atol, dict) else [atol]
    for name in ("rtol", "atol", "output_step", "dense_step", "max_step", "atol_algebraic"):
        value = getattr(exp, name, None)
        values = tolerances if name == "atol" else [value]
        if name == "output_step" and _number(value) == 0:
            continue          # 0: the solver's own steps and events
        if bad is None and (value is not None or name in ("rtol", "atol")) and \
                not all(_positive(v) for v in values):
            bad = f"{name} = {value!r} must be a finite number > 0" + \
                (" (or 0: the solver's steps)" if name == "output_step" else "")
    if bad is None and not all(ATOL_RANGE[0] <= _number(v) <= ATOL_RANGE[1] for v in tolerances):
        bad = (f"atol = {atol!r} is outside {ATOL_RANGE[0]:g} to {ATOL_RANGE[1]:g} (SI units): "
               "above, every position, speed and force counts as zero; below, no solution "
               "gets closer than rtol makes it")
    if bad is None and _positive(exp.rtol) and \
            not RTOL_RANGE[0] <= _number(exp.rtol) <= RTOL_RANGE[1]:
        bad = (f"rtol = {exp.rtol!r} is outside {RTOL_RANGE[0]:g} to {RTOL_RANGE[1]:g}: below, "
               "no step's error test can pass in double precision; above, a step may carry "
               "a tenth of its value as error")
    options = getattr(exp, "options", None)
    if bad is None and options:   # a field no run reads: the settings were silently ignored
        bad = (f"options = {options!r} is not read by any run: give the settings as "
               "Experiment's own arguments (t_end, t0, rtol, atol, output_step, max_step, "
               "atol_algebraic, dense_step, stop)")
    stop = getattr(exp, "stop", None)
    if bad is None and stop is not None and not isinstance(stop, Stop):
        bad = (f"stop = {stop!r} must be an acausal.Stop, e.g. Stop('hook.phi', '<=', -0.1) "
               f"(found {type(stop).__name__})")
    if bad is not None:
        raise _bad(path, "experiment", f"experiment {bad}")


def _free(ns, path):
    """``free_parameters`` as name -> (low, high) floats, low < high."""
    free = ns.get("free_parameters") or {}
    out = {}
    if isinstance(free, dict):
        for name, b in free.items():
            lo, hi = (map(_number, b) if isinstance(b, (tuple, list)) and len(b) == 2
                      else (None, None))
            if lo is None or hi is None or not lo < hi:
                break
            out[name] = (lo, hi)
        else:
            return out
    raise _bad(path, "free_parameters", "'free_parameters' must be a dict of name -> "
               "(low, high) with numbers low < high")


def _measure_units(ns, measures, path):
    """measure -> SI unit from ``measure_units`` or the functions' ``unit``."""
    given = ns.get("measure_units") or {}
    if not isinstance(given, dict) or not all(isinstance(u, str) for u in given.values()):
        raise _bad(path, "measure_units", "'measure_units' must be a dict of measure -> unit")
    unknown = sorted(set(given) - set(measures))
    if unknown:
        raise _bad(path, "measure_units", f"'measure_units' names {unknown[0]!r}, which is "
                   "not a measure")
    units = {name: getattr(fn, "unit", None) for name, fn in measures.items()}
    units.update(given)
    return {k: u for k, u in units.items() if isinstance(u, str)}


def _conditions(ns, path):
    """The ``conditions`` a model file declares, as name -> (low, high,
    unit); a plain list of names has no ranges (None, None, "")."""
    given = ns.get("conditions") or {}
    if isinstance(given, (list, tuple)) and all(isinstance(c, str) for c in given):
        return {name: (None, None, "") for name in given}
    out = {}
    for name, spec in (given.items() if isinstance(given, dict) else [(None, None)]):
        ok = isinstance(name, str) and isinstance(spec, (tuple, list)) and len(spec) in (2, 3)
        low, high = (_number(spec[0]), _number(spec[1])) if ok else (None, None)
        if low is None or high is None or not low < high:
            raise _bad(path, "conditions", f"conditions[{name!r}] must be (low, high) or "
                       f"(low, high, unit) with low < high (found {spec!r}); 'conditions' "
                       "may also be a list of parameter names")
        out[name] = (low, high, str(spec[2]) if len(spec) == 3 else "")
    return out


_CACHE = {}


def _check_names(mf, cm, path):
    """``conditions`` and ``free_parameters`` name free parameters of the
    model, and a condition's unit has its parameter's dimension (a
    ``free_parameters`` entry the model lacks, or a condition range in
    furlongs for a force, passed without a word)."""
    from .data.units import parse_unit
    for what, names in (("conditions", mf.conditions), ("free_parameters", mf.free)):
        for name in names:
            try:
                cm.param_index(name)
            except AcausalError as exc:
                raise _bad(path, what, f"{what}: {exc}") from None
    units = {e.name: e.unit for e in cm.params}
    for name, (_, _, unit) in mf.conditions.items():
        if not unit:
            continue
        try:
            given = parse_unit(unit).dimensionality
        except Exception:  # noqa: BLE001 - pint raises several kinds on what it cannot read
            raise _bad(path, "conditions", f"conditions[{name!r}]: unit {unit!r} is not a "
                       "unit") from None
        try:
            own = parse_unit(units.get(name) or "1").dimensionality
        except Exception:  # noqa: BLE001 - the parameter's unit unreadable: nothing to compare
            continue
        if given != own:
            raise _bad(path, "conditions", f"conditions[{name!r}]: unit {unit!r} does "
                       f"not have the dimension of {name}'s unit [{units.get(name)}]")


def compile_file(path):
    """(ModelFile, CompiledModel) for a model file, compiled once per process
    and file version."""
    apath = os.path.abspath(path)
    key = (apath, os.path.getmtime(apath) if os.path.exists(apath) else None)
    hit = _CACHE.get(key)
    if hit is not None:
        return hit
    mf = load_model_file(apath)
    if mf.experiment.stop is not None:
        mf.model.event(mf.experiment.stop.event(mf.model))
    cm = compile_model(mf.model)
    _check_names(mf, cm, apath)
    _CACHE[key] = (mf, cm)
    return mf, cm


# what the model file's own code (a measure, its plot) may raise and the
# command reports: its errors, sys.exit and os._exit (see no_hard_exit)
FILE_CODE_FAILURES = (Exception, SystemExit, HardExit)


def _measured(fn, result):
    """``float(fn(result))``, run as the model file's code."""
    with no_hard_exit():
        return float(fn(result))


def evaluate_measures(mf, result):
    """name -> float for every measure; a measure that fails raises an error
    naming it."""
    out = {}
    for name, fn in mf.measures.items():
        try:
            out[name] = _measured(fn, result)
        except FILE_CODE_FAILURES as exc:   # sys.exit() in a measure: it failed
            raise ModelFileError(f"{mf.path}: measure {name!r} failed: "
                                 f"{type(exc).__name__}: {exc}") from None
    return out


def measure_unit(mf, name):
    """The SI unit a measure declares (a :class:`~acausal.Measure` or the
    file's ``measure_units``), or None."""
    return mf.measure_unit(name)


def show_measure(mf, name, value):
    """``value`` (SI) as text in the measure's display unit: ``'1.89987 ms'``
    (a measure without a declared unit: the bare number)."""
    fn = mf.measures.get(name)
    if not isinstance(fn, Measure):
        return f"{value:.6g}"
    v, unit = fn.shown(value)
    return f"{v:.6g} {unit}" if unit != "1" else f"{v:.6g}"


def measure_values(mf, result):
    """(name -> float, name -> reason): every measure of the model file; one
    that cannot be computed from this result (an event that never happened,
    say) is NaN in the first dict and has its reason in the second, so the
    others are kept."""
    values, missing = {}, {}
    for name, fn in mf.measures.items():
        try:
            values[name] = _measured(fn, result)
        except FILE_CODE_FAILURES as exc:  # noqa: BLE001 - the model file's code:
            # reported, not raised (a measure's sys.exit() ended the command, results unsaid)
            values[name] = float("nan")
            missing[name] = f"{type(exc).__name__}: {exc}"
            continue
        if values[name] != values[name]:
            missing[name] = "no value (the measure gave NaN)"
    return values, missing


def call_plot(mf, result, path):
    """Call the model file's ``plot(result, path)``; whatever it raises
    (sys.exit included) becomes a ModelFileError naming the file's line
    (a plot function that raised ended the command with a traceback, after
    the run and its CSV)."""
    try:
        with no_hard_exit():
            mf.namespace["plot"](result, path)
    except FILE_CODE_FAILURES as exc:  # noqa: BLE001 - the model file's code
        raise _error(mf.path, _line(exc, mf.path), f"its plot(result, path) failed: "
                     f"{type(exc).__name__}: {_short(exc)}") from None


def _short(exc):
    return " ".join(str(exc).split())[:300]


def run_file(path, params=None, **overrides):
    """Simulate a model file; returns (result, measures)."""
    mf, cm = compile_file(path)
    opts = mf.experiment.run_options()
    opts.update({k: v for k, v in overrides.items() if v is not None})
    res = cm.simulate(params=params, **opts)
    return res, evaluate_measures(mf, res)


def sweep_task(path, point, max_memory=None):
    """One sweep point: the model file compiled once per worker process
    (the compile cache is per process), simulated with ``point`` as
    parameter overrides; returns the measures (NaN for one that cannot be
    computed, with its reason in ``"__missing__"``). ``max_memory``: the
    bytes this worker's run may store (:func:`acausal.runtime.hybrid.simulate`).
    Module-level, so picklable."""
    mf, cm = compile_file(path)
    opts = mf.experiment.run_options()
    if max_memory is not None:
        opts["max_memory"] = max_memory
    values, missing = measure_values(mf, cm.simulate(params=point, **opts))
    return {**values, "__missing__": missing}
