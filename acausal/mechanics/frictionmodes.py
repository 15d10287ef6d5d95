"""The friction mode machine (MSL's ``PartialFriction``), shared by every
friction element of both domains (:mod:`acausal.mechanics.rotational` and
:mod:`acausal.mechanics.translational`: BearingFriction, Brake, Clutch,
OneWayClutch, LossyGear, SupportFriction, MassWithStopAndFriction).

Sign convention: :mod:`acausal.lang.connectors`. A friction element has a
velocity ``w`` between its frictional surfaces (``w_rel``, or the velocity
of its flanges relative to its support), the acceleration ``a = der(w)``
and a friction force/torque ``F`` counted like a damper's: ``F`` is what
the outside applies on the element, so the element acts on the moving
surface with ``-F``; sliding friction has the sign of ``w``.

The machine (Otter, Elmqvist & Mattsson 1999; MSL 4.0.0
``Rotational.Interfaces.PartialFriction`` and the UsersGuide
"ModelingOfFriction"). One path parameter ``sa`` covers every configuration
with the same two equations, so the structure of the model never changes::

    locked (stuck, staying stuck):   a = 0               F = sa  (the holding force)
    free (normal force <= 0):        a = sa              F = 0
    sliding or starting forward:     a = sa - slide_fwd  F = law(+1, w)
    sliding or starting backward:    a = sa - slide_bwd  F = law(-1, w)

with, for MSL's PartialFriction, ``slide_fwd = F0_max = -slide_bwd``. The
discrete state is MSL's: ``mode`` (Unknown 3 before the start, Free 2,
Forward 1, Stuck 0, Backward -1) and the booleans ``startForward``,
``startBackward`` (0/1). ``locked`` = Stuck (or Unknown) and neither start
flag. Transitions, each an event of the element (name = path + suffix):

* ``initial_mode`` (once, at the start): Free when the normal force is
  <= 0, else Forward if ``w > 0``, Backward if ``w < 0``, else Stuck.
* ``break_forward`` / ``break_backward``: locked and ``sa`` (the force
  needed to stay stuck) rises above the break-away level ``break_fwd``
  (falls below ``break_bwd``): ``startForward`` (``startBackward``). Then
  ``mode`` is Forward at once if ``w >= 0`` (MSL: if ``w > 0``; see below).
* ``slide_forward`` / ``slide_backward``: starting and ``w`` leaves zero in
  that direction: Forward (Backward), the start flag is cleared.
* ``abort_forward`` / ``abort_backward``: starting forward and ``sa``
  falls below the level that keeps it (``hold_fwd``; ``F0`` for
  PartialFriction) before ``w`` left zero: back to locked (backward
  likewise).
* ``slide_stop``: sliding and ``w`` reaches zero (MSL's relation ``w > 0``
  switches): Stuck, locked; the break-away tests then run again at the same
  instant and may start it in either direction at once. When ``w`` has
  jumped past ``-w_small`` (``+w_small``) it slides the other way directly.
* ``release`` / ``engage`` (elements with a normal force): the normal
  force falls to <= 0: Free; it rises above 0: Forward/Backward by the sign
  of ``w``, or Stuck.

Every transition is also re-checked after any event of the model (an event
iteration, as Modelica's), so a mode that is not valid at the new point is
left at once.

Two elements that lock the same motion (their velocities proportional in
the compiled model: a bearing and a brake on one shaft, MSL's LossyGear
with a BearingFriction) leave their holding torques undetermined (MSL's
UsersGuide "RequirementsForSimulationTool": "there does not exist a unique
solution"), and the integrator cannot step a singular system. The
re-initialisation splits the load by least squares, closest to the values
before the event (what that guide suggests); then (bookkeeping event
``coupled_lock``, not logged) only the first of them in the model's order
stays locked, and each other one starts to slide in the direction of its
share, at its sliding level. The motion starts when their total break-away
is exceeded. This reproduces the reference results of MSL's LossyGearDemo2,
mode by mode.

Where this differs from MSL 4.0.0 (each only at an exact tie, where MSL's
own outcome depends on the tool's event epsilon):

* at a break-away with ``w = 0`` exactly, MSL keeps ``mode = Stuck`` and the
  start flag until ``w`` has left zero (an infinitesimal time: 1.5e-12 to
  2.4e-6 s in the reference results, where only Dymola's event epsilon
  separates the two); here the element is Forward (Backward) at once. IDA
  cannot locate ``w`` leaving an exact zero (a root function that is zero
  where a segment starts is ignored). With ``w`` of the other sign (a stuck
  element whose drift velocity is -1e-16), the start flag stays until ``w``
  crosses zero, as in MSL.
* ``startForward`` is kept while ``sa >= hold_fwd`` (MSL: ``sa > F0``),
  and a start is dropped, or a sliding element at ``w = 0`` stopped, only
  when the margin exceeds ``TIE`` = 1e-12 (relative to the level): with
  ``peak = 1`` and the motion held by another element, the "starting"
  element has ``a = 0`` up to round-off (+-1e-31) and ``sa = F0``; MSL's
  strict test would drop the flag and raise it again at once, for ever.
* the root functions are never exactly zero where a segment starts (a
  tie gives -1 or +1 instead), so that IDA sees every later crossing.

The element needs inertia on the sliding side, or another element that
fixes the motion, as in Modelica.
"""
import sympy as sp
from sympy import Eq as Rel
from sympy import Ne, Piecewise

from acausal.lang import Component, Discrete, Eq, Event, Parameter, Variable

__all__ = ["PartialFrictionModes", "PartialFriction", "PartialRotFriction",
           "UNKNOWN", "FREE", "FORWARD", "STUCK", "BACKWARD"]

UNKNOWN, FREE, FORWARD, STUCK, BACKWARD = 3, 2, 1, 0, -1
TIE = 1e-12   # a level (relative) or an acceleration (absolute) within this of its threshold is at it


def magnitude(x):
    """|x| as a Piecewise: its derivative is the branch's (sympy's Abs
    differentiates through re/im, which the code generators do not print)."""
    return Piecewise((x, x >= 0), (-x, True))


def _value(state, expr):
    """The value of a sympy expression of model symbols in an event action
    (a lone symbol is read as it is: what substituting it gives)."""
    if isinstance(expr, sp.Symbol):
        return float(state[expr])
    expr = sp.sympify(expr)
    if expr.is_number:
        return float(expr)
    return float(expr.xreplace({s: state[s] for s in expr.free_symbols}))


def _true(state, cond):
    """The truth of a sympy condition of model symbols in an event action."""
    if cond in (True, False) or isinstance(cond, (sp.logic.boolalg.BooleanTrue,
                                                   sp.logic.boolalg.BooleanFalse)):
        return bool(cond)
    return bool(cond.xreplace({s: sp.Float(state[s]) for s in cond.free_symbols}))


class PartialFrictionModes(Component):
    """The mode machine (see the module docstring). A friction element is
    this machine plus its kinematics and its law: the leaf (or a domain
    partial, :class:`PartialFriction`, :class:`PartialRotFriction`)
    implements

    * :meth:`friction_motion` -> ``(w, a)``: velocity and acceleration
      between the frictional surfaces (expressions of its variables);
    * :meth:`friction_force` -> the symbol of ``F``;
    * :meth:`sliding_force` ``(direction)`` -> ``F`` while sliding or
      starting in ``direction`` (+1, -1), an expression of ``w`` etc.;
    * :meth:`break_level`, :meth:`hold_level`, :meth:`slide_offset`
      ``(direction)``: the break-away level, the level that keeps a start,
      and the offset of ``sa`` in sliding (``a = sa - offset``);
    * optionally :meth:`engagement` (free when it is <= 0; None: never
      free), :meth:`blocked` ``(direction)`` (a condition of discrete
      values forbidding motion that way: a hard stop, a freewheel),
      :meth:`jump_level` (``w_small``: a jump of ``w`` past it reverses a
      sliding element at once; None: never) and :meth:`locked_jump_level`
      (a jump of ``w`` past it starts a locked element forward; None).

    Discrete states: ``mode`` (3 Unknown, 2 Free, 1 Forward, 0 Stuck, -1
    Backward), ``startForward``, ``startBackward`` (0/1). States: ``sa``
    (no unit) path parameter (the holding force while locked),
    ``sa_offset`` (no unit) its offset while sliding, ``locked``, ``free``
    [1] (0/1, as MSL's booleans), ``lossPower`` [W] = F*w (MSL's).
    """

    mode = Discrete(UNKNOWN, "1", "3 unknown (before the start), 2 free, 1 sliding forward, "
                    "0 stuck, -1 sliding backward")
    startForward = Discrete(0, "1", "1 while stuck and starting to slide forward")
    startBackward = Discrete(0, "1", "1 while stuck and starting to slide backward")
    sa = Variable(0.0, None, "path parameter of the friction characteristic (the holding "
                  "force/torque while locked; the acceleration shifted by sa_offset while "
                  "sliding): no unit, as MSL's")
    sa_offset = Variable(0.0, None, "the level subtracted from sa while sliding (MSL's "
                         "tau0_max/unitTorque): no unit")
    locked = Variable(0.0, "1", "1 while stuck and not starting to slide")
    free = Variable(0.0, "1", "1 while the element transmits nothing (normal force <= 0)")
    lossPower = Variable(0.0, "W", "power dissipated by the friction, F*w (>= 0)")

    # -- what a leaf provides ------------------------------------------------
    def friction_motion(self):
        raise NotImplementedError

    def friction_force(self):
        raise NotImplementedError

    def sliding_force(self, direction):
        raise NotImplementedError

    def break_level(self, direction):
        raise NotImplementedError

    def hold_level(self, direction):
        return self.break_level(direction)

    def slide_offset(self, direction):
        return self.break_level(direction)

    def engagement(self):
        return None

    def blocked(self, direction):
        return sp.false

    def jump_level(self):
        return None

    def locked_jump_level(self):
        return None

    # -- the configuration -------------------------------------------------------
    def _configuration(self):
        """(locked, free, forward) conditions of the discrete state."""
        m, sf, sb = self.mode, self.startForward, self.startBackward
        stuck = Rel(m, STUCK) | Rel(m, UNKNOWN)
        locked = stuck & Rel(sf, 0) & Rel(sb, 0)
        free = Rel(m, FREE) if self.engagement() is not None else sp.false
        forward = Rel(m, FORWARD) | (stuck & Rel(sf, 1))
        return locked, free, forward

    def _locked_condition(self):
        """Locked after the start (Unknown is locked only until initial_mode)."""
        return Rel(self.mode, STUCK) & Rel(self.startForward, 0) & Rel(self.startBackward, 0)

    def _locked_now(self, state):
        """:meth:`_locked_condition` at an event's ``state``, from the numbers
        (the action runs at every event of every element: building the sympy
        condition and substituting into it was half of a stick-slip pair
        model's simulation time)."""
        m, sf, sb = self._flags()
        return bool(state[m] == STUCK and state[sf] == 0 and state[sb] == 0)

    def _built(self, key, make):
        """``make()``, an expression of this element's symbols, built once per
        path: the actions run at every event of the model, and building the
        element's expressions again each time (a sympy Symbol per variable
        read) was most of the friction actions' share of a stick-slip model's
        simulation, about 12 % of its profile (5 % of its time end to end)."""
        memo = self.__dict__.setdefault("_expressions", {})
        k = (self.path, key)
        if k not in memo:
            memo[k] = make()
        return memo[k]

    def _flags(self):
        """The symbols of (mode, startForward, startBackward)."""
        return self._built("flags", lambda: (self.mode, self.startForward, self.startBackward))

    def _velocity(self):
        """``w`` of :meth:`friction_motion`."""
        return self._built("w", lambda: self.friction_motion()[0])

    def _blocked(self, d):
        return self._built(("blocked", d), lambda: self.blocked(d))

    def _sa(self):
        return self._built("sa", lambda: self.sa)

    def _friction_elements(self):
        """Every friction element of the model this one belongs to, in the
        model's order."""
        top = self
        while getattr(top, "_parent", None) is not None:
            top = top._parent
        return [c for c in (top.walk() if hasattr(top, "walk") else [top])
                if isinstance(c, PartialFrictionModes)]

    def equations(self):
        w, a = self.friction_motion()
        F, sa = self.friction_force(), self.sa
        locked, free, forward = self._configuration()
        acc = [(a, locked)]
        force = [(F - sa, locked)]
        if free is not sp.false:
            acc.append((a - sa, free))
            force.append((F, free))
        # sa carries no unit and sa_offset stands for the force level in sa's
        # terms (MSL divides by unitTorque, unitAngularAcceleration)
        acc.append((a - sa + self.sa_offset, True))
        force += [(F - self.sliding_force(1), forward), (F - self.sliding_force(-1), True)]
        return [Eq(0, Piecewise(*acc)), Eq(0, Piecewise(*force)),
                Eq(self.lossPower, F * w),
                # (0 where it is not used: a sliding law need not make sense
                # while locked, and LossyGear's is discontinuous there)
                Eq(self.sa_offset, Piecewise((0, locked | free), (self.slide_offset(1), forward),
                                             (self.slide_offset(-1), True))),
                Eq(self.locked, Piecewise((1, locked), (0, True))),
                Eq(self.free, Piecewise((1, free), (0, True)))]

    # -- the transitions -----------------------------------------------------------
    def events(self):
        w, a = self.friction_motion()
        sa, m = self.sa, self.mode
        sf, sb = self.startForward, self.startBackward
        e = self.engagement()
        active = sp.true if e is None else e > 0
        locked = self._locked_condition()
        sliding = Rel(m, FORWARD) | Rel(m, BACKWARD)
        starting = {1: Rel(m, STUCK) & Rel(sf, 1), -1: Rel(m, STUCK) & Rel(sb, 1)}
        pre = f"{self.path}." if self.path else ""

        def nonzero(x, otherwise):
            # x, or `otherwise` where x is exactly 0: IDA ignores a root
            # function that is exactly zero where a segment starts (until it
            # moves away from zero, and then it does not report the change)
            return Piecewise((x, Ne(x, 0)), (otherwise, True))

        def off(expr, cond):            # the root where cond holds, -1 elsewhere
            return Piecewise((expr, cond & active), (-1, True))

        evs = [Event(pre + "initial_mode", Piecewise((1, Rel(m, UNKNOWN)), (-1, True)), 1,
                     self._act_initial, recheck=True)]
        if e is not None:
            evs.append(Event(pre + "release", Piecewise(
                (nonzero(-e, 1), Ne(m, FREE) & Ne(m, UNKNOWN)), (-1, True)), 1,
                self._act_release, recheck=True))
            evs.append(Event(pre + "engage", Piecewise(
                (nonzero(e, -1), Rel(m, FREE)), (-1, True)), 1, self._act_engage, recheck=True))
        for d, name in ((1, "forward"), (-1, "backward")):
            brk = d * (sa - self.break_level(d))
            jump = self.locked_jump_level() if d == 1 else None
            if jump is not None:
                brk = sp.Max(brk, w - jump)
            evs.append(Event(pre + "break_" + name, off(nonzero(brk, -1),
                                                        locked & ~self.blocked(d)), 1,
                             self._act_break(d), recheck=True))
            evs.append(Event(pre + "slide_" + name, off(nonzero(d * w, -1), starting[d]), 1,
                             self._act_go(d), recheck=True))
            hold = self.hold_level(d)
            evs.append(Event(pre + "abort_" + name,
                             off(d * (hold - sa) - TIE * (1 + magnitude(hold)), starting[d]), 1,
                             self._act_abort(d), recheck=True))
        evs.append(Event(pre + "slide_stop",
                         off(nonzero(-m * w, -m * a - TIE), sliding), 1,
                         self._act_slide_stop, recheck=True))
        others = [c for c in self._friction_elements() if c is not self]
        if others:
            anyone = sp.Or(*[c._locked_condition() for c in others])
            evs.append(Event(pre + "coupled_lock", Piecewise((1, locked & anyone), (-1, True)), 1,
                             self._act_coupled_lock, recheck=True, log=False))
        return evs

    # -- event actions (each writes absolute values: two of one element never
    #    fire at one instant, their conditions exclude each other) ------------------
    def _set(self, state, mode, sf=0, sb=0):
        m, f, b = self._flags()
        state[m] = mode
        state[f] = sf
        state[b] = sb

    def _direction(self, state, w):
        """Forward/Backward by the sign of w where not blocked, else Stuck."""
        if w > 0 and not _true(state, self._blocked(1)):
            return FORWARD
        if w < 0 and not _true(state, self._blocked(-1)):
            return BACKWARD
        return STUCK

    def _engaged(self, state):
        e = self._built("engagement", self.engagement)
        return e is None or _value(state, e) > 0

    def _act_initial(self, state):
        if not self._engaged(state):
            self._set(state, FREE)
        else:
            self._set(state, self._direction(state, _value(state, self._velocity())))

    def _act_release(self, state):
        self._set(state, FREE)

    def _act_engage(self, state):
        self._set(state, self._direction(state, _value(state, self._velocity())))

    def _act_break(self, d):
        def act(state):
            if d * _value(state, self._velocity()) >= 0:   # moving that way, or at rest: slides
                self._set(state, d)
            else:                                 # wait until w has crossed zero
                self._set(state, STUCK, sf=int(d == 1), sb=int(d == -1))
        return act

    def _act_go(self, d):
        def act(state):
            hold = _value(state, self._built(("hold", d), lambda: self.hold_level(d)))
            if d * (hold - _value(state, self._sa())) - TIE * (1 + abs(hold)) > 0:
                self._set(state, STUCK)          # the start is over first (MSL order)
            else:
                self._set(state, d)
        return act

    def _act_abort(self, d):
        def act(state):
            self._set(state, STUCK)
        return act

    def _act_coupled_lock(self, state):
        """Two locked elements that hold the same motion (a bearing and a
        brake on one shaft, a lossy gear and its bearing: their velocities
        are proportional) leave their holding torques undetermined: MSL's
        "RequirementsForSimulationTool". The re-initialisation has split the
        load by least squares, closest to the values before the event (the
        choice MSL's users guide suggests); to integrate, only the first of
        them (in the model's order) stays locked, and this one starts to
        slide in the direction of its share of the load (at once if the
        velocity allows, else waiting, as after a break-away)."""
        if not self._locked_now(state):
            return
        for other in self._friction_elements():
            if other is self:
                return                            # none before this one holds the same motion
            if other._locked_now(state) and self._coupled(state, other):
                share = _value(state, self._sa())
                self._act_break(1 if share >= 0 else -1)(state)
                return

    def _coupled(self, state, other):
        """True when this element's velocity is a constant multiple of the
        other's in the compiled model (the same motion)."""
        cm = state.cm
        key = (id(cm), other.path)
        memo = self.__dict__.setdefault("_coupling", {})
        if key not in memo:
            try:
                mine = cm.resolve(self.friction_motion()[0])
                theirs = cm.resolve(other.friction_motion()[0])
                ratio = sp.simplify(mine / theirs) if theirs != 0 else sp.nan
                values = dict(zip(cm.param_syms, state.p))
                ratio = ratio.xreplace(values)
                memo[key] = bool(ratio.is_number and ratio.is_finite and ratio != 0)
            except Exception:       # an expression the compiled model cannot give
                memo[key] = False
        return memo[key]

    def _act_slide_stop(self, state):
        w = self._velocity()
        m = int(state[self._flags()[0]])
        jump = self._built("jump", self.jump_level)
        if jump is not None and m * _value(state, w) < -_value(state, jump) \
                and not _true(state, self._blocked(-m)):
            self._set(state, -m)                  # w jumped across zero (a reinit elsewhere)
        else:
            self._set(state, STUCK)


class PartialFriction(PartialFrictionModes):
    """MSL ``Translational.Interfaces.PartialFriction``: the mode machine
    with the levels of a friction force, ``f0`` (sliding friction at
    ``v = 0``) and ``f0_max`` (break-away force), which the leaf defines.
    Break-away at ``sa > f0_max`` (``< -f0_max``), a start is kept while
    ``sa >= f0``, and ``a = sa -+ f0_max`` while sliding.

    Parameters: ``v_small`` [m/s] a velocity jump past it (a reinit) reverses
    a sliding element at once. States: ``f0``, ``f0_max`` [N]; the machine's
    (``mode``, ``startForward``, ``startBackward``, ``sa``, ``locked``,
    ``free``).
    """

    v_small = Parameter(1e-3, "m/s", "relative velocity near to zero: a jump of the velocity "
                        "past it reverses a sliding element at once", min=0.0, min_open=True)
    f0 = Variable(0.0, "N", "friction force for v = 0 while sliding forward")
    f0_max = Variable(0.0, "N", "largest friction force for v = 0 while stuck (break-away)")

    def break_level(self, direction):
        return direction * self.f0_max

    def hold_level(self, direction):
        return direction * self.f0

    def jump_level(self):
        return self.v_small


class PartialRotFriction(PartialFrictionModes):
    """MSL ``Rotational.Interfaces.PartialFriction``: the mode machine with
    the levels of a friction torque, ``tau0`` (sliding friction at ``w = 0``)
    and ``tau0_max`` (break-away torque), which the leaf defines.
    Break-away at ``sa > tau0_max`` (``< -tau0_max``), a start is kept while
    ``sa >= tau0``, and ``a = sa -+ tau0_max`` while sliding.

    Parameters: ``w_small`` [rad/s] an angular velocity jump past it (a
    reinit) reverses a sliding element at once (MSL's default 1e10 turns
    this off). States: ``tau0``, ``tau0_max`` [N*m]; the machine's.
    """

    w_small = Parameter(1e10, "rad/s", "relative angular velocity near to zero: a jump of the "
                        "velocity past it reverses a sliding element at once",
                        min=0.0, min_open=True)
    tau0 = Variable(0.0, "N*m", "friction torque for w = 0 while sliding forward")
    tau0_max = Variable(0.0, "N*m", "largest friction torque for w = 0 while stuck "
                        "(break-away)")

    def break_level(self, direction):
        return direction * self.tau0_max

    def hold_level(self, direction):
        return direction * self.tau0

    def jump_level(self):
        return self.w_small
