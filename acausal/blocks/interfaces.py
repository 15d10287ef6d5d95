"""Partial blocks (MSL ``Modelica.Blocks.Interfaces``): the causal signal
connectors and the partial models that own them.

A block is a causal component: its outputs follow from its inputs, its
parameters and ``time`` (:class:`~acausal.lang.connectors.RealInput`,
:class:`~acausal.lang.connectors.RealOutput`; a signal connector is its own
variable, see :mod:`acausal.lang.connectors`). ``model.connect(src.y,
clutch.f_normalized)`` sets the input to the output.
"""
from acausal.lang import Component, Parameter
from acausal.lang.connectors import RealInput, RealOutput

__all__ = ["RealInput", "RealOutput", "SO", "SI", "SISO", "SignalSource"]


class SO(Component):
    """A block with one output (MSL ``SO``).

    Connectors: ``y`` (RealOutput).
    """

    y = RealOutput("output signal")


class SI(Component):
    """A block with one input (MSL ``SI``).

    Connectors: ``u`` (RealInput).
    """

    u = RealInput("input signal")


class SISO(SI, SO):
    """A block with one input and one output (MSL ``SISO``).

    Connectors: ``u`` (RealInput), ``y`` (RealOutput).
    """


class SignalSource(SO):
    """A signal source (MSL ``SignalSource``): ``y = offset + (a law of time
    that is zero before startTime)``; a leaf adds that law.

    Parameters: ``offset`` (the output's unit) added to the output,
    ``startTime`` [s] when the law starts. Connectors: ``y`` (RealOutput).
    Signal values (offset, height, amplitude, k) carry the unit of the
    signal, which is not declared (MSL's plain ``Real`` signals): the unit
    check leaves them out.
    """

    offset = Parameter(0.0, None, "offset added to the output signal (the output's unit)")
    startTime = Parameter(0.0, "s", "output = offset for time < startTime")
