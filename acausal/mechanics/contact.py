"""Impact contact: the report's continuous contact-force module with a
switched zero-junction (section 2.2, eqs. 1-4).

Two bodies are free until their surfaces touch; while in contact a
visco-elastic force ``F = K delta^gamma * (1 + chi * d(delta)/dt / v_i)``
pushes them apart, where ``delta`` is the indentation and ``v_i`` the
relative velocity at the onset of the impact. A discrete ``mode`` is the
switched zero-junction of the report's bond graph: with ``mode = 0`` the
contact carries no force (the junction is open), with ``mode = 1`` the
force law acts.

Sign convention (:mod:`acausal.connectors`; positions along one +s axis)::

        body A                          body B
     flange_a.s                       flange_b.s
         o------|                  |------o          --> +s
                |<----- s_rel ---->|  (between the flanges: s_rel = s_b - s_a)

  * ``gap`` is the value of ``s_rel = flange_b.s - flange_a.s`` at which the
    surfaces touch (0 when the flanges sit on the surfaces themselves,
    ``R_a + R_b`` when they sit at the centres of two balls).
  * ``delta = gap - s_rel = flange_a.s - flange_b.s + gap``: the indentation,
    positive when A has moved into B (A on the left of B).
  * ``delta_dot = d(delta)/dt = v_a - v_b``: positive while they approach.
  * ``fc >= 0`` [N]: the contact force, pushing the bodies apart: on body A
    along -s, on body B along +s. In connector terms (force positive *into*
    the component) ``flange_a.f = +fc`` and ``flange_b.f = -fc``, i.e. the
    tension ``f`` of :class:`~acausal.mechanics.partials.PartialCompliant` is
    ``-fc``.

Modes and events (every switch happens where the force is zero, so the
force is continuous in time and the switching cannot chatter; "delta
through 0" means through ``-delta_tol``, 1e-12 m, see :class:`PartialContact`):

  * ``mode 0`` free: ``onset`` when ``delta`` rises through 0 (also tested
    at the start: surfaces that touch or overlap at t = 0 begin in contact).
    The action captures ``v_impact = delta_dot``, ``t_onset``, counts
    ``n_impacts``.
  * ``mode 1`` contact: ``release`` when ``delta`` falls through 0;
    ``pull_off`` when the damping factor ``1 + chi*delta_dot/v_i`` falls
    through 0 (the force would pull: the bodies part with ``delta > 0``).
    Both record ``t_release`` and ``v_release = delta_dot``. ``peak`` when
    ``dF/dt`` falls through 0 records ``f_peak`` (largest local maximum of
    the impact, located by IDA's root finding: exact to the root tolerance).
  * ``mode 2`` lifted (after a pull-off, ``delta`` still > 0): ``reengage``
    when the damping factor rises back through 0 (the same impact goes on,
    same ``v_i``); ``release`` when ``delta`` falls through 0 (back to 0).

Accuracy: the onset, release and peak instants are IDA roots (located to
about 1e-15 s); their accuracy is that of the states. IDA controls the error
of the *absolute* positions, so keep ``rtol * |s|`` well below the largest
indentation (about (5 m v^2 / 4 K)^0.4): e.g. balls at |s| = 0.06 m with an
indentation of 2e-5 m lose 6e-7 of their exchanged velocity at rtol 1e-10,
1e-8 at rtol 1e-12.

A flange with no mass behind it (a contact on the free end of a spring) is
not supported reliably: ``delta`` is pinned by the spring while the contact
is open and free while it is closed, and with ``e = 1`` the term that makes
the closed system index 1 vanishes. Such a model failed at rtol 1e-10; put
a small mass at that node (tested: 0.01 kg against 0.1 kg).

Per-impact measures are discrete values set by the actions; the helpers
:func:`impacts`, :func:`contact_period`, :func:`peak_force`,
:func:`impact_velocity` and :func:`restitution` read them from a result.
Event names are prefixed with the component path (``"wall.onset"``).
"""
import math
from collections import namedtuple

import numpy as np
import sympy as sp
from sympy import Piecewise

from acausal.lang import Component, Discrete, Eq, Event, Flange, Model, Parameter, Variable, der
from acausal.errors import MeasureError, ParameterError

from .partials import PartialCompliant

PEAK_MARGIN = 1e-6  # a new force maximum must exceed the last one by this fraction
LAWS = ("lankarani_nikravesh", "hunt_crossley", "flores", "beta")


class PosPow(sp.Function):
    """``PosPow(x, g) = x^g`` for ``x > 0``, else 0 (``g >= 0``): the
    indentation power ``max(delta, 0)^gamma`` with a derivative that needs
    no division (sympy's derivative of ``Max(x, 0)**g`` divides by
    ``Max(x, 0)``, which is 0 out of contact)."""

    nargs = 2

    def fdiff(self, argindex=1):
        x, g = self.args
        if argindex == 1:
            return g * PosPow(x, g - 1)
        if argindex == 2:
            # log of max(x, tiny): the generated code computes shared
            # sub-expressions ahead of the branches, so log(x) itself would be
            # evaluated out of contact (x <= 0) as well; there PosPow is 0
            return PosPow(x, g) * sp.log(sp.Max(x, sp.Float(1e-300)))
        raise sp.ArgumentIndexError(self, argindex)

    @classmethod
    def eval(cls, x, g):
        if x.is_number and g.is_number:
            return x ** g if x > 0 else sp.Integer(0)
        return None

    def _pythoncode(self, printer):
        x, g = (printer._print(a) for a in self.args)
        return f"(({x})**({g}) if ({x}) > 0 else 0.0)"

    def _numpycode(self, printer):   # over arrays of rows (acausal.runtime.observe)
        x, g = (printer._print(a) for a in self.args)
        return f"_where(({x}) > 0, ({x})**({g}), 0.0)"

    def _ccode(self, printer):   # the compiled backend (acausal/codegen_c.py)
        x, g = (printer._print(a) for a in self.args)
        return f"(({x}) > 0 ? pow({x}, {g}) : 0.0)"


def hertz_stiffness(R_i, R_j, E_i, E_j, nu_i=0.3, nu_j=0.3):
    """Hertz stiffness of two spheres [N/m^1.5] (the report's eqs. 3, 4,
    after Lankarani and Nikravesh 1994)::

        K = 4 / (3 pi (h_i + h_j)) * sqrt(R_i R_j / (R_i + R_j)),
        h_m = (1 - nu_m^2) / (pi E_m)

    ``R`` [m] radii (``math.inf`` for a plane; a concave surface has a
    negative radius), ``E`` [Pa] Young's moduli, ``nu`` [1] Poisson ratios.
    """
    for name, v in (("R_i", R_i), ("R_j", R_j), ("E_i", E_i), ("E_j", E_j)):
        if not (v > 0 or (name.startswith("R") and v < 0)) or v != v:
            raise ParameterError(f"hertz_stiffness: {name} = {v!r} must be a non-zero number "
                             "(E > 0)")
    for name, v in (("nu_i", nu_i), ("nu_j", nu_j)):
        if not -1.0 < v < 0.5 + 1e-12:
            raise ParameterError(f"hertz_stiffness: Poisson ratio {name} = {v!r} must lie in "
                             "(-1, 0.5]")
    if math.isinf(R_i) and math.isinf(R_j):
        raise ParameterError("hertz_stiffness: two planes (R_i = R_j = inf) have no Hertz "
                         "stiffness")
    R = 1.0 / (1.0 / R_i + 1.0 / R_j)   # R_i R_j / (R_i + R_j), safe with inf
    if R <= 0:
        raise ParameterError(f"hertz_stiffness: effective radius {R:g} m <= 0 (a concave "
                         "surface must be larger than the convex one)")
    h_i = (1.0 - nu_i ** 2) / (math.pi * E_i)
    h_j = (1.0 - nu_j ** 2) / (math.pi * E_j)
    return 4.0 / (3.0 * math.pi * (h_i + h_j)) * math.sqrt(R)


def damping_chi(law, e):
    """The damping factor chi of ``F = K delta^n (1 + chi * delta_dot / v_i)``
    for a target restitution ``e`` (works on numbers and sympy symbols)."""
    if law == "hunt_crossley":
        return 3 * (1 - e) / 2
    if law == "lankarani_nikravesh":
        return 3 * (1 - e ** 2) / 4
    if law == "flores":
        return 8 * (1 - e) / (5 * e)
    raise ParameterError(f"no restitution-based chi for law {law!r}")


class PartialContact(Component):
    """The contact law, its modes and events, for an indentation ``delta``
    defined by the subclass (which also maps ``fc`` onto its flanges).

    Law (``F`` = ``fc`` while ``mode`` = 1, 0 otherwise, ``D = max(delta, 0)``):

      * ``lankarani_nikravesh`` (the report's eq. 2, default):
        ``F = K D^gamma (1 + chi delta_dot / v_i)``, ``chi = 3 (1 - e^2) / 4``
        (``beta = 3 K (1 - e^2) / (4 v_i)`` in the report's eq. 1);
      * ``hunt_crossley``: same form, ``chi = 3 (1 - e) / 2``;
      * ``flores``: same form, ``chi = 8 (1 - e) / (5 e)``;
      * ``beta``: the report's eq. 1 with a constant coefficient,
        ``F = K D^gamma + beta D^gamma delta_dot``.

    ``v_i = max(v_impact, v_min)``: ``v_min`` only matters for impacts slower
    than it (and for a contact that is already closed at the start, where
    ``v_impact`` = the approach velocity then, possibly 0).

    Parameters: ``K`` [N/m^gamma] stiffness (> 0; see :func:`hertz_stiffness`),
    ``gamma`` [1] exponent (>= 1, 1.5 = Hertz), ``e`` [1] target coefficient
    of restitution (0 < e <= 1; 1 = undamped), ``beta`` [N*s/m^(gamma+1)]
    (law ``beta`` only, >= 0), ``v_min`` [m/s] floor of the impact velocity
    (> 0), ``delta_tol`` [m] detection tolerance (>= 0, default 1e-12: the
    mode switches at ``delta = -delta_tol`` where the force is still 0, so
    that surfaces placed exactly touching at the start, ``delta = 0``, begin
    in contact; IDA cannot see a root function that starts at exactly 0),
    ``law`` (structural, one of :data:`LAWS`), ``peak_event``
    (structural, default True: locate each force maximum with an event,
    which adds the relative acceleration ``a_rel`` = d(delta_dot)/dt, so the
    index reduction differentiates the positions twice; False drops both).
    States: ``delta`` [m], ``delta_dot`` [m/s], ``a_rel`` [m/s2] (with
    ``peak_event``), ``fc`` [N]. Discrete: ``mode`` (0 free, 1 contact,
    2 lifted), ``n_impacts``, ``v_impact`` [m/s], ``t_onset`` [s],
    ``t_release`` [s], ``v_release`` [m/s] (delta_dot at separation,
    negative), ``f_peak`` [N].
    """

    diagnosis_site = "contact"   # what acausal.diagnose may extend here

    K = Parameter(1e9, "N/m^gamma", "contact stiffness", min=0.0, min_open=True)
    gamma = Parameter(1.5, "1", "force exponent (1.5 = Hertz)", min=1.0)
    e = Parameter(1.0, "1", "coefficient of restitution", min=0.0, min_open=True, max=1.0)
    beta = Parameter(0.0, "N*s/m^(gamma+1)", "hysteretic damping coefficient (law 'beta')",
                     min=0.0)
    v_min = Parameter(1e-4, "m/s", "floor of the impact velocity in the damping term",
                      min=0.0, min_open=True)
    delta_tol = Parameter(1e-12, "m", "contact detection tolerance (see the class doc)",
                          min=0.0)
    law = Parameter("lankarani_nikravesh", "1", "damping law", structural=True, choices=LAWS)
    peak_event = Parameter(True, "1", "locate force maxima with an event", structural=True,
                           choices=(True, False))

    delta = Variable(0.0, "m", "indentation (> 0 when the surfaces overlap)")
    delta_dot = Variable(0.0, "m/s", "indentation rate (> 0 approaching)")
    fc = Variable(0.0, "N", "contact force (>= 0, pushes the bodies apart)")
    a_rel = Variable(0.0, "m/s2", "relative acceleration d(delta_dot)/dt (peak_event only)")

    mode = Discrete(0, "1", "0 free, 1 in contact, 2 lifted off with delta > 0")
    n_impacts = Discrete(0, "1", "number of impacts so far")
    v_impact = Discrete(0.0, "m/s", "delta_dot at the onset of the last impact")
    v_i = Discrete(1.0, "m/s", "max(v_impact, v_min): the velocity scale of the damping")
    t_onset = Discrete(0.0, "s", "time of the onset of the last impact")
    t_release = Discrete(0.0, "s", "time of the last separation")
    v_release = Discrete(0.0, "m/s", "delta_dot at the last separation")
    f_peak = Discrete(0.0, "N", "largest force maximum of the last impact")

    # -- the law ----------------------------------------------------------------
    def _factor(self):
        """The damping factor F / (K D^gamma); the force pulls when it is < 0."""
        if self.law == "beta":
            return 1 + self.beta * self.delta_dot / self.K
        return 1 + damping_chi(self.law, self.e) * self.delta_dot / self.v_i

    def _factor_rate(self):
        if self.law == "beta":
            return self.beta * self.a_rel / self.K
        return damping_chi(self.law, self.e) * self.a_rel / self.v_i

    def equations(self):
        law = self.K * PosPow(self.delta, self.gamma) * PosPow(self._factor(), 1)
        eqs = [Eq(self.delta_dot, der(self.delta)),
               Eq(self.fc, Piecewise((law, Eq(self.mode, 1)), (0, True)))]
        if self.peak_event:
            eqs.append(Eq(self.a_rel, der(self.delta_dot)))
        return eqs

    def declarations(self):
        decl = super().declarations()
        if self._values.get("peak_event", True) is False:
            decl.pop("a_rel", None)   # no relative acceleration without the peak event
        return decl

    # -- modes ------------------------------------------------------------------
    def events(self):
        p = self.path
        m0, m1, m2 = Eq(self.mode, 0), Eq(self.mode, 1), Eq(self.mode, 2)
        fac = self._factor()
        sym = dict(mode=self.mode, n=self.n_impacts, v_impact=self.v_impact, v_i=self.v_i,
                   v_min=self.v_min, t_onset=self.t_onset, t_release=self.t_release,
                   v_release=self.v_release, f_peak=self.f_peak,
                   delta_dot=self.delta_dot, fc=self.fc)

        def onset(s):
            s[sym["mode"]] = 1
            s[sym["n"]] = s[sym["n"]] + 1
            s[sym["v_impact"]] = s[sym["delta_dot"]]
            s[sym["v_i"]] = max(s[sym["delta_dot"]], s[sym["v_min"]])
            s[sym["t_onset"]] = s.t
            s[sym["f_peak"]] = 0.0

        def separate(s):
            if s[sym["mode"]] == 1:
                s[sym["t_release"]] = s.t
                s[sym["v_release"]] = s[sym["delta_dot"]]
            s[sym["mode"]] = 0

        def pull_off(s):
            s[sym["t_release"]] = s.t
            s[sym["v_release"]] = s[sym["delta_dot"]]
            s[sym["mode"]] = 2

        def reengage(s):
            s[sym["mode"]] = 1

        g = self.delta + self.delta_tol   # > 0: touching (the force needs delta > 0)
        evs = [Event(f"{p}.onset", Piecewise((g, m0), (-1, True)), +1, onset, recheck=True),
               Event(f"{p}.release", Piecewise((g, m1 | m2), (1, True)), -1, separate),
               Event(f"{p}.pull_off", Piecewise((fac, m1), (1, True)), -1, pull_off),
               Event(f"{p}.reengage", Piecewise((fac, m2), (-1, True)), +1, reengage)]
        if self.peak_event:
            dFdt = self.K * (self.gamma * PosPow(self.delta, self.gamma - 1) * self.delta_dot
                             * fac + PosPow(self.delta, self.gamma) * self._factor_rate())

            def peak(s):
                s[sym["f_peak"]] = max(s[sym["f_peak"]], s[sym["fc"]])

            # armed only while the force is above the largest maximum so far, so
            # that a resting contact's decaying oscillation fires no more events
            f1 = self.K * PosPow(self.delta, self.gamma) * PosPow(fac, 1)   # fc in mode 1
            rising = m1 & (f1 > self.f_peak * (1 + PEAK_MARGIN))
            evs.append(Event(f"{p}.peak", Piecewise((dFdt, rising), (1, True)), -1, peak,
                             observer=True))
        return evs


class Contact(PartialContact, PartialCompliant):
    """Impact contact between two translational flanges (see the module
    docstring for the picture): ``delta = gap - (flange_b.s - flange_a.s)``,
    ``flange_a.f = fc``, ``flange_b.f = -fc`` (pushes A along -s, B along +s);
    the law is :class:`PartialContact`'s.

    Parameters: ``gap`` [m] flange distance ``s_b - s_a`` at first touch,
    and those of :class:`PartialContact`. States: ``s_rel`` [m], ``f`` [N]
    (= -fc) and those of :class:`PartialContact`.
    Connectors: ``flange_a`` (the body on the -s side), ``flange_b``.
    """

    gap = Parameter(0.0, "m", "s_rel = flange_b.s - flange_a.s at which the surfaces touch")

    def equations(self):
        return [Eq(self.delta, self.gap - self.s_rel), Eq(self.f, -self.fc)]


class EndStop(PartialContact):
    """Elastic end stop: a contact between one flange and a fixed limit.

    ``side = "upper"``: the flange may move up to ``s_limit``;
    ``delta = flange.s - s_limit``, the stop pushes it along -s
    (``flange.f = +fc``). ``side = "lower"``: ``delta = s_limit - flange.s``,
    pushes along +s (``flange.f = -fc``)::

        side="lower"  |///|<-- o -->|///|  side="upper"
                   s_limit   flange   s_limit        --> +s

    Parameters: ``s_limit`` [m] position of the stop surface, ``side``
    (structural: "upper" or "lower"), and those of :class:`PartialContact`.
    States: those of :class:`PartialContact`. Connectors: ``flange``.
    """

    flange = Flange("the moving body's flange")
    s_limit = Parameter(0.0, "m", "position of the stop surface")
    side = Parameter("upper", "1", "which side of the flange the stop is on",
                     structural=True, choices=("upper", "lower"))

    def equations(self):
        if self.side == "upper":
            return [Eq(self.delta, self.flange.s - self.s_limit), Eq(self.flange.f, self.fc)]
        return [Eq(self.delta, self.s_limit - self.flange.s), Eq(self.flange.f, -self.fc)]


class Clearance(Model):
    """Backlash: free relative travel ``|s_rel - s_rel0| <= gap`` between two
    flanges, an impact contact (:class:`Contact`, same law) at each end::

        flange_a o---[ lower |<-- gap -->  *  <-- gap -->| upper ]---o flange_b
                                         s_rel0

    ``lower`` closes when ``s_rel = flange_b.s - flange_a.s`` falls below
    ``s_rel0 - gap`` (pushes B along +s), ``upper`` when it rises above
    ``s_rel0 + gap`` (pushes B along -s). Sub-components ``lower`` and
    ``upper`` carry the per-impact measures (``clearance.upper.n_impacts``).

    Parameters: ``gap`` [m] free travel on each side (>= 0), ``s_rel0`` [m]
    centre, ``K``, ``gamma``, ``e``, ``beta``, ``v_min``, ``delta_tol``
    (shared by both sides: ``params={"slot.K": ...}``) and the structural
    ``law``, ``peak_event``.
    Connectors: ``flange_a``, ``flange_b``.
    """

    diagnosis_site = "clearance"   # what acausal.diagnose may extend here

    SHARED = ("K", "gamma", "e", "beta", "v_min", "delta_tol")

    def __init__(self, gap=1e-3, s_rel0=0.0, K=1e9, gamma=1.5, e=1.0, beta=0.0, v_min=1e-4,
                 delta_tol=1e-12, law="lankarani_nikravesh", peak_event=True):
        super().__init__()
        self.parameter("gap", gap, "m", "free travel on each side", min=0.0)
        self.parameter("s_rel0", s_rel0, "m", "centre of the free travel")
        given = dict(K=K, gamma=gamma, e=e, beta=beta, v_min=v_min, delta_tol=delta_tol)
        for name in self.SHARED:
            d = getattr(PartialContact, name)
            self.parameter(name, given[name], d.unit, d.desc, min=d.min, max=d.max,
                           min_open=d.min_open, max_open=d.max_open)
        self.lower = Contact(law=law, peak_event=peak_event)
        self.upper = Contact(law=law, peak_event=peak_event)
        # both sides use this model's parameters (names are relative to this
        # model here; flattening gives them their full paths)
        shared = {name: self.symbol(name) for name in self.SHARED}
        gap, s_rel0 = self.symbol("gap"), self.symbol("s_rel0")
        # lower: s_rel < s_rel0 - gap  ->  Contact(a, b) with its gap = s_rel0 - gap
        self.lower.set(gap=s_rel0 - gap, **shared)
        # upper: s_rel > s_rel0 + gap  ->  Contact(b, a), whose s_rel is -s_rel
        self.upper.set(gap=-(s_rel0 + gap), **shared)
        self.connect(self.lower.flange_a, self.upper.flange_b)
        self.connect(self.lower.flange_b, self.upper.flange_a)
        self.flange_a = self.lower.flange_a
        self.flange_b = self.lower.flange_b


# -- measures -------------------------------------------------------------------
Impact = namedtuple("Impact", "t_onset t_release period v_impact v_release restitution f_peak")


def impacts(res, path):
    """Every impact of the contact at ``path`` in a result, in order, as
    :class:`Impact` tuples. ``period = t_release - t_onset`` (onset to the
    last separation of that impact; NaN if still in contact at the end),
    ``restitution = -v_release / v_impact``, ``f_peak`` (0 if the force had
    no interior maximum, e.g. ``peak_event=False``: see :func:`peak_force`)."""
    n = res[f"{path}.n_impacts"]
    cols = {k: res[f"{path}.{k}"] for k in ("t_onset", "t_release", "v_impact", "v_release",
                                           "f_peak", "mode")}
    out = []
    for k in range(1, int(round(n.max())) + 1 if len(n) else 1):
        j = int(np.flatnonzero(n == k)[-1])   # the last row of impact k
        t_on, t_rel = float(cols["t_onset"][j]), float(cols["t_release"][j])
        v_i, v_r = float(cols["v_impact"][j]), float(cols["v_release"][j])
        if t_rel < t_on or cols["mode"][j] == 1:   # not separated yet
            t_rel = v_r = math.nan
        rest = -v_r / v_i if v_i != 0 else math.nan
        out.append(Impact(t_on, t_rel, t_rel - t_on, v_i, v_r, rest,
                          float(cols["f_peak"][j])))
    return out


def _pick(res, path, k, field):
    imp = impacts(res, path)
    if not imp:
        raise MeasureError(f"contact {path!r} had no impact", component=path)
    return getattr(imp[k], field)


def contact_period(res, path, k=0):
    """Duration [s] of impact ``k`` (0 = first, -1 = last) of the contact at
    ``path``, from onset to separation (exact to IDA's root tolerance)."""
    return _pick(res, path, k, "period")


def impact_velocity(res, path, k=0):
    """Approach velocity delta_dot [m/s] at the onset of impact ``k``."""
    return _pick(res, path, k, "v_impact")


def restitution(res, path, k=0):
    """Restitution reached by impact ``k``: -v_release / v_impact."""
    return _pick(res, path, k, "restitution")


def peak_force(res, path, k=0):
    """Peak force [N] of impact ``k``: the event-located value when
    ``peak_event`` is on (exact to the root tolerance); otherwise the largest
    ``fc`` among the output points of that impact (accuracy depends on
    ``output_step``: the force is under-estimated by at most about
    (pi * step / period)^2 / 8, the worst case for a half-sine pulse; for the
    Hertz impact of the tests 7e-7 at step = period / 320, 6.5e-3 at
    period / 11)."""
    imp = impacts(res, path)[k]
    if imp.f_peak > 0:
        return imp.f_peak
    t = res.t
    end = imp.t_release if imp.t_release == imp.t_release else t[-1]
    sel = (t >= imp.t_onset) & (t <= end)
    return float(np.max(res[f"{path}.fc"][sel])) if sel.any() else 0.0


def n_impacts(res, path):
    """Number of impacts of the contact at ``path``."""
    return int(round(res[f"{path}.n_impacts"][-1]))
