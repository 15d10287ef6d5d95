"""Rotational (1-D) mechanics. Sign convention: :mod:`acausal.connectors`."""
from sympy import Eq

from acausal import Component, Parameter, RotFlange, der

from .partials import PartialRotCompliant, PartialRotRigid


class Fixed(Component):
    """A rotational flange fixed at angle ``phi0``.

    Parameters: ``phi0`` [rad] angle. Connectors: ``flange``.
    """

    flange = RotFlange("fixed flange")
    phi0 = Parameter(0.0, "rad", "fixed angle")

    def equations(self):
        return [Eq(self.flange.phi, self.phi0)]


class Inertia(PartialRotRigid):
    """A rotating body: ``J * der(w) = flange.tau``.

    Parameters: ``J`` [kg*m^2] moment of inertia (> 0). States: ``phi``
    [rad], ``w`` [rad/s]. Connectors: ``flange``.
    """

    J = Parameter(1.0, "kg*m^2", "moment of inertia", min=0.0, min_open=True)

    def equations(self):
        return [Eq(self.J * der(self.w), self.flange.tau)]


class TorsionSpring(PartialRotCompliant):
    """Linear torsion spring: ``tau = c * (phi_rel - phi_rel0)``.

    Parameters: ``c`` [N*m/rad] stiffness (>= 0), ``phi_rel0`` [rad]
    unstretched angle. Connectors: ``flange_a``, ``flange_b``.
    """

    c = Parameter(1.0, "N*m/rad", "spring constant", min=0.0)
    phi_rel0 = Parameter(0.0, "rad", "unstretched relative angle")

    def equations(self):
        return [Eq(self.tau, self.c * (self.phi_rel - self.phi_rel0))]


class RotationalDamper(PartialRotCompliant):
    """Linear rotational damper: ``tau = d * der(phi_rel)``.

    Parameters: ``d`` [N*m*s/rad] damping constant (>= 0).
    Connectors: ``flange_a``, ``flange_b``.
    """

    d = Parameter(0.0, "N*m*s/rad", "damping constant", min=0.0)

    def equations(self):
        return [Eq(self.tau, self.d * der(self.phi_rel))]
