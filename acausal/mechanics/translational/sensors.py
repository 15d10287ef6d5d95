"""Translational sensors (MSL ``Translational.Sensors``): ideal, they take
no force (absolute and relative sensors) or pass it through unchanged
(force, power and multi sensors). The measured values are ``RealOutput``
signals where MSL has them (``connect(sensor.v, block.u)``), named as in
MSL, and are read from a result under the same names (``res["ps.s"]``).
Sign convention: :mod:`acausal.lang.connectors`.

Signs are MSL's: a force sensor's ``f`` is ``flange_a.f``, the force on
the sensor at ``flange_a`` (a source pushing on ``flange_a`` reads
positive; in series in place of a :class:`~.components.Spring` under
tension it reads ``-spring.f``); ``power`` is the power entering at
``flange_a``.
"""

from acausal.lang import Eq, Variable, der
from acausal.lang.connectors import RealOutput

from ..partials import PartialAbsoluteSensor, PartialFlowSensor, PartialRelativeSensor

__all__ = ["PositionSensor", "SpeedSensor", "AccSensor", "ForceSensor", "PowerSensor",
           "MultiSensor", "RelPositionSensor", "RelSpeedSensor", "RelAccSensor"]


class PositionSensor(PartialAbsoluteSensor):
    """Measures the absolute position (MSL ``PositionSensor``): ``s =
    flange.s`` (takes no force).

    Connectors: ``flange``, ``s`` [m] (RealOutput).
    """

    s = RealOutput("absolute position of the flange", "m")

    def equations(self):
        return [Eq(self.s, self.flange.s)]


class SpeedSensor(PartialAbsoluteSensor):
    """Measures the absolute velocity (MSL ``SpeedSensor``): ``v =
    der(flange.s)``.

    Connectors: ``flange``, ``v`` [m/s] (RealOutput).
    """

    v = RealOutput("absolute velocity of the flange", "m/s")

    def equations(self):
        return [Eq(self.v, der(self.flange.s))]


class AccSensor(PartialAbsoluteSensor):
    """Measures the absolute acceleration (MSL ``AccSensor``): ``v =
    der(flange.s)``, ``a = der(v)``.

    States: ``v`` [m/s]. Connectors: ``flange``, ``a`` [m/s2] (RealOutput).
    """

    v = Variable(0.0, "m/s", "absolute velocity of the flange")
    a = RealOutput("absolute acceleration of the flange", "m/s2")

    def equations(self):
        return [Eq(self.v, der(self.flange.s)), Eq(self.a, der(self.v))]


class ForceSensor(PartialFlowSensor):
    """Measures the force transmitted between its two flanges, which it
    joins rigidly (MSL ``ForceSensor``): ``f = flange_a.f = -flange_b.f``,
    the force acting on the sensor at ``flange_a`` (MSL's sign: a source
    pushing on ``flange_a`` with ``f > 0`` reads ``f``; in place of a
    spring under tension it reads ``-spring.f``).

    Connectors: ``flange_a``, ``flange_b``, ``f`` [N] (RealOutput).
    """

    f = RealOutput("force in flange_a and flange_b (f = flange_a.f = -flange_b.f)", "N")

    def equations(self):
        return [Eq(self.f, self.flange_a.f)]


class PowerSensor(PartialFlowSensor):
    """Measures the power transmitted between its two flanges (MSL
    ``PowerSensor``): ``power = flange_a.f * der(flange_a.s)``, the power
    entering at ``flange_a`` (positive when it flows from the flange_a side
    to the flange_b side).

    Connectors: ``flange_a``, ``flange_b``, ``power`` [W] (RealOutput).
    """

    power = RealOutput("power entering at flange_a, flange_a.f * der(flange_a.s)", "W")

    def equations(self):
        return [Eq(self.power, self.flange_a.f * der(self.flange_a.s))]


class MultiSensor(PartialFlowSensor):
    """Measures force, velocity and power at once (MSL ``MultiSensor``):
    ``f = flange_a.f`` (as :class:`ForceSensor`), ``v = der(flange_a.s)``,
    ``power = f * v`` (the power entering at ``flange_a``).

    Connectors: ``flange_a``, ``flange_b``, ``f`` [N], ``v`` [m/s],
    ``power`` [W] (RealOutputs).
    """

    f = RealOutput("force in flange_a and flange_b (f = flange_a.f = -flange_b.f)", "N")
    v = RealOutput("absolute velocity of the flanges", "m/s")
    power = RealOutput("power entering at flange_a, f * v", "W")

    def equations(self):
        return [Eq(self.f, self.flange_a.f), Eq(self.v, der(self.flange_a.s)),
                Eq(self.power, self.f * self.v)]


class RelPositionSensor(PartialRelativeSensor):
    """Measures ``s_rel = flange_b.s - flange_a.s`` (MSL
    ``RelPositionSensor``; takes no force).

    Connectors: ``flange_a``, ``flange_b``, ``s_rel`` [m] (RealOutput).
    """

    s_rel = RealOutput("relative position flange_b.s - flange_a.s", "m")

    def equations(self):
        return [Eq(self.s_rel, self.flange_b.s - self.flange_a.s)]


class RelSpeedSensor(PartialRelativeSensor):
    """Measures ``v_rel = der(s_rel)`` (MSL ``RelSpeedSensor``; takes no
    force).

    States: ``s_rel`` [m]. Connectors: ``flange_a``, ``flange_b``,
    ``v_rel`` [m/s] (RealOutput).
    """

    s_rel = Variable(0.0, "m", "relative position flange_b.s - flange_a.s")
    v_rel = RealOutput("relative velocity der(s_rel)", "m/s")

    def equations(self):
        return [Eq(self.s_rel, self.flange_b.s - self.flange_a.s),
                Eq(self.v_rel, der(self.s_rel))]


class RelAccSensor(PartialRelativeSensor):
    """Measures ``a_rel = der(v_rel)``, ``v_rel = der(s_rel)`` (MSL
    ``RelAccSensor``; takes no force).

    States: ``s_rel`` [m], ``v_rel`` [m/s]. Connectors: ``flange_a``,
    ``flange_b``, ``a_rel`` [m/s2] (RealOutput).
    """

    s_rel = Variable(0.0, "m", "relative position flange_b.s - flange_a.s")
    v_rel = Variable(0.0, "m/s", "relative velocity der(s_rel)")
    a_rel = RealOutput("relative acceleration der(v_rel)", "m/s2")

    def equations(self):
        return [Eq(self.s_rel, self.flange_b.s - self.flange_a.s),
                Eq(self.v_rel, der(self.s_rel)), Eq(self.a_rel, der(self.v_rel))]
