"""Translational friction elements (MSL ``Modelica.Mechanics.Translational.Components``:
SupportFriction, Brake, MassWithStopAndFriction), each a leaf of the shared
mode machine :class:`acausal.mechanics.frictionmodes.PartialFrictionModes` (modes,
events and their names: see that module).

Sign convention: :mod:`acausal.lang.connectors`. A friction force ``f`` is
what the outside applies on the element; it acts on the sliding body with
``-f`` and has the sign of the sliding velocity (MSL's). Tables are
interpolated linearly and extrapolated with their end intervals
(:func:`acausal.mechanics.tables.interpolate`).
"""
import math

import sympy as sp
from sympy import Eq as Rel
from sympy import Ne, Piecewise

from acausal.errors import InitializationError, ParameterError
from acausal.lang import Discrete, Eq, Event, Parameter, RealInput, Variable, der

from ..frictionmodes import STUCK, UNKNOWN, PartialFriction
from ..partials import PartialElementaryTwoFlangesAndSupport2, PartialRigid
from ..tables import Table, interpolate

__all__ = ["SupportFriction", "Brake", "MassWithStopAndFriction", "stribeck_table"]


def _peak(what):
    return Parameter(1.0, "1", f"peak of the {what} at v = 0 (break-away = peak * sliding "
                     "value at v = 0)", min=1.0)


class _SlidingOnSupport(PartialElementaryTwoFlangesAndSupport2):
    """Two flanges joined rigidly, sliding on the support: ``s =
    flange_a.s - support.s = flange_b.s - support.s``, ``v = der(s)``, ``a =
    der(v)``; the friction force ``f = flange_a.f + flange_b.f`` is taken by
    the support."""

    s = Variable(0.0, "m", "position of the flanges relative to the support")
    v = Variable(0.0, "m/s", "velocity of the flanges relative to the support")
    a = Variable(0.0, "m/s2", "acceleration of the flanges relative to the support")
    f = Variable(0.0, "N", "friction force (sum of the flange forces)")

    def equations(self):
        return [Eq(self.s, self.s_a), Eq(self.flange_b.s, self.flange_a.s),
                Eq(self.v, der(self.s)), Eq(self.a, der(self.v)),
                Eq(self.flange_a.f + self.flange_b.f - self.f, 0)]

    def friction_motion(self):
        return self.v, self.a

    def friction_force(self):
        return self.f


class SupportFriction(_SlidingOnSupport, PartialFriction):
    """Coulomb friction between two rigidly joined flanges and their support
    (MSL ``SupportFriction``), with a table of the sliding force::

        sliding:  f = +f_pos(v)  (v > 0),   -f_pos(-v)  (v < 0)
        stuck:    der(v) = 0, while -f0_max <= f <= f0_max
        f0 = f_pos(0),  f0_max = peak*f0

    Modes and events: :mod:`acausal.mechanics.frictionmodes` (never free).
    A Stribeck table: :func:`stribeck_table`.

    Parameters: ``f_pos`` table of rows (v [m/s], f [N]), v >= 0, strictly
    increasing; ``peak`` [1] (>= 1); ``useSupport`` (structural);
    ``v_small`` [m/s]. States: ``s`` [m], ``v`` [m/s], ``a`` [m/s2], ``f``
    [N]; the machine's (``mode``, ``startForward``, ``startBackward``,
    ``sa``, ``locked``). Connectors: ``flange_a``, ``flange_b``,
    ``support`` (with useSupport).
    """

    f_pos = Table(((0.0, 1.0),), 2, ("m/s", "N"),
                  "positive sliding friction characteristic f(v) for v >= 0: rows (v [m/s], "
                  "f [N])")
    peak = _peak("friction force")

    def equations(self):
        return [Eq(self.f0, interpolate(self.f_pos, 1, 0)), Eq(self.f0_max, self.peak * self.f0)]

    def sliding_force(self, direction):
        return direction * interpolate(self.f_pos, 1, direction * self.v)


class Brake(_SlidingOnSupport, PartialFriction):
    """A translational brake (MSL ``Translational.Components.Brake``):
    Coulomb friction between two rigidly joined flanges and their support,
    pressed with the normal force ``fn = fn_max*f_normalized``::

        free (fn <= 0):  f = 0
        sliding:         f = cgeo*fn*mu_pos(v)   (v > 0; odd in v)
        stuck:           der(v) = 0, while |f| <= f0_max
        f0 = mu_pos(0)*cgeo*fn,  f0_max = peak*f0

    Modes and events: :mod:`acausal.mechanics.frictionmodes` (``release``
    / ``engage`` when ``fn`` reaches 0).

    Parameters: ``mu_pos`` table of rows (v [m/s], mu [1]), v >= 0,
    strictly increasing; ``peak`` [1] (>= 1); ``cgeo`` [1] geometry
    constant (>= 0); ``fn_max`` [N] largest normal force (>= 0);
    ``useSupport`` (structural); ``v_small`` [m/s]. Inputs:
    ``f_normalized`` [1] normalized normal force (0..1). States: ``s``
    [m], ``v`` [m/s], ``a`` [m/s2], ``f`` [N], ``fn`` [N], ``mu0`` [1];
    the machine's. Connectors: ``flange_a``, ``flange_b``, ``support``
    (with useSupport), ``f_normalized`` (RealInput).
    """

    mu_pos = Table(((0.0, 0.5),), 2, ("m/s", "1"),
                   "positive sliding friction coefficient mu(v) for v >= 0: rows (v [m/s], "
                   "mu [1])")
    peak = _peak("friction coefficient")
    cgeo = Parameter(1.0, "1", "geometry constant containing the friction distribution "
                     "(force = cgeo*mu*fn)", min=0.0)
    fn_max = Parameter(1.0, "N", "largest normal force (fn = fn_max*f_normalized)", min=0.0)
    f_normalized = RealInput("normalized normal force 0..1 (fn = fn_max*f_normalized; the "
                             "brake is active when > 0)")
    mu0 = Variable(0.0, "1", "friction coefficient at v = 0")
    fn = Variable(0.0, "N", "normal force")

    def equations(self):
        return [Eq(self.mu0, interpolate(self.mu_pos, 1, 0)),
                Eq(self.fn, self.fn_max * self.f_normalized),
                Eq(self.f0, self.mu0 * self.cgeo * self.fn),
                Eq(self.f0_max, self.peak * self.f0)]

    def engagement(self):
        return self.fn

    def sliding_force(self, direction):
        return self.cgeo * self.fn * direction * interpolate(self.mu_pos, 1, direction * self.v)


def stribeck_table(F_prop, F_Coulomb, F_Stribeck, fexp, v_max, n=100):
    """A table of the Stribeck friction law ``f = F_Coulomb + F_prop*v +
    F_Stribeck*exp(-fexp*v)`` at ``n`` speeds evenly spaced on ``[0,
    v_max]`` (MSL ``Translational.Examples.Utilities.GenerateStribeckFrictionTable``),
    for :class:`SupportFriction`'s ``f_pos``.

    ``F_prop`` [N*s/m], ``F_Coulomb`` [N], ``F_Stribeck`` [N], ``fexp``
    [s/m], ``v_max`` [m/s] (> 0), ``n`` (>= 2). Returns a tuple of rows
    (v [m/s], f [N]).
    """
    if not (isinstance(n, int) and n >= 2):
        raise ParameterError(f"stribeck_table: n = {n!r} must be an integer >= 2")
    if not v_max > 0:
        raise ParameterError(f"stribeck_table: v_max = {v_max!r} [m/s] must be > 0")
    rows = []
    for i in range(n):
        v = v_max * i / (n - 1)
        rows.append((v, F_Coulomb + F_prop * v + F_Stribeck * math.exp(-fexp * v)))
    return tuple(rows)


class MassWithStopAndFriction(PartialRigid, PartialFriction):
    """A sliding mass with Stribeck friction against the ground and hard
    stops (MSL ``MassWithStopAndFriction``). The mass of length ``L`` slides
    with its centre ``s`` between ``smin + L/2`` and ``smax - L/2``::

        m*der(v) = flange_a.f + flange_b.f - f,   v = der(s)
        sliding:  f = F_prop*v + sign(v)*(F_Coulomb + F_Stribeck*exp(-fexp*|v|))
        stuck:    der(v) = 0, while |f| <= f0_max
        f0 = F_Coulomb + F_Stribeck,  f0_max = 1.001*f0

    A hard stop is perfectly plastic: when ``s`` reaches a stop (events
    ``stop_at_smax``, ``stop_at_smin``) the velocity is set to 0 at that
    instant and the mass is stuck there; it cannot slide into the stop (the
    mode machine's start in that direction is blocked) and leaves it when
    the force pulling it away exceeds ``f0_max`` (events ``leave_smax``,
    ``leave_smin`` once it has moved off). The velocity jump is carried by
    the discrete ``v_jump``: ``v = v_forces - v_jump``, where ``v_forces``
    is the integral of the forces over the mass. MSL also resets ``s`` to
    the stop exactly; here ``s`` stays where the stop was located (past it
    by the event location tolerance, ~1e-15 relative). Free (no friction at
    all: ``f0 <= 0`` and ``F_prop <= 0``) only between the stops. Modes and
    the other events: :mod:`acausal.mechanics.frictionmodes`.

    Parameters: ``m`` [kg] (> 0); ``F_prop`` [N*s/m] velocity-proportional
    friction (>= 0); ``F_Coulomb`` [N] constant friction; ``F_Stribeck`` [N]
    Stribeck friction at v = 0; ``fexp`` [s/m] its exponential decay (>= 0);
    ``smax``, ``smin`` [m] the stops (for the ends of the mass); ``L`` [m]
    length; ``v_small`` [m/s]. States: ``s`` [m] centre, ``v`` [m/s], ``a``
    [m/s2], ``f`` [N], ``v_forces`` [m/s]; discrete ``stopped`` (-1 at the
    left stop, +1 at the right, 0 between), ``v_jump`` [m/s]; the
    machine's. Connectors: ``flange_a`` (s - L/2), ``flange_b`` (s + L/2).
    """

    m = Parameter(1.0, "kg", "mass", min=0.0, min_open=True)
    F_prop = Parameter(1.0, "N*s/m", "velocity dependent friction", min=0.0)
    F_Coulomb = Parameter(5.0, "N", "constant friction: Coulomb force")
    F_Stribeck = Parameter(10.0, "N", "Stribeck effect (friction added at v = 0)")
    fexp = Parameter(2.0, "s/m", "exponential decay of the Stribeck effect", min=0.0)
    smax = Parameter(25.0, "m", "right stop for the right end of the sliding mass")
    smin = Parameter(-25.0, "m", "left stop for the left end of the sliding mass")
    v = Variable(0.0, "m/s", "absolute velocity of the mass (0 at a stop)")
    a = Variable(0.0, "m/s2", "absolute acceleration of the mass")
    f = Variable(0.0, "N", "friction force (against the motion)")
    v_forces = Variable(0.0, "m/s", "integral of the forces over the mass: v + v_jump")
    v_jump = Discrete(0.0, "m/s", "sum of the velocities taken away at the hard stops")
    stopped = Discrete(0, "1", "-1 at the left stop, +1 at the right stop, 0 between")

    def equations(self):
        # v_forces is the state (the integral of the forces); v = der(s) is
        # v_forces - v_jump, so a jump of v_jump moves v and s goes on from there
        return [Eq(der(self.s), self.v_forces - self.v_jump),
                Eq(self.v, der(self.s)), Eq(self.a, der(self.v_forces)),
                Eq(self.m * der(self.v_forces),
                   self.flange_a.f + self.flange_b.f - self.f),
                Eq(self.f0, self.F_Coulomb + self.F_Stribeck),
                Eq(self.f0_max, 1.001 * self.f0)]

    # -- the friction law ----------------------------------------------------
    def friction_motion(self):
        # the velocity as a function of the states (v itself is der(s)), so
        # that its sign at an event is the one the states give
        return self.v_forces - self.v_jump, self.a

    def friction_force(self):
        return self.f

    def sliding_force(self, direction):
        d, w = direction, self.friction_motion()[0]
        return self.F_prop * w + d * (self.F_Coulomb + self.F_Stribeck * sp.exp(-self.fexp * d * w))

    def engagement(self):
        # free only between the stops and without any friction
        return Piecewise((1, Ne(self.stopped, 0)),
                         (sp.Max(self.F_Coulomb + self.F_Stribeck, self.F_prop), True))

    def blocked(self, direction):
        return Rel(self.stopped, direction)

    # -- the hard stops --------------------------------------------------------
    def _ends(self):
        return self.smin + self.L / 2, self.smax - self.L / 2

    def events(self):
        lo, hi = self._ends()
        s, stopped = self.s, self.stopped
        pre = f"{self.path}." if self.path else ""

        def nonzero(x):
            return Piecewise((x, Ne(x, 0)), (-1, True))

        return [
            Event(pre + "stop_at_smax", Piecewise((nonzero(s - hi), Ne(stopped, 1)), (-1, True)),
                  1, self._act_hard_stop(1), recheck=True),
            Event(pre + "stop_at_smin", Piecewise((nonzero(lo - s), Ne(stopped, -1)), (-1, True)),
                  1, self._act_hard_stop(-1), recheck=True),
            Event(pre + "leave_smax", Piecewise((nonzero(hi - s), Rel(stopped, 1)), (-1, True)),
                  1, self._act_leave, recheck=True),
            Event(pre + "leave_smin", Piecewise((nonzero(s - lo), Rel(stopped, -1)), (-1, True)),
                  1, self._act_leave, recheck=True),
            Event(pre + "initial_stops", Piecewise((1, Rel(self.mode, UNKNOWN)), (-1, True)), 1,
                  self._act_initial_stops, recheck=True, log=False),
        ]

    def _act_hard_stop(self, side):
        def act(state):
            state[self.v_jump] = state[self.v_forces]      # v = v_forces - v_jump = 0
            state[self.stopped] = side
            self._set(state, STUCK)
        return act

    def _act_leave(self, state):
        state[self.stopped] = 0

    def _act_initial_stops(self, state):
        s, v, half = state[self.s], state[self.v], state[self.L] / 2
        smin, smax = state[self.smin], state[self.smax]
        where = self.path or type(self).__name__
        if smin + half > smax - half:
            raise ParameterError(
                f"{where}: the stops leave no room for the mass: smax - smin = "
                f"{smax - smin:g} m < L = {2 * half:g} m", component=self.path)
        if s - half < smin or (s - half == smin and v < 0):
            raise InitializationError(
                f"{where}: the mass starts beyond its left stop: s - L/2 = {s - half:g} m, "
                f"smin = {smin:g} m, v = {v:g} m/s (it may start on the stop only at rest "
                "or moving right)", component=self.path, variable=f"{where}.s")
        if s + half > smax or (s + half == smax and v > 0):
            raise InitializationError(
                f"{where}: the mass starts beyond its right stop: s + L/2 = {s + half:g} m, "
                f"smax = {smax:g} m, v = {v:g} m/s (it may start on the stop only at rest "
                "or moving left)", component=self.path, variable=f"{where}.s")
        state[self.stopped] = -1 if s - half <= smin else (1 if s + half >= smax else 0)
