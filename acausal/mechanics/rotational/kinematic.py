"""Rotational kinematic sources (MSL ``Rotational.Sources.Position``,
``Speed``, ``Accelerate``, ``Move``): the rotation of a flange relative to
its support follows a signal (a :class:`~acausal.lang.connectors.RealInput`,
connected to a block's output or bound to an expression of time:
``Position(exact=True, phi_ref=0.5*sin(2*pi*time))``). The flange takes whatever
torque the motion needs; with ``useSupport=True`` the support takes the
reaction, otherwise the ground does. A model whose every motion is
prescribed has no states and still runs.

Sign convention: :mod:`acausal.lang.connectors`.
"""
import sympy as sp

from acausal.lang import Eq, Parameter, RealInput, Variable, der
from acausal.lang.symbols import KnownDerivatives

from ..partials import PartialRotElementaryOneFlangeAndSupport2
from ..shared import bessel_filter

__all__ = ["Position", "Speed", "Accelerate", "Move"]


class Position(PartialRotElementaryOneFlangeAndSupport2):
    """Flange angle given by the input ``phi_ref`` (MSL ``Position``).

    ``exact=True``: ``phi = phi_ref`` (the input is differentiated twice by
    the index reduction; ``w`` and ``a`` are MSL's dummies, 0).
    ``exact=False`` (MSL's default): ``phi`` follows ``phi_ref`` through a
    second-order Bessel filter of cut-off ``f_crit``,
    ``a = ((phi_ref - phi)*w_crit - af*w)*w_crit/bf``, starting at
    ``phi = phi_ref`` (MSL's initial equation).

    Parameters: ``exact`` (structural), ``f_crit`` [Hz] (> 0),
    ``useSupport`` (structural). States: ``phi`` [rad] relative to the
    support, ``w`` [rad/s], ``a`` [rad/s2] (filter states when not exact).
    Connectors: ``flange``, ``phi_ref`` (RealInput, rad), ``support`` (with
    useSupport).
    """

    diagnosis_site = "driver"   # what acausal.diagnose may extend here

    exact = Parameter(False, "1", "true: phi = phi_ref exactly; false: phi_ref filtered",
                      structural=True, choices=(False, True))
    f_crit = Parameter(50.0, "Hz", "critical frequency of the filter (exact=False)", min=0.0,
                       min_open=True)
    w = Variable(0.0, "rad/s", "angular velocity relative to the support (exact=False; else 0)")
    a = Variable(0.0, "rad/s2", "angular acceleration relative to the support (exact=False; "
                 "else 0)")
    phi_ref = RealInput("reference angle of the flange relative to the support", "rad")

    def equations(self):
        if self.exact:
            return [Eq(self.phi, self.phi_ref), Eq(self.w, 0), Eq(self.a, 0)]
        return [Eq(self.w, der(self.phi)), Eq(self.a, der(self.w)),
                bessel_filter(self.a, self.phi_ref, self.phi, self.w, self.f_crit)]

    def initial_equations(self):
        return [] if self.exact else [Eq(self.phi, self.phi_ref)]


class Speed(PartialRotElementaryOneFlangeAndSupport2):
    """Flange angular velocity given by the input ``w_ref`` (MSL
    ``Speed``); the angle starts at ``phi = 0`` (a fixed start, as MSL's).

    ``exact=True``: ``w = w_ref`` (the input is differentiated once; ``a``
    is MSL's dummy, 0). ``exact=False``: first-order filter
    ``a = (w_ref - w)*w_crit``, ``w_crit = 2*pi*f_crit``, starting at
    ``w = w_ref``.

    Parameters: ``exact`` (structural), ``f_crit`` [Hz] (> 0),
    ``useSupport`` (structural). States: ``phi`` [rad], ``w`` [rad/s],
    ``a`` [rad/s2] (not exact). Connectors: ``flange``, ``w_ref``
    (RealInput, rad/s), ``support`` (with useSupport).
    """

    diagnosis_site = "driver"   # what acausal.diagnose may extend here

    exact = Parameter(False, "1", "true: w = w_ref exactly; false: w_ref filtered",
                      structural=True, choices=(False, True))
    f_crit = Parameter(50.0, "Hz", "critical frequency of the filter (exact=False)", min=0.0,
                       min_open=True)
    phi = Variable(0.0, "rad", "angle of the flange relative to the support", fixed=True)
    w = Variable(0.0, "rad/s", "angular velocity relative to the support")
    a = Variable(0.0, "rad/s2", "angular acceleration relative to the support (exact=False; "
                 "else 0)")
    w_ref = RealInput("reference angular velocity of the flange", "rad/s")

    def equations(self):
        eqs = [Eq(self.w, der(self.phi))]
        if self.exact:
            return eqs + [Eq(self.w, self.w_ref), Eq(self.a, 0)]
        return eqs + [Eq(self.a, der(self.w)),
                      Eq(self.a, (self.w_ref - self.w) * 2 * sp.pi * self.f_crit)]

    def initial_equations(self):
        return [] if self.exact else [Eq(self.w, self.w_ref)]


class Accelerate(PartialRotElementaryOneFlangeAndSupport2):
    """Flange angular acceleration given by the input ``a_ref`` (MSL
    ``Accelerate``): ``a = a_ref``; angular velocity and angle are its
    integrals from the fixed starts ``phi = 0``, ``w = 0`` (MSL's).

    Parameters: ``useSupport`` (structural). States: ``phi`` [rad], ``w``
    [rad/s], ``a`` [rad/s2]. Connectors: ``flange``, ``a_ref`` (RealInput,
    rad/s2), ``support`` (with useSupport).
    """

    diagnosis_site = "driver"   # what acausal.diagnose may extend here

    phi = Variable(0.0, "rad", "angle of the flange relative to the support", fixed=True)
    w = Variable(0.0, "rad/s", "angular velocity relative to the support", fixed=True)
    a = Variable(0.0, "rad/s2", "angular acceleration relative to the support")
    a_ref = RealInput("angular acceleration of the flange", "rad/s2")

    def equations(self):
        return [Eq(self.w, der(self.phi)), Eq(self.a, der(self.w)), Eq(self.a, self.a_ref)]


class Move(PartialRotElementaryOneFlangeAndSupport2):
    """Flange rotation given by three inputs (MSL ``Move``): ``u1`` angle,
    ``u2`` angular velocity, ``u3`` angular acceleration (MSL's ``u[1..3]``;
    ``move.u`` is the tuple). ``phi = u1``, and the index reduction takes
    ``u2`` and ``u3`` as its derivatives instead of differentiating ``u1``
    (MSL's derivative annotation).

    Parameters: ``useSupport`` (structural). States: ``phi`` [rad].
    Connectors: ``flange``, ``u1`` (rad), ``u2`` (rad/s), ``u3`` (rad/s2)
    (RealInputs), ``support`` (with useSupport).
    """

    diagnosis_site = "driver"   # what acausal.diagnose may extend here

    u1 = RealInput("angle of the flange relative to the support", "rad")
    u2 = RealInput("angular velocity of the flange", "rad/s")
    u3 = RealInput("angular acceleration of the flange", "rad/s2")

    @property
    def u(self):
        """(u1, u2, u3): MSL's ``u[1..3]``."""
        return (self.u1, self.u2, self.u3)

    def equations(self):
        return [Eq(self.phi, KnownDerivatives(self.u1.symbol, self.u2.symbol, self.u3.symbol))]
