"""Typed errors. Every error names what is wrong and where (component path,
variable, equation, file and line) so that the command line can print one
readable message instead of a traceback."""


class AcausalError(Exception):
    """Base class of all errors raised by the library."""


class ModelError(AcausalError):
    """The model is not well formed (bad parameter, bad connection, ...)."""


class ParameterError(ModelError):
    """A parameter value is out of its bounds or of the wrong kind."""


class ConnectionError_(ModelError):
    """Connectors that cannot be connected (different domains, ...)."""


class StructuralError(ModelError):
    """The flattened system is structurally singular: equations in excess or
    missing. ``excess`` and ``missing`` list what is involved."""

    def __init__(self, message, excess=(), missing=()):
        super().__init__(message)
        self.excess = list(excess)
        self.missing = list(missing)


class InitializationError(ModelError):
    """No consistent initial point satisfies the fixed start values."""


class SolverError(AcausalError):
    """The integrator failed. ``t`` is the time of failure, ``component`` the
    component most likely responsible, ``result`` what was computed so far."""

    def __init__(self, message, t=None, component=None, result=None):
        super().__init__(message)
        self.t = t
        self.component = component
        self.result = result


class ChatteringError(SolverError):
    """Too many events in a tiny time window."""


class LimitError(SolverError):
    """A limit the caller set (stored output rows, wall time, solver steps)
    stopped the run; ``result`` holds what was computed up to ``t`` and
    ``component`` names the component whose events dominated."""


class ModelFileError(ModelError):
    """A model file could not be loaded; the message names file and line."""
