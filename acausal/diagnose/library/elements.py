"""Small elements the hypotheses insert that the component library does not
have (sign convention: :mod:`acausal.connectors`).

* :class:`DisplacementForce` / :class:`DisplacementTorque`: a force growing
  linearly with the displacement of a flange from where it was at the start
  of the run (captured by an initial event, so it needs no start value).
* :class:`VelocityRestitution`, :class:`PowerRestitution`: mixins that make
  a contact's coefficient of restitution fall with the impact velocity
  (linearly, or as a power law).
* :class:`StickSlipForce` / :class:`StickSlipTorque`: dry friction with
  stiction between one flange and the frame, a leaf of the library's
  friction mode machine (:mod:`acausal.mechanics.frictionmodes`, MSL's
  ``PartialFriction``): it sticks and slips by events, as MSL's
  ``SupportFriction`` / ``BearingFriction`` with a constant sliding level do,
  but needs no second flange and no support (the frame takes the reaction).
"""
from sympy import Max, Min, Piecewise

from ...lang import (Component, Discrete, Eq, Event, Flange, Parameter, RotFlange, Variable,
                     der)
from ...mechanics.frictionmodes import PartialFriction, PartialRotFriction

E_MIN = 0.01   # smallest restitution VelocityRestitution lets the law reach


def _capture(comp, across):
    """The initial event that stores the flange position in ``x_start``
    (fires once, in the initial event iteration, as friction's initial
    mode does)."""
    me = comp

    def start(state):
        state[me.x_start] = state[across]
        state[me.init] = 0

    pre = f"{comp.path}." if comp.path else ""
    return Event(pre + "capture_start", Piecewise((1, Eq(comp.init, 1)), (-1, True)), 1, start,
                 recheck=True)


class DisplacementForce(Component):
    """A force ``f = k * (flange.s - x_start)`` along +s, reacting on the
    frame (``flange.f = -f``, as :class:`acausal.mechanics.translational.Force`),
    where ``x_start`` is the flange position at the start of the run.
    ``k > 0`` pushes the flange further the way it has moved (a force that
    grows with the stroke); ``k < 0`` pulls it back (a spring-like loss).

    Parameters: ``k`` [N/m]. States: ``f`` [N]. Discrete: ``x_start`` [m],
    ``init``. Connectors: ``flange``.
    """

    flange = Flange("flange the force acts on")
    k = Parameter(0.0, "N/m", "force per unit displacement from the start position")
    f = Variable(0.0, "N", "applied force along +s")
    x_start = Discrete(0.0, "m", "flange position at the start of the run")
    init = Discrete(1, "1", "1 until the start position is captured")

    def equations(self):
        return [Eq(self.f, self.k * (self.flange.s - self.x_start)),
                Eq(self.flange.f, -self.f)]

    def events(self):
        return [_capture(self, self.flange.s)]


class DisplacementTorque(Component):
    """A torque ``tau = k * (flange.phi - x_start)`` about +phi reacting on
    the frame (``flange.tau = -tau``), ``x_start`` the flange angle at the
    start of the run. Parameters: ``k`` [N*m/rad]. States: ``tau`` [N*m].
    Discrete: ``x_start`` [rad], ``init``. Connectors: ``flange``."""

    flange = RotFlange("flange the torque acts on")
    k = Parameter(0.0, "N*m/rad", "torque per unit rotation from the start angle")
    tau = Variable(0.0, "N*m", "applied torque about +phi")
    x_start = Discrete(0.0, "rad", "flange angle at the start of the run")
    init = Discrete(1, "1", "1 until the start angle is captured")

    def equations(self):
        return [Eq(self.tau, self.k * (self.flange.phi - self.x_start)),
                Eq(self.flange.tau, -self.tau)]

    def events(self):
        return [_capture(self, self.flange.phi)]


class StickSlipForce(PartialFriction):
    """Dry (Coulomb) friction with stiction between ``flange`` and the frame
    (a guide), by the shared mode machine (events, MSL's law)::

        sliding:  f = F*sign(v)                  (v != 0, or starting)
        stuck:    der(v) = 0, while -peak*F <= f <= peak*F
        f0 = F,  f0_max = peak*F

    ``f`` is the force the flange applies on the element (the element acts
    on the flange's body with ``-f``: against the sliding velocity). With
    ``F = 0`` the element transmits nothing (a body at rest breaks away at
    any force), so the extended model is the nominal one.

    Parameters: ``F`` [N] sliding (kinetic) friction level (>= 0); ``peak``
    [1] break-away level / sliding level (>= 1); ``v_small`` [m/s] (the
    machine's). States: ``v`` [m/s], ``a`` [m/s2], ``f`` [N]; the machine's
    (``mode``, ``startForward``, ``startBackward``, ``sa``, ``locked``,
    ``f0``, ``f0_max``, ``lossPower``). Connectors: ``flange``.
    """

    flange = Flange("flange of the sliding body (the frame takes the reaction)")
    F = Parameter(0.0, "N", "sliding (kinetic) friction force", min=0.0)
    peak = Parameter(1.0, "1", "break-away force / sliding friction force", min=1.0)
    v = Variable(0.0, "m/s", "velocity of the flange relative to the frame")
    a = Variable(0.0, "m/s2", "acceleration of the flange relative to the frame")
    f = Variable(0.0, "N", "friction force (applied on the element by the flange)")

    def equations(self):
        return [Eq(self.v, der(self.flange.s)), Eq(self.a, der(self.v)),
                Eq(self.flange.f, self.f),
                Eq(self.f0, self.F), Eq(self.f0_max, self.peak * self.F)]

    def friction_motion(self):
        return self.v, self.a

    def friction_force(self):
        return self.f

    def sliding_force(self, direction):
        return direction * self.F


class StickSlipTorque(PartialRotFriction):
    """Dry (Coulomb) friction with stiction between ``flange`` and the frame
    (a bearing), by the shared mode machine (events, MSL's law)::

        sliding:  tau = T*sign(w)
        stuck:    der(w) = 0, while -peak*T <= tau <= peak*T
        tau0 = T,  tau0_max = peak*T

    ``tau`` is the torque the flange applies on the element (it acts on the
    flange's body with ``-tau``). ``T = 0``: the nominal model.

    Parameters: ``T`` [N*m] sliding (kinetic) friction torque (>= 0);
    ``peak`` [1] break-away / sliding level (>= 1); ``w_small`` [rad/s] (the
    machine's). States: ``w`` [rad/s], ``a`` [rad/s2], ``tau`` [N*m]; the
    machine's. Connectors: ``flange``.
    """

    flange = RotFlange("flange of the turning body (the frame takes the reaction)")
    T = Parameter(0.0, "N*m", "sliding (kinetic) friction torque", min=0.0)
    peak = Parameter(1.0, "1", "break-away torque / sliding friction torque", min=1.0)
    w = Variable(0.0, "rad/s", "angular velocity of the flange relative to the frame")
    a = Variable(0.0, "rad/s2", "angular acceleration of the flange relative to the frame")
    tau = Variable(0.0, "N*m", "friction torque (applied on the element by the flange)")

    def equations(self):
        return [Eq(self.w, der(self.flange.phi)), Eq(self.a, der(self.w)),
                Eq(self.flange.tau, self.tau),
                Eq(self.tau0, self.T), Eq(self.tau0_max, self.peak * self.T)]

    def friction_motion(self):
        return self.w, self.a

    def friction_force(self):
        return self.tau

    def sliding_force(self, direction):
        return direction * self.T


class RestitutionLaw:
    """Mixin for a :class:`acausal.mechanics.contact.PartialContact`: the damping
    of each impact uses ``e_eff`` (:meth:`_e_eff`, a function of the impact
    velocity ``v_i`` captured at the onset, so constant during an impact)
    instead of ``e``. Law ``beta`` has no restitution and is left unchanged.
    Subclasses define :meth:`_e_eff`."""

    def _e_eff(self):
        raise NotImplementedError

    def _factor(self):
        if self.law == "beta":
            return super()._factor()
        from acausal.mechanics.contact import damping_chi
        return 1 + damping_chi(self.law, self._e_eff()) * self.delta_dot / self.v_i

    def _factor_rate(self):
        if self.law == "beta":
            return super()._factor_rate()
        from acausal.mechanics.contact import damping_chi
        return damping_chi(self.law, self._e_eff()) * self.a_rel / self.v_i


class VelocityRestitution(RestitutionLaw):
    """``e(v_i) = clip(e - slope * v_i, E_MIN, 1)``; ``slope`` [s/m] is the
    symbol stored in the instance attribute ``_e_slope`` (a model parameter).
    Applied by :func:`make_velocity_restitution`."""

    def _e_eff(self):
        return Max(E_MIN, Min(1, self.e - self._e_slope * self.v_i))


class PowerRestitution(RestitutionLaw):
    """A restitution power law ``e(v_i) = clip(e * (v_i / v_ref)^(-p), E_MIN,
    1)`` (``p`` >= 0: faster impacts dissipate a larger fraction); ``p`` and
    ``v_ref`` are the symbols in ``_e_power`` and ``_e_vref``. Applied by
    :func:`make_power_restitution`."""

    def _e_eff(self):
        return Max(E_MIN, Min(1, self.e * (self.v_i / self._e_vref) ** (-self._e_power)))


_SWAPPED = {}


def _swap(contact, mixin):
    """Give ``contact`` (a PartialContact instance, already in its model) the
    class ``mixin`` + its own (same connectors, parameters, start values and
    connections)."""
    cls = type(contact)
    if not issubclass(cls, mixin):
        sub = _SWAPPED.get((cls, mixin))
        if sub is None:
            sub = _SWAPPED[(cls, mixin)] = type(f"{mixin.__name__}{cls.__name__}", (mixin, cls),
                                                {"__module__": __name__,
                                                 "__doc__": cls.__doc__})
        contact.__class__ = sub
    return contact


def make_velocity_restitution(contact, slope):
    """Make ``contact``'s restitution fall with the impact velocity at ``slope``
    (:class:`VelocityRestitution`)."""
    _swap(contact, VelocityRestitution)
    object.__setattr__(contact, "_e_slope", slope)
    return contact


def make_power_restitution(contact, power, v_ref):
    """Make ``contact``'s restitution follow the power law of
    :class:`PowerRestitution` with exponent ``power`` and reference speed ``v_ref``."""
    _swap(contact, PowerRestitution)
    object.__setattr__(contact, "_e_power", power)
    object.__setattr__(contact, "_e_vref", v_ref)
    return contact
