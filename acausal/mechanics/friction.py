"""Coulomb + viscous friction with stick/slip modes (not MSL components:
MSL's friction elements with normal-force inputs, friction tables, the free
mode, hard stops and lossy gears are in :mod:`acausal.mechanics.rotational`
and :mod:`acausal.mechanics.translational`). The four elements here run on
the same mode machine, :mod:`acausal.mechanics.frictionmodes` (MSL's
``PartialFriction``), with a constant kinetic level ``F_c``, a break-away
level ``F_s >= F_c`` and a viscous term.

Sign convention: :mod:`acausal.connectors` (through variables positive INTO
the component). Every element here has a relative motion ``x_rel`` (the
position/angle of flange_b relative to flange_a, or of the flange relative
to the fixed ground), its rate ``v_rel`` and a friction force/torque ``f``
(``tau``) counted like a damper's: ``f`` is what the outside applies on the
element at flange_b, so the element pushes flange_b's body with ``-f``
(and flange_a's body with ``+f``)::

    sliding forward/backward (mode = +1/-1):  f = +-F_c + d*v_rel   (opposes v_rel)
    stuck (mode = 0):                           der(v_rel) = 0, |f| <= F_s

The machine's levels: break-away at ``|f| > F_s`` (``break_forward``,
``break_backward``), a start is kept while the holding force stays at or
above ``F_c`` (else ``abort_*``), and ``slide_stop`` when a sliding
``v_rel`` reaches 0, after which the break-away tests run again at the same
instant: the body stays stuck (``|f| <= F_s``) or slides the other way
(at once when ``v_rel`` is at or past zero that way, else as soon as
``v_rel`` crosses zero: ``slide_forward``/``slide_backward``). ``mode``
is 3 before the start, then ``initial_mode`` sets it by the sign of
``v_rel`` (0 at rest: the break-away tests follow at once). Event names
carry the component's path (``fr.slide_stop``). Other events, states and
the exact-tie rules: :mod:`acausal.mechanics.frictionmodes`.

``F_s < F_c`` is rejected when the component is built and again when a run
starts with overridden parameter values (a ParameterError naming ``F_s``).
Giving only ``F_c`` at construction sets ``F_s = F_c``.

The element needs inertia on the sliding side (a mass or inertia at the
flange, or on the node): a massless node with d = 0 leaves the sliding
velocity undetermined, as in Modelica.

Why a mode machine and not a smooth law: a ``tanh``-smoothed Coulomb law
cannot hold a body at rest under a load below break-away; it creeps (and a
stiff smoothing makes the integrator crawl near v = 0).

Limitations (numbers, not hopes): the stuck mode keeps the relative
velocity reached at the ``slide_stop`` root, which IDA locates to about
``100 * 2.2e-16 * (|t| + |h|)`` s, so a stuck body can creep at
``|a| * that`` (of order 1e-12 m/s for a = 10 m/s^2, t = 10 s); a body that
starts at rest stays exactly at rest while stuck.
"""
import sympy as sp
from sympy import Piecewise

from acausal.lang import Component, Eq, Event, Flange, Parameter, RotFlange, Variable, der
from acausal.errors import ParameterError

from .frictionmodes import PartialFrictionModes
from .partials import PartialCompliant, PartialRotCompliant


def _num(value):
    """A float when ``value`` is a plain number, else None (bound parameter)."""
    if isinstance(value, sp.Basic):
        return float(value) if value.is_number else None
    return float(value)


def _param_value(state, sym):
    """A parameter's value in an event action, also when it is bound to an
    expression of other parameters (then it is not a free parameter)."""
    value = f"{float(state[sym]):g}"
    bound = state.cm.bound.get(sym.name)
    return f"{value} (bound to {bound})" if bound is not None else value


class _CoulombViscous(PartialFrictionModes):
    """The law of the four elements on the shared mode machine (a partial:
    it adds no declarations; the leaves declare the parameters named in
    ``_names = (kinetic, static, viscous)``, ``v_rel``, ``a_rel`` and the
    force/torque ``_force_name``)."""

    _names = ("F_c", "F_s", "d")
    _force_name = "f"

    def __init__(self, **kw):
        kin, sta, _ = self._names
        if kin in kw and sta not in kw:   # pure Coulomb: break-away = kinetic level
            kw[sta] = kw[kin]
        super().__init__(**kw)

    # -- parameter check across two parameters --------------------------------
    def set(self, **kw):
        out = super().set(**kw)
        kin, sta, _ = self._names
        if kin in self._values and sta in self._values:
            fc, fs = _num(self._values[kin]), _num(self._values[sta])
            if fc is not None and fs is not None and fs < fc:
                where = f"{self.path}.{sta}" if self.path else f"{type(self).__name__}.{sta}"
                raise ParameterError(
                    f"parameter {where} = {fs:g} (break-away {self._unit_of(sta)}) must be "
                    f">= {kin} = {fc:g}: the static friction level cannot be below the "
                    "kinetic (Coulomb) one")
        return out

    def _unit_of(self, name):
        return f"[{self.declarations()[name].unit}]"

    # -- the law on the shared machine --------------------------------------------
    def _levels(self):
        kin, sta, visc = self._names
        return getattr(self, kin), getattr(self, sta), getattr(self, visc)

    def friction_motion(self):
        return self.v_rel, self.a_rel

    def friction_force(self):
        return getattr(self, self._force_name)

    def sliding_force(self, direction):
        F_c, _, d = self._levels()
        return direction * F_c + d * self.v_rel

    def break_level(self, direction):
        return direction * self._levels()[1]

    def hold_level(self, direction):
        F_c, F_s, _ = self._levels()
        return direction * (F_c - F_s)

    def slide_offset(self, direction):
        # sa = the relative acceleration while sliding or starting (offset 0),
        # so the hold level is F_c - F_s in those terms: a start is dropped
        # when the acceleration falls below (F_c - F_s)/(unit mass), as MSL's
        # sa < f0 with its offset f0_max. Not the break-away level: sa of the
        # size of F_s would carry eps*F_s of round-off into the acceleration,
        # which IDA's error test then sees at tight tolerances (stick_slip.py
        # at rtol 1e-12, atol 1e-15: too many steps at the slip's speed peak)
        return 0

    def events(self):
        kin, sta, _ = self._names
        F_c, F_s, _ = self._levels()
        label = f"{self.path}.{sta}" if self.path else sta
        pre = f"{self.path}." if self.path else ""

        def invalid(state):
            raise ParameterError(
                f"parameter {label} = {_param_value(state, F_s)} (break-away "
                f"{self._unit_of(sta)}) must be >= {kin} = {_param_value(state, F_c)}: the "
                "static friction level cannot be below the kinetic (Coulomb) one")

        # a piecewise-constant root: it only acts in the initial event iteration
        return [Event(pre + "check_" + sta, Piecewise((1, F_s < F_c), (-1, True)), 1, invalid,
                      recheck=True)]


class Friction(_CoulombViscous, PartialCompliant):
    """Coulomb + viscous friction between two translational flanges, with
    stiction (e.g. a block on a moving belt: flange_a = belt, flange_b =
    block).

    Law, with ``v_rel = der(s_rel)`` (flange_b relative to flange_a) and
    ``f`` the force at flange_b (the element pushes flange_b with ``-f``,
    flange_a with ``+f``)::

        sliding (mode = +-1): f = F_c*mode + d*v_rel
        stuck   (mode = 0):   der(v_rel) = 0, |f| <= F_s

    Stuck -> sliding when ``f`` crosses ``+F_s`` (forward) or ``-F_s``
    (backward); sliding -> stuck when ``v_rel`` reaches 0 and the holding
    force is at most ``F_s``, otherwise it slides the other way (at once, or
    when ``v_rel`` has crossed zero: MSL's start flags).
    A normal-force form is obtained by binding ``F_c = mu*N`` and
    ``F_s = mu_s*N`` to model parameters.

    Parameters: ``F_c`` [N] kinetic (Coulomb) friction force (>= 0), ``F_s``
    [N] break-away (static) friction force (>= F_c; F_c when not given),
    ``d`` [N*s/m] viscous coefficient (>= 0).
    States: ``s_rel`` [m], ``v_rel`` [m/s], ``a_rel`` [m/s^2], ``f`` [N];
    the shared machine's (discrete ``mode``: 3 before the start, -1 sliding
    backward, 0 stuck, +1 sliding forward; ``startForward``,
    ``startBackward``; ``sa``, ``locked``, ``lossPower`` [W]).
    Connectors: ``flange_a``, ``flange_b``.
    """

    F_c = Parameter(0.0, "N", "kinetic (Coulomb) friction force", min=0.0)
    F_s = Parameter(0.0, "N", "break-away (static) friction force, >= F_c", min=0.0)
    d = Parameter(0.0, "N*s/m", "viscous friction coefficient", min=0.0)
    v_rel = Variable(0.0, "m/s", "relative velocity der(s_rel)")
    a_rel = Variable(0.0, "m/s^2", "relative acceleration der(v_rel)")

    def equations(self):
        return [Eq(self.v_rel, der(self.s_rel)), Eq(self.a_rel, der(self.v_rel))]


class GroundFriction(_CoulombViscous, Component):
    """Coulomb + viscous friction of a body sliding on the fixed ground (a
    block on a table): :class:`Friction` with flange_a fixed.

    Law, with ``v_rel = der(flange.s)`` and ``f = flange.f`` (the element
    pushes the body on its flange with ``-f``)::

        sliding (mode = +-1): f = F_c*mode + d*v_rel
        stuck   (mode = 0):   der(v_rel) = 0, |f| <= F_s

    Parameters: ``F_c`` [N] kinetic (Coulomb) friction force (>= 0), ``F_s``
    [N] break-away (static) friction force (>= F_c; F_c when not given),
    ``d`` [N*s/m] viscous coefficient (>= 0).
    States: ``v_rel`` [m/s], ``a_rel`` [m/s^2], ``f`` [N]; the shared
    machine's (``mode`` 3 before the start, -1, 0, +1; ``startForward``,
    ``startBackward``; ``sa``, ``locked``, ``lossPower`` [W]).
    Connectors: ``flange``.
    """

    flange = Flange("the sliding body's flange")
    F_c = Parameter(0.0, "N", "kinetic (Coulomb) friction force", min=0.0)
    F_s = Parameter(0.0, "N", "break-away (static) friction force, >= F_c", min=0.0)
    d = Parameter(0.0, "N*s/m", "viscous friction coefficient", min=0.0)
    v_rel = Variable(0.0, "m/s", "velocity of the flange der(flange.s)")
    a_rel = Variable(0.0, "m/s^2", "acceleration der(v_rel)")
    f = Variable(0.0, "N", "force into the element at the flange")

    def equations(self):
        return [Eq(self.v_rel, der(self.flange.s)), Eq(self.a_rel, der(self.v_rel)),
                Eq(self.flange.f, self.f)]


class RotFriction(_CoulombViscous, PartialRotCompliant):
    """Coulomb + viscous friction between two rotational flanges (a clutch
    that stays engaged, a bearing between shaft and a moving housing).

    Law, with ``w_rel = der(phi_rel)`` (flange_b relative to flange_a) and
    ``tau`` the torque at flange_b (the element twists flange_b with
    ``-tau``)::

        sliding (mode = +-1): tau = tau_c*mode + d*w_rel
        stuck   (mode = 0):   der(w_rel) = 0, |tau| <= tau_s

    Parameters: ``tau_c`` [N*m] kinetic (Coulomb) friction torque (>= 0),
    ``tau_s`` [N*m] break-away torque (>= tau_c; tau_c when not given), ``d``
    [N*m*s/rad] viscous coefficient (>= 0).
    States: ``phi_rel`` [rad], ``w_rel`` [rad/s], ``a_rel`` [rad/s^2],
    ``tau`` [N*m]; the shared machine's (``mode`` 3 before the start, -1,
    0, +1; ``startForward``, ``startBackward``; ``sa``, ``locked``,
    ``lossPower`` [W]).
    Connectors: ``flange_a``, ``flange_b``.
    """

    _names = ("tau_c", "tau_s", "d")
    _force_name = "tau"

    tau_c = Parameter(0.0, "N*m", "kinetic (Coulomb) friction torque", min=0.0)
    tau_s = Parameter(0.0, "N*m", "break-away (static) friction torque, >= tau_c", min=0.0)
    d = Parameter(0.0, "N*m*s/rad", "viscous friction coefficient", min=0.0)
    w_rel = Variable(0.0, "rad/s", "relative angular velocity der(phi_rel)")
    a_rel = Variable(0.0, "rad/s^2", "relative angular acceleration der(w_rel)")

    @property
    def v_rel(self):
        return self.w_rel

    def equations(self):
        return [Eq(self.w_rel, der(self.phi_rel)), Eq(self.a_rel, der(self.w_rel))]


class BearingFriction(_CoulombViscous, Component):
    """Coulomb + viscous friction of a shaft in a fixed housing (a bearing):
    :class:`RotFriction` with flange_a fixed.

    Law, with ``w_rel = der(flange.phi)`` and ``tau = flange.tau`` (the
    element twists the shaft with ``-tau``)::

        sliding (mode = +-1): tau = tau_c*mode + d*w_rel
        stuck   (mode = 0):   der(w_rel) = 0, |tau| <= tau_s

    Parameters: ``tau_c`` [N*m] kinetic (Coulomb) friction torque (>= 0),
    ``tau_s`` [N*m] break-away torque (>= tau_c; tau_c when not given), ``d``
    [N*m*s/rad] viscous coefficient (>= 0).
    States: ``w_rel`` [rad/s], ``a_rel`` [rad/s^2], ``tau`` [N*m]; the
    shared machine's (``mode`` 3 before the start, -1, 0, +1;
    ``startForward``, ``startBackward``; ``sa``, ``locked``, ``lossPower``
    [W]).
    Connectors: ``flange``.
    """

    _names = ("tau_c", "tau_s", "d")
    _force_name = "tau"

    flange = RotFlange("the shaft's flange")
    tau_c = Parameter(0.0, "N*m", "kinetic (Coulomb) friction torque", min=0.0)
    tau_s = Parameter(0.0, "N*m", "break-away (static) friction torque, >= tau_c", min=0.0)
    d = Parameter(0.0, "N*m*s/rad", "viscous friction coefficient", min=0.0)
    w_rel = Variable(0.0, "rad/s", "angular velocity der(flange.phi)")
    a_rel = Variable(0.0, "rad/s^2", "angular acceleration der(w_rel)")
    tau = Variable(0.0, "N*m", "torque into the element at the flange")

    @property
    def v_rel(self):
        return self.w_rel

    def equations(self):
        return [Eq(self.w_rel, der(self.flange.phi)), Eq(self.a_rel, der(self.w_rel)),
                Eq(self.flange.tau, self.tau)]
