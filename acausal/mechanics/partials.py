"""Partial models that own the connector equations, so that a leaf
component is only its parameters and its law (Modelica's PartialCompliant /
PartialRigid). Sign convention: see :mod:`acausal.connectors`."""
import inspect
import numbers

import sympy as sp

from acausal.lang import Component, Eq, Flange, Parameter, RotFlange, Variable, der

from acausal.errors import ParameterError


class PartialCompliant(Component):
    """Two translational flanges and the force between them.

    States: ``s_rel`` [m] = flange_b.s - flange_a.s; ``f`` [N] force at
    flange_b (positive = the element is pulled apart, i.e. in tension).
    Connectors: ``flange_a``, ``flange_b``.
    """

    diagnosis_site = "compliant"   # what acausal.diagnose may extend here

    flange_a = Flange("left flange")
    flange_b = Flange("right flange")
    s_rel = Variable(0.0, "m", "relative displacement flange_b.s - flange_a.s")
    f = Variable(0.0, "N", "force at flange_b (tension positive)")

    def equations(self):
        return [Eq(self.s_rel, self.flange_b.s - self.flange_a.s),
                Eq(self.flange_b.f, self.f),
                Eq(self.flange_a.f, -self.f)]


class PartialRotCompliant(Component):
    """Two rotational flanges and the torque between them.

    States: ``phi_rel`` [rad] = flange_b.phi - flange_a.phi; ``tau`` [N*m]
    torque at flange_b. Connectors: ``flange_a``, ``flange_b``.
    """

    diagnosis_site = "compliant"   # what acausal.diagnose may extend here

    flange_a = RotFlange("left flange")
    flange_b = RotFlange("right flange")
    phi_rel = Variable(0.0, "rad", "relative angle flange_b.phi - flange_a.phi")
    tau = Variable(0.0, "N*m", "torque at flange_b")

    def equations(self):
        return [Eq(self.phi_rel, self.flange_b.phi - self.flange_a.phi),
                Eq(self.flange_b.tau, self.tau),
                Eq(self.flange_a.tau, -self.tau)]


class PartialRigid(Component):
    """A translational body with one flange: position ``s`` [m] and velocity
    ``v`` [m/s]; ``flange.f`` is the sum of the forces applied on it."""

    diagnosis_site = "body"   # what acausal.diagnose may extend here

    flange = Flange("the body's flange (all forces act here)")
    s = Variable(0.0, "m", "absolute position")
    v = Variable(0.0, "m/s", "absolute velocity")

    def equations(self):
        from acausal.lang import der
        return [Eq(self.flange.s, self.s), Eq(der(self.s), self.v)]


class PartialRotRigid(Component):
    """A rotating body with one flange: angle ``phi`` [rad] and angular
    velocity ``w`` [rad/s]; ``flange.tau`` is the sum of applied torques."""

    diagnosis_site = "body"   # what acausal.diagnose may extend here

    flange = RotFlange("the body's flange (all torques act here)")
    phi = Variable(0.0, "rad", "absolute angle")
    w = Variable(0.0, "rad/s", "absolute angular velocity")

    def equations(self):
        from acausal.lang import der
        return [Eq(self.flange.phi, self.phi), Eq(der(self.phi), self.w)]


# -- sensors -------------------------------------------------------------------
class PartialAbsoluteSensor(Component):
    """One translational flange that takes no force (``flange.f = 0``): the
    sensor measures without acting. Connectors: ``flange``."""

    diagnosis_site = "sensor"   # what acausal.diagnose may extend here

    flange = Flange("measured flange (no force taken)")

    def equations(self):
        return [Eq(self.flange.f, 0)]


class PartialRelativeSensor(Component):
    """Two translational flanges that take no force. Connectors:
    ``flange_a``, ``flange_b``."""

    diagnosis_site = "sensor"   # what acausal.diagnose may extend here

    flange_a = Flange("reference flange (no force taken)")
    flange_b = Flange("measured flange (no force taken)")

    def equations(self):
        return [Eq(self.flange_a.f, 0), Eq(self.flange_b.f, 0)]


class PartialRotAbsoluteSensor(Component):
    """One rotational flange that takes no torque. Connectors: ``flange``."""

    diagnosis_site = "sensor"   # what acausal.diagnose may extend here

    flange = RotFlange("measured flange (no torque taken)")

    def equations(self):
        return [Eq(self.flange.tau, 0)]


class PartialRotRelativeSensor(Component):
    """Two rotational flanges that take no torque. Connectors: ``flange_a``,
    ``flange_b``."""

    diagnosis_site = "sensor"   # what acausal.diagnose may extend here

    flange_a = RotFlange("reference flange (no torque taken)")
    flange_b = RotFlange("measured flange (no torque taken)")

    def equations(self):
        return [Eq(self.flange_a.tau, 0), Eq(self.flange_b.tau, 0)]


# -- sources: a law given as a number, an expression or a function -------------
def _n_positional(fn):
    """How many positional arguments ``fn`` takes (1 when unknown)."""
    if isinstance(fn, sp.Lambda):
        return len(fn.variables)
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):
        return 1
    n, var = 0, False
    for p in sig.parameters.values():
        if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD):
            n += 1
        elif p.kind == p.VAR_POSITIONAL:
            var = True
    return 2 if var else n


class PartialSource(Component):
    """A source whose value (force or torque) follows a law given at
    construction as

    * a number: a constant, kept as the run-time parameter ``<name>_const``
      (changeable with ``simulate(params=...)`` without recompiling);
    * a sympy expression: of :data:`acausal.time` and of model parameters
      (e.g. a ``model.parameter(...)`` symbol);
    * a callable ``law(x)`` or ``law(x, v)``: called with the symbol of the
      source's own flange across variable (position or angle) and, if it
      takes two arguments, of its rate (velocity or angular velocity); it
      returns a sympy expression (it may also use ``acausal.time``).

    A leaf sets ``quantity`` = (name, unit, description) and
    ``across_name``, declares the Variable of that name and writes its
    connector equation with :meth:`law`.
    """

    diagnosis_site = "source"   # what acausal.diagnose may extend here

    quantity = ("u", "1", "source value")
    across_name = "across variable"   # how the law's argument is called in messages

    def __init__(self, value=0.0, **kw):
        super().__init__(**kw)
        name, unit, desc = self.quantity
        where = f"{type(self).__name__}.{name}"
        if isinstance(value, bool):
            raise ParameterError(f"{where} must be a number, a sympy expression or a "
                                 f"function, got {value!r}")
        if isinstance(value, numbers.Real) or (isinstance(value, sp.Basic) and value.is_number):
            p = Parameter(0.0, unit, f"constant {desc}")
            p.name = f"{name}_const"
            self._extra[p.name] = p
            self._values[p.name] = p.check(value, type(self).__name__)
            object.__setattr__(self, "_law", None)
        elif isinstance(value, sp.Basic) and not isinstance(value, sp.Lambda):
            object.__setattr__(self, "_law", value)
        elif callable(value):
            object.__setattr__(self, "_law", value)
            self._call(value, sp.Symbol("x"), sp.Symbol("v"))  # fail early
        else:
            raise ParameterError(f"{where} must be a number, a sympy expression or a "
                                 f"function of the flange {self.across_name}, "
                                 f"got {value!r}")

    def _call(self, fn, x, v):
        name = self.quantity[0]
        where = f"{type(self).__name__} {self.path}".rstrip()
        n = _n_positional(fn)
        if n not in (1, 2):
            raise ParameterError(f"{where}: the {name} law must take 1 argument (the "
                                 f"flange {self.across_name}) or 2 (and its rate); "
                                 f"it takes {n}")
        try:
            out = fn(x) if n == 1 else fn(x, v)
            return sp.sympify(out, strict=True)
        except Exception as exc:
            hint = ""
            if "truth value" in str(exc):
                hint = " (the law gets sympy symbols: use sympy.Max/Min/Piecewise, not " \
                       "max/min/if)"
            raise ParameterError(f"{where}: the {name} law failed: "
                                 f"{type(exc).__name__}: {exc}{hint}") from None

    def law(self, x):
        """The source value as a sympy expression; ``x`` is the flange's
        across variable symbol."""
        if self._law is None:
            return self.symbol(f"{self.quantity[0]}_const")
        if isinstance(self._law, sp.Basic) and not isinstance(self._law, sp.Lambda):
            return self._law
        return self._call(self._law, x, der(x))
