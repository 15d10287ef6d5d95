"""The library of physical causes diagnosis can name.

Each :class:`Hypothesis` is a model extension: at a location of the model
graph (:class:`~acausal.diagnose.library.graph.ModelGraph`) it inserts a component
whose magnitude is a new model-level parameter (in a sub-model named
``hyp_<short>``, e.g. ``hyp_cf.F``). Every magnitude starts at 0, where the
extended model is the nominal one (to the solver's tolerance: measured
<= 1e-9 relative at rtol 1e-10), so a fit starts from the calibrated
simulation. The exception is ``flexible_link``: at T = 0 it keeps a stiff
link of period T0 (see :meth:`FlexibleLink.defaults`), which follows the
nominal model to 1e-4 .. 1.2e-3 on the breaker, 7e-3 on the Hertz impact
(measured); compare its fits with the extension at T = 0. Bounds and scales
come from typical magnitudes of the nominal run (:meth:`ModelGraph.typical`).

Fixed (not fitted) parameters with defaults taken from the nominal run
(:meth:`Hypothesis.defaults`: ``hyp_cf.v_eps``, ``hyp_fl.T0``) are set by
:func:`build_extended` and :func:`write_extended_model`; :meth:`Hypothesis.apply`
alone uses the class's ``fixed`` fallbacks unless ``values`` gives them.

========================  ==============  =============================================
id                        site            law (sign)
========================  ==============  =============================================
coulomb_friction          joint           f = -F tanh(v/v_eps) against the frame:
                                          kinetic Coulomb friction opposing the
                                          velocity (regularised, no stiction)
quadratic_damping         body            f = -c v|v| against the frame (opposes v)
constant_load             body            f = F along +s (+phi), either sign
hardening_spring          spring          f = k3 (s_rel - L_free)^3 in parallel (tension
                                          positive; k3 > 0 hardens, < 0 softens)
clearance                 contact         extra free travel g >= 0 before the surfaces
                                          touch
flexible_link             body:component  the component moves to a new node (fraction r
                                          of the body's mass) joined to the body by a
                                          spring-damper of local period sqrt(T0^2 + T^2)
                                          (T0 small and fixed: T = 0 is nearly rigid)
position_dependent_force  source          f = k (s - s_start) added on the source's
                                          flange, either sign
contact_damping_law       contact         e(v_i) = e - a v_i (clipped to [0.01, 1]),
                                          a >= 0: restitution falls with impact speed
========================  ==============  =============================================

Families (``FAMILIES``: cause class -> members, the head first; the other
members are fitted where the head is competitive, :mod:`.families`):
friction (``coulomb_viscous_friction``: + b v; ``stribeck_friction``:
(F + dF exp(-(v/v_s)^2)) tanh(v/v_eps); ``stick_slip_friction``: F sign(v)
sliding and held at rest within peak*F, by the friction mode machine's
events, so a body that stops against its spring stays there;
``viscous_damping``: b v), drag (``power_drag``: c v
(v^2 + v_eps^2)^((n-1)/2) / v_ref^(n-2)), spring_nonlinearity
(``bilinear_spring``: k2 (u - clip(u, -d, d)); ``dead_band_spring``: the
spring's force c (u - clip(u, -b, b))), contact_damping
(``restitution_power_law``: e (v_i/v_ref)^(-p); ``contact_law_<law>``: the
contact's damping follows the Hunt-Crossley, Lankarani-Nikravesh or Flores
law with restitution e + de).

Model files: :meth:`Hypothesis.code` gives the statements that apply a
hypothesis to ``model`` (a call of :meth:`Hypothesis.apply` with the values
written out), :func:`write_extended_model` a complete model file that
imports the original, and :func:`build_extended` the compiled extended
model (cached per file version, hypothesis and location).
"""
import copy
import os
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ...lang import Model
from ...lang.symbols import FastMax, FastMin
from ...runtime.model import compile_model
from ...errors import ModelError
from ...modelfile import load_model_file
from .domain import domain_of
from .elements import make_power_restitution, make_velocity_restitution
from .graph import ModelGraph, has_role
from .nominal import nominal_result
from ..problem import second_prefix


@dataclass
class ParamSpec:
    """A parameter a hypothesis adds and a fit may vary. ``name`` is its
    model-level path (``hyp_cf.F``); ``initial`` the value at which the
    extended model equals the nominal one; ``low``/``high`` fit bounds;
    ``scale`` a typical magnitude (for scaling the fit)."""

    name: str
    initial: float
    low: float
    high: float
    unit: str
    desc: str
    scale: float


class Hypothesis:
    """One physical cause: where it can act, what it adds, how to fit it.

    Subclasses set ``id``, ``title``, ``explanation``, ``law``,
    ``site_kinds``, ``prefix`` (the sub-model name, ``hyp_<short>``) and
    ``distinguishing_experiment``, and implement :meth:`candidates`,
    :meth:`params` and :meth:`_extend`.
    """

    id = ""
    title = ""
    explanation = ""
    law = ""
    site_kinds = ()
    prefix = "hyp"
    distinguishing_experiment = ""
    fixed = {}          # name -> default of parameters added but not fitted
    odd = True          # the law is odd in the site's motion (friction, drag): the same
    #                     cause at a site moving the other way has the same sign
    #                     (acausal.diagnose.stages.kinematics.convert); False: a constant load
    relative_cost = 1.0  # a simulation's cost against the nominal model's (task ordering)
    refines = None      # the head whose law this member equals outside a regime the data
    #                     must show (stick_slip_friction: Coulomb friction, except that it
    #                     holds a stopped body): within the parsimony margin the head is
    #                     named (acausal.diagnose.stages.families.prefer_simplest)

    # -- interface ------------------------------------------------------------------
    def candidates(self, graph):
        """Locations (paths) in ``graph`` where this cause can act."""
        raise NotImplementedError

    def params(self, graph, location):
        """The :class:`ParamSpec` list to fit at ``location``."""
        raise NotImplementedError

    def defaults(self, graph, location):
        """Defaults of the fixed (not fitted) parameters that depend on the
        nominal run (``graph`` with a result): name -> value."""
        return {}

    def apply(self, model, location, values=None):
        """Extend ``model`` in place at ``location``: add the sub-model
        ``prefix`` with the parameters and components, connect them. ``values``
        (parameter path -> value) override the initial values (and the
        defaults of the fixed parameters). Returns the specs (their
        ``initial`` is the neutral value, not ``values``)."""
        graph = ModelGraph(model)
        if location not in self.candidates(graph):
            raise ModelError(f"hypothesis {self.id}: {location!r} is not one of its "
                             f"locations in this model: "
                             + (", ".join(self.candidates(graph)) or "none"))
        specs = self.params(graph, location)
        vals = {s.name: s.initial for s in specs}
        vals.update({f"{self.prefix}.{k}": v for k, v in self.fixed.items()})
        for k, v in (values or {}).items():
            if k not in vals:
                raise ModelError(f"hypothesis {self.id}: no parameter {k!r}; it has "
                                 + ", ".join(vals))
            vals[k] = float(v)
        if self.prefix in model.children():
            raise ModelError(f"hypothesis {self.id}: the model already has a member "
                             f"{self.prefix!r} (applied twice?)")
        hyp = Model()
        model.add(self.prefix, hyp)
        self._extend(model, graph, hyp, location, vals)
        return specs

    def renamed(self, prefix):
        """This hypothesis with its sub-model named ``prefix`` (a pair that
        applies one hypothesis at two sites: ``hyp_cf`` and ``hyp_cf2``)."""
        out = copy.copy(self)
        out.prefix = prefix
        return out

    def code(self, location, values):
        """Python statements that apply this hypothesis with ``values`` to a
        variable ``model`` in a model file."""
        vals = ", ".join(f"{k!r}: {float(v)!r}" for k, v in sorted((values or {}).items()))
        default = HYPOTHESES[self.id].prefix if self.id in HYPOTHESES else type(self).prefix
        which = (f"_HYPOTHESES[{self.id!r}]" if self.prefix == default else
                 f"_HYPOTHESES[{self.id!r}].renamed({self.prefix!r})")
        return (f"# hypothesis {self.id} at {location}: {self.title}\n"
                f"#   {self.law}\n"
                "from acausal.diagnose.library.hypotheses import HYPOTHESES as _HYPOTHESES\n"
                f"hypothesis_specs = {which}.apply(model, {location!r}, "
                f"{{{vals}}})\n")

    # -- helpers for subclasses -----------------------------------------------------------
    def _extend(self, model, graph, hyp, location, vals):
        raise NotImplementedError

    def _par(self, hyp, vals, name, unit, desc, **bounds):
        return hyp.parameter(name, vals[f"{self.prefix}.{name}"], unit, desc, **bounds)

    def _spec(self, name, low, high, unit, desc, initial=0.0, scale=None):
        return ParamSpec(f"{self.prefix}.{name}", float(initial), float(low), float(high), unit,
                         desc, float(scale if scale is not None else 0.1 * max(abs(low),
                                                                             abs(high))))

    def __repr__(self):
        return f"<Hypothesis {self.id}>"


def _orig(graph, comp, name, hyp, vals, prefix, unit, desc):
    """A parameter's value as an absolute expression; a plain number is kept
    as the new parameter ``<prefix>.<name>0`` so that it stays settable when
    ``comp.<name>`` becomes bound."""
    v = comp.value(name)
    if isinstance(v, sp.Basic) and not v.is_number:
        return graph.absolute(v, comp)
    key = f"{prefix}.{name}0"
    return hyp.parameter(f"{name}0", vals.get(key, float(v)), unit,
                         f"{desc} (was {comp.path}.{name})")


# -- the hypotheses --------------------------------------------------------------------------
class CoulombFriction(Hypothesis):
    id = "coulomb_friction"
    title = "Coulomb (dry) friction at a joint"
    prefix = "hyp_cf"
    site_kinds = ("joint",)
    fixed = {"v_eps": 1e-3}
    law = ("f = -F*tanh(v/v_eps) on the body against the frame: kinetic Coulomb friction "
           "of level F opposing the velocity, regularised over |v| < v_eps (v_eps = 1e-3 "
           "x the body's peak nominal speed; no stiction)")
    explanation = ("A constant-magnitude friction force (torque) at the guide (bearing) of "
                   "the body opposes its motion whatever the speed: it removes energy in "
                   "proportion to the travel and delays slow motions more than fast ones.")
    distinguishing_experiment = ("Vary the drive speed (impact velocity): Coulomb friction "
                                 "costs the same force at every speed, viscous friction "
                                 "grows with speed and quadratic drag with its square; a "
                                 "slow quasi-static push measures the break-away level "
                                 "directly; a constant load keeps its direction when the "
                                 "motion is reversed, friction does not.")

    def candidates(self, graph):
        return [s.path for s in graph.joints]

    def params(self, graph, location):
        t = graph.typical(location)
        d = domain_of(graph.components[location])
        return [self._spec(d.force_name, 0.0, 0.5 * t["force"], d.force_unit,
                           f"Coulomb friction level at the {d.guide} of {location}")]

    def defaults(self, graph, location):
        return {"v_eps": 1e-3 * graph.typical(location)["speed"]}

    def _extend(self, model, graph, hyp, location, vals):
        # the law reads the body's own velocity (a state with its start value),
        # not der(flange position): the initialisation then starts the steep
        # tanh at the right speed
        body = model.find(location)
        d = domain_of(body)
        F = self._par(hyp, vals, d.force_name, d.force_unit,
                      f"Coulomb friction level at {location}", min=0.0)
        eps = self._par(hyp, vals, "v_eps", d.rate_unit, "speed below which the friction "
                        "is regularised", min=0.0, min_open=True)
        hyp.friction = d.source(-F * sp.tanh(getattr(body, d.rate) / eps))
        model.connect(hyp.friction.flange, body.flange)


class QuadraticDamping(Hypothesis):
    id = "quadratic_damping"
    title = "Quadratic (fluid) drag on a body"
    prefix = "hyp_qd"
    site_kinds = ("body",)
    law = "f = -c*v*|v| on the body against the frame (opposes the velocity)"
    explanation = ("A drag growing with the square of the speed (air or oil displaced by "
                   "the part, turbulent flow in a dashpot) brakes the fast phases and "
                   "leaves the slow ones almost untouched.")
    distinguishing_experiment = ("Run at two or more drive speeds: the lost force scales with "
                                 "v^2 (quadratic drag), with v (viscous friction) or not at "
                                 "all (Coulomb friction); the deceleration of a coasting "
                                 "body follows 1/(1 + k t) rather than a straight line or "
                                 "an exponential.")

    def candidates(self, graph):
        return [s.path for s in graph.joints]

    def params(self, graph, location):
        t = graph.typical(location)
        unit = domain_of(graph.components[location]).unit("{F}*s^2/{L}^2")
        return [self._spec("c", 0.0, 0.5 * t["force"] / t["speed"] ** 2, unit,
                           f"quadratic drag coefficient on {location}")]

    def _extend(self, model, graph, hyp, location, vals):
        body = model.find(location)
        d = domain_of(body)
        c = self._par(hyp, vals, "c", d.unit("{F}*s^2/{L}^2"), f"quadratic drag on {location}",
                      min=0.0)
        v = getattr(body, d.rate)
        hyp.drag = d.source(-c * v * sp.Abs(v))
        model.connect(hyp.drag.flange, body.flange)


class ConstantLoad(Hypothesis):
    id = "constant_load"
    title = "An unmodelled constant load (preload) on a body"
    prefix = "hyp_cl"
    site_kinds = ("body",)
    odd = False         # keeps its direction: at a site moving the other way it changes sign
    law = "f = F on the body along +s (+phi) against the frame, either sign"
    explanation = ("A constant force or torque the model leaves out (weight, a spring "
                   "preload that is off, a magnet, a pressure) shifts the balance of "
                   "forces by the same amount everywhere along the travel.")
    distinguishing_experiment = ("Reverse the motion or stop it: a constant load keeps its "
                                 "direction (it accelerates the body one way when released "
                                 "at rest), friction always opposes the velocity and "
                                 "vanishes at rest below break-away; a static force "
                                 "measurement at several positions separates it from a "
                                 "spring (position-dependent) force.")

    def candidates(self, graph):
        return [s.path for s in graph.joints]

    def params(self, graph, location):
        t = graph.typical(location)
        d = domain_of(graph.components[location])
        return [self._spec(d.force_name, -0.5 * t["force"], 0.5 * t["force"], d.force_unit,
                           f"constant load on {location} along {d.axis}")]

    def _extend(self, model, graph, hyp, location, vals):
        body = model.find(location)
        d = domain_of(body)
        F = self._par(hyp, vals, d.force_name, d.force_unit,
                      f"constant load on {location} along {d.axis}")
        hyp.load = d.source(F)
        model.connect(hyp.load.flange, body.flange)


class HardeningSpring(Hypothesis):
    id = "hardening_spring"
    title = "A nonlinear (hardening or softening) spring"
    prefix = "hyp_hs"
    site_kinds = ("spring",)
    law = ("f = k3*(s_rel - L_free)^3 in parallel with the spring, L_free = s_rel0 - f0/c "
           "its free length (tension positive: k3 > 0 hardens both ways, k3 < 0 softens)")
    explanation = ("The spring's force grows faster (or slower) than linearly with its "
                   "deflection (coil contact, progressive pitch, a rubber stop in series): "
                   "the error grows with the deflection and the oscillation frequency "
                   "depends on the amplitude.")
    distinguishing_experiment = ("Measure the spring's force at three or more deflections "
                                 "(a static force-deflection curve), or run with two "
                                 "different preloads or amplitudes: only a nonlinear spring "
                                 "changes the period with the amplitude.")

    def candidates(self, graph):
        return [s.path for s in graph.springs]

    def params(self, graph, location):
        s = graph.site("spring", location)
        _, dev = graph.spring_deflection(s.component)
        c = graph.param(s.component, "c")
        hi = (c if c > 0 else 1.0) / dev ** 2
        unit = domain_of(s.component).unit("{F}/{L}^3")
        return [self._spec("k3", -hi / 4, hi, unit, f"cubic stiffness in parallel with "
                           f"{location} (cubic force = linear force at the typical deflection "
                           f"when k3 = high)")]

    def _extend(self, model, graph, hyp, location, vals):
        spring = model.find(location)
        d = domain_of(spring)
        _, u = _spring_offset(graph, spring, d)
        k3 = self._par(hyp, vals, "k3", d.unit("{F}/{L}^3"), f"cubic stiffness at {location}")
        _parallel_force(model, hyp, "cubic", spring, d, lambda x: k3 * u(x) ** 3)


class ExtraClearance(Hypothesis):
    """The hypothesis of an extra clearance (gap) before a contact (not the
    component :class:`acausal.mechanics.contact.Clearance`, one of the
    contacts it acts on)."""

    id = "clearance"
    title = "A clearance (gap) before a contact"
    prefix = "hyp_gap"
    site_kinds = ("contact",)
    law = ("the surfaces touch after an extra free travel g >= 0: Contact gap -> gap - g, "
           "EndStop s_limit -> s_limit +- g, Clearance gap -> gap + g")
    explanation = ("The parts travel further than modelled before they meet (wear, "
                   "tolerances, a loose pin): the impact comes later and faster (the drive "
                   "accelerates the free part over the extra travel) and everything after "
                   "it shifts.")
    distinguishing_experiment = ("Record the instant of first contact (a contact switch or "
                                 "the force onset) relative to the start of the motion, or "
                                 "run at two drive forces: a clearance delays the impact by "
                                 "the time to cover g, which depends on the speed, while "
                                 "a change of the contact law leaves the onset in place.")

    def _contacts(self, graph):
        out = []
        for s in graph.contacts:
            c = s.component
            parent = c._parent
            if has_role(parent, "clearance"):
                if parent.path not in out:
                    out.append(parent.path)
            elif "gap" in c.declarations() or "s_limit" in c.declarations():
                out.append(s.path)
        return out

    def candidates(self, graph):
        return self._contacts(graph)

    def params(self, graph, location):
        comp = graph.model.find(location)
        paths = [s.path for s in graph.contacts
                 if s.path == location or s.path.startswith(location + ".")]
        hi = 0.0
        for p in paths:
            d = graph._series(f"{p}.delta")
            if d is not None:
                hi = max(hi, 2 * float(d.max()))
        d = domain_of(graph.components[paths[0]])
        if hi <= 0:
            hi = 0.01 if d.rotational else 1e-4
        return [self._spec("g", 0.0, hi, d.length_unit,
                           f"extra clearance before {comp.path} closes")]

    def _extend(self, model, graph, hyp, location, vals):
        comp = model.find(location)
        unit = domain_of(graph.components[[s.path for s in graph.contacts
                                           if s.path == location
                                           or s.path.startswith(location + ".")][0]]
                         ).length_unit
        g = self._par(hyp, vals, "g", unit, f"extra clearance before {location} closes",
                      min=0.0)
        if has_role(comp, "clearance"):
            gap = _orig(graph, comp, "gap", hyp, vals, self.prefix, unit, "free travel")
            comp.set(gap=gap + g)
        elif "gap" in comp.declarations():
            gap = _orig(graph, comp, "gap", hyp, vals, self.prefix, unit, "contact gap")
            comp.set(gap=gap - g)
        else:
            lim = _orig(graph, comp, "s_limit", hyp, vals, self.prefix, unit, "stop position")
            comp.set(s_limit=lim + g if comp.side == "upper" else lim - g)


class FlexibleLink(Hypothesis):
    id = "flexible_link"
    title = "A flexible link inside a body"
    prefix = "hyp_fl"
    site_kinds = ("body",)
    fixed = {"T0": 1e-5, "r": 0.1, "zeta": 0.1}
    # a new node and a stiff link (a degree of freedom, short time scales): its
    # runs took 1.5-3x the nominal model's on the breaker (benchmarks/diagnose_speed.py)
    relative_cost = 2.0
    law = ("the component is moved to a new node of mass r*m joined to the body (left "
           "with (1-r)*m) by a spring-damper with local period T_link = sqrt(T0^2 + T^2): "
           "k = 4 pi^2 m_red / T_link^2, d = 2 zeta_eff sqrt(k m_red), m_red = r (1-r) m, "
           "zeta_eff = zeta + (1 - zeta) T0^2 / T_link^2 (critical while stiff)")
    explanation = ("The part is not rigid between the point where the component acts and "
                   "the rest of the body (a bending arm, a twisting shaft, a long rod): "
                   "the load arrives late and softened, the impact lasts longer and a "
                   "local oscillation at the link's period may appear.")
    distinguishing_experiment = ("Measure the motion at both ends of the part (two "
                                 "encoders or accelerometers) or look for a ringing at the "
                                 "link's period after the impact; a clearance gives a "
                                 "delay without ringing and a softer contact law changes "
                                 "only the impact.")

    def candidates(self, graph):
        out = []
        for j in graph.joints:
            body = j.component
            if not has_role(body, "body"):
                continue        # a planar joint: no mass of its own to split
            seen = []
            for o in graph.at_node(body.flange):
                if o is body:
                    continue
                unit = o._parent if has_role(o._parent, "clearance") else o
                if unit in seen:
                    continue
                seen.append(unit)
                if has_role(o, "sensor", "ground", "driver", "source"):
                    continue
                if has_role(o, "contact"):
                    out.append(f"{j.path}:{unit.path}")
                elif not has_role(o, "compliant") and len(graph.ports(o)) >= 2 \
                        and graph.reaches_body(o, body):
                    out.append(f"{j.path}:{unit.path}")
        return out

    def defaults(self, graph, location):
        """T0 = T_load / 5, T_load = (range of the moved component's load) /
        (its largest rate) in the nominal run: the stiff link follows the
        load within about (T0 / T_load)^2."""
        bpath, upath = location.split(":")
        body = graph.components[bpath]
        moved = [p for p in graph.nodes[graph.node(body.flange)]
                 if p.owner.path == upath or p.owner.path.startswith(upath + ".")]
        dur = graph._duration()
        series = [graph._series(p.through.name) for p in moved]
        t = graph.result.t if graph.result is not None else None
        T_load = dur
        if t is not None and all(f is not None for f in series) and series:
            f = sum(series)
            dt = np.diff(t)
            ok = dt > 0
            rate = np.max(np.abs(np.diff(f)[ok] / dt[ok])) if ok.any() else 0.0
            if rate > 0 and np.ptp(f) > 0:
                T_load = min(dur, float(np.ptp(f) / rate))
        return {"T0": T_load / 5}

    def params(self, graph, location):
        t = graph.typical(location.split(":")[0])
        hi = t["time"] / 10
        return [self._spec("T", 0.0, hi, "s", f"local period of the link {location} "
                           "(0 = rigid up to T0)")]

    def _extend(self, model, graph, hyp, location, vals):
        bpath, upath = location.split(":")
        body = model.find(bpath)
        dom = domain_of(body)
        mname = graph.mass_param(body)
        m0 = _orig(graph, body, mname, hyp, vals, self.prefix, dom.mass_unit,
                   "mass of the whole body")
        T = self._par(hyp, vals, "T", "s", f"local period of the link {location}", min=0.0)
        T0 = self._par(hyp, vals, "T0", "s", "local period of the link at T = 0 (stiff)",
                       min=0.0, min_open=True)
        r = self._par(hyp, vals, "r", "1", "fraction of the body's mass at the moved node",
                      min=0.0, max=1.0, min_open=True, max_open=True)
        zeta = self._par(hyp, vals, "zeta", "1", "damping ratio of the link", min=0.0)
        m_red = r * (1 - r) * m0
        k = 4 * sp.pi ** 2 * m_red / (T0 ** 2 + T ** 2)
        # critically damped while stiff (T << T0: the stiff mode decays and the
        # integrator steps over it), damping ratio zeta once compliant (T >> T0)
        zeta_eff = zeta + (1 - zeta) * T0 ** 2 / (T0 ** 2 + T ** 2)
        d = 2 * zeta_eff * sp.sqrt(k * m_red)
        starts = {}
        for n in (dom.across, dom.rate):
            st = body.start(n)
            starts[n] = type(st)(graph.absolute(st.value, body), st.fixed)
        body.set(**{mname: (1 - r) * m0})
        hyp.node = dom.component("body", **{dom.mass_name: r * m0}, **starts)
        hyp.link = dom.component("spring_damper", c=k, d=d, **{dom.rel0: 0.0})
        model.connect(body.flange, hyp.link.flange_a)
        model.connect(hyp.link.flange_b, hyp.node.flange)
        moved = [p for p in graph.nodes[graph.node(body.flange)]
                 if p.owner.path == upath or p.owner.path.startswith(upath + ".")]
        for p in moved:
            model.disconnect(p)
        model.connect(hyp.node.flange, *moved)


class PositionDependentForce(Hypothesis):
    id = "position_dependent_force"
    title = "An actuator force that varies with the stroke"
    prefix = "hyp_pf"
    site_kinds = ("source",)
    law = ("f = k*(s - s_start) added on the source's flange along +s (+phi), s_start its "
           "position at the start of the run; either sign")
    explanation = ("The actuator's force is not constant over the stroke (a solenoid's "
                   "force grows as its air gap closes, a spring-driven drive loses force as "
                   "it relaxes): the error grows with the distance travelled.")
    distinguishing_experiment = ("Measure the actuator force against position on a test "
                                 "bench (blocked at several strokes), or start the motion "
                                 "from different positions: a stroke-dependent force changes "
                                 "with the start position, a constant load or friction "
                                 "does not.")

    def candidates(self, graph):
        return [s.path for s in graph.sources]

    def params(self, graph, location):
        src = graph.site("source", location).component
        dom = domain_of(src)
        # the source's value: a leaf of PartialSource names it (``quantity``);
        # MSL's force and torque laws (ConstantTorque, SignForce, ...) carry it
        # in the variable named after the domain's through variable (f, tau)
        q = getattr(src, "quantity", (dom.through,))[0]
        f = graph._series(f"{location}.{q}")
        if f is not None:
            F = float(max(abs(f).max(), 0.0))
        else:
            try:
                F = abs(graph.param(src, f"{q}_const"))
            except KeyError:
                F = 0.0
        x = graph._series(src.flange.across.name)
        X = float(x.max() - x.min()) if x is not None else 0.0
        F = F if F > 0 else 1.0
        X = X if X > 0 else dom.small
        unit = dom.unit("{F}/{L}")
        return [self._spec("k", -F / X, F / X, unit, f"change of the force of {location} per "
                           "unit displacement of its flange")]

    def _extend(self, model, graph, hyp, location, vals):
        src = model.find(location)
        dom = domain_of(src)
        k = self._par(hyp, vals, "k", dom.unit("{F}/{L}"),
                      f"force of {location} per unit displacement")
        hyp.force = dom.component("displacement_source", k=k)
        model.connect(hyp.force.flange, src.flange)


class ContactDampingLaw(Hypothesis):
    id = "contact_damping_law"
    title = "Restitution that falls with the impact velocity"
    prefix = "hyp_cd"
    site_kinds = ("contact",)
    law = ("the contact's damping uses e(v_i) = clip(e - a*v_i, 0.01, 1), v_i the impact "
           "velocity, a >= 0")
    explanation = ("The coefficient of restitution is not a constant: faster impacts "
                   "dissipate a larger fraction of their energy (plastic flow, friction in "
                   "the contact), so the rebound and the energy passed on depend on the "
                   "impact speed more than the model says.")
    distinguishing_experiment = ("Repeat the impact at several impact velocities and "
                                 "compare the rebound speeds (restitution per impact): a "
                                 "velocity-dependent restitution shows a trend, a wrong "
                                 "constant restitution or stiffness a constant offset.")

    def candidates(self, graph):
        return [s.path for s in graph.contacts
                if "e" in s.component.declarations() and s.component.law != "beta"]

    def params(self, graph, location):
        c = graph.site("contact", location).component
        e0 = graph.param(c, "e")
        v = graph._series(f"{location}.v_impact")
        V = float(abs(v).max()) if v is not None else 0.0
        V = V if V > 0 else 1.0
        return [self._spec("a", 0.0, e0 / (2 * V), "s/m", f"fall of the restitution of "
                           f"{location} per unit impact velocity")]

    def _extend(self, model, graph, hyp, location, vals):
        a = self._par(hyp, vals, "a", "s/m", f"fall of the restitution of {location} per "
                      "m/s of impact velocity", min=0.0)
        make_velocity_restitution(model.find(location), a)


# -- family members: other standard laws of the same effects ---------------------------------
class CoulombViscousFriction(CoulombFriction):
    id = "coulomb_viscous_friction"
    title = "Coulomb plus viscous friction at a joint"
    prefix = "hyp_cvf"
    law = ("f = -F*tanh(v/v_eps) - b*v on the body against the frame: Coulomb friction "
           "plus a viscous term (lubricated guide)")
    explanation = ("A friction force with a constant part (dry contact) and a part growing "
                   "in proportion to the speed (a lubricating film, seals).")

    def params(self, graph, location):
        t = graph.typical(location)
        d = domain_of(graph.components[location])
        return super().params(graph, location) + [self._spec(
            "b", 0.0, 0.5 * t["force"] / t["speed"], d.unit("{F}*s/{L}"),
            f"viscous friction coefficient at the {d.guide} of {location}")]

    def _extend(self, model, graph, hyp, location, vals):
        super()._extend(model, graph, hyp, location, vals)
        body = model.find(location)
        d = domain_of(body)
        b = self._par(hyp, vals, "b", d.unit("{F}*s/{L}"), f"viscous friction at {location}",
                      min=0.0)
        hyp.viscous = d.source(-b * getattr(body, d.rate))
        model.connect(hyp.viscous.flange, body.flange)


class StribeckFriction(CoulombFriction):
    id = "stribeck_friction"
    title = "Stribeck friction at a joint"
    prefix = "hyp_sf"
    law = ("f = -(F + dF*exp(-(v/v_s)^2))*tanh(v/v_eps): kinetic level F, static excess "
           "dF >= 0 falling off over the Stribeck speed v_s (tau, dtau when rotational)")
    explanation = ("Friction that is higher near rest than in sliding (the Stribeck effect "
                   "of a lubricated contact): slow phases lose more than fast ones.")

    def params(self, graph, location):
        t = graph.typical(location)
        d = domain_of(graph.components[location])
        return super().params(graph, location) + [
            self._spec(f"d{d.force_name}", 0.0, 0.5 * t["force"], d.force_unit,
                       f"static friction excess over the kinetic level at {location}"),
            self._spec("v_s", 1e-3 * t["speed"], t["speed"], d.rate_unit,
                       f"Stribeck speed at {location}", initial=0.1 * t["speed"],
                       scale=0.1 * t["speed"])]

    def _extend(self, model, graph, hyp, location, vals):
        body = model.find(location)
        d = domain_of(body)
        F = self._par(hyp, vals, d.force_name, d.force_unit,
                      f"kinetic friction level at {location}", min=0.0)
        dF = self._par(hyp, vals, f"d{d.force_name}", d.force_unit,
                       f"static excess at {location}", min=0.0)
        vs = self._par(hyp, vals, "v_s", d.rate_unit, "Stribeck speed", min=0.0, min_open=True)
        eps = self._par(hyp, vals, "v_eps", d.rate_unit, "speed below which the friction "
                        "is regularised", min=0.0, min_open=True)
        v = getattr(body, d.rate)
        hyp.friction = d.source(-(F + dF * sp.exp(-(v / vs) ** 2)) * sp.tanh(v / eps))
        model.connect(hyp.friction.flange, body.flange)


class StickSlipFriction(CoulombFriction):
    """Dry friction that sticks and slips by events: the library's friction
    mode machine (:mod:`acausal.mechanics.frictionmodes`, MSL's
    ``PartialFriction``) in :class:`.elements.StickSlipForce` /
    ``StickSlipTorque`` between the site's flange and the frame. The smooth
    members (``tanh(v/v_eps)``) pass through zero speed with a force that
    vanishes there, so they cannot hold a body at rest against a spring;
    this one holds it while the force needed stays within the break-away
    level ``peak*F`` and slides at ``F`` otherwise."""

    id = "stick_slip_friction"
    title = "Dry friction with stiction (stick-slip) at a joint"
    prefix = "hyp_ssf"
    refines = "coulomb_friction"   # the same law while it slides
    fixed = {"peak": 1.0}
    # events at every stop and reversal (each a re-initialisation): on the stick
    # rig (tests/diagnose/stick_rig.py, compiled, loaded host) 22.8 ms a run at
    # F = 0 (14 events) and 14.8 ms at F = 0.9 N (it sticks), nominal 6.6 ms
    relative_cost = 3.0
    law = ("sliding: f = -F*sign(v) on the body against the frame; stuck (v = 0): the body "
           "is held while the force needed stays within peak*F (peak = 1: break-away level "
           "= sliding level F); stick and slip by events, MSL's friction mode machine")
    explanation = ("Dry friction in the guide (bearing) that stops the body and holds it "
                   "where the remaining forces cannot overcome it: the motion ends early, "
                   "away from the spring's rest position, and stays there.")
    distinguishing_experiment = ("Release the body from several positions: a body held by "
                                 "stiction stops within +-F/c of the spring's rest "
                                 "position and stays there, a viscous or smooth "
                                 "kinetic loss lets it creep back to rest; a slow "
                                 "quasi-static push measures the break-away level.")

    def defaults(self, graph, location):
        return {}

    def _extend(self, model, graph, hyp, location, vals):
        body = model.find(location)
        d = domain_of(body)
        F = self._par(hyp, vals, d.force_name, d.force_unit,
                      f"sliding (kinetic) friction level at {location}", min=0.0)
        peak = self._par(hyp, vals, "peak", "1", "break-away level / sliding level",
                         min=1.0)
        hyp.friction = d.component("stick_slip", **{"T" if d.rotational else "F": F},
                                   peak=peak)
        model.connect(hyp.friction.flange, body.flange)


class ViscousDamping(Hypothesis):
    """Plain viscous friction, linear in the rate. In the friction family
    (not drag): it is the loss of a lubricated bearing or guide that MSL's
    friction elements carry as their ``F_prop`` / ``d`` term, it is nested in
    ``coulomb_viscous_friction`` (F = 0), so the family's parsimony
    (:func:`acausal.diagnose.stages.families.prefer_simplest`) names it
    when the Coulomb part of that member is not supported, and a pair of
    it with Coulomb friction at one site is that member (two members of one
    family at one site are never a pair)."""

    id = "viscous_damping"
    title = "Viscous friction (damping) at a joint"
    prefix = "hyp_vd"
    site_kinds = ("joint",)
    law = "f = -b*v on the body against the frame (linear in the rate)"
    explanation = ("A loss in proportion to the speed (a lubricating film, oil in a "
                   "bearing, eddy currents, a leak in a dashpot): an oscillation decays "
                   "exponentially and a driven motion loses force in proportion to its "
                   "speed.")
    distinguishing_experiment = ("Run at two or more drive speeds or amplitudes: the lost "
                                 "force scales with v (viscous), v^2 (quadratic drag) or "
                                 "not at all (Coulomb friction); a free decay's amplitude "
                                 "falls geometrically (viscous) rather than linearly "
                                 "(Coulomb).")

    def candidates(self, graph):
        return [s.path for s in graph.joints]

    def params(self, graph, location):
        t = graph.typical(location)
        d = domain_of(graph.components[location])
        return [self._spec("b", 0.0, 0.5 * t["force"] / t["speed"], d.unit("{F}*s/{L}"),
                           f"viscous friction coefficient at the {d.guide} of {location}")]

    def _extend(self, model, graph, hyp, location, vals):
        body = model.find(location)
        d = domain_of(body)
        b = self._par(hyp, vals, "b", d.unit("{F}*s/{L}"), f"viscous friction at {location}",
                      min=0.0)
        hyp.viscous = d.source(-b * getattr(body, d.rate))
        model.connect(hyp.viscous.flange, body.flange)


class PowerDrag(QuadraticDamping):
    id = "power_drag"
    title = "Drag growing with a power n of the speed"
    prefix = "hyp_pd"
    fixed = {"v_ref": 1.0, "v_eps": 1e-3}
    law = ("f = -c*v*(v^2 + v_eps^2)^((n-1)/2) / v_ref^(n-2) (about -c*v*|v|^(n-1)/v_ref^(n-2); "
           "n = 2 is quadratic drag, n = 1 viscous), v_ref the body's typical speed")
    explanation = ("A drag growing with a power of the speed between linear (laminar, "
                   "viscous) and quadratic or steeper (turbulent, orifice flow).")
    # the laws it becomes at a standard exponent: at n = 1 it is viscous damping
    # (of the friction family), at n = 2 quadratic drag (its own family's head);
    # those exponents are its standard shapes
    same_law = {"n": {1.0: "viscous_damping", 2.0: "quadratic_damping"}}
    standard_shapes = {short: tuple(laws) for short, laws in same_law.items()}

    def params(self, graph, location):
        return super().params(graph, location) + [self._spec(
            "n", 1.0, 3.0, "1", f"exponent of the drag on {location}", initial=2.0, scale=0.5)]

    def defaults(self, graph, location):
        v = graph.typical(location)["speed"]
        return {"v_ref": v, "v_eps": 1e-3 * v}

    def _extend(self, model, graph, hyp, location, vals):
        body = model.find(location)
        d = domain_of(body)
        c = self._par(hyp, vals, "c", d.unit("{F}*s^2/{L}^2"), f"drag on {location}", min=0.0)
        n = self._par(hyp, vals, "n", "1", "drag exponent", min=1.0, max=3.0)
        vr = self._par(hyp, vals, "v_ref", d.rate_unit, "reference speed", min=0.0,
                       min_open=True)
        eps = self._par(hyp, vals, "v_eps", d.rate_unit, "regularisation speed", min=0.0,
                        min_open=True)
        v = getattr(body, d.rate)
        hyp.drag = d.source(-c * v * (v ** 2 + eps ** 2) ** ((n - 1) / 2) / vr ** (n - 2))
        model.connect(hyp.drag.flange, body.flange)


def _spring_offset(graph, spring, d):
    """(c, u(x)): the spring's rate (its value) and its deflection from its
    free length as a function of the relative displacement x (as
    :class:`HardeningSpring`)."""
    decl = spring.declarations()

    def ab(name):
        return graph.absolute(spring.value(name), spring) if name in decl else 0
    c = ab("c")
    rigid = isinstance(c, (int, float)) and c == 0
    free = ab(d.rel0) if rigid else ab(d.rel0) - ab(d.preload) / c
    return c, (lambda x: x - free)


def _parallel_force(model, hyp, name, spring, d, force):
    """``hyp.<name>``: a force (torque) ``force(x)`` of the relative
    displacement x, in parallel with ``spring`` (the spring nonlinearity
    family's members)."""
    setattr(hyp, name, d.component("relative_source", **{d.through: force}))
    source = getattr(hyp, name)
    model.connect(source.flange_a, spring.flange_a)
    model.connect(source.flange_b, spring.flange_b)


def _clip(u, w):
    return FastMax(-w, FastMin(w, u))


class BilinearSpring(HardeningSpring):
    id = "bilinear_spring"
    title = "A piecewise-linear (bilinear) spring"
    prefix = "hyp_bs"
    law = ("f = k2*(u - clip(u, -d, d)) in parallel with the spring, u its deflection from "
           "the free length: an extra stiffness k2 beyond |u| = d (a stop or second coil "
           "engaging; k2 < 0 softens)")
    explanation = ("The spring's rate changes at a deflection (a second spring or a rubber "
                   "stop engages, a coil closes): the force is piecewise linear.")

    def params(self, graph, location):
        s = graph.site("spring", location)
        _, dev = graph.spring_deflection(s.component)
        c = graph.param(s.component, "c")
        c = c if c > 0 else 1.0
        d = domain_of(s.component)
        return [self._spec("k2", -c / 2, 4 * c, d.unit("{F}/{L}"),
                           f"extra stiffness of {location} beyond the knee"),
                self._spec("d", 0.0, 2 * dev, d.length_unit, f"knee deflection of {location}",
                           initial=dev / 2, scale=dev / 2)]

    def _extend(self, model, graph, hyp, location, vals):
        spring = model.find(location)
        d = domain_of(spring)
        _, u = _spring_offset(graph, spring, d)
        k2 = self._par(hyp, vals, "k2", d.unit("{F}/{L}"), f"extra stiffness at {location}")
        w = self._par(hyp, vals, "d", d.length_unit, f"knee of {location}", min=0.0)
        _parallel_force(model, hyp, "knee", spring, d, lambda x: k2 * (u(x) - _clip(u(x), w)))


class DeadBandSpring(HardeningSpring):
    id = "dead_band_spring"
    title = "A dead band (play) in a spring's attachment"
    prefix = "hyp_db"
    law = ("the spring's force is c*(u - clip(u, -b, b)): no force while its deflection u "
           "from the free length lies within +-b (f = -c*clip(u, -b, b) added in parallel)")
    explanation = ("The spring is attached with play (a loose pin, a slot): it carries no "
                   "force over a band of travel around its free length, so small "
                   "oscillations are slower and the motion crosses the band freely.")

    def params(self, graph, location):
        s = graph.site("spring", location)
        _, dev = graph.spring_deflection(s.component)
        d = domain_of(s.component)
        return [self._spec("b", 0.0, dev, d.length_unit, f"half-width of the dead band of "
                           f"{location}", scale=dev / 10)]

    def _extend(self, model, graph, hyp, location, vals):
        spring = model.find(location)
        d = domain_of(spring)
        _, u = _spring_offset(graph, spring, d)
        # the spring's own rate (its symbol, not its value: a calibrated or
        # fitted spring.c moves the band's force with the spring's)
        c = spring.c
        b = self._par(hyp, vals, "b", d.length_unit, f"dead band of {location}", min=0.0)
        _parallel_force(model, hyp, "band", spring, d, lambda x: -c * _clip(u(x), b))


class RestitutionPowerLaw(ContactDampingLaw):
    id = "restitution_power_law"
    title = "Restitution falling as a power of the impact velocity"
    prefix = "hyp_rp"
    fixed = {"v_ref": 1.0}
    law = ("the contact's damping uses e(v_i) = clip(e*(v_i/v_ref)^(-p), 0.01, 1), v_i the "
           "impact velocity, v_ref the nominal run's largest, p >= 0")
    explanation = ("The restitution falls with the impact speed as a power law (as measured "
                   "for many metal impacts, e ~ v^(-1/4) in the plastic range).")

    def params(self, graph, location):
        return [self._spec("p", 0.0, 1.0, "1", f"exponent of the restitution of {location} "
                           "against the impact velocity", scale=0.1)]

    def defaults(self, graph, location):
        v = graph._series(f"{location}.v_impact")
        return {"v_ref": float(abs(v).max()) if v is not None and abs(v).max() > 0 else 1.0}

    def _extend(self, model, graph, hyp, location, vals):
        p = self._par(hyp, vals, "p", "1", f"restitution exponent of {location}", min=0.0)
        vr = self._par(hyp, vals, "v_ref", "m/s", "reference impact speed", min=0.0,
                       min_open=True)
        make_power_restitution(model.find(location), p, vr)


class ContactLaw(Hypothesis):
    """The contact's damping follows another standard law (``law``), with its
    restitution refitted (``de`` added to the model's ``e``)."""

    site_kinds = ("contact",)

    def __init__(self, law):
        short = {"hunt_crossley": "hc", "lankarani_nikravesh": "ln", "flores": "fo"}[law]
        self.target = law
        self.id = f"contact_law_{law}"
        self.prefix = f"hyp_{short}"
        self.title = f"The contact's damping follows the {law.replace('_', '-')} law"
        self.law = (f"F = K*delta^n*(1 + chi(e + de)*delta_dot/v_i) with chi of the {law} law "
                    "in place of the model's, e + de its restitution")
        self.explanation = ("The contact dissipates energy with another dependence on the "
                            "indentation rate than modelled (the standard laws differ in how "
                            "the damping grows with the impact: Hunt-Crossley, "
                            "Lankarani-Nikravesh, Flores).")
        self.distinguishing_experiment = ContactDampingLaw.distinguishing_experiment

    def candidates(self, graph):
        return [s.path for s in graph.contacts if "e" in s.component.declarations()
                and s.component.law not in ("beta", self.target)
                and graph.param(s.component, "e") < 0.999]

    def params(self, graph, location):
        comp = graph.site("contact", location).component
        e0 = graph.param(comp, "e")
        low, high = max(-0.5, 0.05 - e0), 1 - e0
        de0 = min(max(_same_damping(comp.law, self.target, e0) - e0, low), high)
        return [self._spec("de", low, high, "1",
                           f"change of the restitution of {location} under the {self.target} "
                           "law", initial=de0, scale=0.05)]

    def _extend(self, model, graph, hyp, location, vals):
        c = model.find(location)
        e0 = _orig(graph, c, "e", hyp, vals, self.prefix, "1", "restitution")
        de = self._par(hyp, vals, "de", "1", f"change of the restitution of {location}")
        c.set(law=self.target, e=e0 + de)


CONTACT_LAWS = ("hunt_crossley", "lankarani_nikravesh", "flores")


def _same_damping(law, target, e):
    """The restitution under ``target`` whose damping factor chi equals the
    model's (``law`` at ``e``): where the member reproduces the nominal
    contact, its neutral start (the laws' chi fall monotonically with e;
    bisection on [0.01, 1])."""
    from ...mechanics.contact import damping_chi
    want = damping_chi(law, e)
    lo, hi = 0.01, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if damping_chi(target, mid) > want else (lo, mid)
    return 0.5 * (lo + hi)


HYPOTHESES = {h.id: h for h in (CoulombFriction(), QuadraticDamping(), ConstantLoad(),
                                 HardeningSpring(), ExtraClearance(), FlexibleLink(),
                                 PositionDependentForce(), ContactDampingLaw(),
                                 CoulombViscousFriction(), StribeckFriction(),
                                 StickSlipFriction(), ViscousDamping(), PowerDrag(),
                                 BilinearSpring(), DeadBandSpring(), RestitutionPowerLaw())
              + tuple(ContactLaw(law) for law in CONTACT_LAWS)}

# Families: where an effect has several standard laws, the first member (the
# family's head) is fitted at every site and the others only where the head
# is competitive (acausal/diagnose/families.py); the data choose the member.
FAMILIES = {
    "friction": ("coulomb_friction", "coulomb_viscous_friction", "stribeck_friction",
                 "stick_slip_friction", "viscous_damping"),
    "drag": ("quadratic_damping", "power_drag"),
    "spring_nonlinearity": ("hardening_spring", "bilinear_spring", "dead_band_spring"),
    "contact_damping": ("contact_damping_law", "restitution_power_law")
    + tuple(f"contact_law_{law}" for law in CONTACT_LAWS),
}


# -- model files -------------------------------------------------------------------------------
def _hypothesis(hyp_id):
    h = HYPOTHESES.get(hyp_id)
    if h is None:
        raise ModelError(f"no hypothesis {hyp_id!r}; hypotheses: {', '.join(HYPOTHESES)}")
    return h


def file_defaults(mf, hyp_id, location, graph=None, h=None):
    """Values of a hypothesis's fixed parameters taken from the model file's
    nominal run (coulomb_friction: v_eps, flexible_link: T0); the same for
    :func:`build_extended` and :func:`write_extended_model`. ``graph``: the
    file's graph with its nominal run (built when not given; ``mf.model``
    must not be extended yet). ``h``: the hypothesis object (default: the
    library's ``hyp_id``)."""
    h = h or _hypothesis(hyp_id)
    if type(h).defaults is Hypothesis.defaults:
        return {}
    if graph is None:
        graph = ModelGraph(mf.model, result=nominal_result(mf.path))
    return {f"{h.prefix}.{k}": float(v) for k, v in h.defaults(graph, location).items()}


_CACHE = {}


def build_extended(path, hyp_id, location, values=None, h=None):
    """(ModelFile, CompiledModel) of the model file at ``path`` extended by
    hypothesis ``hyp_id`` at ``location``. The file is loaded fresh, the
    hypothesis applied, the experiment's stop event added (as
    :func:`acausal.modelfile.compile_file` does) and the model compiled once
    per process for each (file version, hypothesis, location). ``values``
    become the compiled model's parameter defaults (a copy sharing the
    generated code: no recompilation). The specs, with bounds and scales
    from the file's nominal run, are in ``mf.namespace["hypothesis_specs"]``;
    ``mf.namespace["hypothesis"]`` is ``(hyp_id, location)``. ``h``: a
    hypothesis object outside the library (e.g. :mod:`.generic`)."""
    h = h or _hypothesis(hyp_id)
    apath = os.path.abspath(path)
    key = (apath, os.path.getmtime(apath) if os.path.exists(apath) else None, hyp_id, location)
    hit = _CACHE.get(key)
    if hit is None:
        mf = load_model_file(apath)
        graph = ModelGraph(mf.model, result=nominal_result(apath))
        specs = h.params(graph, location)         # scaled by the nominal run
        h.apply(mf.model, location, file_defaults(mf, hyp_id, location, graph, h))
        if mf.experiment.stop is not None:
            mf.model.event(mf.experiment.stop.event(mf.model))
        cm = compile_model(mf.model)
        mf.namespace["hypothesis_specs"] = specs
        mf.namespace["hypothesis"] = (hyp_id, location)
        hit = _CACHE[key] = (mf, cm)
    mf, cm = hit
    if values:
        cm = with_defaults(cm, values)
    return mf, cm


def pair_members(pair):
    """The two hypothesis objects of ``pair`` = ((hyp_id, location), ...):
    the second renamed (:func:`.problem.second_prefix`) when its sub-model
    would clash with the first's (one hypothesis at two sites)."""
    h1, h2 = (_hypothesis(h) for h, _ in pair)
    if h2.prefix == h1.prefix:
        h2 = h2.renamed(second_prefix(h2.prefix))
    return h1, h2


def build_pair(path, pair):
    """(ModelFile, CompiledModel) of the model file extended by two
    hypotheses at once, ``pair`` = ((hyp_id, location), (hyp_id, location));
    the same hypothesis at two sites gets its second sub-model renamed
    (:func:`pair_members`). Cached per process as :func:`build_extended`.
    The fixed parameters' defaults come from the unextended file's nominal
    run."""
    apath = os.path.abspath(path)
    key = (apath, os.path.getmtime(apath) if os.path.exists(apath) else None, tuple(pair))
    hit = _CACHE.get(key)
    if hit is None:
        mf = load_model_file(apath)
        graph = ModelGraph(mf.model, result=nominal_result(apath))
        hyps = pair_members(pair)
        defaults = [file_defaults(mf, h, loc, graph, hyp) for (h, loc), hyp in zip(pair, hyps)]
        for (h, loc), hyp, d in zip(pair, hyps, defaults):
            hyp.apply(mf.model, loc, d)
        if mf.experiment.stop is not None:
            mf.model.event(mf.experiment.stop.event(mf.model))
        hit = _CACHE[key] = (mf, compile_model(mf.model))
    return hit


def with_defaults(cm, values):
    """A compiled model whose free parameters default to ``values`` (checked
    against their bounds); shares the generated code."""
    return cm.with_defaults(values)


def _fmt_value(v):
    return f"{v:.6g}"


def write_extended_model(path, hyp_id, location, values, out_path):
    """Write a model file that loads the model file at ``path`` (by a path
    relative to ``out_path``'s folder where possible), applies hypothesis
    ``hyp_id`` at ``location`` with ``values`` and re-exports its
    ``experiment``, ``measures``, ``free_parameters`` (plus the hypothesis's
    parameters with their fit bounds) and ``plot``. Runnable with
    ``acausal simulate out_path``. Returns ``out_path``."""
    h = _hypothesis(hyp_id)
    apath = os.path.abspath(path)
    out_abs = os.path.abspath(out_path)
    mf = load_model_file(apath)
    graph = ModelGraph(mf.model, result=nominal_result(apath))
    vals = dict(file_defaults(mf, hyp_id, location, graph))
    vals.update({k: float(v) for k, v in (values or {}).items()})
    specs = h.params(graph, location)
    try:
        rel = os.path.relpath(apath, os.path.dirname(out_abs))
    except ValueError:     # another drive
        rel = None
    where = (f"_os.path.join(_os.path.dirname(_os.path.abspath(__file__)), {rel!r})"
             if rel is not None else repr(apath))
    fitted = "\n".join(f"    {s.name} = {_fmt_value(vals.get(s.name, s.initial))} [{s.unit}]"
                       f"  ({s.desc})" for s in specs)
    bounds = ", ".join(f"{s.name!r}: ({s.low!r}, {s.high!r})" for s in specs)
    src = f'''"""{os.path.basename(apath)} extended by the hypothesis {hyp_id!r} at {location!r}.

{h.title}. {h.explanation}

Law: {h.law}.
Values:
{fitted}

Written by acausal.diagnose.write_extended_model; run it with
`acausal simulate {os.path.basename(out_abs)}`.
"""
import os as _os

from acausal.modelfile import load_model_file as _load_model_file

_base = _load_model_file({where})
model = _base.model
experiment = _base.experiment
measures = dict(_base.measures)
free_parameters = dict(_base.free)
free_parameters.update({{{bounds}}})
plot = _base.namespace.get("plot")

{h.code(location, vals)}'''
    os.makedirs(os.path.dirname(out_abs) or ".", exist_ok=True)
    with open(out_abs, "w") as fh:
        fh.write(src)
    return out_abs


def __getattr__(name):
    """``Clearance``: the old name of :class:`ExtraClearance` (deprecated:
    :class:`acausal.mechanics.contact.Clearance` is the component)."""
    if name == "Clearance":
        import warnings
        warnings.warn("acausal.diagnose.library.hypotheses.Clearance is now ExtraClearance",
                      DeprecationWarning, stacklevel=2)
        return ExtraClearance
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
