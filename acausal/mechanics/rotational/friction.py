"""Rotational friction elements (MSL ``Modelica.Mechanics.Rotational.Components``:
BearingFriction, Brake, Clutch, OneWayClutch, LossyGear), each a leaf of
the shared mode machine :class:`acausal.mechanics.frictionmodes.PartialFrictionModes`
(modes, events and their names: see that module).

Sign convention: :mod:`acausal.lang.connectors`. A friction torque ``tau``
is what the outside applies on the element; it acts on the shaft with
``-tau`` and has the sign of the sliding velocity (MSL's). Tables are
interpolated linearly and extrapolated with their end intervals
(:func:`acausal.mechanics.tables.interpolate`).
"""
import sympy as sp
from sympy import Piecewise

from acausal.errors import ParameterError
from acausal.lang import Eq, Parameter, RealInput, Variable, der

from ..frictionmodes import PartialFrictionModes, PartialRotFriction, magnitude
from ..partials import (NonZeroParameter, PartialRotCompliantWithRelativeStates,
                        PartialRotElementaryTwoFlangesAndSupport2)
from ..tables import Table, interpolate

__all__ = ["BearingFriction", "Brake", "Clutch", "OneWayClutch", "LossyGear", "IDEAL_LOSS_TABLE"]


def _mu_pos():
    return Table(((0.0, 0.5),), 2, ("rad/s", "1"),
                 "positive sliding friction coefficient mu(w) for w >= 0: rows (w [rad/s], "
                 "mu [1])")


def _peak(what):
    return Parameter(1.0, "1", f"peak of the {what} at w = 0 (break-away = peak * sliding "
                     "value at w = 0)", min=1.0)


class _ShaftOnSupport(PartialRotElementaryTwoFlangesAndSupport2):
    """Two flanges joined rigidly, sliding on the support: ``phi =
    flange_a.phi - support.phi = flange_b.phi - support.phi``, ``w =
    der(phi)``, ``a = der(w)``; the friction torque ``tau = flange_a.tau +
    flange_b.tau`` is taken by the support."""

    phi = Variable(0.0, "rad", "angle of the flanges relative to the support")
    w = Variable(0.0, "rad/s", "angular velocity of the flanges relative to the support")
    a = Variable(0.0, "rad/s2", "angular acceleration of the flanges relative to the support")
    tau = Variable(0.0, "N*m", "friction torque (sum of the flange torques)")

    def equations(self):
        return [Eq(self.phi, self.phi_a), Eq(self.flange_b.phi, self.flange_a.phi),
                Eq(self.w, der(self.phi)), Eq(self.a, der(self.w)),
                Eq(self.flange_a.tau + self.flange_b.tau - self.tau, 0)]

    def friction_motion(self):
        return self.w, self.a

    def friction_force(self):
        return self.tau


class BearingFriction(_ShaftOnSupport, PartialRotFriction):
    """Coulomb friction in a bearing (MSL ``BearingFriction``): the shaft
    (``flange_a`` and ``flange_b``, rigidly joined) turns in its housing
    (``support``, or the ground) against a friction torque from a table::

        sliding:  tau = +tau_pos(w)  (w > 0),   -tau_pos(-w)  (w < 0)
        stuck:    der(w) = 0, while -tau0_max <= tau <= tau0_max
        tau0 = tau_pos(0),  tau0_max = peak*tau0

    Modes and events: :mod:`acausal.mechanics.frictionmodes` (never free).

    Parameters: ``tau_pos`` table of rows (w [rad/s], tau [N*m]), w >= 0,
    strictly increasing; ``peak`` [1] (>= 1); ``useSupport`` (structural);
    ``w_small`` [rad/s]. States: ``phi`` [rad], ``w`` [rad/s], ``a``
    [rad/s2], ``tau`` [N*m]; the machine's (``mode``, ``startForward``,
    ``startBackward``, ``sa``, ``locked``). Connectors: ``flange_a``,
    ``flange_b``, ``support`` (with useSupport).
    """

    tau_pos = Table(((0.0, 1.0),), 2, ("rad/s", "N*m"),
                    "positive sliding friction characteristic tau(w) for w >= 0: rows "
                    "(w [rad/s], tau [N*m])")
    peak = _peak("friction torque")

    def equations(self):
        return [Eq(self.tau0, interpolate(self.tau_pos, 1, 0)),
                Eq(self.tau0_max, self.peak * self.tau0)]

    def sliding_force(self, direction):
        return direction * interpolate(self.tau_pos, 1, direction * self.w)


class _NormalForce:
    """A normal force ``fn = fn_max*f_normalized`` from a signal input (a
    mixin): the element is free (transmits nothing) while ``fn <= 0``; the
    friction torque is ``cgeo*fn*mu(w)`` with ``mu`` from ``mu_pos``."""

    def _normal_force_equations(self):
        return [Eq(self.mu0, interpolate(self.mu_pos, 1, 0)),
                Eq(self.fn, self.fn_max * self.f_normalized),
                Eq(self.tau0, self.mu0 * self.cgeo * self.fn),
                Eq(self.tau0_max, self.peak * self.tau0)]

    def engagement(self):
        return self.fn

    def sliding_force(self, direction):
        w, _ = self.friction_motion()
        return self.cgeo * self.fn * direction * interpolate(self.mu_pos, 1, direction * w)


class Brake(_NormalForce, _ShaftOnSupport, PartialRotFriction):
    """A brake (MSL ``Rotational.Components.Brake``): Coulomb friction
    between the shaft (``flange_a``, ``flange_b``, rigidly joined) and its
    housing (``support``, or the ground), pressed with the normal force
    ``fn = fn_max*f_normalized``::

        free (fn <= 0):  tau = 0
        sliding:         tau = cgeo*fn*mu_pos(w)   (w > 0; odd in w)
        stuck:           der(w) = 0, while |tau| <= tau0_max
        tau0 = mu_pos(0)*cgeo*fn,  tau0_max = peak*tau0

    Modes and events: :mod:`acausal.mechanics.frictionmodes` (``release``
    / ``engage`` when ``fn`` reaches 0).

    Parameters: ``mu_pos`` table of rows (w [rad/s], mu [1]), w >= 0,
    strictly increasing; ``peak`` [1] (>= 1); ``cgeo`` [m] geometry constant
    (friction radius, >= 0); ``fn_max`` [N] largest normal force (>= 0);
    ``useSupport`` (structural); ``w_small`` [rad/s]. Inputs:
    ``f_normalized`` [1] normalized normal force (0..1). States: ``phi``
    [rad], ``w`` [rad/s], ``a`` [rad/s2], ``tau`` [N*m], ``fn`` [N],
    ``mu0`` [1]; the machine's. Connectors: ``flange_a``, ``flange_b``,
    ``support`` (with useSupport), ``f_normalized`` (RealInput).
    """

    mu_pos = _mu_pos()
    peak = _peak("friction coefficient")
    cgeo = Parameter(1.0, "m", "geometry constant containing the friction distribution "
                     "(torque = cgeo*mu*fn)", min=0.0)
    fn_max = Parameter(1.0, "N", "largest normal force (fn = fn_max*f_normalized)", min=0.0)
    f_normalized = RealInput("normalized normal force 0..1 (fn = fn_max*f_normalized; the "
                             "brake is active when > 0)")
    mu0 = Variable(0.0, "1", "friction coefficient at w = 0")
    fn = Variable(0.0, "N", "normal force")

    def equations(self):
        return self._normal_force_equations()


class Clutch(_NormalForce, PartialRotCompliantWithRelativeStates, PartialRotFriction):
    """A clutch (MSL ``Rotational.Components.Clutch``): Coulomb friction
    between ``flange_a`` and ``flange_b``, pressed with the normal force
    ``fn = fn_max*f_normalized``; ``w_rel = der(flange_b.phi -
    flange_a.phi)``, ``tau = flange_b.tau = -flange_a.tau``::

        free (fn <= 0):  tau = 0
        sliding:         tau = cgeo*fn*mu_pos(w_rel)   (w_rel > 0; odd in w_rel)
        stuck:           der(w_rel) = 0, while |tau| <= tau0_max
        tau0 = mu_pos(0)*cgeo*fn,  tau0_max = peak*tau0

    (MSL 4.0.0 evaluates the start-backward branch at ``+w_rel``; here the
    law is odd in ``w_rel`` in every branch, which differs only by the
    table's slope times the tiny ``w_rel`` of the start.) Modes and events:
    :mod:`acausal.mechanics.frictionmodes`.

    Parameters: ``mu_pos`` table of rows (w [rad/s], mu [1]); ``peak`` [1]
    (>= 1); ``cgeo`` [m] (>= 0); ``fn_max`` [N] (>= 0); ``w_small``
    [rad/s]; ``phi_nominal`` [rad]. Inputs: ``f_normalized`` [1]. States:
    ``phi_rel`` [rad], ``w_rel`` [rad/s], ``a_rel`` [rad/s2], ``tau``
    [N*m], ``fn`` [N], ``mu0`` [1]; the machine's. Connectors:
    ``flange_a``, ``flange_b``, ``f_normalized`` (RealInput).
    """

    mu_pos = _mu_pos()
    peak = _peak("friction coefficient")
    cgeo = Parameter(1.0, "m", "geometry constant containing the friction distribution "
                     "(torque = cgeo*mu*fn)", min=0.0)
    fn_max = Parameter(1.0, "N", "largest normal force (fn = fn_max*f_normalized)", min=0.0)
    f_normalized = RealInput("normalized normal force 0..1 (fn = fn_max*f_normalized; the "
                             "clutch is engaged when > 0)")
    a_rel = Variable(0.0, "rad/s2", "relative angular acceleration der(w_rel)")
    mu0 = Variable(0.0, "1", "friction coefficient at w_rel = 0")
    fn = Variable(0.0, "N", "normal force")

    def equations(self):
        return [Eq(self.a_rel, der(self.w_rel))] + self._normal_force_equations()

    def friction_motion(self):
        return self.w_rel, self.a_rel

    def friction_force(self):
        return self.tau


EPS0 = 1e-4   # OneWayClutch: relative hysteresis of the break-away torque (MSL's eps0)


class OneWayClutch(PartialRotCompliantWithRelativeStates, PartialFrictionModes):
    """A freewheel and a clutch in parallel (MSL ``OneWayClutch``): the
    relative rotation ``w_rel = der(flange_b.phi - flange_a.phi)`` cannot
    become negative (the freewheel locks and takes any torque that way);
    forward, the clutch slips with ``tau = cgeo*fn*mu_pos(w_rel)`` when
    engaged (``fn = fn_max*f_normalized > 0``), freely (``tau = 0``) when
    not::

        slipping (w_rel > 0):  tau = cgeo*fn*mu_pos(w_rel)   (0 when disengaged)
        locked (w_rel = 0):    der(w_rel) = 0, while tau <= tau0_max
        tau0 = mu_pos(0)*cgeo*fn,
        tau0_max = max(peak, 1 + 1e-4)*tau0  (engaged),  1e-4*mu_pos(0)*cgeo*fn_max  (not)

    so a locked freewheel needs a (small) forward torque to start slipping
    even when disengaged. ``mode`` is 1 while slipping, 0 while locked
    (never -1 or free). Events: :mod:`acausal.mechanics.frictionmodes`.

    Parameters: ``mu_pos`` table of rows (w [rad/s], mu [1]); ``peak`` [1]
    (>= 1); ``cgeo`` [m] (>= 0); ``fn_max`` [N] (>= 0); ``w_small``
    [rad/s] a jump of ``w_rel`` past it starts a locked clutch slipping
    (MSL's default 1e10 turns this off); ``phi_nominal`` [rad]. Inputs:
    ``f_normalized`` [1]. States: ``phi_rel`` [rad], ``w_rel`` [rad/s],
    ``a_rel`` [rad/s2], ``tau`` [N*m], ``fn`` [N], ``tau0``, ``tau0_max``
    [N*m]; the machine's. Connectors: ``flange_a``, ``flange_b``,
    ``f_normalized`` (RealInput).
    """

    mu_pos = _mu_pos()
    peak = _peak("friction coefficient")
    cgeo = Parameter(1.0, "m", "geometry constant containing the friction distribution "
                     "(torque = cgeo*mu*fn)", min=0.0)
    fn_max = Parameter(1.0, "N", "largest normal force (fn = fn_max*f_normalized)", min=0.0)
    w_small = Parameter(1e10, "rad/s", "a jump of w_rel past it starts a locked clutch "
                        "slipping", min=0.0, min_open=True)
    f_normalized = RealInput("normalized normal force 0..1 (fn = fn_max*f_normalized; the "
                             "clutch is engaged when > 0)")
    a_rel = Variable(0.0, "rad/s2", "relative angular acceleration der(w_rel)")
    fn = Variable(0.0, "N", "normal force (0 when disengaged)")
    tau0 = Variable(0.0, "N*m", "friction torque for w_rel = 0 while slipping")
    tau0_max = Variable(0.0, "N*m", "largest torque for w_rel = 0 while locked (break-away)")

    def equations(self):
        u = sp.sympify(self.f_normalized)    # the input signal as a symbol
        mu0 = interpolate(self.mu_pos, 1, 0)
        peak2 = sp.Max(self.peak, 1 + EPS0)
        return [Eq(self.a_rel, der(self.w_rel)),
                Eq(self.fn, Piecewise((0, u <= 0), (self.fn_max * u, True))),
                Eq(self.tau0, mu0 * self.cgeo * self.fn),
                Eq(self.tau0_max, Piecewise((EPS0 * mu0 * self.cgeo * self.fn_max, u <= 0),
                                            (peak2 * self.tau0, True)))]

    def friction_motion(self):
        return self.w_rel, self.a_rel

    def friction_force(self):
        return self.tau

    def sliding_force(self, direction):
        return self.cgeo * self.fn * direction * interpolate(self.mu_pos, 1,
                                                             direction * self.w_rel)

    def break_level(self, direction):
        return direction * self.tau0_max

    def hold_level(self, direction):
        return direction * self.tau0

    def slide_offset(self, direction):
        return direction * self.tau0

    def blocked(self, direction):
        return sp.true if direction < 0 else sp.false

    def locked_jump_level(self):
        return self.w_small


class _LossTable(Table):
    """LossyGear's ``lossTable``: rows (|w_a| [rad/s], eta_mf1, eta_mf2 [1],
    tau_bf1, tau_bf2 [N*m]), the speed increasing strictly, the mesh
    efficiencies in (0, 1]."""

    def check(self, value, where):
        rows = super().check(value, where)
        label = f"{where}.{self.name}" if where else self.name
        for k, row in enumerate(rows):
            for j in (1, 2):
                if not 0 < row[j] <= 1:
                    raise ParameterError(
                        f"parameter {label}: row {k + 1}, column {j + 1} (eta_mf{j}) = "
                        f"{row[j]:g}: a mesh efficiency must be in (0, 1]", variable=label)
        return rows


IDEAL_LOSS_TABLE = ((0.0, 1.0, 1.0, 0.0, 0.0),)


class LossyGear(PartialRotElementaryTwoFlangesAndSupport2, PartialFrictionModes):
    """A gear with mesh efficiency and bearing friction, which may stick
    (MSL ``LossyGear``; Pelchen, Schweiger & Otter 2002, with Bertsch's
    2009 correction)::

        phi_a = ratio*phi_b                       (relative to the support)
        0 = flange_b.tau + ratio*(flange_a.tau - tauLoss)
        w_a = der(phi_a),  a_a = der(w_a)

    ``tauLoss`` is the torque lost in the teeth and the bearings, referred
    to ``flange_a``. With the table's values at ``|w_a|`` (``eta_mf1``:
    mesh efficiency when ``flange_a`` drives, ``eta_mf2`` when ``flange_b``
    drives, ``tau_bf1``/``tau_bf2``: bearing friction referred to
    ``flange_a`` in those cases)::

        quadrant1 = (1 - eta_mf1)*flange_a.tau + tau_bf1      (w_a > 0, a drives)
        quadrant2 = (1 - 1/eta_mf2)*flange_a.tau + tau_bf2    (w_a > 0, b drives)
        quadrant3 = (1 - eta_mf1)*flange_a.tau - tau_bf1      (w_a < 0, b drives)
        quadrant4 = (1 - 1/eta_mf2)*flange_a.tau - tau_bf2    (w_a < 0, a drives)
        rolling forward:   tauLoss = quadrant1 if tau_eta >= 0 else quadrant2
        rolling backward:  tauLoss = quadrant4 if tau_eta >= 0 else quadrant3
        stuck:             a_a = 0, tauLoss = the torque that holds it

    where ``tau_eta = flange_a.tau -+ tau_bf_a`` (the torque past flange_a's
    own bearing, ``tau_bf_a`` the part of the bearing friction on the a
    side) tells which side drives. The gear starts rolling forward when the
    loss needed to stay stuck exceeds ``tauLossMax_p`` (the loss available
    at ``w_a = 0+``: quadrant 1 or 2 at zero speed, chosen by ``flange_a.tau
    - tau_bf_a(0)``), backward when it is below ``tauLossMin_m``. The mode
    machine is :mod:`acausal.mechanics.frictionmodes`'s, with these levels
    (and no hold above the break-away level, as MSL's LossyGear); a loss
    table equal to ``[0, 1, 1, 0, 0]`` is an ideal gear (``mode`` Free,
    no loss). The quadrant is chosen continuously (the loss is continuous
    where ``tau_eta`` changes sign), not frozen between events as in MSL.

    A negative ``ratio`` is a reversing stage: the losses refer to
    ``flange_a`` whatever the sign. Zero is rejected.

    Parameters: ``ratio`` [1] flange_a.phi/flange_b.phi (non-zero);
    ``lossTable`` rows (|w_a| [rad/s], eta_mf1 [1], eta_mf2 [1], tau_bf1
    [N*m], tau_bf2 [N*m]), efficiencies in (0, 1]; ``useSupport``
    (structural). States: ``phi_a``, ``phi_b`` [rad], ``w_a`` [rad/s],
    ``a_a`` [rad/s2], ``tauLoss``, ``tau_eta`` [N*m]; the machine's
    (``mode``, ``startForward``, ``startBackward``, ``sa``, ``locked``,
    ``free``). Connectors: ``flange_a``, ``flange_b``, ``support`` (with
    useSupport).
    """

    ratio = NonZeroParameter(1.0, "1", "transmission ratio flange_a.phi/flange_b.phi")
    lossTable = _LossTable(IDEAL_LOSS_TABLE, 5, ("rad/s", "1", "1", "N*m", "N*m"),
                           "mesh efficiencies and bearing friction against |w_a|: rows (|w_a| "
                           "[rad/s], eta_mf1, eta_mf2 [1], tau_bf1, tau_bf2 [N*m])")
    w_a = Variable(0.0, "rad/s", "angular velocity of flange_a relative to the support")
    a_a = Variable(0.0, "rad/s2", "angular acceleration of flange_a relative to the support")
    tauLoss = Variable(0.0, "N*m", "torque lost in the teeth and bearings, referred to flange_a")
    tau_eta = Variable(0.0, "N*m", "torque that tells the driving side (flange_a.tau past the "
                       "bearing friction on side a)")

    def _ideal(self):
        return all(abs(x - y) <= 1e-15 for row in self.lossTable
                   for x, y in zip(row, IDEAL_LOSS_TABLE[0])) and len(self.lossTable) == 1

    def _at(self, speed):
        """(eta_mf1, eta_mf2, tau_bf1, tau_bf2, tau_bf_a) at ``speed`` >= 0."""
        eta1, eta2 = (interpolate(self.lossTable, j, speed) for j in (1, 2))
        bf1, bf2 = (magnitude(interpolate(self.lossTable, j, speed)) for j in (3, 4))
        split = (bf1 - bf2) / (eta1 - 1 / eta2)
        if all(r[1] == 1.0 and r[2] == 1.0 for r in self.lossTable):
            bf_a = bf1 / 2      # no mesh loss: the bearing friction is split evenly
        else:
            bf_a = Piecewise((bf1 / 2, (magnitude(eta1 - 1) <= 1e-15) & (magnitude(eta2 - 1) <= 1e-15)),
                             (split, True))
        return eta1, eta2, bf1, bf2, bf_a

    def _quadrants(self, speed):
        eta1, eta2, bf1, bf2, _ = self._at(speed)
        t = self.flange_a.tau
        return ((1 - eta1) * t + bf1, (1 - 1 / eta2) * t + bf2,
                (1 - eta1) * t - bf1, (1 - 1 / eta2) * t - bf2)

    def equations(self):
        locked, _, forward = self._configuration()
        bf_a = self._at(magnitude(self.w_a))[4]
        t = self.flange_a.tau
        return [Eq(self.phi_a, self.ratio * self.phi_b),
                Eq(0, self.flange_b.tau + self.ratio * (t - self.tauLoss)),
                Eq(self.w_a, der(self.phi_a)), Eq(self.a_a, der(self.w_a)),
                Eq(self.tau_eta, Piecewise((t, locked), (t - bf_a, forward), (t + bf_a, True)))]

    # -- the machine's law ------------------------------------------------------
    def friction_motion(self):
        return self.w_a, self.a_a

    def friction_force(self):
        return self.tauLoss

    def engagement(self):
        return sp.Integer(0) if self._ideal() else None

    def sliding_force(self, direction):
        q1, q2, q3, q4 = self._quadrants(magnitude(self.w_a))
        pos = self.tau_eta >= 0
        if direction > 0:
            return Piecewise((q1, pos), (q2, True))
        return Piecewise((q4, pos), (q3, True))

    def break_level(self, direction):
        q1, q2, q3, q4 = self._quadrants(0)
        bf_a0 = self._at(0)[4]
        t = self.flange_a.tau
        if direction > 0:
            return Piecewise((q1, t - bf_a0 > 0), (q2, True))
        return Piecewise((q4, t + bf_a0 > 0), (q3, True))

    def slide_offset(self, direction):
        return self.sliding_force(direction)
