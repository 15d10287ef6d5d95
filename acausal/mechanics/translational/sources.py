"""Translational sources (MSL ``Translational.Sources``): forces given as
signals, laws or speed-dependent characteristics, and prescribed motion.
Sign convention: :mod:`acausal.lang.connectors`."""

import sympy as sp
from sympy import Piecewise

from acausal.lang import Eq, Flange, Parameter, time

from .kinematic import Accelerate, Move, Position, Speed  # noqa: F401 (MSL's Sources)
from ..shared import REGULARIZATIONS, regularized_sign  # noqa: F401  (public here too)
from ..partials import (PartialCompliant, PartialElementaryOneFlangeAndSupport2, PartialForce,
                        PartialSource, SourceValue)

__all__ = ["Force", "Force2", "RelativeForce", "ConstantForce", "SignForce",
           "QuadraticSpeedDependentForce", "LinearSpeedDependentForce", "ForceStep", "Position",
           "Speed", "Accelerate", "Move"]

class Force(PartialSource, PartialElementaryOneFlangeAndSupport2):
    """A force ``f`` applied on ``flange`` along +s, reacting on the support
    (MSL ``Force``): ``flange.f = -f`` (so a mass on that flange gets
    ``m*a = f``); with ``useSupport=True`` the ``support`` flange takes
    ``+f``, otherwise the reaction goes to the ground.

    ``f`` is MSL's input signal, or a law (see
    :class:`acausal.mechanics.partials.PartialSource`)::

        Force()                                   # input: connect(sine.y, force.f)
        Force(f=100.0)                            # constant; run-time parameter f_const
        Force(f=200.0 * sympy.sin(50 * time))     # expression of acausal.time (and parameters)
        Force(f=lambda s: k0 * (g0 - s))          # function of the flange position s
        Force(f=lambda s, v: -d0 * v)             # ... and of its velocity v

    The function receives sympy symbols and returns a sympy expression
    (use ``sympy.Max``/``Piecewise``, not ``max``/``if``); it may also use
    ``acausal.time``. A number keeps ``f_const`` changeable between runs
    (``params={"force.f_const": 200}``); an expression's numbers are fixed
    (use ``model.parameter(...)`` symbols in it to sweep them).

    Parameters: ``f_const`` [N] (only when ``f`` is a number),
    ``useSupport`` (structural). States: ``f`` [N] the applied force, ``s``
    [m] flange position relative to the support. Connectors: ``flange``,
    ``f`` (RealInput, when no law is given), ``support`` (with useSupport).
    """

    quantity = ("f", "N", "driving force along +s")
    across_name = "position"
    f = SourceValue(0.0, "N", "driving force along +s (= -flange.f)")

    def __init__(self, f=None, **kw):
        super().__init__(f, **kw)

    def equations(self):
        return [Eq(self.f, self.law(self.flange.s)), Eq(self.flange.f, -self.f)]


class Force2(PartialSource):
    """A force ``f`` between two flanges (MSL ``Force2``): ``flange_a.f =
    f``, ``flange_b.f = -f``: a positive ``f`` pushes ``flange_b``'s body
    along +s and ``flange_a``'s along -s (drives them apart).

    ``f`` is MSL's input signal (``Force2()``, ``connect(sine.y,
    force.f)``) or a law as for :class:`Force`, of the relative position
    ``flange_b.s - flange_a.s`` (and its rate).

    Parameters: ``f_const`` [N] (only when ``f`` is a number). States:
    ``f`` [N]. Connectors: ``flange_a``, ``flange_b``, ``f`` (RealInput,
    when no law is given).
    """

    quantity = ("f", "N", "force pushing the flanges apart")
    across_name = "relative position flange_b.s - flange_a.s"
    flange_a = Flange("left flange (pushed along -s by a positive f)")
    flange_b = Flange("right flange (pushed along +s by a positive f)")
    f = SourceValue(0.0, "N", "force pushing the flanges apart")

    def __init__(self, f=None, **kw):
        super().__init__(f, **kw)

    def equations(self):
        return [Eq(self.f, self.law(self.flange_b.s - self.flange_a.s)),
                Eq(self.flange_a.f, self.f), Eq(self.flange_b.f, -self.f)]


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


class ConstantForce(PartialForce):
    """A constant force, independent of speed (MSL ``ConstantForce``): the
    body on the flange receives ``f_constant`` along +s (``f = flange.f =
    -f_constant``).

    Parameters: ``f_constant`` [N] nominal force (negative: a load against
    positive motion), ``useSupport`` (structural). States: ``f`` [N] (=
    -f_constant), ``s`` [m], ``v`` [m/s]. Connectors: ``flange``,
    ``support`` (with useSupport).
    """

    f_constant = Parameter(0.0, "N", "nominal force (if negative, a load in the positive "
                           "direction of motion)")

    def equations(self):
        return [Eq(self.f, -self.f_constant)]


class SignForce(PartialForce):
    """A constant force that changes sign with the speed (MSL
    ``SignForce``): the body receives ``f_nominal * sign(v)``, regularised
    below ``v0`` (``f = -f_nominal * regularized_sign(v, v0, reg)``, see
    :func:`regularized_sign`), ``v`` relative to the support.

    Parameters: ``f_nominal`` [N] nominal force (negative: a load),
    ``v0`` [m/s] regularisation below v0 (> 0), ``reg`` (structural: "Exp",
    "Sine", "Linear", "CoSine"; MSL's default "Exp"), ``useSupport``
    (structural). States: ``f`` [N], ``s`` [m], ``v`` [m/s]. Connectors:
    ``flange``, ``support`` (with useSupport).
    """

    f_nominal = Parameter(0.0, "N", "nominal force (if negative, force is acting as load)")
    v0 = Parameter(0.1, "m/s", "regularization below v0", min=0.0, min_open=True)
    reg = Parameter("Exp", "1", "type of regularization", structural=True,
                    choices=REGULARIZATIONS)

    def equations(self):
        return [Eq(self.f, -self.f_nominal * regularized_sign(self.v, self.v0, self.reg))]


class QuadraticSpeedDependentForce(PartialForce):
    """A force growing with the square of the speed (MSL
    ``QuadraticSpeedDependentForce``), ``v`` relative to the support; the
    body receives::

        ForceDirection=True:   f_nominal * (v/v_nominal)^2              (same sign both ways)
        ForceDirection=False:  f_nominal * (v/v_nominal) * |v/v_nominal| (a drag when f_nominal < 0)

    Parameters: ``f_nominal`` [N] nominal force (negative: a load),
    ``v_nominal`` [m/s] nominal speed (> 0), ``ForceDirection``
    (structural), ``useSupport`` (structural). States: ``f`` [N] (=
    flange.f), ``s`` [m], ``v`` [m/s]. Connectors: ``flange``, ``support``
    (with useSupport).
    """

    f_nominal = Parameter(0.0, "N", "nominal force (if negative, force is acting as load in "
                          "positive direction of motion)")
    v_nominal = Parameter(1.0, "m/s", "nominal speed", min=0.0, min_open=True)
    ForceDirection = Parameter(True, "1", "same direction of force in both directions of "
                               "motion", structural=True, choices=(True, False))

    def equations(self):
        r = self.v / self.v_nominal
        shape = r ** 2 if self.ForceDirection else r * sp.Abs(r)
        return [Eq(self.f, -self.f_nominal * shape)]


class LinearSpeedDependentForce(PartialForce):
    """A force proportional to the speed (MSL ``LinearSpeedDependentForce``),
    ``v`` relative to the support; the body receives ``f_nominal *
    |v/v_nominal|`` (``ForceDirection=True``) or ``f_nominal *
    v/v_nominal`` (False).

    Parameters: ``f_nominal`` [N], ``v_nominal`` [m/s] (> 0),
    ``ForceDirection`` (structural), ``useSupport`` (structural). States:
    ``f`` [N], ``s`` [m], ``v`` [m/s]. Connectors: ``flange``, ``support``
    (with useSupport).
    """

    f_nominal = Parameter(0.0, "N", "nominal force (if negative, force is acting as load in "
                          "positive direction of motion)")
    v_nominal = Parameter(1.0, "m/s", "nominal speed", min=0.0, min_open=True)
    ForceDirection = Parameter(True, "1", "same direction of force in both directions of "
                               "motion", structural=True, choices=(True, False))

    def equations(self):
        r = self.v / self.v_nominal
        return [Eq(self.f, -self.f_nominal * (sp.Abs(r) if self.ForceDirection else r))]


class ForceStep(PartialForce):
    """A force step in time (MSL ``ForceStep``): the body receives
    ``offsetForce`` before ``startTime`` and ``offsetForce + stepForce``
    from then on (``f = -offsetForce - (0 if time < startTime else
    stepForce)``; the step is a time event).

    Parameters: ``stepForce`` [N] height of the step (negative: a load),
    ``offsetForce`` [N] offset, ``startTime`` [s], ``useSupport``
    (structural). States: ``f`` [N], ``s`` [m], ``v`` [m/s]. Connectors:
    ``flange``, ``support`` (with useSupport).
    """

    stepForce = Parameter(1.0, "N", "height of force step (if negative, force is acting as "
                          "load)")
    offsetForce = Parameter(0.0, "N", "offset of force")
    startTime = Parameter(0.0, "s", "force = offset for time < startTime")

    def equations(self):
        step = Piecewise((0, time < self.startTime), (self.stepForce, True))
        return [Eq(self.f, -self.offsetForce - step)]
