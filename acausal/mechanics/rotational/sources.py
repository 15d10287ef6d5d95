"""Rotational sources (force, torque and motion inputs). Sign convention: :mod:`acausal.lang.connectors`."""
from sympy import Basic, SympifyError, sympify

from acausal.lang import Component, Eq, RotFlange, Variable

from acausal.errors import ParameterError

from ..partials import (PartialRotCompliant,
                       PartialSource)

__all__ = ["Torque", "RelativeTorque", "Angle"]


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
