"""Partial models that own the connector equations, so that a leaf
component is only its parameters and its law (Modelica's PartialCompliant /
PartialRigid). Sign convention: see :mod:`acausal.connectors`."""
import inspect
import numbers
import sys

import sympy as sp

from acausal.lang import Component, Eq, Flange, Parameter, RotFlange, Variable, der
from acausal.lang.connectors import RealInput

from acausal.errors import ModelError, ParameterError


class NonZeroParameter(Parameter):
    """A parameter that may have either sign but not be zero (an arm, a gear
    ratio): zero would make the transformer degenerate."""

    def check_bounds(self, v, label):
        super().check_bounds(v, label)
        if v == 0:
            raise ParameterError(f"parameter {label} = 0 [{self.unit}] must be non-zero "
                                 f"({self.desc})", variable=label)


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
    """A rigid translational element of length ``L`` between two flanges
    (MSL ``Translational.Interfaces.PartialRigid``)::

        flange_a o=========|=========o flange_b        --> +s
           s - L/2         s         s + L/2

    ``flange_a.s = s - L/2``, ``flange_b.s = s + L/2``.

    Parameters: ``L`` [m] length from flange_a to flange_b (>= 0).
    States: ``s`` [m] position of the element's centre. Connectors:
    ``flange_a`` (left), ``flange_b`` (right).
    """

    flange_a = Flange("left flange (s - L/2)")
    flange_b = Flange("right flange (s + L/2)")
    L = Parameter(0.0, "m", "length of the component, from flange_a to flange_b", min=0.0)
    s = Variable(0.0, "m", "absolute position of the centre (= flange_a.s + L/2)")

    def equations(self):
        return [Eq(self.flange_a.s, self.s - self.L / 2),
                Eq(self.flange_b.s, self.s + self.L / 2)]


class PartialRigidBody(PartialRigid):
    """A rigid translational body of length ``L``: :class:`PartialRigid`'s
    two end flanges plus a centre ``flange`` (``flange.s = s``), velocity
    ``v`` and acceleration ``a``. Every flange may stay unconnected (it then
    carries no force), so a body is used either with one flange (``flange``,
    the breaker's way: all forces act at ``s``) or as MSL's two-flange
    ``Mass`` (``flange_a``, ``flange_b``), or both.

    :meth:`net_force` is the sum of the forces its three flanges apply.
    States: ``s`` [m] centre, ``v`` [m/s] = der(s), ``a`` [m/s2] = der(v).
    Connectors: ``flange_a`` (at s - L/2), ``flange_b`` (at s + L/2),
    ``flange`` (at s).
    """

    diagnosis_site = "body"   # what acausal.diagnose may extend here

    flange_a = Flange("left flange (s - L/2); no force when unconnected", optional=True)
    flange_b = Flange("right flange (s + L/2); no force when unconnected", optional=True)
    flange = Flange("centre flange (s); no force when unconnected", optional=True)
    v = Variable(0.0, "m/s", "absolute velocity")
    a = Variable(0.0, "m/s2", "absolute acceleration")

    def net_force(self):
        """The sum of the forces applied at the body's flanges [N]."""
        return self.flange_a.f + self.flange_b.f + self.flange.f

    def equations(self):
        return [Eq(self.flange.s, self.s), Eq(self.v, der(self.s)), Eq(self.a, der(self.v))]


class PartialRotRigid(Component):
    """A rigid rotating body: two flanges (MSL ``Inertia``'s ``flange_a``,
    ``flange_b``) and a third, ``flange`` (the single flange of earlier
    versions), all at the body's angle ``phi``; angular velocity ``w`` and
    acceleration ``a``. Every flange may stay unconnected (no torque then).

    :meth:`net_torque` is the sum of the torques its three flanges apply.
    States: ``phi`` [rad], ``w`` [rad/s] = der(phi), ``a`` [rad/s2] =
    der(w). Connectors: ``flange_a``, ``flange_b``, ``flange``.
    """

    diagnosis_site = "body"   # what acausal.diagnose may extend here

    flange_a = RotFlange("left flange; no torque when unconnected", optional=True)
    flange_b = RotFlange("right flange; no torque when unconnected", optional=True)
    flange = RotFlange("the body's flange; no torque when unconnected", optional=True)
    phi = Variable(0.0, "rad", "absolute angle")
    w = Variable(0.0, "rad/s", "absolute angular velocity")
    a = Variable(0.0, "rad/s2", "absolute angular acceleration")

    def net_torque(self):
        """The sum of the torques applied at the body's flanges [N*m]."""
        return self.flange_a.tau + self.flange_b.tau + self.flange.tau

    def equations(self):
        return [Eq(self.flange.phi, self.phi), Eq(self.flange_a.phi, self.phi),
                Eq(self.flange_b.phi, self.phi), Eq(self.w, der(self.phi)),
                Eq(self.a, der(self.w))]


class PartialCompliantWithRelativeStates(PartialCompliant):
    """:class:`PartialCompliant` plus the relative velocity ``v_rel =
    der(s_rel)`` (MSL ``PartialCompliantWithRelativeStates``). A fixed start
    value may be given to ``s_rel`` and ``v_rel``
    (``SpringDamper(s_rel=0.5, v_rel=0)``).

    ``s_nominal`` is MSL's scale of ``s_rel``: given explicitly, it is
    ``s_rel``'s nominal value (absolute tolerance ``rtol * s_nominal``;
    read when the model is compiled); left at its default (MSL's 1e-4 m)
    it sets none, so models written before keep their tolerances.

    Parameters: ``s_nominal`` [m] (> 0). States: ``s_rel`` [m], ``v_rel``
    [m/s], ``f`` [N]. Connectors: ``flange_a``, ``flange_b``.
    """

    s_nominal = Parameter(1e-4, "m", "nominal value of s_rel (used for scaling)", min=0.0,
                          min_open=True)
    v_rel = Variable(0.0, "m/s", "relative velocity der(s_rel)")

    def set(self, **kw):
        out = super().set(**kw)
        if "s_nominal" in kw:
            self.__dict__.setdefault("_scales_given", set()).add("s_nominal")
        return out

    def nominal(self, name):
        given = super().nominal(name)
        if name == "s_rel" and given is None:
            return _nominal_parameter(self, "s_nominal")
        return given

    def equations(self):
        return [Eq(self.v_rel, der(self.s_rel))]


class PartialRotCompliantWithRelativeStates(PartialRotCompliant):
    """:class:`PartialRotCompliant` plus the relative angular velocity
    ``w_rel = der(phi_rel)`` (MSL ``PartialCompliantWithRelativeStates``).

    ``phi_nominal`` is MSL's scale of ``phi_rel``: given explicitly, it is
    ``phi_rel``'s nominal value (the solver's absolute tolerance on it is
    then ``rtol * phi_nominal``; read when the model is compiled). Left at
    its default (MSL's 1e-4), it sets no nominal, so models written before
    keep their tolerances. ``with_nominal(phi_rel=...)`` wins over it.

    Parameters: ``phi_nominal`` [rad] (>= 0). States: ``phi_rel`` [rad],
    ``w_rel`` [rad/s], ``tau`` [N*m]. Connectors: ``flange_a``,
    ``flange_b``.
    """

    phi_nominal = Parameter(1e-4, "rad", "nominal value of phi_rel (used for scaling)",
                            min=0.0)
    w_rel = Variable(0.0, "rad/s", "relative angular velocity der(phi_rel)")

    def set(self, **kw):
        out = super().set(**kw)
        if "phi_nominal" in kw:
            self.__dict__.setdefault("_scales_given", set()).add("phi_nominal")
        return out

    def nominal(self, name):
        given = super().nominal(name)
        if name == "phi_rel" and given is None:
            return _nominal_parameter(self, "phi_nominal")
        return given

    def equations(self):
        return [Eq(self.w_rel, der(self.phi_rel))]


def _nominal_parameter(comp, name):
    """The nominal value a scale parameter such as MSL's ``phi_nominal``
    gives: its value when it was set explicitly to a number, MSL's 1 when
    that number is below machine epsilon, else None."""
    if name not in comp.__dict__.get("_scales_given", ()):
        return None
    value = comp.value(name)
    if isinstance(value, sp.Basic) and not value.is_number:
        return None
    value = float(value)
    return value if value >= sys.float_info.epsilon else 1.0


# -- support flanges (MSL's useSupport) ------------------------------------------
def declared_connector(ctype, name, desc):
    """A connector declaration named ``name`` outside a class body."""
    decl = ctype(desc)
    decl.name = name
    return decl


class PartialConditionalConnectors(Component):
    """Connectors that exist only when a structural flag is true (MSL's
    conditional connectors, ``Support support if useSupport``).

    ``_conditional`` maps a connector name to (flag parameter, connector
    declaration). Without its flag the connector does not exist: it has no
    variables, and reaching for it (``gear.support``) is a ModelError saying
    which flag enables it.
    """

    _conditional = {}

    def connectors(self):
        out = super().connectors()
        for name, (flag, decl) in self._conditional.items():
            if self._values.get(flag):
                out[name] = decl
        return out

    def port(self, name):
        cond = self._conditional.get(name)
        if cond is not None and not self._values.get(cond[0]):
            where = self.path or type(self).__name__
            raise ModelError(f"{where} has no connector {name!r}: that side is fixed to the "
                             f"ground ({cond[0]}=False); build it with {cond[0]}=True to "
                             "connect it", component=self.path)
        return super().port(name)

    def __getattr__(self, name):
        if name in type(self)._conditional and "_values" in self.__dict__:
            return self.port(name)
        raise AttributeError(f"{type(self).__name__} has no attribute {name!r}")


class _WithSupport(PartialConditionalConnectors):
    """MSL's ``useSupport``: with ``useSupport=True`` the component has a
    ``support`` flange (its housing) that takes the reaction; with
    ``useSupport=False`` (default) it has none and its housing is fixed to
    the ground at 0. A leaf reads the support's position with
    :meth:`support_across` and sets its force with :meth:`support_reaction`.
    """

    useSupport = Parameter(False, "1", "true: a support flange (housing); false: grounded",
                           structural=True, choices=(False, True))
    _conditional = {"support": ("useSupport", declared_connector(Flange, "support",
                                                        "support/housing of the component"))}

    def support_across(self):
        """The support's position (angle), 0 when grounded."""
        if self.useSupport:
            return self.port("support").pairs()[0][0]
        return sp.Integer(0)

    def support_reaction(self, through):
        """[support through = ``through``] when there is a support, else []."""
        if self.useSupport:
            return [Eq(self.port("support").pairs()[0][1], through)]
        return []


_ROT_SUPPORT = {"support": ("useSupport", declared_connector(RotFlange, "support",
                                                    "support/housing of the component"))}


class PartialElementaryOneFlangeAndSupport2(_WithSupport):
    """One translational ``flange`` and an optional ``support`` (MSL's
    partial of the same name): ``s = flange.s - support.s``; the support
    takes ``-flange.f``.

    Parameters: ``useSupport`` (structural). States: ``s`` [m] flange
    position relative to the support. Connectors: ``flange``, ``support``
    (only with ``useSupport=True``).
    """

    flange = Flange("flange of the component")
    s = Variable(0.0, "m", "distance between flange and support (= flange.s - support.s)")

    def equations(self):
        return ([Eq(self.s, self.flange.s - self.support_across())]
                + self.support_reaction(-self.flange.f))


class PartialForce(PartialElementaryOneFlangeAndSupport2):
    """A force law on one flange relative to its support (MSL
    ``PartialForce``): ``f = flange.f`` is the force the component takes
    from the flange (the body there receives ``-f``), ``v = der(s)`` the
    flange's velocity relative to the support. A leaf gives ``f``.

    Parameters: ``useSupport`` (structural). States: ``s`` [m], ``v``
    [m/s], ``f`` [N]. Connectors: ``flange``, ``support`` (with useSupport).
    """

    diagnosis_site = "source"   # what acausal.diagnose may extend here

    f = Variable(0.0, "N", "force the component takes from the flange (= flange.f; the "
                 "body receives -f)")
    v = Variable(0.0, "m/s", "velocity of flange with respect to support (= der(s))")

    def equations(self):
        return [Eq(self.f, self.flange.f), Eq(self.v, der(self.s))]


class PartialElementaryTwoFlangesAndSupport2(_WithSupport):
    """Two translational flanges and an optional ``support`` (MSL's partial
    of the same name): ``s_a = flange_a.s - support.s``, ``s_b = flange_b.s
    - support.s``; the support takes ``-flange_a.f - flange_b.f``.

    Parameters: ``useSupport`` (structural). States: ``s_a``, ``s_b`` [m].
    Connectors: ``flange_a``, ``flange_b``, ``support`` (with useSupport).
    """

    flange_a = Flange("left flange")
    flange_b = Flange("right flange")
    s_a = Variable(0.0, "m", "distance between left flange and support")
    s_b = Variable(0.0, "m", "distance between right flange and support")

    def equations(self):
        s0 = self.support_across()
        return ([Eq(self.s_a, self.flange_a.s - s0), Eq(self.s_b, self.flange_b.s - s0)]
                + self.support_reaction(-self.flange_a.f - self.flange_b.f))


class PartialRotElementaryOneFlangeAndSupport2(_WithSupport):
    """One rotational ``flange`` and an optional ``support`` (MSL
    ``Rotational.Interfaces.PartialElementaryOneFlangeAndSupport2`` with
    ``PartialTorque``'s angle): ``phi = flange.phi - support.phi``; the
    support takes ``-flange.tau``.

    Parameters: ``useSupport`` (structural). States: ``phi`` [rad] flange
    angle relative to the support. Connectors: ``flange``, ``support``
    (with useSupport).
    """

    _conditional = _ROT_SUPPORT
    flange = RotFlange("flange of the shaft")
    phi = Variable(0.0, "rad", "angle of flange with respect to support (= flange.phi - "
                   "support.phi)")

    def equations(self):
        return ([Eq(self.phi, self.flange.phi - self.support_across())]
                + self.support_reaction(-self.flange.tau))


class PartialTorque(PartialRotElementaryOneFlangeAndSupport2):
    """A torque law on one flange relative to its support (MSL
    ``PartialTorque`` with the leaves' ``w`` and ``tau``): ``tau =
    -flange.tau`` is the torque that accelerates the flange (the body there
    receives ``+tau``), ``w = der(phi)`` the flange's angular velocity
    relative to the support. A leaf gives ``tau``.

    Parameters: ``useSupport`` (structural). States: ``phi`` [rad], ``w``
    [rad/s], ``tau`` [N*m]. Connectors: ``flange``, ``support`` (with
    useSupport).
    """

    diagnosis_site = "source"   # what acausal.diagnose may extend here

    tau = Variable(0.0, "N*m", "accelerating torque acting at the flange (= -flange.tau)")
    w = Variable(0.0, "rad/s", "angular velocity of flange with respect to support "
                 "(= der(phi))")

    def equations(self):
        return [Eq(self.tau, -self.flange.tau), Eq(self.w, der(self.phi))]


class PartialRotElementaryTwoFlangesAndSupport2(_WithSupport):
    """Two rotational flanges and an optional ``support`` (MSL's partial of
    the same name): ``phi_a = flange_a.phi - support.phi``, ``phi_b =
    flange_b.phi - support.phi``; the support takes ``-flange_a.tau -
    flange_b.tau``.

    Parameters: ``useSupport`` (structural). States: ``phi_a``, ``phi_b``
    [rad]. Connectors: ``flange_a``, ``flange_b``, ``support`` (with
    useSupport).
    """

    _conditional = _ROT_SUPPORT
    flange_a = RotFlange("flange of left shaft")
    flange_b = RotFlange("flange of right shaft")
    phi_a = Variable(0.0, "rad", "angle between left shaft flange and support")
    phi_b = Variable(0.0, "rad", "angle between right shaft flange and support")

    def equations(self):
        p0 = self.support_across()
        return ([Eq(self.phi_a, self.flange_a.phi - p0), Eq(self.phi_b, self.flange_b.phi - p0)]
                + self.support_reaction(-self.flange_a.tau - self.flange_b.tau))


class PartialElementaryRotationalToTranslational(PartialConditionalConnectors):
    """A rotational flange ``flangeR`` and a translational flange ``flangeT``
    with optional housings (MSL's partial of the same name):
    ``useSupportR=True`` adds ``supportR`` (rotational housing, takes
    ``-flangeR.tau``), ``useSupportT=True`` adds ``supportT`` (translational
    housing, takes ``-flangeT.f``); without them that housing is grounded.
    A leaf writes its law with :meth:`phi_rel` = ``flangeR.phi -
    supportR.phi`` and :meth:`s_rel` = ``flangeT.s - supportT.s``.

    Parameters: ``useSupportR``, ``useSupportT`` (structural). Connectors:
    ``flangeR``, ``flangeT``, ``supportR``, ``supportT`` (with their flags).
    """

    flangeR = RotFlange("flange of the rotational shaft")
    flangeT = Flange("flange of the translational rod")
    useSupportR = Parameter(False, "1", "true: a rotational support flange; false: grounded",
                            structural=True, choices=(False, True))
    useSupportT = Parameter(False, "1", "true: a translational support flange; false: "
                            "grounded", structural=True, choices=(False, True))
    _conditional = {
        "supportR": ("useSupportR", declared_connector(RotFlange, "supportR",
                                              "rotational support/housing of the component")),
        "supportT": ("useSupportT", declared_connector(Flange, "supportT",
                                              "translational support/housing of the component")),
    }

    def phi_rel(self):
        """flangeR.phi relative to its housing [rad]."""
        return self.flangeR.phi - (self.supportR.phi if self.useSupportR else 0)

    def s_rel(self):
        """flangeT.s relative to its housing [m]."""
        return self.flangeT.s - (self.supportT.s if self.useSupportT else 0)

    def equations(self):
        eqs = []
        if self.useSupportR:
            eqs.append(Eq(self.supportR.tau, -self.flangeR.tau))
        if self.useSupportT:
            eqs.append(Eq(self.supportT.f, -self.flangeT.f))
        return eqs


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


class PartialFlowSensor(Component):
    """Two translational flanges joined rigidly, through which the force
    passes unchanged (the partial of MSL's ForceSensor, PowerSensor and
    MultiSensor): ``flange_a.s = flange_b.s``, ``flange_a.f + flange_b.f =
    0``. Connectors: ``flange_a``, ``flange_b``.
    """

    diagnosis_site = "sensor"   # what acausal.diagnose may extend here

    flange_a = Flange("left flange")
    flange_b = Flange("right flange")

    def equations(self):
        return [Eq(self.flange_a.s, self.flange_b.s),
                Eq(self.flange_a.f + self.flange_b.f, 0)]


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


class PartialRotFlowSensor(Component):
    """Two rotational flanges joined rigidly, through which the torque
    passes unchanged (the partial of MSL's TorqueSensor, PowerSensor and
    MultiSensor): ``flange_a.phi = flange_b.phi``, ``flange_a.tau +
    flange_b.tau = 0``. Connectors: ``flange_a``, ``flange_b``.
    """

    diagnosis_site = "sensor"   # what acausal.diagnose may extend here

    flange_a = RotFlange("left flange")
    flange_b = RotFlange("right flange")

    def equations(self):
        return [Eq(self.flange_a.phi, self.flange_b.phi),
                Eq(self.flange_a.tau + self.flange_b.tau, 0)]


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


class SourceValue(Variable):
    """The value of a :class:`PartialSource` (a force or torque): a variable
    set by the source's law, or, on a source built without a law, MSL's
    ``RealInput`` connector of the same name (``connect(sine.y,
    force.f)``). Read on an instance it is the connector in the second case,
    the variable's symbol in the first; both stand for the same variable
    (``force.f``) in equations."""

    def __get__(self, obj, objtype=None):
        if obj is None:
            return self
        if self.name in obj.__dict__.get("_inputs", {}):
            return obj.port(self.name)
        return obj.symbol(self.name)


class PartialSource(Component):
    """A source whose value (force or torque) is MSL's ``RealInput`` signal,
    or follows a law given at construction as

    * nothing (``None``, the default of :class:`~acausal.mechanics.translational.Force`
      and :class:`~acausal.mechanics.rotational.Torque`): the value is an
      input connector of the value's name, to be connected to a signal
      (``connect(sine.y, force.f)``), as MSL's sources;
    * a number: a constant, kept as the run-time parameter ``<name>_const``
      (changeable with ``simulate(params=...)`` without recompiling);
    * a sympy expression: of :data:`acausal.time` and of model parameters
      (e.g. a ``model.parameter(...)`` symbol);
    * a callable ``law(x)`` or ``law(x, v)``: called with the symbol of the
      source's own flange across variable (position or angle) and, if it
      takes two arguments, of its rate (velocity or angular velocity); it
      returns a sympy expression (it may also use ``acausal.time``).

    A leaf sets ``quantity`` = (name, unit, description) and
    ``across_name``, declares the :class:`SourceValue` of that name and
    writes ``Eq(value, self.law(x))`` (which is empty for an input) and its
    connector equation.
    """

    diagnosis_site = "source"   # what acausal.diagnose may extend here

    quantity = ("u", "1", "source value")
    across_name = "across variable"   # how the law's argument is called in messages

    def __init__(self, value=0.0, **kw):
        object.__setattr__(self, "_inputs", {})
        if value is None:
            name, unit, desc = self.quantity
            decl = RealInput(f"{desc} (input signal)", unit)
            decl.name = name
            self._inputs[name] = decl
        super().__init__(**kw)
        name, unit, desc = self.quantity
        where = f"{type(self).__name__}.{name}"
        if value is None:
            object.__setattr__(self, "_law", None)
            return
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

    @property
    def is_input(self):
        """True when the value is an input signal (no law given)."""
        return bool(self._inputs)

    def declarations(self):
        decl = super().declarations()
        for name in self.__dict__.get("_inputs", {}):
            decl.pop(name, None)       # the input connector is that variable
        return decl

    def connectors(self):
        out = super().connectors()
        out.update(self.__dict__.get("_inputs", {}))
        return out

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
        across variable symbol. For an input, the input's variable."""
        if self._inputs:
            return self.symbol(self.quantity[0])
        if self._law is None:
            return self.symbol(f"{self.quantity[0]}_const")
        if isinstance(self._law, sp.Basic) and not isinstance(self._law, sp.Lambda):
            return self._law
        return self._call(self._law, x, der(x))
