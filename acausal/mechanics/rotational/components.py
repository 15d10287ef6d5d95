"""Rotational components (MSL ``Rotational.Components``). Sign convention:
:mod:`acausal.lang.connectors`."""
import sympy as sp
from sympy import Piecewise

from acausal.lang import Component, Discrete, Eq, Event, Parameter, RotFlange, Variable, der

from ..contact import PosPow
from ..partials import (NonZeroParameter, PartialElementaryRotationalToTranslational,
                        PartialRotCompliant, PartialRotCompliantWithRelativeStates,
                        PartialRotElementaryTwoFlangesAndSupport2, PartialRotRelativeSensor,
                        PartialRotRigid)

__all__ = ["Fixed", "Inertia", "Disc", "TorsionSpring", "RotationalDamper", "SpringDamper",
           "Spring", "Damper", "ElastoBacklash", "ElastoBacklash2", "IdealGear", "IdealGearR2T",
           "IdealRollingWheel", "RelativeStates"]

B_EPS = 1e-10   # MSL's minimum backlash [rad]: below it the backlash elements are linear
TOUCH_TOL = 1e-12   # [rad] the contact regions switch this far before the gap's edge


class Fixed(Component):
    """A rotational flange fixed at angle ``phi0``: ``flange.phi = phi0``.

    Parameters: ``phi0`` [rad] angle. Connectors: ``flange``.
    """

    diagnosis_site = "ground"   # what acausal.diagnose may extend here

    flange = RotFlange("fixed flange")
    phi0 = Parameter(0.0, "rad", "fixed angle")

    def equations(self):
        return [Eq(self.flange.phi, self.phi0)]


class Inertia(PartialRotRigid):
    """A rotating body (MSL ``Inertia``): ``J * der(w)`` = the sum of the
    torques at its flanges, ``w = der(phi)``, ``a = der(w)``. ``flange_a``,
    ``flange_b`` (MSL's) and ``flange`` are all at ``phi``; use any of them
    (an unconnected one carries no torque).

    Parameters: ``J`` [kg*m^2] moment of inertia (> 0; a massless shaft is
    a direct connection). States: ``phi`` [rad], ``w`` [rad/s], ``a``
    [rad/s2]. Connectors: ``flange_a``, ``flange_b``, ``flange``.
    """

    J = Parameter(1.0, "kg*m^2", "moment of inertia", min=0.0, min_open=True)

    def equations(self):
        return [Eq(self.J * der(self.w), self.net_torque())]


class Disc(Component):
    """A massless rigid disc whose right flange is turned by a fixed angle
    from its left one (MSL ``Disc``): ``flange_a.phi = phi - deltaPhi/2``,
    ``flange_b.phi = phi + deltaPhi/2``, ``flange_a.tau + flange_b.tau = 0``.

    Parameters: ``deltaPhi`` [rad] flange_b.phi - flange_a.phi. States:
    ``phi`` [rad] the disc's angle. Connectors: ``flange_a``, ``flange_b``.
    """

    flange_a = RotFlange("left flange (phi - deltaPhi/2)")
    flange_b = RotFlange("right flange (phi + deltaPhi/2)")
    deltaPhi = Parameter(0.0, "rad", "fixed rotation of flange_b relative to flange_a")
    phi = Variable(0.0, "rad", "absolute rotation angle of the disc")

    def equations(self):
        return [Eq(self.flange_a.phi, self.phi - self.deltaPhi / 2),
                Eq(self.flange_b.phi, self.phi + self.deltaPhi / 2),
                Eq(self.flange_a.tau + self.flange_b.tau, 0)]


class TorsionSpring(PartialRotCompliant):
    """Linear torsion spring (MSL ``Spring``): ``tau = c * (phi_rel -
    phi_rel0) + tau0``.

    With ``tau0 = 0`` (default, MSL's law) ``phi_rel0`` is the unstretched
    angle. For a preloaded spring set ``phi_rel0`` to the installed relative
    angle and ``tau0`` to the installed torque there (sign as ``tau``: the
    torque the outside applies on ``flange_b``); the free angle is
    ``phi_rel0 - tau0 / c``.

    Parameters: ``c`` [N*m/rad] stiffness (>= 0), ``phi_rel0`` [rad]
    reference angle, ``tau0`` [N*m] torque at ``phi_rel0`` (preload).
    States: ``phi_rel`` [rad], ``tau`` [N*m]. Connectors: ``flange_a``,
    ``flange_b``.
    """

    c = Parameter(1.0, "N*m/rad", "spring constant", min=0.0)
    phi_rel0 = Parameter(0.0, "rad", "reference angle (unstretched when tau0 = 0)")
    tau0 = Parameter(0.0, "N*m", "torque at phi_rel = phi_rel0 (preload)")

    def equations(self):
        return [Eq(self.tau, self.c * (self.phi_rel - self.phi_rel0) + self.tau0)]


class RotationalDamper(PartialRotCompliantWithRelativeStates):
    """Linear rotational damper (MSL ``Damper``): ``tau = d * w_rel``,
    dissipating ``lossPower = tau * w_rel``.

    Parameters: ``d`` [N*m*s/rad] damping constant (>= 0), ``phi_nominal``
    [rad]. States: ``phi_rel`` [rad], ``w_rel`` [rad/s], ``tau`` [N*m],
    ``lossPower`` [W]. Connectors: ``flange_a``, ``flange_b``.
    """

    d = Parameter(0.0, "N*m*s/rad", "damping constant", min=0.0)
    lossPower = Variable(0.0, "W", "dissipated power tau * w_rel")

    def equations(self):
        return [Eq(self.tau, self.d * self.w_rel), Eq(self.lossPower, self.tau * self.w_rel)]


class SpringDamper(PartialRotCompliantWithRelativeStates):
    """Torsion spring and damper in parallel (MSL ``SpringDamper``):
    ``tau = c * (phi_rel - phi_rel0) + tau0 + d * w_rel``
    (``phi_rel0``/``tau0`` as in :class:`TorsionSpring`), dissipating
    ``lossPower = d * w_rel^2``.

    Parameters: ``c`` [N*m/rad] (>= 0), ``phi_rel0`` [rad], ``tau0``
    [N*m], ``d`` [N*m*s/rad] (>= 0), ``phi_nominal`` [rad]. States:
    ``phi_rel`` [rad], ``w_rel`` [rad/s], ``tau`` [N*m], ``lossPower`` [W].
    Connectors: ``flange_a``, ``flange_b``.
    """

    c = Parameter(1.0, "N*m/rad", "spring constant", min=0.0)
    phi_rel0 = Parameter(0.0, "rad", "reference angle (unstretched when tau0 = 0)")
    tau0 = Parameter(0.0, "N*m", "spring torque at phi_rel = phi_rel0 (preload)")
    d = Parameter(0.0, "N*m*s/rad", "damping constant", min=0.0)
    lossPower = Variable(0.0, "W", "power dissipated by the damper, d * w_rel^2")

    def equations(self):
        tau_d = self.d * self.w_rel
        return [Eq(self.tau, self.c * (self.phi_rel - self.phi_rel0) + self.tau0 + tau_d),
                Eq(self.lossPower, tau_d * self.w_rel)]


class _PartialBacklash(PartialRotCompliantWithRelativeStates):
    """A spring and damper in series with a backlash of total width ``b``,
    centred on ``phi_rel0`` (``phi_diff = phi_rel - phi_rel0``)::

        free  (region 0):   |phi_diff| <= b/2:  tau_c = 0
        upper (region +1):  phi_diff > b/2:     tau_c = c * (phi_diff - b/2)
        lower (region -1):  phi_diff < -b/2:    tau_c = c * (phi_diff + b/2)

    ``tau_d = d * w_rel``; the leaf says how ``tau`` combines them in
    contact. ``region`` switches with an event when ``phi_diff`` crosses
    ``+-b/2`` (MSL's events on ``phi_diff > bMax``, ``< bMin``). A backlash
    ``b <= 1e-10`` rad (MSL's ``bEps``) makes the element a plain spring
    and damper, ``tau = tau_c + tau_d`` with ``tau_c = c * phi_diff``, and
    switches no regions. The events switch ``region`` 1e-12 rad
    (:data:`TOUCH_TOL`) inside the gap's edge, where the spring torque is
    still exactly 0 (``tau_c`` is ``c`` times the penetration beyond the
    edge), so that a run starting exactly at the edge starts in contact
    (IDA cannot see a root function that starts at zero).

    During initialisation the characteristic is MSL's strictly rising one,
    so that an initialisation that must invert it (a torque given, the
    angle sought) is not singular::

        tau_c = c*(phi_diff - b/2)   phi_diff > 1.5*b/2
                c*(phi_diff + b/2)   phi_diff < -1.5*b/2
                (c/3)*phi_diff       otherwise;      tau = tau_c + tau_d

    (continuous at ``+-1.5*b/2``); the run's first event iteration switches
    to the law above (discrete ``initializing``: 1 until then), keeping the
    states the initialisation found, as MSL does after ``initial()``.
    """

    c = Parameter(1e5, "N*m/rad", "spring constant (> 0)", min=0.0, min_open=True)
    d = Parameter(0.0, "N*m*s/rad", "damping constant", min=0.0)
    b = Parameter(0.0, "rad", "total backlash", min=0.0)
    phi_rel0 = Parameter(0.0, "rad", "unstretched spring angle (centre of the backlash)")
    tau_c = Variable(0.0, "N*m", "spring torque")
    tau_d = Variable(0.0, "N*m", "damping torque d * w_rel")
    lossPower = Variable(0.0, "W", "dissipated power")
    region = Discrete(0, "1", "+1: phi_diff > b/2, -1: phi_diff < -b/2, 0: in the gap")
    initializing = Discrete(1, "1", "1 during the initialisation (MSL's initial()), then 0")

    def _contact_torque(self, side):
        """``tau`` in contact on ``side`` (+1 upper, -1 lower), and the
        dissipated power there."""
        raise NotImplementedError

    def equations(self):
        diff = self.phi_rel - self.phi_rel0
        half = self.b / 2
        linear = self.b <= B_EPS
        up, low = Eq(self.region, 1), Eq(self.region, -1)
        tau_up, loss_up = self._contact_torque(+1)
        tau_low, loss_low = self._contact_torque(-1)
        init = Eq(self.initializing, 1)
        # MSL's initial characteristic: strictly rising, continuous at 1.5*b/2
        tau_init = Piecewise((self.c * (diff - half), diff > 1.5 * half),
                             (self.c * (diff + half), diff < -1.5 * half),
                             (self.c / 3 * diff, True))
        plain = init | linear
        return [
            Eq(self.tau_c, Piecewise((tau_init, init), (self.c * diff, linear),
                                     (self.c * PosPow(diff - half, 1), up),
                                     (-self.c * PosPow(-half - diff, 1), low), (0, True))),
            Eq(self.tau_d, self.d * self.w_rel),
            Eq(self.tau, Piecewise((self.tau_c + self.tau_d, plain), (tau_up, up),
                                   (tau_low, low), (0, True))),
            Eq(self.lossPower, Piecewise((self.tau_d * self.w_rel, plain), (loss_up, up),
                                         (loss_low, low), (0, True))),
        ]

    def events(self):
        p, region = self.path, self.region
        diff = self.phi_rel - self.phi_rel0
        half = self.b / 2 - TOUCH_TOL
        gated = self.b > B_EPS
        free, up, low = Eq(region, 0), Eq(region, 1), Eq(region, -1)

        def setter(value):
            def action(s):
                s[region] = value
            return action

        def initialized(s):
            s[me.initializing] = 0

        me = self
        # each function is > 0 where its region must change (recheck) and
        # crosses zero where the change happens
        return [
            # piecewise constant: acts in the run's first event iteration only
            Event(f"{p}.initialized", Piecewise((1, Eq(self.initializing, 1)), (-1, True)), +1,
                  initialized, recheck=True, log=False),
            Event(f"{p}.upper_contact", Piecewise((diff - half, gated & free), (-1, True)), +1,
                  setter(1), recheck=True),
            Event(f"{p}.lower_contact", Piecewise((-half - diff, gated & free), (-1, True)), +1,
                  setter(-1), recheck=True),
            Event(f"{p}.upper_release", Piecewise((diff - half, gated & up), (1, True)), -1,
                  setter(0), recheck=True),
            Event(f"{p}.lower_release", Piecewise((-half - diff, gated & low), (1, True)), -1,
                  setter(0), recheck=True),
        ]


class ElastoBacklash(_PartialBacklash):
    """Backlash in series with a linear spring and damper (MSL
    ``ElastoBacklash``), with the regions of :class:`_PartialBacklash`. In
    contact the damping torque is limited so that the torque is continuous
    when contact begins and never pulls::

        upper: tau = 0 if tau_c + tau_d <= 0 else tau_c + min(tau_c, tau_d)
        lower: tau = 0 if tau_c + tau_d >= 0 else tau_c + max(tau_c, tau_d)

    (no events inside contact: MSL's ``noEvent``); ``lossPower`` is the
    limited damping torque times ``w_rel``.

    Parameters: ``c`` [N*m/rad] spring constant (> 0), ``d`` [N*m*s/rad]
    damping (>= 0), ``b`` [rad] total backlash (>= 0), ``phi_rel0`` [rad],
    ``phi_nominal`` [rad]. States: ``phi_rel`` [rad], ``w_rel`` [rad/s],
    ``tau``, ``tau_c``, ``tau_d`` [N*m], ``lossPower`` [W]. Discrete:
    ``region``. Connectors: ``flange_a``, ``flange_b``.
    """

    def _contact_torque(self, side):
        tc, td = self.tau_c, self.tau_d
        total = tc + td
        if side > 0:
            lim = sp.Min(tc, td)
            push = total > 0
        else:
            lim = sp.Max(tc, td)
            push = total < 0
        return (Piecewise((tc + lim, push), (0, True)),
                Piecewise((lim * self.w_rel, push), (0, True)))


class ElastoBacklash2(_PartialBacklash):
    """Backlash in series with a linear spring and damper (MSL
    ``ElastoBacklash2``), with the regions of :class:`_PartialBacklash`. In
    contact the whole damping torque acts, so the torque may jump when
    contact begins; it never pulls::

        upper: tau = 0 if tau_c + tau_d <= 0 else tau_c + tau_d
        lower: tau = 0 if tau_c + tau_d >= 0 else tau_c + tau_d

    ``lossPower = tau_d * w_rel`` while the contact pushes.

    Parameters: ``c`` [N*m/rad] spring constant (> 0), ``d`` [N*m*s/rad]
    damping (>= 0), ``b`` [rad] total backlash (>= 0), ``phi_rel0`` [rad],
    ``phi_nominal`` [rad]. States: ``phi_rel`` [rad], ``w_rel`` [rad/s],
    ``tau``, ``tau_c``, ``tau_d`` [N*m], ``lossPower`` [W]. Discrete:
    ``region``. Connectors: ``flange_a``, ``flange_b``.
    """

    def _contact_torque(self, side):
        tc, td = self.tau_c, self.tau_d
        total = tc + td
        push = total > 0 if side > 0 else total < 0
        return (Piecewise((total, push), (0, True)),
                Piecewise((td * self.w_rel, push), (0, True)))


class IdealGear(PartialRotElementaryTwoFlangesAndSupport2):
    """Ideal gear without inertia (MSL ``IdealGear``), power conserving:
    ``phi_a = ratio * phi_b``, ``ratio * flange_a.tau + flange_b.tau = 0``,
    with the angles relative to the housing (``support`` with
    ``useSupport=True``, which then takes the reaction torque
    ``-(flange_a.tau + flange_b.tau)``; grounded otherwise). An inertia
    ``J_b`` on ``flange_b`` is felt on ``flange_a`` as ``J_b / ratio^2``. A
    negative ratio reverses the sense.

    Parameters: ``ratio`` [1] transmission ratio flange_a.phi/flange_b.phi
    (non-zero), ``useSupport`` (structural). States: ``phi_a``, ``phi_b``
    [rad]. Connectors: ``flange_a``, ``flange_b``, ``support`` (with
    useSupport).
    """

    ratio = NonZeroParameter(1.0, "1", "transmission ratio flange_a.phi / flange_b.phi")

    def equations(self):
        return [Eq(self.phi_a, self.ratio * self.phi_b),
                Eq(self.ratio * self.flange_a.tau + self.flange_b.tau, 0)]


class IdealGearR2T(PartialElementaryRotationalToTranslational):
    """Gearbox turning rotation into translation (MSL ``IdealGearR2T``), power
    conserving: ``(flangeR.phi - supportR.phi) = ratio * (flangeT.s -
    supportT.s)``, ``ratio * flangeR.tau + flangeT.f = 0``.

    Parameters: ``ratio`` [rad/m] transmission ratio flangeR.phi/flangeT.s
    (non-zero), ``useSupportR``, ``useSupportT`` (structural). Connectors:
    ``flangeR``, ``flangeT``, ``supportR``, ``supportT`` (with their flags).
    """

    ratio = NonZeroParameter(1.0, "rad/m", "transmission ratio flangeR.phi / flangeT.s")

    def equations(self):
        return [Eq(self.phi_rel(), self.ratio * self.s_rel()),
                Eq(self.ratio * self.flangeR.tau + self.flangeT.f, 0)]


class IdealRollingWheel(PartialElementaryRotationalToTranslational):
    """A wheel rolling without slip and without inertia (MSL
    ``IdealRollingWheel``): ``radius * (flangeR.phi - supportR.phi) =
    flangeT.s - supportT.s``, ``radius * flangeT.f + flangeR.tau = 0``
    (power conserving: ``flangeR.tau * w + flangeT.f * v = 0``).

    Parameters: ``radius`` [m] wheel radius (> 0), ``useSupportR``,
    ``useSupportT`` (structural). Connectors: ``flangeR``, ``flangeT``,
    ``supportR``, ``supportT`` (with their flags).
    """

    radius = Parameter(0.3, "m", "wheel radius", min=0.0, min_open=True)

    def equations(self):
        return [Eq(self.radius * self.phi_rel(), self.s_rel()),
                Eq(self.radius * self.flangeT.f + self.flangeR.tau, 0)]


class RelativeStates(PartialRotRelativeSensor):
    """Relative angle, speed and acceleration between two flanges, taking
    no torque (MSL ``RelativeStates``): ``phi_rel = flange_b.phi -
    flange_a.phi``, ``w_rel = der(phi_rel)``, ``a_rel = der(w_rel)``. MSL
    uses it to make ``phi_rel``, ``w_rel`` the states; here fixed start
    values on them (``RelativeStates(phi_rel=0.1, w_rel=0)``) make the
    solver keep them as states where it can.

    States: ``phi_rel`` [rad], ``w_rel`` [rad/s], ``a_rel`` [rad/s2].
    Connectors: ``flange_a``, ``flange_b``.
    """

    phi_rel = Variable(0.0, "rad", "relative angle flange_b.phi - flange_a.phi")
    w_rel = Variable(0.0, "rad/s", "relative angular velocity der(phi_rel)")
    a_rel = Variable(0.0, "rad/s2", "relative angular acceleration der(w_rel)")

    def equations(self):
        return [Eq(self.phi_rel, self.flange_b.phi - self.flange_a.phi),
                Eq(self.w_rel, der(self.phi_rel)), Eq(self.a_rel, der(self.w_rel))]


# Modelica / ModelingToolkitStandardLibrary names
Spring = TorsionSpring
Damper = RotationalDamper
