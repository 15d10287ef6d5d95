"""Typed errors. Every error a user can cause is an :class:`AcausalError`
subclass that names what is wrong and where (component path, variable,
file, line and column, time), so that the command line prints one readable
line instead of a traceback. Anything else that escapes is a bug.

Hierarchy::

    AcausalError                      payload: component, variable, file, line, column, t
      ModelError                      the model is not well formed
        ParameterError                a parameter value is not allowed
        ConnectionError_              connectors that cannot be joined
        StructuralError               structurally singular (excess, missing)
        InitializationError           no consistent initial point
        ModelFileError                a model file could not be loaded
      DataError                       a measured-data file is wrong (file:line, column)
      CalibrationError                a calibration cannot be carried out
      AnalysisError                   a linearisation or trim cannot be carried out
      DiagnosisError                  a diagnosis cannot be carried out
      SolverError                     the integrator failed (t, component, result)
        ChatteringError               too many events in a tiny window
        LimitError                    a limit stopped the run (the partial result kept)
          Interrupted                 Ctrl-C, SIGTERM or a watchdog stopped the run
      UsageError                      an option or argument that cannot be used
        BudgetError                   the work asked for exceeds a budget (before it starts)
"""
import re

_PAYLOAD = ("component", "variable", "file", "line", "column", "t")


def _restore(cls, args, state):
    """Unpickle an error without calling its ``__init__`` (whose signature
    differs between subclasses)."""
    err = cls.__new__(cls)
    Exception.__init__(err, *args)
    err.__dict__.update(state)
    return err


def _picklable(state):
    """``state`` with each value that cannot be pickled replaced by None: a
    SolverError's partial ``result`` holds its compiled model, whose
    components may be classes of a model file (module ``__acausal_model__``),
    which no other process can import. Raised in a process pool's worker,
    such an error could not be sent back: the worker died and the pool with
    it (a detection-power run lost its last 25 cases to one truth that IDA
    could not integrate). The message and the location always travel."""
    import pickle
    out = {}
    for key, value in state.items():
        try:
            pickle.dumps(value)
        except Exception:   # noqa: BLE001 - any failure to pickle: leave it behind
            value = None
        out[key] = value
    return out


class AcausalError(Exception):
    """Base class of every error a user can cause.

    ``message`` says what is wrong; the optional keyword arguments say where:
    ``component`` (dotted path), ``variable``, ``file``, ``line``, ``column``
    and ``t`` (simulated time [s]). ``str()`` gives one line: the location
    (``file:line:``, ``column 'c':``, ``at t = ...``) not already in the
    message, then the message with its line breaks joined.
    """

    def __init__(self, message="", *, component=None, variable=None, file=None,
                 line=None, column=None, t=None):
        super().__init__(message)
        self.message = str(message)
        self.component, self.variable = component, variable
        self.file, self.line, self.column, self.t = file, line, column, t

    def __reduce__(self):  # keep the payload when pickled (dask workers, ...)
        return _restore, (type(self), self.args, _picklable(self.__dict__))

    def location(self):
        """The location prefix of :meth:`__str__` (``''`` when none is known
        or the message already starts with it)."""
        parts = []
        file = getattr(self, "file", None)
        if file is not None and not self.message.startswith(str(file)):
            line = getattr(self, "line", None)
            parts.append(f"{file}:{line}" if line is not None else str(file))
        column = getattr(self, "column", None)
        if column is not None and f"column '{column}'" not in self.message:
            parts.append(f"column '{column}'")
        return ": ".join(parts)

    def __str__(self):
        text = getattr(self, "message", None) or (str(self.args[0]) if self.args else "")
        text = re.sub(r"([.:;,]?)\s*\n\s*(?:- )?",
                      lambda m: ": " if m.group(1) == ":" else "; ", text.strip())
        where = self.location()
        return f"{where}: {text}" if where else text


class ModelError(AcausalError):
    """The model is not well formed (bad parameter, bad connection, ...)."""


class ParameterError(ModelError):
    """A parameter value is out of its bounds or of the wrong kind;
    ``variable`` names the parameter."""


class ConnectionError_(ModelError):
    """Connectors that cannot be connected (different domains, ...)."""


class StructuralError(ModelError):
    """The flattened system is structurally singular: equations in excess or
    missing. ``excess`` and ``missing`` list what is involved."""

    def __init__(self, message, excess=(), missing=(), **where):
        super().__init__(message, **where)
        self.excess = list(excess)
        self.missing = list(missing)


class InitializationError(ModelError):
    """No consistent initial point satisfies the fixed start values."""


class SolverError(AcausalError):
    """The integrator failed. ``t`` is the time of failure, ``component`` the
    component most likely responsible, ``result`` what was computed so far."""

    def __init__(self, message, t=None, component=None, result=None, **where):
        super().__init__(message, t=t, component=component, **where)
        self.result = result


class ChatteringError(SolverError):
    """Too many events in a tiny time window."""


class LimitError(SolverError):
    """A limit the caller set (stored output rows, wall time, solver steps)
    stopped the run; ``result`` holds what was computed up to ``t`` and
    ``component`` names the component whose events dominated."""


class Interrupted(LimitError):
    """The run was interrupted (Ctrl-C, SIGTERM, a memory or wall-time
    watchdog); ``result`` holds what was computed up to ``t``."""


class ModelFileError(ModelError):
    """A model file could not be loaded; the message names file and line."""


class DataError(AcausalError):
    """A problem in a data file, located by ``file``, ``line`` and ``column``
    (a column name).

    The message reads ``file:LINE: column 'NAME': reason``; parts that are
    unknown (``None``) are left out. ``reason`` is the bare reason.
    """

    def __init__(self, reason, file=None, line=None, column=None):
        super().__init__(reason, file=file, line=line, column=column)
        self.reason = reason


class CalibrationError(AcausalError):
    """The calibration could not be carried out (no bracket, no data...)."""


class DiagnosisError(AcausalError):
    """The diagnosis could not be carried out (bad data, no fit, ...)."""


class AnalysisError(AcausalError):
    """A linearisation or trim cannot be carried out: an operating point
    that is not consistent, a name that is not an input, state or output,
    no static equilibrium (:mod:`acausal.analysis`)."""


class UsageError(AcausalError):
    """An option or argument that cannot be used as given (a malformed
    ``--param`` spec, ``workers=0``, a missing optional package, ...)."""


class BudgetError(UsageError):
    """The work asked for exceeds a budget before anything runs (memory
    estimated as points x rows, a count of points or rows): a usage error."""


class OutputGridError(BudgetError, LimitError):
    """An output grid of more rows than ``max_rows`` (or than the memory
    limit holds), refused before the run: a usage error, and a LimitError
    as it always was for callers that catch one."""


class UnknownNameError(AcausalError, KeyError):
    """A name that is not there (a variable of a result, an experiment of a
    dataset). Also a ``KeyError``, so that mappings keep their meaning."""


class MeasureError(AcausalError):
    """A measure cannot be computed from a result (no impact, no event)."""
