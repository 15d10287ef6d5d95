"""Levers: transformers between rotation and translation.

All are massless, rigid and power conserving, with their pivot on the fixed
frame (like Modelica's IdealGear with a grounded support). ``IdealGear``
lives in :mod:`acausal.mechanics.rotational` (with MSL's support flange) and
is importable from here as before. Put the mass or inertia of a lever in an
:class:`~acausal.mechanics.rotational.Inertia` or
:class:`~acausal.mechanics.translational.Mass` on one of its flanges.
Sign convention: :mod:`acausal.connectors`.
"""
from sympy import cos, sin

from acausal.lang import Component, Eq, Flange, Parameter, RotFlange, Variable

from .partials import NonZeroParameter
from .rotational.components import IdealGear   # MSL's place; kept importable from here

__all__ = ["IdealLever", "TwoArmLever", "IdealGear"]


class IdealLever(Component):
    """A rigid arm turning a rotation into a translation (the bond-graph TF
    with modulus ``arm`` or ``arm*cos(phi)``):

    * small angle (``exact=False``): ``flange_t.s = arm * phi``,
      ``flange_r.tau = -arm * flange_t.f``;
    * exact (``exact=True``): ``flange_t.s = arm * sin(phi)``,
      ``flange_r.tau = -arm * cos(phi) * flange_t.f``

    with ``phi = flange_r.phi``. Power is conserved:
    ``flange_r.tau * der(phi) + flange_t.f * der(flange_t.s) = 0``. The
    exact form is a pin on the arm driving a slider along a line
    perpendicular to the arm at ``phi = 0`` (a scotch yoke); it is singular
    at ``phi = +-pi/2``. An inertia ``J`` on ``flange_r`` and a mass ``m``
    on ``flange_t`` move as one inertia ``J + m*arm^2`` (small angle).
    ``arm`` is signed: a negative arm moves the point the other way.

    Parameters: ``arm`` [m] lever arm (non-zero), ``exact`` (structural) exact
    kinematics. Connectors: ``flange_r`` (rotational), ``flange_t``
    (translational).
    """

    flange_r = RotFlange("rotating side (the lever's shaft)")
    flange_t = Flange("translating side (the point on the arm)")
    arm = NonZeroParameter(0.1, "m", "lever arm (signed, non-zero)")
    exact = Parameter(False, "1", "use arm*sin(phi) instead of arm*phi", structural=True,
                      choices=(False, True))

    def equations(self):
        phi = self.flange_r.phi
        k = sin(phi) if self.exact else phi
        dk = cos(phi) if self.exact else 1
        return [Eq(self.flange_t.s, self.arm * k),
                Eq(self.flange_r.tau, -self.arm * dk * self.flange_t.f)]


class TwoArmLever(Component):
    """A massless rigid lever on a fixed pivot with two arms on the same side:
    ``flange_a.s = a * phi``, ``flange_b.s = b * phi`` and torque balance
    ``a * flange_a.f + b * flange_b.f = 0`` (small-angle form; with
    ``exact=True`` the arms see ``arm * sin(phi)`` and the balance is
    multiplied by ``cos(phi)``). Arms are signed: an arm on the other side
    of the pivot is negative.

    Parameters: ``a``, ``b`` [m] arm lengths, ``exact`` (structural).
    States: ``phi`` [rad] lever angle. Connectors: ``flange_a``, ``flange_b``.
    """

    flange_a = Flange("point on arm a")
    flange_b = Flange("point on arm b")
    a = Parameter(0.1, "m", "arm length to flange_a")
    b = Parameter(0.1, "m", "arm length to flange_b")
    exact = Parameter(False, "1", "use arm*sin(phi) instead of arm*phi", structural=True,
                      choices=(False, True))
    phi = Variable(0.0, "rad", "lever angle")

    def equations(self):
        k = sin(self.phi) if self.exact else self.phi
        dk = cos(self.phi) if self.exact else 1
        return [Eq(self.flange_a.s, self.a * k),
                Eq(self.flange_b.s, self.b * k),
                Eq(self.a * dk * self.flange_a.f + self.b * dk * self.flange_b.f, 0)]
