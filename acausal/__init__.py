"""acausal: equation-based (Modelica-style) simulation of mechanisms.

Pipeline, one module per stage: :mod:`.flatten` -> :mod:`.aliases` ->
:mod:`.structure` -> :mod:`.causalize` -> :mod:`.codegen` (all driven by
:mod:`.compile`) -> :mod:`.simulate` -> :mod:`.result`.
"""
from sympy import Piecewise, cos, exp, sin, sqrt  # noqa: F401  (for model files)

from .component import Component, Model
from .compile import CompiledModel, compile_model
from .connectors import Flange, Frame, Port, RotFlange
from .declare import Assertion, Discrete, Event, Parameter, Start, Variable, guess
from .experiment import Experiment, Measure, Stop
from .errors import (AcausalError, ChatteringError, InitializationError, LimitError, ModelError,
                     ParameterError, SolverError, StructuralError)
from .symbols import Eq, der, time

__all__ = [
    "Component", "Model", "CompiledModel", "compile_model", "Flange", "RotFlange", "Frame", "Port",
    "Parameter", "Variable", "Discrete", "Event", "Assertion", "Start", "guess", "der",
    "time", "Eq", "Experiment", "Measure", "Stop", "AcausalError", "ModelError",
    "ParameterError", "StructuralError",
    "InitializationError", "SolverError", "ChatteringError", "LimitError",
]
