"""Rotational sources (MSL ``Rotational.Sources``): torques given as
signals, laws or speed-dependent characteristics, and prescribed motion.
Sign convention: :mod:`acausal.lang.connectors`."""
import sympy as sp
from sympy import Basic, Piecewise, SympifyError, sympify

from acausal.lang import Component, Eq, Parameter, RotFlange, Variable, time

from acausal.errors import ParameterError

from ..partials import (PartialRotCompliant, PartialRotElementaryOneFlangeAndSupport2,
                        PartialSource, PartialTorque, SourceValue)
from ..shared import REGULARIZATIONS, regularized_sign
from .kinematic import Accelerate, Move, Position, Speed  # noqa: F401 (MSL's Sources)

__all__ = ["Torque", "Torque2", "RelativeTorque", "ConstantTorque", "SignTorque",
           "QuadraticSpeedDependentTorque", "LinearSpeedDependentTorque", "TorqueStep", "Angle",
           "Position", "Speed", "Accelerate", "Move"]


class Torque(PartialSource, PartialRotElementaryOneFlangeAndSupport2):
    """A torque ``tau`` applied on ``flange`` about +phi, reacting on the
    support (MSL ``Torque``): ``flange.tau = -tau`` (an inertia there gets
    ``J*der(w) = tau``); with ``useSupport=True`` the ``support`` flange
    takes ``+tau``, otherwise the reaction goes to the ground.

    ``tau`` is MSL's input signal (``Torque()``, ``connect(sine.y,
    torque.tau)``), or a number (run-time parameter ``tau_const``), a sympy
    expression of ``acausal.time`` and parameters, or a function
    ``lambda phi: ...`` / ``lambda phi, w: ...`` of the flange angle (and
    angular velocity) returning a sympy expression, exactly as
    :class:`acausal.mechanics.translational.Force`.

    Parameters: ``tau_const`` [N*m] (only when ``tau`` is a number),
    ``useSupport`` (structural). States: ``tau`` [N*m] the applied torque,
    ``phi`` [rad] flange angle relative to the support. Connectors:
    ``flange``, ``tau`` (RealInput, when no law is given), ``support``
    (with useSupport).
    """

    quantity = ("tau", "N*m", "accelerating torque about +phi")
    across_name = "angle"
    tau = SourceValue(0.0, "N*m", "accelerating torque acting at the flange (= -flange.tau)")

    def __init__(self, tau=None, **kw):
        super().__init__(tau, **kw)

    def equations(self):
        return [Eq(self.tau, self.law(self.flange.phi)), Eq(self.flange.tau, -self.tau)]


class Torque2(PartialSource):
    """A torque ``tau`` acting on two flanges (MSL ``Torque2``):
    ``flange_a.tau = tau``, ``flange_b.tau = -tau``: a positive ``tau``
    accelerates ``flange_b``'s body about +phi and ``flange_a``'s about
    -phi.

    ``tau`` is MSL's input signal (``Torque2()``) or a law as for
    :class:`Torque`, of the relative angle ``flange_b.phi - flange_a.phi``
    (and its rate).

    Parameters: ``tau_const`` [N*m] (only when ``tau`` is a number). States:
    ``tau`` [N*m]. Connectors: ``flange_a``, ``flange_b``, ``tau``
    (RealInput, when no law is given).
    """

    quantity = ("tau", "N*m", "torque driving the two flanges apart")
    across_name = "relative angle flange_b.phi - flange_a.phi"
    flange_a = RotFlange("left flange (accelerated about -phi by a positive tau)")
    flange_b = RotFlange("right flange (accelerated about +phi by a positive tau)")
    tau = SourceValue(0.0, "N*m", "torque driving the two flanges apart")

    def __init__(self, tau=None, **kw):
        super().__init__(tau, **kw)

    def equations(self):
        return [Eq(self.tau, self.law(self.flange_b.phi - self.flange_a.phi)),
                Eq(self.flange_a.tau, self.tau), Eq(self.flange_b.tau, -self.tau)]


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


class ConstantTorque(PartialTorque):
    """A constant torque, independent of speed (MSL ``ConstantTorque``):
    ``tau = tau_constant`` accelerates the flange (``flange.tau = -tau``).

    Parameters: ``tau_constant`` [N*m] (negative: a load against positive
    rotation), ``useSupport`` (structural). States: ``tau`` [N*m], ``phi``
    [rad], ``w`` [rad/s]. Connectors: ``flange``, ``support`` (with
    useSupport).
    """

    tau_constant = Parameter(0.0, "N*m", "constant torque (if negative, torque is acting as "
                             "load in positive direction of rotation)")

    def equations(self):
        return [Eq(self.tau, self.tau_constant)]


class SignTorque(PartialTorque):
    """A constant torque that changes sign with the speed (MSL
    ``SignTorque``): ``tau = tau_nominal * regularized_sign(w, w0, reg)``
    (see :func:`acausal.mechanics.translational.sources.regularized_sign`),
    ``w`` relative to the support.

    Parameters: ``tau_nominal`` [N*m] (negative: a load), ``w0`` [rad/s]
    regularisation below w0 (> 0), ``reg`` (structural: "Exp", "Sine",
    "Linear", "CoSine"), ``useSupport`` (structural). States: ``tau``
    [N*m], ``phi`` [rad], ``w`` [rad/s]. Connectors: ``flange``, ``support``
    (with useSupport).
    """

    tau_nominal = Parameter(0.0, "N*m", "nominal torque (if negative, torque is acting as "
                            "load)")
    w0 = Parameter(0.1, "rad/s", "regularization below w0", min=0.0, min_open=True)
    reg = Parameter("Exp", "1", "type of regularization", structural=True,
                    choices=REGULARIZATIONS)

    def equations(self):
        return [Eq(self.tau, self.tau_nominal * regularized_sign(self.w, self.w0, self.reg))]


class QuadraticSpeedDependentTorque(PartialTorque):
    """A torque growing with the square of the speed (MSL
    ``QuadraticSpeedDependentTorque``), ``w`` relative to the support::

        TorqueDirection=True:   tau = tau_nominal * (w/w_nominal)^2
        TorqueDirection=False:  tau = tau_nominal * (w/w_nominal) * |w/w_nominal|

    Parameters: ``tau_nominal`` [N*m] (negative: a load), ``w_nominal``
    [rad/s] (> 0), ``TorqueDirection`` (structural), ``useSupport``
    (structural). States: ``tau`` [N*m], ``phi`` [rad], ``w`` [rad/s].
    Connectors: ``flange``, ``support`` (with useSupport).
    """

    tau_nominal = Parameter(0.0, "N*m", "nominal torque (if negative, torque is acting as "
                            "load in positive direction of rotation)")
    w_nominal = Parameter(1.0, "rad/s", "nominal speed", min=0.0, min_open=True)
    TorqueDirection = Parameter(True, "1", "same direction of torque in both directions of "
                                "rotation", structural=True, choices=(True, False))

    def equations(self):
        r = self.w / self.w_nominal
        shape = r ** 2 if self.TorqueDirection else r * sp.Abs(r)
        return [Eq(self.tau, self.tau_nominal * shape)]


class LinearSpeedDependentTorque(PartialTorque):
    """A torque proportional to the speed (MSL
    ``LinearSpeedDependentTorque``): ``tau = tau_nominal * |w/w_nominal|``
    (``TorqueDirection=True``) or ``tau_nominal * w/w_nominal`` (False).

    Parameters: ``tau_nominal`` [N*m], ``w_nominal`` [rad/s] (> 0),
    ``TorqueDirection`` (structural), ``useSupport`` (structural). States:
    ``tau`` [N*m], ``phi`` [rad], ``w`` [rad/s]. Connectors: ``flange``,
    ``support`` (with useSupport).
    """

    tau_nominal = Parameter(0.0, "N*m", "nominal torque (if negative, torque is acting as "
                            "load in positive direction of rotation)")
    w_nominal = Parameter(1.0, "rad/s", "nominal speed", min=0.0, min_open=True)
    TorqueDirection = Parameter(True, "1", "same direction of torque in both directions of "
                                "rotation", structural=True, choices=(True, False))

    def equations(self):
        r = self.w / self.w_nominal
        return [Eq(self.tau, self.tau_nominal * (sp.Abs(r) if self.TorqueDirection else r))]


class TorqueStep(PartialTorque):
    """A torque step in time (MSL ``TorqueStep``): ``tau = offsetTorque +
    (0 if time < startTime else stepTorque)`` (the step is a time event).

    Parameters: ``stepTorque`` [N*m] height of the step (negative: a load),
    ``offsetTorque`` [N*m], ``startTime`` [s], ``useSupport`` (structural).
    States: ``tau`` [N*m], ``phi`` [rad], ``w`` [rad/s]. Connectors:
    ``flange``, ``support`` (with useSupport).
    """

    stepTorque = Parameter(1.0, "N*m", "height of torque step (if negative, torque is acting "
                           "as load)")
    offsetTorque = Parameter(0.0, "N*m", "offset of torque")
    startTime = Parameter(0.0, "s", "torque = offset for time < startTime")

    def equations(self):
        step = Piecewise((0, time < self.startTime), (self.stepTorque, True))
        return [Eq(self.tau, self.offsetTorque + step)]


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
