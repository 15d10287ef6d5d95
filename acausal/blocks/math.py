"""Mathematical blocks (MSL ``Modelica.Blocks.Math``): outputs that are
functions of inputs, with MSL's names, parameters and laws.

Each block is causal: its output follows from its inputs and parameters
(``connect(sine.y, gain.u)``, ``connect(gain.y, torque.tau)``).
"""
import sympy as sp

from acausal.lang import Component, Eq, Parameter
from acausal.lang.connectors import RealInput, RealOutput

from .interfaces import SISO

__all__ = ["Gain", "Add", "Feedback", "Product", "Division", "Abs", "Sin", "Cos", "Atan"]


class Gain(SISO):
    """Output the product of a gain and the input (MSL ``Gain``):
    ``y = k * u``.

    Parameters: ``k`` [1] gain. Connectors: ``u`` (RealInput), ``y``
    (RealOutput).
    """

    k = Parameter(1.0, "1", "gain value multiplied with the input signal")

    def equations(self):
        return [Eq(self.y, self.k * self.u)]


class _SI2SO(Component):
    """Two inputs ``u1``, ``u2`` and one output ``y`` (MSL ``SI2SO``)."""

    u1 = RealInput("connector of the first input signal")
    u2 = RealInput("connector of the second input signal")
    y = RealOutput("connector of the output signal")


class Add(_SI2SO):
    """Weighted sum of two inputs (MSL ``Add``): ``y = k1*u1 + k2*u2``.

    Parameters: ``k1``, ``k2`` [1] gains. Connectors: ``u1``, ``u2``
    (RealInput), ``y`` (RealOutput).
    """

    k1 = Parameter(1.0, "1", "gain of the first input")
    k2 = Parameter(1.0, "1", "gain of the second input")

    def equations(self):
        return [Eq(self.y, self.k1 * self.u1 + self.k2 * self.u2)]


class Feedback(Component):
    """Difference of a command and a feedback signal (MSL ``Feedback``):
    ``y = u1 - u2``.

    Connectors: ``u1`` (RealInput, the command), ``u2`` (RealInput, the
    feedback), ``y`` (RealOutput).
    """

    u1 = RealInput("commanded input")
    u2 = RealInput("feedback input")
    y = RealOutput("difference u1 - u2")

    def equations(self):
        return [Eq(self.y, self.u1 - self.u2)]


class Product(_SI2SO):
    """Product of two inputs (MSL ``Product``): ``y = u1 * u2``.

    Connectors: ``u1``, ``u2`` (RealInput), ``y`` (RealOutput).
    """

    def equations(self):
        return [Eq(self.y, self.u1 * self.u2)]


class Division(_SI2SO):
    """Quotient of two inputs (MSL ``Division``): ``y = u1 / u2``.

    Connectors: ``u1``, ``u2`` (RealInput, ``u2`` must not be 0), ``y``
    (RealOutput).
    """

    def equations(self):
        return [Eq(self.y, self.u1 / self.u2)]


class Abs(SISO):
    """Absolute value of the input (MSL ``Abs``, ``generateEvent = false``):
    ``y = |u|``.

    Connectors: ``u`` (RealInput), ``y`` (RealOutput).
    """

    def equations(self):
        return [Eq(self.y, sp.Abs(self.u))]


class Sin(SISO):
    """Sine of the input (MSL ``Sin``): ``y = sin(u)``, ``u`` in rad.

    Connectors: ``u`` (RealInput), ``y`` (RealOutput).
    """

    def equations(self):
        return [Eq(self.y, sp.sin(self.u))]


class Cos(SISO):
    """Cosine of the input (MSL ``Cos``): ``y = cos(u)``, ``u`` in rad.

    Connectors: ``u`` (RealInput), ``y`` (RealOutput).
    """

    def equations(self):
        return [Eq(self.y, sp.cos(self.u))]


class Atan(SISO):
    """Inverse tangent of the input (MSL ``Atan``): ``y = atan(u)`` in
    (-pi/2, pi/2) rad.

    Connectors: ``u`` (RealInput), ``y`` (RealOutput).
    """

    def equations(self):
        return [Eq(self.y, sp.atan(self.u))]
