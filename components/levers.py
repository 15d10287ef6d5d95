"""Levers and transformers between rotation and translation."""
from sympy import Eq, cos, sin

from acausal import Component, Flange, Parameter, Variable


class TwoArmLever(Component):
    """A massless rigid lever on a fixed pivot with two arms on the same side:
    ``flange_a.s = a * phi``, ``flange_b.s = b * phi`` and torque balance
    ``a * flange_a.f + b * flange_b.f = 0`` (small-angle form; with
    ``exact=True`` the arms see ``arm * sin(phi)``).

    Parameters: ``a``, ``b`` [m] arm lengths, ``exact`` (structural).
    States: ``phi`` [rad] lever angle. Connectors: ``flange_a``, ``flange_b``.
    """

    flange_a = Flange("point on arm a")
    flange_b = Flange("point on arm b")
    a = Parameter(0.1, "m", "arm length to flange_a")
    b = Parameter(0.1, "m", "arm length to flange_b")
    exact = Parameter(False, "1", "use arm*sin(phi) instead of arm*phi", structural=True,
                      choices=(False, True))
    phi = Variable(0.0, "rad", "lever angle")

    def equations(self):
        k = sin(self.phi) if self.exact else self.phi
        dk = cos(self.phi) if self.exact else 1
        return [Eq(self.flange_a.s, self.a * k),
                Eq(self.flange_b.s, self.b * k),
                Eq(self.a * dk * self.flange_a.f + self.b * dk * self.flange_b.f, 0)]
