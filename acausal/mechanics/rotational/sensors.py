"""Rotational sensors. Sign convention: :mod:`acausal.lang.connectors`."""

from acausal.lang import Component, Eq, RotFlange, Variable, der


from ..partials import (PartialRotAbsoluteSensor, PartialRotRelativeSensor)

__all__ = ["AngleSensor", "SpeedSensor", "AccSensor", "TorqueSensor", "RelAngleSensor", "RelSpeedSensor"]


class AngleSensor(PartialRotAbsoluteSensor):
    """Measures the absolute angle: ``phi = flange.phi`` (takes no torque).

    States: ``phi`` [rad]. Connectors: ``flange``.
    """

    phi = Variable(0.0, "rad", "measured absolute angle")

    def equations(self):
        return [Eq(self.phi, self.flange.phi)]


class SpeedSensor(PartialRotAbsoluteSensor):
    """Measures the absolute angular velocity: ``w = der(flange.phi)``.

    States: ``w`` [rad/s]. Connectors: ``flange``.
    """

    w = Variable(0.0, "rad/s", "measured absolute angular velocity")

    def equations(self):
        return [Eq(self.w, der(self.flange.phi))]


class AccSensor(PartialRotAbsoluteSensor):
    """Measures the absolute angular acceleration: ``a = der(der(flange.phi))``.

    States: ``w`` [rad/s], ``a`` [rad/s^2]. Connectors: ``flange``.
    """

    w = Variable(0.0, "rad/s", "absolute angular velocity")
    a = Variable(0.0, "rad/s^2", "measured absolute angular acceleration")

    def equations(self):
        return [Eq(self.w, der(self.flange.phi)), Eq(self.a, der(self.w))]


class TorqueSensor(Component):
    """Measures the torque transmitted between its two flanges, which it
    joins rigidly: ``flange_a.phi = flange_b.phi``,
    ``flange_a.tau + flange_b.tau = 0``, ``tau = flange_b.tau`` — the same
    sign as a :class:`TorsionSpring`'s ``tau`` in the same place.
    (Modelica's and MTK's TorqueSensor report ``flange_a.tau``, the opposite
    sign.)

    States: ``tau`` [N*m]. Connectors: ``flange_a``, ``flange_b``.
    """

    flange_a = RotFlange("left flange")
    flange_b = RotFlange("right flange")
    tau = Variable(0.0, "N*m", "transmitted torque (as a spring's tau)")

    def equations(self):
        return [Eq(self.flange_a.phi, self.flange_b.phi),
                Eq(self.flange_a.tau + self.flange_b.tau, 0),
                Eq(self.tau, self.flange_b.tau)]


class RelAngleSensor(PartialRotRelativeSensor):
    """Measures ``phi_rel = flange_b.phi - flange_a.phi`` (takes no torque).

    States: ``phi_rel`` [rad]. Connectors: ``flange_a``, ``flange_b``.
    """

    phi_rel = Variable(0.0, "rad", "measured relative angle flange_b.phi - flange_a.phi")

    def equations(self):
        return [Eq(self.phi_rel, self.flange_b.phi - self.flange_a.phi)]


class RelSpeedSensor(PartialRotRelativeSensor):
    """Measures ``w_rel = der(flange_b.phi - flange_a.phi)`` (takes no torque).

    States: ``phi_rel`` [rad], ``w_rel`` [rad/s]. Connectors: ``flange_a``,
    ``flange_b``.
    """

    phi_rel = Variable(0.0, "rad", "relative angle flange_b.phi - flange_a.phi")
    w_rel = Variable(0.0, "rad/s", "measured relative angular velocity")

    def equations(self):
        return [Eq(self.phi_rel, self.flange_b.phi - self.flange_a.phi),
                Eq(self.w_rel, der(self.phi_rel))]
