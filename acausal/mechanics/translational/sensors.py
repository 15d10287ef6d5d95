"""Translational sensors. Sign convention: :mod:`acausal.lang.connectors`."""

from acausal.lang import Component, Eq, Flange, Variable, der


from ..partials import (PartialAbsoluteSensor, PartialRelativeSensor)

__all__ = ["PositionSensor", "SpeedSensor", "AccSensor", "ForceSensor", "RelPositionSensor", "RelSpeedSensor"]


class PositionSensor(PartialAbsoluteSensor):
    """Measures the absolute position: ``s = flange.s`` (takes no force).

    States: ``s`` [m]. Connectors: ``flange``.
    """

    s = Variable(0.0, "m", "measured absolute position")

    def equations(self):
        return [Eq(self.s, self.flange.s)]


class SpeedSensor(PartialAbsoluteSensor):
    """Measures the absolute velocity: ``v = der(flange.s)``.

    States: ``v`` [m/s]. Connectors: ``flange``.
    """

    v = Variable(0.0, "m/s", "measured absolute velocity")

    def equations(self):
        return [Eq(self.v, der(self.flange.s))]


class AccSensor(PartialAbsoluteSensor):
    """Measures the absolute acceleration: ``a = der(der(flange.s))``.

    States: ``v`` [m/s], ``a`` [m/s^2]. Connectors: ``flange``.
    """

    v = Variable(0.0, "m/s", "absolute velocity")
    a = Variable(0.0, "m/s^2", "measured absolute acceleration")

    def equations(self):
        return [Eq(self.v, der(self.flange.s)), Eq(self.a, der(self.v))]


class ForceSensor(Component):
    """Measures the force transmitted between its two flanges, which it
    joins rigidly: ``flange_a.s = flange_b.s``, ``flange_a.f + flange_b.f = 0``,
    ``f = flange_b.f`` — tension positive, the same sign as a
    :class:`Spring`'s ``f`` in the same place. (Modelica's and MTK's
    ForceSensor report ``flange_a.f``, the opposite sign.)

    States: ``f`` [N]. Connectors: ``flange_a``, ``flange_b``.
    """

    flange_a = Flange("left flange")
    flange_b = Flange("right flange")
    f = Variable(0.0, "N", "transmitted force (tension positive)")

    def equations(self):
        return [Eq(self.flange_a.s, self.flange_b.s),
                Eq(self.flange_a.f + self.flange_b.f, 0),
                Eq(self.f, self.flange_b.f)]


class RelPositionSensor(PartialRelativeSensor):
    """Measures ``s_rel = flange_b.s - flange_a.s`` (takes no force).

    States: ``s_rel`` [m]. Connectors: ``flange_a``, ``flange_b``.
    """

    s_rel = Variable(0.0, "m", "measured relative position flange_b.s - flange_a.s")

    def equations(self):
        return [Eq(self.s_rel, self.flange_b.s - self.flange_a.s)]


class RelSpeedSensor(PartialRelativeSensor):
    """Measures ``v_rel = der(flange_b.s - flange_a.s)`` (takes no force).

    States: ``s_rel`` [m], ``v_rel`` [m/s]. Connectors: ``flange_a``,
    ``flange_b``.
    """

    s_rel = Variable(0.0, "m", "relative position flange_b.s - flange_a.s")
    v_rel = Variable(0.0, "m/s", "measured relative velocity")

    def equations(self):
        return [Eq(self.s_rel, self.flange_b.s - self.flange_a.s),
                Eq(self.v_rel, der(self.s_rel))]
