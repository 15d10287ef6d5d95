"""Translational kinematic sources (MSL ``Translational.Sources.Position``,
``Speed``, ``Accelerate``, ``Move``): the motion of a flange relative to
its support follows a signal (a :class:`~acausal.lang.connectors.RealInput`,
connected to a block's output or bound to an expression of time:
``Position(exact=True, s_ref=0.1*sin(2*pi*time))``). The flange takes whatever
force the motion needs; with ``useSupport=True`` the support takes the
reaction, otherwise the ground does. A model whose every motion is
prescribed has no states and still runs.

Sign convention: :mod:`acausal.lang.connectors`.
"""
import sympy as sp

from acausal.errors import ParameterError
from acausal.lang import Eq, Parameter, RealInput, Variable, der
from acausal.lang.symbols import KnownDerivatives

from ..partials import PartialElementaryOneFlangeAndSupport2
from ..shared import BESSEL_AF, BESSEL_BF, bessel_filter  # noqa: F401  (public here too)

__all__ = ["Position", "Speed", "Accelerate", "Move", "BESSEL_AF", "BESSEL_BF"]


class Position(PartialElementaryOneFlangeAndSupport2):
    """Flange position given by the input ``s_ref`` (MSL ``Position``).

    ``exact=True``: ``s = s_ref`` (the input is differentiated twice by the
    index reduction, so it must be smooth: a ramp's kinks are time events;
    ``v`` and ``a`` are MSL's dummies, 0). ``exact=False`` (MSL's default):
    ``s`` follows ``s_ref`` through a critically damped second-order Bessel
    filter of cut-off ``f_crit``, ``a = ((s_ref - s)*w_crit - af*v)*w_crit/bf``,
    starting at ``s = s_ref`` (MSL's initial equation).

    ``Position(s=expr)`` (this library's earlier form) means
    ``Position(s_ref=expr, exact=True)``.

    Parameters: ``exact`` (structural), ``f_crit`` [Hz] (> 0),
    ``useSupport`` (structural). States: ``s`` [m] flange position relative
    to the support, ``v`` [m/s], ``a`` [m/s2] (filter states when not
    exact). Connectors: ``flange``, ``s_ref`` (RealInput, m), ``support``
    (with useSupport).
    """

    diagnosis_site = "driver"   # what acausal.diagnose may extend here

    exact = Parameter(False, "1", "true: s = s_ref exactly; false: s_ref filtered",
                      structural=True, choices=(False, True))
    f_crit = Parameter(50.0, "Hz", "critical frequency of the filter (exact=False)", min=0.0,
                       min_open=True)
    v = Variable(0.0, "m/s", "absolute velocity of the flange (exact=False; else 0)")
    a = Variable(0.0, "m/s2", "absolute acceleration of the flange (exact=False; else 0)")
    s_ref = RealInput("reference position of the flange", "m")

    def __init__(self, **kw):
        if "s" in kw and "s_ref" not in kw and "exact" not in kw:
            ref = kw.pop("s")
            try:
                expr = sp.sympify(ref, strict=True)
            except (sp.SympifyError, TypeError):
                expr = None
            if isinstance(ref, bool) or not isinstance(expr, sp.Basic):
                raise ParameterError(f"Position.s must be a number or a sympy expression of "
                                     f"time, got {ref!r}")
            kw["s_ref"], kw["exact"] = expr, True
        super().__init__(**kw)

    def equations(self):
        if self.exact:
            return [Eq(self.s, self.s_ref), Eq(self.v, 0), Eq(self.a, 0)]
        return [Eq(self.v, der(self.s)), Eq(self.a, der(self.v)),
                bessel_filter(self.a, self.s_ref, self.s, self.v, self.f_crit)]

    def initial_equations(self):
        return [] if self.exact else [Eq(self.s, self.s_ref)]


class Speed(PartialElementaryOneFlangeAndSupport2):
    """Flange velocity given by the input ``v_ref`` (MSL ``Speed``); the
    position starts at ``s = 0`` (a fixed start, as MSL's).

    ``exact=True``: ``v = v_ref`` (the input is differentiated once; ``a``
    is MSL's dummy, 0). ``exact=False``: first-order filter
    ``a = (v_ref - v)*w_crit``, ``w_crit = 2*pi*f_crit``, starting at
    ``v = v_ref``.

    Parameters: ``exact`` (structural), ``f_crit`` [Hz] (> 0),
    ``useSupport`` (structural). States: ``s`` [m], ``v`` [m/s], ``a``
    [m/s2] (not exact). Connectors: ``flange``, ``v_ref`` (RealInput, m/s),
    ``support`` (with useSupport).
    """

    diagnosis_site = "driver"   # what acausal.diagnose may extend here

    exact = Parameter(False, "1", "true: v = v_ref exactly; false: v_ref filtered",
                      structural=True, choices=(False, True))
    f_crit = Parameter(50.0, "Hz", "critical frequency of the filter (exact=False)", min=0.0,
                       min_open=True)
    s = Variable(0.0, "m", "flange position relative to the support", fixed=True)
    v = Variable(0.0, "m/s", "absolute velocity of the flange")
    a = Variable(0.0, "m/s2", "absolute acceleration of the flange (exact=False; else 0)")
    v_ref = RealInput("reference speed of the flange", "m/s")

    def equations(self):
        eqs = [Eq(self.v, der(self.s))]
        if self.exact:
            return eqs + [Eq(self.v, self.v_ref), Eq(self.a, 0)]
        return eqs + [Eq(self.a, der(self.v)),
                      Eq(self.a, (self.v_ref - self.v) * 2 * sp.pi * self.f_crit)]

    def initial_equations(self):
        return [] if self.exact else [Eq(self.v, self.v_ref)]


class Accelerate(PartialElementaryOneFlangeAndSupport2):
    """Flange acceleration given by the input ``a_ref`` (MSL
    ``Accelerate``): ``a = a_ref``; velocity and position are its
    integrals from the fixed starts ``s = 0``, ``v = 0`` (MSL's; give
    others as start values, e.g. ``Accelerate(v=1.0)``).

    Parameters: ``useSupport`` (structural). States: ``s`` [m], ``v``
    [m/s], ``a`` [m/s2]. Connectors: ``flange``, ``a_ref`` (RealInput,
    m/s2), ``support`` (with useSupport).
    """

    diagnosis_site = "driver"   # what acausal.diagnose may extend here

    s = Variable(0.0, "m", "flange position relative to the support", fixed=True)
    v = Variable(0.0, "m/s", "absolute velocity of the flange", fixed=True)
    a = Variable(0.0, "m/s2", "absolute acceleration of the flange")
    a_ref = RealInput("acceleration of the flange", "m/s2")

    def equations(self):
        return [Eq(self.v, der(self.s)), Eq(self.a, der(self.v)), Eq(self.a, self.a_ref)]


class Move(PartialElementaryOneFlangeAndSupport2):
    """Flange motion given by three inputs (MSL ``Move``): ``u1`` position,
    ``u2`` velocity, ``u3`` acceleration (MSL's ``u[1..3]``; ``move.u`` is
    the tuple). ``s = u1``, and the index reduction takes ``u2`` and ``u3``
    as its first and second derivatives instead of differentiating ``u1``
    (MSL's derivative annotation): the user keeps them consistent, or not on
    purpose (a position-only motion with zero velocity and acceleration).

    Parameters: ``useSupport`` (structural). States: ``s`` [m].
    Connectors: ``flange``, ``u1`` (m), ``u2`` (m/s), ``u3`` (m/s2)
    (RealInputs), ``support`` (with useSupport).
    """

    diagnosis_site = "driver"   # what acausal.diagnose may extend here

    u1 = RealInput("position of the flange", "m")
    u2 = RealInput("velocity of the flange", "m/s")
    u3 = RealInput("acceleration of the flange", "m/s2")

    @property
    def u(self):
        """(u1, u2, u3): MSL's ``u[1..3]``."""
        return (self.u1, self.u2, self.u3)

    def equations(self):
        return [Eq(self.s, KnownDerivatives(self.u1.symbol, self.u2.symbol, self.u3.symbol))]
