"""Rotational sensors (MSL ``Rotational.Sensors``): ideal, they take no
torque (absolute and relative sensors) or pass it through unchanged
(torque, power and multi sensors). The measured values are ``RealOutput``
signals where MSL has them, named as in MSL, and are read from a result
under the same names (``res["ang.phi"]``). Sign convention:
:mod:`acausal.lang.connectors`.

Signs are MSL's: a torque sensor's ``tau`` is ``flange_a.tau``, the
torque on the sensor at ``flange_a`` (in place of a twisted
:class:`~.components.TorsionSpring` it reads ``-spring.tau``); ``power``
is the power entering at ``flange_a``.
"""

from acausal.lang import Eq, Variable, der
from acausal.lang.connectors import RealOutput

from ..partials import PartialRotAbsoluteSensor, PartialRotFlowSensor, PartialRotRelativeSensor

__all__ = ["AngleSensor", "SpeedSensor", "AccSensor", "TorqueSensor", "PowerSensor",
           "MultiSensor", "RelAngleSensor", "RelSpeedSensor", "RelAccSensor"]


class AngleSensor(PartialRotAbsoluteSensor):
    """Measures the absolute angle (MSL ``AngleSensor``): ``phi =
    flange.phi`` (takes no torque).

    Connectors: ``flange``, ``phi`` [rad] (RealOutput).
    """

    phi = RealOutput("absolute angle of the flange", "rad")

    def equations(self):
        return [Eq(self.phi, self.flange.phi)]


class SpeedSensor(PartialRotAbsoluteSensor):
    """Measures the absolute angular velocity (MSL ``SpeedSensor``): ``w =
    der(flange.phi)``.

    Connectors: ``flange``, ``w`` [rad/s] (RealOutput).
    """

    w = RealOutput("absolute angular velocity of the flange", "rad/s")

    def equations(self):
        return [Eq(self.w, der(self.flange.phi))]


class AccSensor(PartialRotAbsoluteSensor):
    """Measures the absolute angular acceleration (MSL ``AccSensor``):
    ``w = der(flange.phi)``, ``a = der(w)``.

    States: ``w`` [rad/s]. Connectors: ``flange``, ``a`` [rad/s2]
    (RealOutput).
    """

    w = Variable(0.0, "rad/s", "absolute angular velocity of the flange")
    a = RealOutput("absolute angular acceleration of the flange", "rad/s2")

    def equations(self):
        return [Eq(self.w, der(self.flange.phi)), Eq(self.a, der(self.w))]


class TorqueSensor(PartialRotFlowSensor):
    """Measures the torque transmitted between its two flanges, which it
    joins rigidly (MSL ``TorqueSensor``): ``tau = flange_a.tau =
    -flange_b.tau``, the torque acting on the sensor at ``flange_a`` (MSL's
    sign: a source driving ``flange_a`` with ``tau > 0`` reads ``tau``; in
    place of a twisted spring it reads ``-spring.tau``).

    Connectors: ``flange_a``, ``flange_b``, ``tau`` [N*m] (RealOutput).
    """

    tau = RealOutput("torque in flange_a and flange_b (tau = flange_a.tau = -flange_b.tau)",
                     "N*m")

    def equations(self):
        return [Eq(self.tau, self.flange_a.tau)]


class PowerSensor(PartialRotFlowSensor):
    """Measures the power transmitted between its two flanges (MSL
    ``PowerSensor``): ``power = flange_a.tau * der(flange_a.phi)``, the
    power entering at ``flange_a``.

    Connectors: ``flange_a``, ``flange_b``, ``power`` [W] (RealOutput).
    """

    power = RealOutput("power entering at flange_a, flange_a.tau * der(flange_a.phi)", "W")

    def equations(self):
        return [Eq(self.power, self.flange_a.tau * der(self.flange_a.phi))]


class MultiSensor(PartialRotFlowSensor):
    """Measures torque, angular velocity and power at once (MSL
    ``MultiSensor``): ``tau = flange_a.tau`` (as :class:`TorqueSensor`),
    ``w = der(flange_a.phi)``, ``power = tau * w`` (the power entering at
    ``flange_a``).

    Connectors: ``flange_a``, ``flange_b``, ``tau`` [N*m], ``w`` [rad/s],
    ``power`` [W] (RealOutputs).
    """

    tau = RealOutput("torque in flange_a and flange_b (tau = flange_a.tau = -flange_b.tau)",
                     "N*m")
    w = RealOutput("absolute angular velocity of the flanges", "rad/s")
    power = RealOutput("power entering at flange_a, tau * w", "W")

    def equations(self):
        return [Eq(self.tau, self.flange_a.tau), Eq(self.w, der(self.flange_a.phi)),
                Eq(self.power, self.tau * self.w)]


class RelAngleSensor(PartialRotRelativeSensor):
    """Measures ``phi_rel = flange_b.phi - flange_a.phi`` (MSL
    ``RelAngleSensor``; takes no torque).

    Connectors: ``flange_a``, ``flange_b``, ``phi_rel`` [rad] (RealOutput).
    """

    phi_rel = RealOutput("relative angle flange_b.phi - flange_a.phi", "rad")

    def equations(self):
        return [Eq(self.phi_rel, self.flange_b.phi - self.flange_a.phi)]


class RelSpeedSensor(PartialRotRelativeSensor):
    """Measures ``w_rel = der(phi_rel)`` (MSL ``RelSpeedSensor``; takes no
    torque).

    States: ``phi_rel`` [rad]. Connectors: ``flange_a``, ``flange_b``,
    ``w_rel`` [rad/s] (RealOutput).
    """

    phi_rel = Variable(0.0, "rad", "relative angle flange_b.phi - flange_a.phi")
    w_rel = RealOutput("relative angular velocity der(phi_rel)", "rad/s")

    def equations(self):
        return [Eq(self.phi_rel, self.flange_b.phi - self.flange_a.phi),
                Eq(self.w_rel, der(self.phi_rel))]


class RelAccSensor(PartialRotRelativeSensor):
    """Measures ``a_rel = der(w_rel)``, ``w_rel = der(phi_rel)`` (MSL
    ``RelAccSensor``; takes no torque).

    States: ``phi_rel`` [rad], ``w_rel`` [rad/s]. Connectors: ``flange_a``,
    ``flange_b``, ``a_rel`` [rad/s2] (RealOutput).
    """

    phi_rel = Variable(0.0, "rad", "relative angle flange_b.phi - flange_a.phi")
    w_rel = Variable(0.0, "rad/s", "relative angular velocity der(phi_rel)")
    a_rel = RealOutput("relative angular acceleration der(w_rel)", "rad/s2")

    def equations(self):
        return [Eq(self.phi_rel, self.flange_b.phi - self.flange_a.phi),
                Eq(self.w_rel, der(self.phi_rel)), Eq(self.a_rel, der(self.w_rel))]
