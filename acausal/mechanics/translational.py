"""Translational (1-D) mechanics: components, sources and sensors.

Sign convention: :mod:`acausal.connectors` (through variables positive INTO
the component; positions along one +s axis). Two-flange elements report
``f`` = ``flange_b.f``, positive when the element is in tension (pulled
apart), and ``s_rel = flange_b.s - flange_a.s``.

Several components may be connected to one flange (a mass has a single
flange; the forces of everything connected to it add up there).
"""
from sympy import Basic, SympifyError, sympify

from acausal.lang import Component, Eq, Flange, Parameter, Variable, der

from acausal.errors import ParameterError

from .partials import (PartialAbsoluteSensor, PartialCompliant, PartialRelativeSensor,
                       PartialRigid, PartialSource)

__all__ = ["Fixed", "Mass", "Spring", "Damper", "SpringDamper", "Force", "RelativeForce",
           "Position",
           "PositionSensor", "SpeedSensor", "AccSensor", "ForceSensor",
           "RelPositionSensor", "RelSpeedSensor"]


# -- components -------------------------------------------------------------------
class Fixed(Component):
    """A flange fixed at position ``s0``: ``flange.s = s0`` (it takes any force).

    Parameters: ``s0`` [m] position. Connectors: ``flange``.
    """

    diagnosis_site = "ground"   # what acausal.diagnose may extend here

    flange = Flange("fixed flange")
    s0 = Parameter(0.0, "m", "fixed position")

    def equations(self):
        return [Eq(self.flange.s, self.s0)]


class Mass(PartialRigid):
    """A point mass: ``m * der(v) = flange.f`` (the sum of the forces of
    everything connected to its flange).

    Parameters: ``m`` [kg] mass (> 0). States: ``s`` [m], ``v`` [m/s]
    (start values: ``Mass(m=1, s=0.1, v=0)``; ``guess(x)`` for a guess).
    Connectors: ``flange``.
    """

    m = Parameter(1.0, "kg", "mass", min=0.0, min_open=True)

    def equations(self):
        return [Eq(self.m * der(self.v), self.flange.f)]


class Spring(PartialCompliant):
    """Linear spring: ``f = c * (s_rel - s_rel0) + f0`` (tension positive).

    With ``f0 = 0`` (default), ``s_rel0`` is the free length. To give a
    preloaded spring the way a designer knows it, set ``s_rel0`` to the
    *installed* length and ``f0`` to the installed force there; the free
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


class Damper(PartialCompliant):
    """Linear damper: ``f = d * der(s_rel)`` (tension positive).

    Parameters: ``d`` [N*s/m] damping constant (>= 0). States: ``s_rel``
    [m], ``f`` [N]. Connectors: ``flange_a``, ``flange_b``.
    """

    d = Parameter(0.0, "N*s/m", "damping constant", min=0.0)

    def equations(self):
        return [Eq(self.f, self.d * der(self.s_rel))]


class SpringDamper(PartialCompliant):
    """Spring and damper in parallel:
    ``f = c * (s_rel - s_rel0) + f0 + d * der(s_rel)`` (tension positive;
    ``s_rel0``/``f0`` as in :class:`Spring`).

    Parameters: ``c`` [N/m] stiffness (>= 0), ``s_rel0`` [m] reference
    length, ``f0`` [N] spring force at ``s_rel0``, ``d`` [N*s/m] damping
    (>= 0). States: ``s_rel`` [m], ``f`` [N]. Connectors: ``flange_a``,
    ``flange_b``.
    """

    c = Parameter(1.0, "N/m", "spring constant", min=0.0)
    s_rel0 = Parameter(0.0, "m", "reference length (free length when f0 = 0)")
    f0 = Parameter(0.0, "N", "spring force at s_rel = s_rel0 (preload, tension positive)")
    d = Parameter(0.0, "N*s/m", "damping constant", min=0.0)

    def equations(self):
        return [Eq(self.f, self.c * (self.s_rel - self.s_rel0) + self.f0
                   + self.d * der(self.s_rel))]


# -- sources --------------------------------------------------------------------
class Force(PartialSource):
    """A force ``f`` applied on ``flange`` along +s, reacting on the fixed
    frame: ``flange.f = -f`` (so a mass on that flange gets ``m*a = f``).

    ``f`` is given as one of (see :class:`acausal.mechanics.partials.PartialSource`)::

        Force(f=100.0)                            # constant; run-time parameter f_const
        Force(f=200.0 * sympy.sin(50 * time))     # expression of acausal.time (and parameters)
        Force(f=lambda s: k0 * (g0 - s))          # function of the flange position s
        Force(f=lambda s, v: -d0 * v)             # ... and of its velocity v

    The function receives sympy symbols and returns a sympy expression
    (use ``sympy.Max``/``Piecewise``, not ``max``/``if``); it may also use
    ``acausal.time``. A number keeps ``f_const`` changeable between runs
    (``params={"force.f_const": 200}``); an expression's numbers are fixed
    (use ``model.parameter(...)`` symbols in it to sweep them).

    Parameters: ``f_const`` [N] (only when ``f`` is a number). States: ``f``
    [N] the applied force. Connectors: ``flange``.
    """

    quantity = ("f", "N", "applied force along +s")
    across_name = "position"
    flange = Flange("flange the force acts on")
    f = Variable(0.0, "N", "applied force along +s")

    def __init__(self, f=0.0, **kw):
        super().__init__(f, **kw)

    def equations(self):
        return [Eq(self.f, self.law(self.flange.s)), Eq(self.flange.f, -self.f)]


class RelativeForce(PartialSource, PartialCompliant):
    """A force between two flanges given by a law of their relative motion
    (a nonlinear spring or damper): ``f = law(s_rel)`` or
    ``f = law(s_rel, v_rel)``, tension positive as in :class:`Spring`
    (``f > 0`` pulls the flanges together: ``flange_b.f = f``,
    ``flange_a.f = -f``), with ``s_rel = flange_b.s - flange_a.s`` and
    ``v_rel = der(s_rel)``. The law is given as for :class:`Force`::

        RelativeForce(f=lambda s_rel: k3 * (s_rel - L0)**3)   # cubic (hardening) spring
        RelativeForce(f=lambda s_rel, v: d2 * v * Abs(v))      # quadratic damper
        RelativeForce(f=50.0)                                 # constant tension, f_const

    Parameters: ``f_const`` [N] (only when ``f`` is a number). States:
    ``s_rel`` [m], ``f`` [N]. Connectors: ``flange_a``, ``flange_b``.
    """

    quantity = ("f", "N", "force between the flanges (tension positive)")
    across_name = "relative position s_rel"

    def __init__(self, f=0.0, **kw):
        super().__init__(f, **kw)

    def equations(self):
        return [Eq(self.f, self.law(self.s_rel))]


class Position(Component):
    """Prescribed motion: ``flange.s = s_ref`` with ``s_ref`` a sympy
    expression of ``acausal.time`` (and parameters), smooth enough to be
    differentiated twice (the index reduction differentiates it to drive a
    mass). The flange takes whatever force that motion needs.

    Parameters: none (``s`` is fixed at construction). States: ``s`` [m].
    Connectors: ``flange``.
    """

    diagnosis_site = "driver"   # what acausal.diagnose may extend here

    flange = Flange("driven flange")
    s = Variable(0.0, "m", "prescribed position")

    def __init__(self, s, **kw):
        super().__init__(**kw)
        try:
            expr = sympify(s, strict=True)
        except SympifyError:
            expr = None
        if not isinstance(expr, Basic) or isinstance(s, bool):
            raise ParameterError(f"Position.s must be a number or a sympy expression of "
                                 f"time, got {s!r}")
        object.__setattr__(self, "_ref", expr)

    def equations(self):
        return [Eq(self.s, self._ref), Eq(self.flange.s, self.s)]


# -- sensors -------------------------------------------------------------------
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
