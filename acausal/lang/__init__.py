"""The modelling language: what a model file is written in.

Components (:class:`Component`, :class:`Model`), connectors (the one sign
convention, :mod:`.connectors`), declarations (parameters with units and
bounds, variables with start values, discretes, events, assertions),
``time`` and ``der``, and the simulation settings of a model file
(:class:`Experiment`, :class:`Measure`, :class:`Stop`).

This layer knows nothing of compiling or simulating: it depends only on
:mod:`acausal.errors` (and, for units, :mod:`acausal.data.units`).
"""
from .component import Component, Model
from .connectors import Connector, Flange, Frame, Port, RealInput, RealOutput, RotFlange
from .declare import Assertion, Discrete, Event, Parameter, Start, TimeEvent, Variable, guess
from .experiment import Experiment, Measure, Stop
from .symbols import Eq, der, time

__all__ = ["Component", "Model", "Connector", "Flange", "RotFlange", "Frame", "Port",
           "RealInput", "RealOutput",
           "Parameter", "Variable", "Discrete", "Event", "TimeEvent", "Assertion", "Start", "guess",
           "Experiment", "Measure", "Stop", "Eq", "der", "time"]
