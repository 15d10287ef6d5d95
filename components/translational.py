"""Translational (1-D) mechanics. Sign convention: :mod:`acausal.connectors`."""
from sympy import Eq

from acausal import Component, Flange, Parameter, der

from .partials import PartialCompliant, PartialRigid


class Fixed(Component):
    """A flange fixed at position ``s0``.

    Parameters: ``s0`` [m] position. Connectors: ``flange``.
    """

    flange = Flange("fixed flange")
    s0 = Parameter(0.0, "m", "fixed position")

    def equations(self):
        return [Eq(self.flange.s, self.s0)]


class Mass(PartialRigid):
    """A point mass: ``m * der(v) = flange.f``.

    Parameters: ``m`` [kg] mass (> 0). States: ``s`` [m], ``v`` [m/s].
    Connectors: ``flange``.
    """

    m = Parameter(1.0, "kg", "mass", min=0.0, min_open=True)

    def equations(self):
        return [Eq(self.m * der(self.v), self.flange.f)]


class Spring(PartialCompliant):
    """Linear spring: ``f = c * (s_rel - s_rel0)``.

    Parameters: ``c`` [N/m] stiffness (>= 0), ``s_rel0`` [m] free length.
    Connectors: ``flange_a``, ``flange_b``.
    """

    c = Parameter(1.0, "N/m", "spring constant", min=0.0)
    s_rel0 = Parameter(0.0, "m", "unstretched length")

    def equations(self):
        return [Eq(self.f, self.c * (self.s_rel - self.s_rel0))]


class Damper(PartialCompliant):
    """Linear damper: ``f = d * der(s_rel)``.

    Parameters: ``d`` [N*s/m] damping constant (>= 0).
    Connectors: ``flange_a``, ``flange_b``.
    """

    d = Parameter(0.0, "N*s/m", "damping constant", min=0.0)

    def equations(self):
        return [Eq(self.f, self.d * der(self.s_rel))]
