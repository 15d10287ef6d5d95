"""Coulomb + viscous friction with stick/slip modes switched by events.

MSL's friction elements (normal-force inputs, friction tables, the free
mode, startForward/startBackward, hard stops, lossy gears) are in
:mod:`acausal.mechanics.rotational` and :mod:`acausal.mechanics.translational`,
on the shared mode machine :mod:`acausal.mechanics.frictionmodes`. The four
elements here keep this module's machine: their tests fix behaviour that
MSL's machine does differently at exact ties (docs/components.md,
"Friction elements").

Sign convention: :mod:`acausal.connectors` (through variables positive INTO
the component). Every element here has a relative motion ``x_rel`` (the
position/angle of flange_b relative to flange_a, or of the flange relative
to the fixed ground), its rate ``v_rel`` and a friction force/torque ``f``
(``tau``) counted like a damper's: ``f`` is what the outside applies on the
element at flange_b, so the element pushes flange_b's body with ``-f``
(and flange_a's body with ``+f``). Friction therefore reads, with
``mode = sign(v_rel)``::

    sliding (mode = +1 or -1):  f = F_c*mode + d*v_rel       (opposes v_rel)
    stuck   (mode = 0):         der(v_rel) = 0                 (f is whatever holds)

The mode machine is Modelica's (Forward / Stuck / Backward, see
Modelica.Mechanics.Rotational.UsersGuide.ModelingOfFriction), with events:

* ``slide_stop``: while sliding, ``mode*v_rel`` falls through 0 -> mode 0.
* ``break_forward`` / ``break_backward`` (re-checked after every event):
  while stuck, ``f`` rises above ``F_s`` / falls below ``-F_s`` -> mode +1 /
  -1. Right after ``slide_stop`` the model is re-initialised stuck, the
  holding force is computed, and these re-checks decide at the same instant
  whether the body stays stuck (|f| <= F_s) or slides the other way. Since
  sliding starts with ``|f_hold| > F_s >= F_c``, the relative acceleration
  right after a break-away points away from zero velocity, so a mode never
  flips back at the same instant (no chattering).
* ``initial_mode`` (fires once, in the initial event iteration): a relative
  velocity that is not exactly zero at the initial point sets
  ``mode = sign(v_rel)``; a run starting with ``v_rel = 0`` starts stuck
  (and the break-away checks that follow at the same instant let it slide
  at once if the holding force exceeds ``F_s``).
* ``F_s < F_c`` is rejected when the component is built and again when a
  run starts with overridden parameter values (a ParameterError naming
  ``F_s``). Giving only ``F_c`` at construction sets ``F_s = F_c``.

Event names carry the component's path (``fr.slide_stop``), so that a model
with several friction elements can tell their events apart in
``result.events``.

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
from sympy import Ne, Piecewise

from acausal.lang import Component, Discrete, Eq, Event, Flange, Parameter, RotFlange, Variable, der
from acausal.errors import ParameterError

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


class _StickSlip:
    """The mode machine shared by the friction elements (a mixin: it adds no
    declarations and no ``equations``; the leaves call its helpers).

    A leaf sets ``_names = (kinetic, static, viscous)`` parameter names and
    declares ``v_rel``, ``a_rel``, ``mode``, ``init`` and its force/torque
    ``_force_name``.
    """

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

    # -- the law ----------------------------------------------------------------
    def _sym(self, name):
        return getattr(self, name)

    def _law(self):
        kin, _, visc = self._names
        F_c, d = self._sym(kin), self._sym(visc)
        v, a, f, mode = self.v_rel, self.a_rel, self._sym(self._force_name), self.mode
        return [Eq(0, Piecewise((a, Eq(mode, 0)),
                                (f - F_c * mode - d * v, True)))]

    def _mode_events(self):
        kin, sta, _ = self._names
        F_c, F_s = self._sym(kin), self._sym(sta)
        v, f, mode, init = self.v_rel, self._sym(self._force_name), self.mode, self.init
        stuck = Eq(mode, 0) & Eq(init, 0)
        me = self
        label = f"{self.path}.{sta}" if self.path else sta
        pre = f"{self.path}." if self.path else ""

        def stop(state):
            state[me.mode] = 0

        def forward(state):
            state[me.mode] = 1

        def backward(state):
            state[me.mode] = -1

        def initial(state):
            v0 = state[me.v_rel]
            if v0 != 0:
                state[me.mode] = 1 if v0 > 0 else -1
            state[me.init] = 0

        def invalid(state):
            raise ParameterError(
                f"parameter {label} = {_param_value(state, F_s)} (break-away "
                f"{self._unit_of(sta)}) must be >= {kin} = {_param_value(state, F_c)}: the "
                "static friction level cannot be below the kinetic (Coulomb) one")

        return [
            Event(pre + "slide_stop", Piecewise((mode * v, Ne(mode, 0)), (1, True)), -1, stop),
            Event(pre + "break_forward", Piecewise((f - F_s, stuck), (-1, True)), 1, forward,
                  recheck=True),
            Event(pre + "break_backward", Piecewise((-F_s - f, stuck), (-1, True)), 1, backward,
                  recheck=True),
            # piecewise-constant roots: they only act in the initial event
            # iteration (a constant 1 or -1 never crosses zero while integrating)
            Event(pre + "initial_mode", Piecewise((1, Eq(init, 1)), (-1, True)), 1, initial,
                  recheck=True),
            Event(pre + "check_" + sta, Piecewise((1, F_s < F_c), (-1, True)), 1, invalid,
                  recheck=True),
        ]


class Friction(_StickSlip, PartialCompliant):
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
    force is at most ``F_s``, otherwise it slides the other way at once.
    A normal-force form is obtained by binding ``F_c = mu*N`` and
    ``F_s = mu_s*N`` to model parameters.

    Parameters: ``F_c`` [N] kinetic (Coulomb) friction force (>= 0), ``F_s``
    [N] break-away (static) friction force (>= F_c; F_c when not given),
    ``d`` [N*s/m] viscous coefficient (>= 0).
    States: ``s_rel`` [m], ``v_rel`` [m/s], ``a_rel`` [m/s^2], ``f`` [N];
    discrete ``mode`` (-1 sliding backward, 0 stuck, +1 sliding forward).
    Connectors: ``flange_a``, ``flange_b``.
    """

    F_c = Parameter(0.0, "N", "kinetic (Coulomb) friction force", min=0.0)
    F_s = Parameter(0.0, "N", "break-away (static) friction force, >= F_c", min=0.0)
    d = Parameter(0.0, "N*s/m", "viscous friction coefficient", min=0.0)
    v_rel = Variable(0.0, "m/s", "relative velocity der(s_rel)")
    a_rel = Variable(0.0, "m/s^2", "relative acceleration der(v_rel)")
    mode = Discrete(0, "1", "-1 sliding backward, 0 stuck, +1 sliding forward")
    init = Discrete(1, "1", "1 until the initial mode decision at the start of a run")

    def equations(self):
        return [Eq(self.v_rel, der(self.s_rel)), Eq(self.a_rel, der(self.v_rel))] + self._law()

    def events(self):
        return self._mode_events()


class GroundFriction(_StickSlip, Component):
    """Coulomb + viscous friction of a body sliding on the fixed ground (a
    block on a table): :class:`Friction` with flange_a fixed.

    Law, with ``v_rel = der(flange.s)`` and ``f = flange.f`` (the element
    pushes the body on its flange with ``-f``)::

        sliding (mode = +-1): f = F_c*mode + d*v_rel
        stuck   (mode = 0):   der(v_rel) = 0, |f| <= F_s

    Parameters: ``F_c`` [N] kinetic (Coulomb) friction force (>= 0), ``F_s``
    [N] break-away (static) friction force (>= F_c; F_c when not given),
    ``d`` [N*s/m] viscous coefficient (>= 0).
    States: ``v_rel`` [m/s], ``a_rel`` [m/s^2], ``f`` [N]; discrete ``mode``
    (-1 sliding backward, 0 stuck, +1 sliding forward).
    Connectors: ``flange``.
    """

    flange = Flange("the sliding body's flange")
    F_c = Parameter(0.0, "N", "kinetic (Coulomb) friction force", min=0.0)
    F_s = Parameter(0.0, "N", "break-away (static) friction force, >= F_c", min=0.0)
    d = Parameter(0.0, "N*s/m", "viscous friction coefficient", min=0.0)
    v_rel = Variable(0.0, "m/s", "velocity of the flange der(flange.s)")
    a_rel = Variable(0.0, "m/s^2", "acceleration der(v_rel)")
    f = Variable(0.0, "N", "force into the element at the flange")
    mode = Discrete(0, "1", "-1 sliding backward, 0 stuck, +1 sliding forward")
    init = Discrete(1, "1", "1 until the initial mode decision at the start of a run")

    def equations(self):
        return [Eq(self.v_rel, der(self.flange.s)), Eq(self.a_rel, der(self.v_rel)),
                Eq(self.flange.f, self.f)] + self._law()

    def events(self):
        return self._mode_events()


class RotFriction(_StickSlip, PartialRotCompliant):
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
    ``tau`` [N*m]; discrete ``mode`` (-1, 0, +1).
    Connectors: ``flange_a``, ``flange_b``.
    """

    _names = ("tau_c", "tau_s", "d")
    _force_name = "tau"

    tau_c = Parameter(0.0, "N*m", "kinetic (Coulomb) friction torque", min=0.0)
    tau_s = Parameter(0.0, "N*m", "break-away (static) friction torque, >= tau_c", min=0.0)
    d = Parameter(0.0, "N*m*s/rad", "viscous friction coefficient", min=0.0)
    w_rel = Variable(0.0, "rad/s", "relative angular velocity der(phi_rel)")
    a_rel = Variable(0.0, "rad/s^2", "relative angular acceleration der(w_rel)")
    mode = Discrete(0, "1", "-1 sliding backward, 0 stuck, +1 sliding forward")
    init = Discrete(1, "1", "1 until the initial mode decision at the start of a run")

    @property
    def v_rel(self):
        return self.w_rel

    def equations(self):
        return [Eq(self.w_rel, der(self.phi_rel)), Eq(self.a_rel, der(self.w_rel))] + \
            self._law()

    def events(self):
        return self._mode_events()


class BearingFriction(_StickSlip, Component):
    """Coulomb + viscous friction of a shaft in a fixed housing (a bearing):
    :class:`RotFriction` with flange_a fixed.

    Law, with ``w_rel = der(flange.phi)`` and ``tau = flange.tau`` (the
    element twists the shaft with ``-tau``)::

        sliding (mode = +-1): tau = tau_c*mode + d*w_rel
        stuck   (mode = 0):   der(w_rel) = 0, |tau| <= tau_s

    Parameters: ``tau_c`` [N*m] kinetic (Coulomb) friction torque (>= 0),
    ``tau_s`` [N*m] break-away torque (>= tau_c; tau_c when not given), ``d``
    [N*m*s/rad] viscous coefficient (>= 0).
    States: ``w_rel`` [rad/s], ``a_rel`` [rad/s^2], ``tau`` [N*m]; discrete
    ``mode`` (-1, 0, +1).
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
    mode = Discrete(0, "1", "-1 sliding backward, 0 stuck, +1 sliding forward")
    init = Discrete(1, "1", "1 until the initial mode decision at the start of a run")

    @property
    def v_rel(self):
        return self.w_rel

    def equations(self):
        return [Eq(self.w_rel, der(self.flange.phi)), Eq(self.a_rel, der(self.w_rel)),
                Eq(self.flange.tau, self.tau)] + self._law()

    def events(self):
        return self._mode_events()
