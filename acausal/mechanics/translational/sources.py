"""Translational sources (force, torque and motion inputs). Sign convention: :mod:`acausal.lang.connectors`."""
from sympy import Basic, SympifyError, sympify

from acausal.lang import Component, Eq, Flange, Variable

from acausal.errors import ParameterError

from ..partials import (PartialCompliant, PartialSource)

__all__ = ["Force", "RelativeForce", "Position"]


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
