"""Small elements the hypotheses insert that the component library does not
have (sign convention: :mod:`acausal.connectors`).

* :class:`DisplacementForce` / :class:`DisplacementTorque`: a force growing
  linearly with the displacement of a flange from where it was at the start
  of the run (captured by an initial event, so it needs no start value).
* :class:`VelocityRestitution`, :class:`PowerRestitution`: mixins that make
  a contact's coefficient of restitution fall with the impact velocity
  (linearly, or as a power law).
"""
from sympy import Max, Min, Piecewise

from ...lang import Component, Discrete, Eq, Event, Flange, Parameter, RotFlange, Variable

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
