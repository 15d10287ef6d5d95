"""Translational components (MSL ``Translational.Components``). Sign
convention: :mod:`acausal.lang.connectors`."""
import sympy as sp
from sympy import Piecewise

from acausal.lang import Component, Discrete, Eq, Event, Flange, Parameter, Variable, der

from ..contact import PosPow
from ..partials import (PartialCompliant, PartialCompliantWithRelativeStates, PartialRigid,
                        PartialRigidBody)

__all__ = ["Fixed", "Mass", "Rod", "Spring", "Damper", "SpringDamper", "ElastoGap"]


class Fixed(Component):
    """A flange fixed at position ``s0``: ``flange.s = s0`` (it takes any force).

    Parameters: ``s0`` [m] position. Connectors: ``flange``.
    """

    diagnosis_site = "ground"   # what acausal.diagnose may extend here

    flange = Flange("fixed flange")
    s0 = Parameter(0.0, "m", "fixed position")

    def equations(self):
        return [Eq(self.flange.s, self.s0)]


class Mass(PartialRigidBody):
    """A sliding mass of length ``L`` (MSL ``Mass``): ``m * der(v)`` = the
    sum of the forces at its flanges, ``v = der(s)``, ``a = der(v)``, ``s``
    the centre::

        flange_a o----[  m  ]----o flange_b          --> +s
                 s - L/2   s   s + L/2
                         flange (at s)

    Two ways to use it, which may be mixed: MSL's, with ``flange_a`` and
    ``flange_b`` (``Mass(m=1, L=1, s=-0.5, v=0)``), or with the single
    ``flange`` at the centre (``Mass(m=1, s=0.1, v=0)``, ``connect(...,
    mass.flange)``: every force acts there). A flange left unconnected
    carries no force. ``s``, ``v`` take start values (a number is a fixed
    start; ``guess(x)`` a guess).

    Parameters: ``m`` [kg] mass (> 0), ``L`` [m] length (>= 0, default 0).
    States: ``s`` [m] centre position, ``v`` [m/s] velocity, ``a`` [m/s2]
    acceleration. Connectors: ``flange_a`` (s - L/2), ``flange_b``
    (s + L/2), ``flange`` (s).
    """

    m = Parameter(1.0, "kg", "mass of the sliding mass", min=0.0, min_open=True)

    def equations(self):
        return [Eq(self.m * der(self.v), self.net_force())]


class Rod(PartialRigid):
    """A massless rigid rod of length ``L`` (MSL ``Rod``): its flanges keep
    the distance ``L`` and the force passes through unchanged,
    ``flange_a.f + flange_b.f = 0``.

    Parameters: ``L`` [m] length (>= 0). States: ``s`` [m] centre position.
    Connectors: ``flange_a`` (s - L/2), ``flange_b`` (s + L/2).
    """

    def equations(self):
        return [Eq(self.flange_a.f + self.flange_b.f, 0)]


class Spring(PartialCompliant):
    """Linear spring (MSL ``Spring``): ``f = c * (s_rel - s_rel0) + f0``
    (tension positive).

    With ``f0 = 0`` (default, MSL's law), ``s_rel0`` is the free length. To
    give a preloaded spring the way a designer knows it, set ``s_rel0`` to
    the *installed* length and ``f0`` to the installed force there; the free
    length is then ``s_rel0 - f0 / c``. ``f0`` follows the tension-positive
    convention: a compression spring installed pushing its flanges apart
    with 2 kN has ``f0 = -2000``.

    Parameters: ``c`` [N/m] stiffness (>= 0), ``s_rel0`` [m] reference
    length, ``f0`` [N] force at ``s_rel0`` (preload). States: ``s_rel`` [m],
    ``f`` [N]. Connectors: ``flange_a``, ``flange_b``.
    """

    c = Parameter(1.0, "N/m", "spring constant", min=0.0)
    s_rel0 = Parameter(0.0, "m", "reference length (free length when f0 = 0)")
    f0 = Parameter(0.0, "N", "force at s_rel = s_rel0 (preload, tension positive)")

    def equations(self):
        return [Eq(self.f, self.c * (self.s_rel - self.s_rel0) + self.f0)]


class Damper(PartialCompliantWithRelativeStates):
    """Linear damper (MSL ``Damper``): ``f = d * v_rel`` (tension positive),
    dissipating ``lossPower = f * v_rel >= 0``.

    Parameters: ``d`` [N*s/m] damping constant (>= 0). States: ``s_rel``
    [m], ``v_rel`` [m/s], ``f`` [N], ``lossPower`` [W]. Connectors:
    ``flange_a``, ``flange_b``.
    """

    d = Parameter(0.0, "N*s/m", "damping constant", min=0.0)
    lossPower = Variable(0.0, "W", "dissipated power f * v_rel")

    def equations(self):
        return [Eq(self.f, self.d * self.v_rel), Eq(self.lossPower, self.f * self.v_rel)]


class SpringDamper(PartialCompliantWithRelativeStates):
    """Spring and damper in parallel (MSL ``SpringDamper``):
    ``f = c * (s_rel - s_rel0) + f0 + d * v_rel`` (tension positive;
    ``s_rel0``/``f0`` as in :class:`Spring`), dissipating
    ``lossPower = d * v_rel^2``.

    Parameters: ``c`` [N/m] stiffness (>= 0), ``s_rel0`` [m] reference
    length, ``f0`` [N] spring force at ``s_rel0``, ``d`` [N*s/m] damping
    (>= 0). States: ``s_rel`` [m], ``v_rel`` [m/s], ``f`` [N],
    ``lossPower`` [W]. Connectors: ``flange_a``, ``flange_b``.
    """

    c = Parameter(1.0, "N/m", "spring constant", min=0.0)
    s_rel0 = Parameter(0.0, "m", "reference length (free length when f0 = 0)")
    f0 = Parameter(0.0, "N", "spring force at s_rel = s_rel0 (preload, tension positive)")
    d = Parameter(0.0, "N*s/m", "damping constant", min=0.0)
    lossPower = Variable(0.0, "W", "power dissipated by the damper, d * v_rel^2")

    def equations(self):
        f_d = self.d * self.v_rel
        return [Eq(self.f, self.c * (self.s_rel - self.s_rel0) + self.f0 + f_d),
                Eq(self.lossPower, f_d * self.v_rel)]


class ElastoGap(PartialCompliantWithRelativeStates):
    """Spring and damper that act only in contact (MSL ``ElastoGap``): the
    flanges touch when ``s_rel < s_rel0``; then::

        f_c = -c * |s_rel - s_rel0|^n                  (pushes apart, <= 0)
        f_d = clamp(d * v_rel, f_c, -f_c)              (|f_d| <= |f_c|)
        f   = f_c + f_d                                (<= 0: never pulls)

    and ``f = 0`` out of contact. The damping force is limited by the spring
    force, so the contact force is continuous at touch-down (no jump to
    ``d * v_rel``) and the contact never pulls the flanges together while
    they separate. ``contact`` switches with an event when ``s_rel`` crosses
    ``s_rel0`` (MSL's event on ``s_rel < s_rel0``); the clamping has no
    events (MSL's ``noEvent``). ``lossPower = f_d * v_rel``.

    Parameters: ``c`` [N/m^n] spring constant (>= 0), ``d`` [N*s/m] damping
    (>= 0), ``s_rel0`` [m] relative position at first touch (MSL's
    unstretched length), ``n`` [1] exponent of the spring force (>= 1).
    States: ``s_rel`` [m], ``v_rel`` [m/s], ``f`` [N], ``f_c``, ``f_d`` [N],
    ``lossPower`` [W]. Discrete: ``contact`` (1 when s_rel < s_rel0).
    Connectors: ``flange_a``, ``flange_b``.
    """

    c = Parameter(1.0, "N/m^n", "spring constant", min=0.0)
    d = Parameter(1.0, "N*s/m", "damping constant", min=0.0)
    s_rel0 = Parameter(0.0, "m", "unstretched spring length (contact when s_rel < s_rel0)")
    n = Parameter(1.0, "1", "exponent of the spring force f_c = -c*|s_rel - s_rel0|^n",
                  min=1.0)
    f_c = Variable(0.0, "N", "spring force (<= 0 in contact, 0 otherwise)")
    f_d = Variable(0.0, "N", "damping force, limited to |f_d| <= |f_c|")
    lossPower = Variable(0.0, "W", "power dissipated by the damping, f_d * v_rel")
    contact = Discrete(0, "1", "1 while s_rel < s_rel0 (in contact), else 0")

    def equations(self):
        on = Eq(self.contact, 1)
        f_c = -self.c * PosPow(self.s_rel0 - self.s_rel, self.n)
        f_d2 = self.d * self.v_rel
        clamped = Piecewise((self.f_c, f_d2 < self.f_c), (-self.f_c, f_d2 > -self.f_c),
                            (f_d2, True))
        return [Eq(self.f_c, Piecewise((f_c, on), (0, True))),
                Eq(self.f_d, Piecewise((clamped, on), (0, True))),
                Eq(self.f, self.f_c + self.f_d),
                Eq(self.lossPower, self.f_d * self.v_rel)]

    def events(self):
        p, contact = self.path, self.contact
        gap = self.s_rel0 - self.s_rel          # > 0: in contact

        def close(s):
            s[contact] = 1

        def open_(s):
            s[contact] = 0

        return [Event(f"{p}.touch", Piecewise((gap, Eq(contact, 0)), (-1, True)), +1, close,
                      recheck=True),
                Event(f"{p}.lift", Piecewise((gap, Eq(contact, 1)), (1, True)), -1, open_,
                      recheck=True)]
