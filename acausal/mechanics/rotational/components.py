"""Rotational components. Sign convention: :mod:`acausal.lang.connectors`."""

from acausal.lang import Component, Eq, Parameter, RotFlange, der


from ..partials import (PartialRotCompliant,
                       PartialRotRigid)

__all__ = ["Fixed", "Inertia", "TorsionSpring", "RotationalDamper", "SpringDamper", "Spring", "Damper"]


class Fixed(Component):
    """A rotational flange fixed at angle ``phi0``: ``flange.phi = phi0``.

    Parameters: ``phi0`` [rad] angle. Connectors: ``flange``.
    """

    diagnosis_site = "ground"   # what acausal.diagnose may extend here

    flange = RotFlange("fixed flange")
    phi0 = Parameter(0.0, "rad", "fixed angle")

    def equations(self):
        return [Eq(self.flange.phi, self.phi0)]


class Inertia(PartialRotRigid):
    """A rotating body: ``J * der(w) = flange.tau`` (the sum of the torques
    of everything connected to its flange).

    Parameters: ``J`` [kg*m^2] moment of inertia (> 0). States: ``phi``
    [rad], ``w`` [rad/s]. Connectors: ``flange``.
    """

    J = Parameter(1.0, "kg*m^2", "moment of inertia", min=0.0, min_open=True)

    def equations(self):
        return [Eq(self.J * der(self.w), self.flange.tau)]


class TorsionSpring(PartialRotCompliant):
    """Linear torsion spring: ``tau = c * (phi_rel - phi_rel0) + tau0``.

    With ``tau0 = 0`` (default) ``phi_rel0`` is the unstretched angle. For a
    preloaded spring set ``phi_rel0`` to the installed relative angle and
    ``tau0`` to the installed torque there (sign as ``tau``: the torque the
    outside applies on ``flange_b``); the free angle is
    ``phi_rel0 - tau0 / c``.

    Parameters: ``c`` [N*m/rad] stiffness (>= 0), ``phi_rel0`` [rad]
    reference angle, ``tau0`` [N*m] torque at ``phi_rel0`` (preload).
    States: ``phi_rel`` [rad], ``tau`` [N*m]. Connectors: ``flange_a``,
    ``flange_b``.
    """

    c = Parameter(1.0, "N*m/rad", "spring constant", min=0.0)
    phi_rel0 = Parameter(0.0, "rad", "reference angle (unstretched when tau0 = 0)")
    tau0 = Parameter(0.0, "N*m", "torque at phi_rel = phi_rel0 (preload)")

    def equations(self):
        return [Eq(self.tau, self.c * (self.phi_rel - self.phi_rel0) + self.tau0)]


class RotationalDamper(PartialRotCompliant):
    """Linear rotational damper: ``tau = d * der(phi_rel)``.

    Parameters: ``d`` [N*m*s/rad] damping constant (>= 0). States:
    ``phi_rel`` [rad], ``tau`` [N*m]. Connectors: ``flange_a``, ``flange_b``.
    """

    d = Parameter(0.0, "N*m*s/rad", "damping constant", min=0.0)

    def equations(self):
        return [Eq(self.tau, self.d * der(self.phi_rel))]


class SpringDamper(PartialRotCompliant):
    """Torsion spring and damper in parallel:
    ``tau = c * (phi_rel - phi_rel0) + tau0 + d * der(phi_rel)``
    (``phi_rel0``/``tau0`` as in :class:`TorsionSpring`).

    Parameters: ``c`` [N*m/rad] (>= 0), ``phi_rel0`` [rad], ``tau0`` [N*m],
    ``d`` [N*m*s/rad] (>= 0). States: ``phi_rel`` [rad], ``tau`` [N*m].
    Connectors: ``flange_a``, ``flange_b``.
    """

    c = Parameter(1.0, "N*m/rad", "spring constant", min=0.0)
    phi_rel0 = Parameter(0.0, "rad", "reference angle (unstretched when tau0 = 0)")
    tau0 = Parameter(0.0, "N*m", "spring torque at phi_rel = phi_rel0 (preload)")
    d = Parameter(0.0, "N*m*s/rad", "damping constant", min=0.0)

    def equations(self):
        return [Eq(self.tau, self.c * (self.phi_rel - self.phi_rel0) + self.tau0
                   + self.d * der(self.phi_rel))]


# Modelica / ModelingToolkitStandardLibrary names
Spring = TorsionSpring
Damper = RotationalDamper
