"""Rotational (1-D) mechanics: components, sources and sensors.

Sign convention: :mod:`acausal.connectors` (torques positive INTO the
component; angles about one positive axis). Two-flange elements report
``tau`` = ``flange_b.tau`` (positive when the element is twisted
positively, ``phi_rel > phi_rel0`` for a spring) and
``phi_rel = flange_b.phi - flange_a.phi``.

Several components may be connected to one flange (an inertia has a single
flange; the torques of everything connected to it add up there).
"""
from sympy import Basic, SympifyError, sympify

from acausal.lang import Component, Eq, Parameter, RotFlange, Variable, der

from acausal.errors import ParameterError

from .partials import (PartialRotAbsoluteSensor, PartialRotCompliant,
                       PartialRotRelativeSensor, PartialRotRigid, PartialSource)

__all__ = ["Fixed", "Inertia", "TorsionSpring", "RotationalDamper", "SpringDamper",
           "Spring", "Damper", "Torque", "RelativeTorque", "Angle", "AngleSensor", "SpeedSensor",
           "AccSensor", "TorqueSensor", "RelAngleSensor", "RelSpeedSensor"]


# -- components -------------------------------------------------------------------
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


# -- sources --------------------------------------------------------------------
class Torque(PartialSource):
    """A torque ``tau`` applied on ``flange`` about +phi, reacting on the
    fixed frame: ``flange.tau = -tau`` (an inertia there gets
    ``J*der(w) = tau``).

    ``tau`` is a number (run-time parameter ``tau_const``), a sympy
    expression of ``acausal.time`` and parameters, or a function
    ``lambda phi: ...`` / ``lambda phi, w: ...`` of the flange angle (and
    angular velocity) returning a sympy expression — exactly as
    :class:`acausal.mechanics.translational.Force`.

    Parameters: ``tau_const`` [N*m] (only when ``tau`` is a number). States:
    ``tau`` [N*m] the applied torque. Connectors: ``flange``.
    """

    quantity = ("tau", "N*m", "applied torque about +phi")
    across_name = "angle"
    flange = RotFlange("flange the torque acts on")
    tau = Variable(0.0, "N*m", "applied torque about +phi")

    def __init__(self, tau=0.0, **kw):
        super().__init__(tau, **kw)

    def equations(self):
        return [Eq(self.tau, self.law(self.flange.phi)), Eq(self.flange.tau, -self.tau)]


class RelativeTorque(PartialSource, PartialRotCompliant):
    """A torque between two rotational flanges given by a law of their
    relative motion (a nonlinear torsion spring or damper):
    ``tau = law(phi_rel)`` or ``tau = law(phi_rel, w_rel)``, signed as a
    :class:`TorsionSpring`'s ``tau`` (``flange_b.tau = tau``,
    ``flange_a.tau = -tau``; ``tau > 0`` twists flange_b back), with
    ``phi_rel = flange_b.phi - flange_a.phi`` and ``w_rel = der(phi_rel)``.
    The law is given as for :class:`Torque` (a number gives ``tau_const``).

    Parameters: ``tau_const`` [N*m] (only when ``tau`` is a number).
    States: ``phi_rel`` [rad], ``tau`` [N*m]. Connectors: ``flange_a``,
    ``flange_b``.
    """

    quantity = ("tau", "N*m", "torque between the flanges (as a torsion spring's tau)")
    across_name = "relative angle phi_rel"

    def __init__(self, tau=0.0, **kw):
        super().__init__(tau, **kw)

    def equations(self):
        return [Eq(self.tau, self.law(self.phi_rel))]


class Angle(Component):
    """Prescribed rotation: ``flange.phi = phi_ref`` with ``phi_ref`` a sympy
    expression of ``acausal.time`` (and parameters), smooth enough to be
    differentiated twice. The flange takes whatever torque that needs.

    States: ``phi`` [rad]. Connectors: ``flange``.
    """

    diagnosis_site = "driver"   # what acausal.diagnose may extend here

    flange = RotFlange("driven flange")
    phi = Variable(0.0, "rad", "prescribed angle")

    def __init__(self, phi, **kw):
        super().__init__(**kw)
        try:
            expr = sympify(phi, strict=True)
        except SympifyError:
            expr = None
        if not isinstance(expr, Basic) or isinstance(phi, bool):
            raise ParameterError(f"Angle.phi must be a number or a sympy expression of "
                                 f"time, got {phi!r}")
        object.__setattr__(self, "_ref", expr)

    def equations(self):
        return [Eq(self.phi, self._ref), Eq(self.flange.phi, self.phi)]


# -- sensors -------------------------------------------------------------------
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
