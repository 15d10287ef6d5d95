"""Translational components (MSL ``Translational.Components``). Sign
convention: :mod:`acausal.lang.connectors`."""
import sympy as sp
from sympy import Piecewise

from acausal.lang import Component, Discrete, Eq, Event, Flange, Model, Parameter, Variable, der
from acausal.lang.connectors import RealInput

from ..contact import PosPow
from ..partials import (PartialCompliant, PartialCompliantWithRelativeStates,
                        PartialForce, PartialRelativeSensor, PartialRigid,
                        PartialRigidBody, declared_connector)
from .sources import REGULARIZATIONS, regularized_sign

__all__ = ["Fixed", "Mass", "Rod", "Spring", "Damper", "SpringDamper", "ElastoGap",
           "RollingResistance", "Vehicle", "RelativeStates"]

TOUCH_TOL = 1e-12   # [m] the contact flag switches this far before the touching point


class Fixed(Component):
    """A flange fixed at position ``s0``: ``flange.s = s0`` (it takes any force).

    Parameters: ``s0`` [m] position. Connectors: ``flange``.
    """

    diagnosis_site = "ground"   # what acausal.diagnose may extend here

    flange = Flange("fixed flange")
    s0 = Parameter(0.0, "m", "fixed position")

    def equations(self):
        return [Eq(self.flange.s, self.s0)]


class Mass(PartialRigidBody):
    """A sliding mass of length ``L`` (MSL ``Mass``): ``m * der(v)`` = the
    sum of the forces at its flanges, ``v = der(s)``, ``a = der(v)``, ``s``
    the centre::

        flange_a o----[  m  ]----o flange_b          --> +s
                 s - L/2   s   s + L/2
                         flange (at s)

    Two ways to use it, which may be mixed: MSL's, with ``flange_a`` and
    ``flange_b`` (``Mass(m=1, L=1, s=-0.5, v=0)``), or with the single
    ``flange`` at the centre (``Mass(m=1, s=0.1, v=0)``, ``connect(...,
    mass.flange)``: every force acts there). A flange left unconnected
    carries no force. ``s``, ``v`` take start values (a number is a fixed
    start; ``guess(x)`` a guess).

    Parameters: ``m`` [kg] mass (> 0), ``L`` [m] length (>= 0, default 0).
    States: ``s`` [m] centre position, ``v`` [m/s] velocity, ``a`` [m/s2]
    acceleration. Connectors: ``flange_a`` (s - L/2), ``flange_b``
    (s + L/2), ``flange`` (s).
    """

    m = Parameter(1.0, "kg", "mass of the sliding mass", min=0.0, min_open=True)

    def equations(self):
        return [Eq(self.m * der(self.v), self.net_force())]


class Rod(PartialRigid):
    """A massless rigid rod of length ``L`` (MSL ``Rod``): its flanges keep
    the distance ``L`` and the force passes through unchanged,
    ``flange_a.f + flange_b.f = 0``.

    Parameters: ``L`` [m] length (>= 0). States: ``s`` [m] centre position.
    Connectors: ``flange_a`` (s - L/2), ``flange_b`` (s + L/2).
    """

    def equations(self):
        return [Eq(self.flange_a.f + self.flange_b.f, 0)]


class Spring(PartialCompliant):
    """Linear spring (MSL ``Spring``): ``f = c * (s_rel - s_rel0) + f0``
    (tension positive).

    With ``f0 = 0`` (default, MSL's law), ``s_rel0`` is the free length. To
    give a preloaded spring the way a designer knows it, set ``s_rel0`` to
    the *installed* length and ``f0`` to the installed force there; the free
    length is then ``s_rel0 - f0 / c``. ``f0`` follows the tension-positive
    convention: a compression spring installed pushing its flanges apart
    with 2 kN has ``f0 = -2000``.

    Parameters: ``c`` [N/m] stiffness (>= 0), ``s_rel0`` [m] reference
    length, ``f0`` [N] force at ``s_rel0`` (preload). States: ``s_rel`` [m],
    ``f`` [N]. Connectors: ``flange_a``, ``flange_b``.
    """

    c = Parameter(1.0, "N/m", "spring constant", min=0.0)
    s_rel0 = Parameter(0.0, "m", "reference length (free length when f0 = 0)")
    f0 = Parameter(0.0, "N", "force at s_rel = s_rel0 (preload, tension positive)")

    def equations(self):
        return [Eq(self.f, self.c * (self.s_rel - self.s_rel0) + self.f0)]


class Damper(PartialCompliantWithRelativeStates):
    """Linear damper (MSL ``Damper``): ``f = d * v_rel`` (tension positive),
    dissipating ``lossPower = f * v_rel >= 0``.

    Parameters: ``d`` [N*s/m] damping constant (>= 0). States: ``s_rel``
    [m], ``v_rel`` [m/s], ``f`` [N], ``lossPower`` [W]. Connectors:
    ``flange_a``, ``flange_b``.
    """

    d = Parameter(0.0, "N*s/m", "damping constant", min=0.0)
    lossPower = Variable(0.0, "W", "dissipated power f * v_rel")

    def equations(self):
        return [Eq(self.f, self.d * self.v_rel), Eq(self.lossPower, self.f * self.v_rel)]


class SpringDamper(PartialCompliantWithRelativeStates):
    """Spring and damper in parallel (MSL ``SpringDamper``):
    ``f = c * (s_rel - s_rel0) + f0 + d * v_rel`` (tension positive;
    ``s_rel0``/``f0`` as in :class:`Spring`), dissipating
    ``lossPower = d * v_rel^2``.

    Parameters: ``c`` [N/m] stiffness (>= 0), ``s_rel0`` [m] reference
    length, ``f0`` [N] spring force at ``s_rel0``, ``d`` [N*s/m] damping
    (>= 0). States: ``s_rel`` [m], ``v_rel`` [m/s], ``f`` [N],
    ``lossPower`` [W]. Connectors: ``flange_a``, ``flange_b``.
    """

    c = Parameter(1.0, "N/m", "spring constant", min=0.0)
    s_rel0 = Parameter(0.0, "m", "reference length (free length when f0 = 0)")
    f0 = Parameter(0.0, "N", "spring force at s_rel = s_rel0 (preload, tension positive)")
    d = Parameter(0.0, "N*s/m", "damping constant", min=0.0)
    lossPower = Variable(0.0, "W", "power dissipated by the damper, d * v_rel^2")

    def equations(self):
        f_d = self.d * self.v_rel
        return [Eq(self.f, self.c * (self.s_rel - self.s_rel0) + self.f0 + f_d),
                Eq(self.lossPower, f_d * self.v_rel)]


class ElastoGap(PartialCompliantWithRelativeStates):
    """Spring and damper that act only in contact (MSL ``ElastoGap``): the
    flanges touch when ``s_rel < s_rel0``; then::

        f_c = -c * |s_rel - s_rel0|^n                  (pushes apart, <= 0)
        f_d = clamp(d * v_rel, f_c, -f_c)              (|f_d| <= |f_c|)
        f   = f_c + f_d                                (<= 0: never pulls)

    and ``f = 0`` out of contact. The damping force is limited by the spring
    force, so the contact force is continuous at touch-down (no jump to
    ``d * v_rel``) and the contact never pulls the flanges together while
    they separate. ``contact`` switches with an event when ``s_rel`` crosses
    ``s_rel0`` (MSL's event on ``s_rel < s_rel0``); the clamping has no
    events (MSL's ``noEvent``). ``lossPower = f_d * v_rel``.

    The events switch ``contact`` at ``s_rel = s_rel0 + 1e-12`` m
    (:data:`TOUCH_TOL`), where the force is still exactly 0, so that a run
    starting with the flanges exactly touching starts in contact (IDA
    cannot see a root function that starts at zero); the force is MSL's
    law at every position.

    Parameters: ``c`` [N/m^n] spring constant (>= 0), ``d`` [N*s/m] damping
    (>= 0), ``s_rel0`` [m] relative position at first touch (MSL's
    unstretched length), ``n`` [1] exponent of the spring force (>= 1).
    States: ``s_rel`` [m], ``v_rel`` [m/s], ``f`` [N], ``f_c``, ``f_d`` [N],
    ``lossPower`` [W]. Discrete: ``contact`` (1 when s_rel < s_rel0).
    Connectors: ``flange_a``, ``flange_b``.
    """

    c = Parameter(1.0, "N/m^n", "spring constant", min=0.0)
    d = Parameter(1.0, "N*s/m", "damping constant", min=0.0)
    s_rel0 = Parameter(0.0, "m", "unstretched spring length (contact when s_rel < s_rel0)")
    n = Parameter(1.0, "1", "exponent of the spring force f_c = -c*|s_rel - s_rel0|^n",
                  min=1.0)
    f_c = Variable(0.0, "N", "spring force (<= 0 in contact, 0 otherwise)")
    f_d = Variable(0.0, "N", "damping force, limited to |f_d| <= |f_c|")
    lossPower = Variable(0.0, "W", "power dissipated by the damping, f_d * v_rel")
    contact = Discrete(0, "1", "1 while s_rel < s_rel0 (in contact), else 0")

    def equations(self):
        on = Eq(self.contact, 1)
        f_c = -self.c * PosPow(self.s_rel0 - self.s_rel, self.n)
        f_d2 = self.d * self.v_rel
        clamped = Piecewise((self.f_c, f_d2 < self.f_c), (-self.f_c, f_d2 > -self.f_c),
                            (f_d2, True))
        return [Eq(self.f_c, Piecewise((f_c, on), (0, True))),
                Eq(self.f_d, Piecewise((clamped, on), (0, True))),
                Eq(self.f, self.f_c + self.f_d),
                Eq(self.lossPower, self.f_d * self.v_rel)]

    def events(self):
        p, contact = self.path, self.contact
        gap = self.s_rel0 - self.s_rel + TOUCH_TOL     # > 0: in contact

        def close(s):
            s[contact] = 1

        def open_(s):
            s[contact] = 0

        return [Event(f"{p}.touch", Piecewise((gap, Eq(contact, 0)), (-1, True)), +1, close,
                      recheck=True),
                Event(f"{p}.lift", Piecewise((gap, Eq(contact, 1)), (1, True)), -1, open_,
                      recheck=True)]


class RelativeStates(PartialRelativeSensor):
    """Relative position, speed and acceleration between two flanges,
    taking no force (MSL ``RelativeStates``): ``s_rel = flange_b.s -
    flange_a.s``, ``v_rel = der(s_rel)``, ``a_rel = der(v_rel)``. MSL uses it
    to make ``s_rel``, ``v_rel`` the states; here fixed start values on them
    (``RelativeStates(s_rel=0.1, v_rel=0)``) make the solver keep them as
    states where it can.

    States: ``s_rel`` [m], ``v_rel`` [m/s], ``a_rel`` [m/s2]. Connectors:
    ``flange_a``, ``flange_b``.
    """

    s_rel = Variable(0.0, "m", "relative position flange_b.s - flange_a.s")
    v_rel = Variable(0.0, "m/s", "relative velocity der(s_rel)")
    a_rel = Variable(0.0, "m/s2", "relative acceleration der(v_rel)")

    def equations(self):
        return [Eq(self.s_rel, self.flange_b.s - self.flange_a.s),
                Eq(self.v_rel, der(self.s_rel)), Eq(self.a_rel, der(self.v_rel))]


class RollingResistance(PartialForce):
    """Rolling resistance of a wheel (MSL ``RollingResistance``): a force
    against the motion relative to the support, ``Cr * fWeight *
    cos(atan(inclination))`` in magnitude, its sign regularised below
    ``v0`` (:func:`~acausal.mechanics.translational.sources.regularized_sign`)::

        f_nominal = -Cr * fWeight * cos(atan(inclination))
        f         = -f_nominal * regularized_sign(v, v0, reg)   (f = flange.f)

    ``Cr`` is the input ``cr`` with ``useCrInput=True``, else
    ``CrConstant``; the inclination (tan of the slope angle) is the input
    ``inclination`` with ``useInclinationInput=True``, else
    ``inclinationConstant``.

    Parameters: ``fWeight`` [N] wheel load due to gravity, ``CrConstant``
    [1], ``inclinationConstant`` [1], ``v0`` [m/s] regularisation (> 0),
    ``reg`` (structural, MSL's default "Exp"), ``useCrInput``,
    ``useInclinationInput``, ``useSupport`` (structural). States: ``f``
    [N], ``f_nominal`` [N], ``s`` [m], ``v`` [m/s]. Connectors: ``flange``,
    ``cr``, ``inclination`` (RealInputs, with their flags), ``support``
    (with useSupport).
    """

    fWeight = Parameter(0.0, "N", "wheel load due to gravity")
    useCrInput = Parameter(False, "1", "enable signal input for Cr", structural=True,
                           choices=(False, True))
    CrConstant = Parameter(0.01, "1", "constant rolling resistance coefficient")
    useInclinationInput = Parameter(False, "1", "enable signal input for inclination",
                                    structural=True, choices=(False, True))
    inclinationConstant = Parameter(0.0, "1", "constant inclination = tan(angle)")
    reg = Parameter("Exp", "1", "type of regularization", structural=True,
                    choices=REGULARIZATIONS)
    v0 = Parameter(0.1, "m/s", "regularization below v0", min=0.0, min_open=True)
    f_nominal = Variable(0.0, "N", "nominal rolling resistance without regularization")
    _conditional = dict(PartialForce._conditional,
                        cr=("useCrInput", declared_connector(RealInput, "cr",
                                                    "rolling resistance coefficient")),
                        inclination=("useInclinationInput", declared_connector(
                            RealInput, "inclination", "inclination = tan(angle)")))

    def equations(self):
        cr = self.port("cr").symbol if self.useCrInput else self.CrConstant
        incl = (self.port("inclination").symbol if self.useInclinationInput
                else self.inclinationConstant)
        return [Eq(self.f_nominal, -cr * self.fWeight * sp.cos(sp.atan(incl))),
                Eq(self.f, -self.f_nominal * regularized_sign(self.v, self.v0, self.reg))]


G_N = 9.80665   # [m/s2] standard gravity (Modelica.Constants.g_n)


class Vehicle(Model):
    """A simple vehicle (MSL ``Vehicle``): a mass driven through a wheel
    (inertia and ideal rolling wheel) against the driving resistances::

        flangeR -- inertia(J) -- idealRollingWheel(R) -- mass(m) -- flangeT
                                                          |
                         fDrag (air, relative to the wind), fRoll (rolling),
                         fGrav (slope)

    * air drag: ``QuadraticSpeedDependentForce`` with ``f_nominal =
      -Cd*A*rho/2`` (at 1 m/s), both directions, its support moving with
      the wind (``windSpeed``, a ``Speed`` source fed by ``vWind`` or
      ``vWindConstant``);
    * rolling resistance: :class:`RollingResistance` with ``fWeight = m*g``,
      linear regularisation below ``vReg``;
    * slope: a force ``-m*g*sin(atan(inclination))``.

    The vehicle's ``s``, ``v``, ``a`` are the mass's; ``Vehicle(s=0, v=0)``
    gives them fixed start values (MSL's ``s(fixed=true)``). With ``J = 0``
    there is no inertia: ``flangeR`` is the wheel's.

    Parameters: ``m`` [kg] total mass (> 0), ``J`` [kg*m^2] drive-train
    inertia (>= 0), ``R`` [m] wheel radius (> 0), ``A`` [m^2] cross
    section, ``Cd`` [1] drag coefficient, ``rho`` [kg/m^3] air density,
    ``g`` [m/s2] gravity, ``vWindConstant`` [m/s], ``CrConstant`` [1],
    ``vReg`` [m/s] (> 0), ``inclinationConstant`` [1]; ``useWindInput``,
    ``useCrInput``, ``useInclinationInput`` (structural). States: ``s`` [m],
    ``v`` [m/s], ``a`` [m/s2]. Connectors: ``flangeT`` (translational),
    ``flangeR`` (rotational), ``vWind``, ``cr``, ``inclination``
    (RealInputs, with their flags).
    """

    def __init__(self, m, J, R, A=1.0, Cd=0.5, rho=1.2, g=G_N, useWindInput=False,
                 vWindConstant=0.0, useCrInput=False, CrConstant=0.015, vReg=1e-3,
                 useInclinationInput=False, inclinationConstant=0.0, s=None, v=None):
        super().__init__()
        m_ = self.parameter("m", m, "kg", "total mass of vehicle", min=0.0, min_open=True)
        g_ = self.parameter("g", g, "m/s2", "constant gravity acceleration")
        J_ = self.parameter("J", J, "kg*m^2", "total rotational inertia of drive train",
                            min=0.0)
        R_ = self.parameter("R", R, "m", "wheel radius", min=0.0, min_open=True)
        A_ = self.parameter("A", A, "m^2", "cross section of vehicle", min=0.0)
        Cd_ = self.parameter("Cd", Cd, "1", "drag resistance coefficient", min=0.0)
        rho_ = self.parameter("rho", rho, "kg/m^3", "density of air", min=0.0)
        self.parameter("vWindConstant", vWindConstant, "m/s", "constant wind velocity")
        self.parameter("CrConstant", CrConstant, "1", "constant rolling resistance coefficient")
        self.parameter("vReg", vReg, "m/s", "velocity for regularization around 0", min=0.0,
                       min_open=True)
        self.parameter("inclinationConstant", inclinationConstant, "1",
                       "constant inclination = tan(angle)")
        from ..rotational.components import IdealRollingWheel, Inertia
        from .kinematic import Speed
        from .sources import Force, QuadraticSpeedDependentForce

        starts = {k: val for k, val in (("s", s), ("v", v)) if val is not None}
        self.mass = Mass(m=m_, **starts)
        self.idealRollingWheel = IdealRollingWheel(radius=R_)
        v_ref = 1.0       # MSL's vRef: the drag's reference speed [m/s]
        self.fDrag = QuadraticSpeedDependentForce(
            useSupport=True, f_nominal=-Cd_ * A_ * rho_ * v_ref ** 2 / 2, ForceDirection=False,
            v_nominal=v_ref)
        self.windSpeed = Speed(**({} if useWindInput
                                  else {"v_ref": self.symbol("vWindConstant")}))
        self.fRoll = RollingResistance(
            fWeight=m_ * g_, useCrInput=useCrInput, CrConstant=self.symbol("CrConstant"),
            useInclinationInput=useInclinationInput,
            inclinationConstant=self.symbol("inclinationConstant"), reg="Linear",
            v0=self.symbol("vReg"))
        incl = (self.fRoll.inclination if useInclinationInput
                else self.symbol("inclinationConstant"))
        self.fGrav = Force(f=-m_ * g_ * sp.sin(sp.atan(sp.sympify(incl))))
        self.connect(self.idealRollingWheel.flangeT, self.mass.flange_a)
        self.connect(self.fDrag.support, self.windSpeed.flange)
        self.connect(self.mass.flange_b, self.fDrag.flange, self.fRoll.flange,
                     self.fGrav.flange)
        if isinstance(J, (int, float)) and J == 0:
            self.flangeR = self.idealRollingWheel.flangeR
        else:
            self.inertia = Inertia(J=J_)
            self.connect(self.inertia.flange_b, self.idealRollingWheel.flangeR)
            self.flangeR = self.inertia.flange_a
        self.flangeT = self.mass.flange_b
        if useWindInput:
            self.vWind = self.windSpeed.v_ref
        if useCrInput:
            self.cr = self.fRoll.cr
        if useInclinationInput:
            self.inclination = self.fRoll.inclination
        for name, unit, desc in (("s", "m", "position of vehicle"),
                                 ("v", "m/s", "velocity of vehicle"),
                                 ("a", "m/s2", "acceleration of vehicle")):
            sym = self.variable(name, 0.0, unit, desc)
            self.equation(Eq(sym, getattr(self.mass, name)))
