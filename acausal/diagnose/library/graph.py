"""The model graph seen by diagnosis: where a physical cause can act.

A :class:`ModelGraph` is built from an *uncompiled* :class:`~acausal.Model`.
It joins the connectors into nodes (as flattening does) and lists the
sites where the hypotheses of :mod:`acausal.diagnose.library.hypotheses` can insert
a component:

* ``body``: a rigid body with one flange (:class:`PartialRigid`,
  :class:`PartialRotRigid`: ``Mass``, ``Inertia``);
* ``joint``: the guide of a sliding body or the bearing of a rotating one,
  i.e. the body against the fixed frame (path = the body's path; bodies whose
  node is fixed or driven by a prescribed motion have none);
* ``spring``: a linear two-flange spring (a compliant element with a
  stiffness parameter ``c``: ``Spring``, ``SpringDamper``, ``TorsionSpring``);
* ``contact``: an impact contact (:class:`PartialContact`: ``Contact``,
  ``EndStop``; the two sides of a ``Clearance``);
* ``source``: a force or torque source acting against the frame
  (:class:`PartialSource` with one flange: ``Force``, ``Torque``).

Each component class of the library declares what it is to the diagnosis
(its ``diagnosis_site`` class attribute: body, compliant, contact,
clearance, source, ground, driver, sensor; :func:`role`), so the graph
needs no list of library classes: a user's component takes part by
declaring the same attribute.

Typical magnitudes (speeds, travels, forces) used to scale hypothesis
parameters come from a nominal simulation result when one is given
(``ModelGraph(model, result=res)`` or :meth:`ModelGraph.from_file`), else
from parameter and start values with fallbacks of 1 (SI units): without a
result the scales are rough.
"""
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ...lang.component import Model
from ...lang.declare import Parameter
from ...errors import ModelError
from ...compiler.flatten import relocate
from .domain import domain_name

KINDS = ("body", "joint", "spring", "contact", "source")
_PLURAL = {"bodies": "body", "joints": "joint", "springs": "spring", "contacts": "contact",
           "sources": "source"}


@dataclass
class Site:
    """A place in the model graph. ``path`` is a component path (a body's
    path for its joint); ``component`` the component object there."""

    kind: str
    path: str
    domain: str          # "translational" | "rotational"
    component: object
    note: str = ""


def role(comp):
    """The diagnosis role a component declares (``diagnosis_site`` class
    attribute of the component library: body, compliant, contact,
    clearance, source, ground, driver, sensor), or None (a link: a lever, a
    four-bar, a user's component)."""
    return getattr(type(comp), "diagnosis_site", None)


def has_role(comp, *roles):
    return role(comp) in roles


def _planar(comp):
    """Whether a component has a planar frame (acausal.mechanics.planar)."""
    return any(type(c).domain == "planar" for c in comp.connectors().values())


def domain_of(comp):
    """'translational' or 'rotational' from the component's connectors
    (the first one for a mixed component such as a lever)."""
    return domain_name(comp)


class ModelGraph:
    """Nodes, components and diagnosis sites of an uncompiled model.

    ``bodies``, ``joints``, ``springs``, ``contacts``, ``sources``: lists of
    :class:`Site`. ``result`` (optional): a nominal simulation result of the
    same model, used only for typical magnitudes (:meth:`typical`).
    """

    def __init__(self, model, result=None):
        if not isinstance(model, Model):
            raise ModelError(f"ModelGraph needs a Model, got {type(model).__name__}")
        self.model = model
        self.result = result
        self._index()
        self._classify()

    @classmethod
    def from_file(cls, path):
        """The graph of a model file with its nominal run attached (the file's
        experiment, default parameters): sensible typical magnitudes."""
        from ...modelfile import load_model_file
        from .nominal import nominal_result
        return cls(load_model_file(path).model, result=nominal_result(path))

    # -- structure --------------------------------------------------------------
    def _index(self):
        comps = list(self.model.walk())
        self.components = {c.path: c for c in comps if not isinstance(c, Model)}
        ports = []
        for c in comps:
            for name in c.connectors():
                ports.append(c.port(name))
        parent = {id(p): id(p) for p in ports}
        self._port = {id(p): p for p in ports}

        def find(i):
            while parent[i] != i:
                parent[i] = parent[parent[i]]
                i = parent[i]
            return i

        for m in comps:
            if isinstance(m, Model):
                for group in m._connections:
                    first = find(id(group[0]))
                    for p in group[1:]:
                        r = find(id(p))
                        if r != first:
                            parent[r] = first
        groups = {}
        for p in ports:
            groups.setdefault(find(id(p)), []).append(p)
        self.nodes = [sorted(g, key=lambda p: p.path) for g in groups.values()]
        self._node_of = {id(p): k for k, g in enumerate(self.nodes) for p in g}
        # every declared name (for making expressions absolute) and parameter values
        self.known = set()
        self._params = {}
        for c in comps:
            for name, d in c.declarations().items():
                sym = c.symbol(name)
                self.known.add(sym.name)
                if isinstance(d, Parameter) and not d.structural:
                    self._params[sym] = (c, c.value(name))
            for name in c.connectors():
                for a, t in c.port(name).pairs():     # a planar frame has three pairs
                    self.known |= {a.name, t.name}
        self._values = None

    def _classify(self):
        self.bodies, self.joints, self.springs, self.contacts, self.sources = [], [], [], [], []
        for path, c in self.components.items():
            dom = domain_of(c)
            if _planar(c):
                self._classify_planar(path, c)
            elif has_role(c, "body"):
                self.bodies.append(Site("body", path, dom, c, self._body_note(c)))
                fixed = [o.path for o in self.at_node(c.flange)
                         if has_role(o, "ground", "driver")]
                if not fixed:
                    self.joints.append(Site("joint", path, dom, c, self._joint_note(c)))
            elif has_role(c, "contact"):
                parent = c._parent
                note = (f"side of the clearance {parent.path}" if has_role(parent, "clearance")
                        else f"{type(c).__name__} between "
                        + ", ".join(self.describe_ports(c)))
                self.contacts.append(Site("contact", path, dom, c, note))
            elif has_role(c, "compliant") and isinstance(c.declarations().get("c"), Parameter):
                self.springs.append(Site("spring", path, dom, c, f"{type(c).__name__} c = "
                                         f"{self._fmt(c, 'c')} between "
                                         + ", ".join(self.describe_ports(c))))
            elif has_role(c, "source") and len(c.connectors()) == 1:
                body = self.body_at(next(iter(self.ports(c))))
                self.sources.append(Site("source", path, dom, c, f"{type(c).__name__} on "
                                         + (body.path if body else "a massless node")))

    def _classify_planar(self, path, c):
        """Planar parts (acausal.mechanics.planar): a Body is a body site
        (its loads act through its joints); a joint is a joint site whose
        effects act across it on its 1-D ``axis`` (the ``diagnosis_flange``:
        friction, drag, a load torque), unless a 1-D body already sits on
        that axis (its bearing site is then the same place); a contact from
        geometry is a contact site."""
        if has_role(c, "body"):
            self.bodies.append(Site("body", path, "planar", c, f"{type(c).__name__} m = "
                                    f"{self._fmt(c, 'm')} kg, I = {self._fmt(c, 'I')} kg*m^2"))
        elif has_role(c, "joint"):
            if self.body_at(c.flange) is None:
                self.joints.append(Site("joint", path, domain_of(c), c,
                                        f"{type(c).__name__} between "
                                        + ", ".join(self.describe_ports(c)[:2])))
        elif has_role(c, "contact"):
            self.contacts.append(Site("contact", path, "planar", c, f"{type(c).__name__} "
                                      "between " + ", ".join(self.describe_ports(c))))

    def _fmt(self, comp, name):
        try:
            return f"{self.number(comp.value(name), comp):.4g}"
        except (TypeError, ValueError):
            return str(comp.value(name))

    def _body_note(self, c):
        name = self.mass_param(c)
        unit = "kg" if domain_of(c) == "translational" else "kg*m^2"
        return f"{type(c).__name__} {name} = {self._fmt(c, name)} {unit}"

    def _joint_note(self, c):
        what = "guide of" if domain_of(c) == "translational" else "bearing of"
        others = [f"{o.path} ({type(o).__name__})" for o in self.at_node(c.flange)
                  if o is not c and self._to_frame(o, c.flange)]
        axes = [o.path for o in self.at_node(c.flange) if _planar(o) and has_role(o, "joint")]
        return (f"{what} {c.path}" + (f"; elements to the frame here: {', '.join(others)}"
                                      if others else "")
                + (f"; the axis of the planar joint {', '.join(axes)}" if axes else ""))

    def _to_frame(self, comp, port):
        """A one-flange element (ground friction, end stop) or a two-flange
        compliant one whose other flange is on a fixed node."""
        if has_role(comp, "body", "sensor", "source"):
            return False
        others = [p for p in self.ports(comp) if self.node(p) != self.node(port)]
        if not others:
            return True
        return has_role(comp, "compliant") and all(
            any(has_role(o, "ground") for o in self.at_node(p)) for p in others)

    # -- queries ------------------------------------------------------------------
    def sites(self, kind):
        """The sites of one kind ('body', 'joint', 'spring', 'contact',
        'source'; plurals accepted)."""
        kind = _PLURAL.get(kind, kind)
        if kind not in KINDS:
            raise ModelError(f"no site kind {kind!r}; kinds: {', '.join(KINDS)}")
        return list(getattr(self, kind + "s" if kind != "body" else "bodies"))

    def site(self, kind, path):
        for s in self.sites(kind):
            if s.path == path:
                return s
        raise ModelError(f"{path!r} is not a {kind} of the model; {kind}s: "
                         + (", ".join(s.path for s in self.sites(kind)) or "none"))

    def ports(self, comp):
        return [comp.port(n) for n in comp.connectors()]

    def node(self, port):
        """Index of the node (connection set) of a connector."""
        return self._node_of[id(port)]

    def at_node(self, port):
        """Components with a connector in ``port``'s node (``port``'s own
        component included), in path order, each once."""
        out = []
        for p in self.nodes[self.node(port)]:
            if p.owner not in out:
                out.append(p.owner)
        return out

    def body_at(self, port):
        """The body in ``port``'s node, or None."""
        for o in self.at_node(port):
            if has_role(o, "body"):
                return o
        return None

    def describe_ports(self, comp):
        """For each connector of ``comp``: the body on its node, else the
        other components there."""
        out = []
        for p in self.ports(comp):
            b = self.body_at(p)
            if b is not None and b is not comp:
                out.append(b.path)
            else:
                others = [o.path for o in self.at_node(p) if o is not comp]
                out.append("/".join(others) or "nothing")
        return out

    def mass_param(self, body):
        """Name of a body's mass or inertia parameter ('m', 'J')."""
        decl = body.declarations()
        for name in ("m", "J"):
            if isinstance(decl.get(name), Parameter):
                return name
        for name, d in decl.items():
            if isinstance(d, Parameter) and d.unit in ("kg", "kg*m^2"):
                return name
        raise ModelError(f"{body.path}: no mass or inertia parameter")

    def reaches_body(self, comp, body):
        """Whether ``comp``, starting from its connectors off ``body``'s
        node, leads through other components to another body or a
        prescribed motion (a link that transmits motion)."""
        start = self.node(body.flange)
        seen_nodes, seen = {start}, {comp, body}
        todo = [self.node(p) for p in self.ports(comp) if self.node(p) != start]
        while todo:
            k = todo.pop()
            if k in seen_nodes:
                continue
            seen_nodes.add(k)
            for p in self.nodes[k]:
                o = p.owner
                if o in seen:
                    continue
                seen.add(o)
                if has_role(o, "body", "driver"):
                    return True
                todo += [self.node(q) for q in self.ports(o)]
        return False

    # -- values --------------------------------------------------------------------
    def absolute(self, expr, comp):
        """``expr`` (given inside ``comp``'s constructor) with every symbol
        named by its full path."""
        if not isinstance(expr, sp.Basic):
            return expr
        return relocate(expr, comp, self.known)

    def values(self):
        """Full path -> float for every non-structural parameter."""
        if self._values is None:
            raw = {sym: self.absolute(v, c) for sym, (c, v) in self._params.items()}
            out = {}
            for _ in range(20):
                changed = False
                for sym, v in raw.items():
                    if sym in out:
                        continue
                    e = sp.sympify(v).xreplace(out) if isinstance(v, sp.Basic) else v
                    try:
                        out[sym] = float(e)
                        changed = True
                    except (TypeError, ValueError):
                        pass
                if not changed:
                    break
            self._values = {s.name: v for s, v in out.items()}
        return self._values

    def number(self, expr, comp=None):
        """The value of a parameter expression (relative to ``comp``)."""
        if not isinstance(expr, sp.Basic):
            return float(expr)
        e = self.absolute(expr, comp) if comp is not None else expr
        vals = {sp.Symbol(k): v for k, v in self.values().items()}
        return float(e.xreplace(vals))

    def param(self, comp, name):
        return self.number(comp.value(name), comp)

    def start(self, comp, name):
        """(value or None, fixed) of a variable's start value."""
        st = comp.start(name)
        try:
            return self.number(st.value, comp), st.fixed
        except (TypeError, ValueError):
            return None, st.fixed

    # -- typical magnitudes -------------------------------------------------------
    def _series(self, name):
        if self.result is None:
            return None
        try:
            return np.asarray(self.result[name], float)
        except KeyError:
            return None

    def typical(self, site_or_path):
        """Typical magnitudes at a body (or joint) site: dict with ``mass``
        (kg or kg*m^2), ``speed`` (max |v|), ``travel`` (range of the
        position), ``force`` (max of the median over time of the largest
        force on the body and of mass*speed^2/(2*travel), the force that
        takes its peak kinetic energy over its travel), ``time`` (duration
        of the run). Units follow the domain (N or N*m, m or rad)."""
        path = site_or_path.path if isinstance(site_or_path, Site) else site_or_path
        body = self.components[path]
        if domain_of(body) not in ("translational", "rotational"):
            raise ModelError(
                f"{path}: a {domain_of(body)} {type(body).__name__} is not a site of a 1-D "
                "hypothesis (its loads act through its joints); joint sites: "
                + (", ".join(s.path for s in self.joints) or "none"))
        rot = domain_of(body) == "rotational"
        xn, vn = ("phi", "w") if rot else ("s", "v")
        m = self.param(body, self.mass_param(body)) if has_role(body, "body") else 0.0
        x = self._series(f"{path}.{xn}")
        v = self._series(f"{path}.{vn}")
        out = dict(mass=m, time=self._duration())
        if v is not None and x is not None:
            speed = float(np.max(np.abs(v)))
            travel = float(np.ptp(x))
        else:
            v0, _ = self.start(body, vn)
            speed = abs(v0) if v0 else 0.0
            travel = 0.0
        out["speed"] = speed if speed > 0 else 1.0
        out["travel"] = travel if travel > 0 else (0.01 if rot else 1e-3)
        forces = []
        for p in self.nodes[self.node(body.flange)]:
            if p.owner is body:
                continue
            f = self._series(p.through.name)
            if f is not None:
                forces.append(np.abs(f))
        f_med = float(np.median(np.max(forces, axis=0))) if forces else 0.0
        f_energy = m * out["speed"] ** 2 / (2 * out["travel"])
        out["force"] = max(f_med, f_energy, self._joint_load(body))
        return out

    def _joint_load(self, comp):
        """A planar joint's typical friction-sized load: the largest reaction
        force it carries times 0.01 m (a revolute: a pin radius) or 0.1 (a
        prismatic: a friction coefficient); 0 for other components."""
        if not has_role(comp, "joint") or not _planar(comp):
            return 0.0
        fx, fy = (self._series(f"{comp.path}.frame_b.{k}") for k in ("fx", "fy"))
        if fx is None or fy is None:
            return 0.0
        reaction = float(np.max(np.hypot(fx, fy)))
        return reaction * (0.01 if domain_of(comp) == "rotational" else 0.1)

    def _duration(self):
        if self.result is not None and len(self.result.t) > 1:
            return float(self.result.t[-1] - self.result.t[0])
        return 1.0

    def spring_deflection(self, spring):
        """(free reference, typical |deflection| from it) of a linear spring."""
        rot = domain_of(spring) == "rotational"
        ref, pre = ("phi_rel0", "tau0") if rot else ("s_rel0", "f0")
        decl = spring.declarations()
        c = self.param(spring, "c")
        x0 = self.param(spring, ref) if ref in decl else 0.0
        f0 = self.param(spring, pre) if pre in decl else 0.0
        free = x0 - f0 / c if c > 0 else x0
        series = self._series(f"{spring.path}.{'phi_rel' if rot else 's_rel'}")
        if series is not None:
            dev = float(np.max(np.abs(series - free)))
        else:
            dev = abs(f0 / c) if c > 0 else 0.0
        return free, dev if dev > 0 else (0.01 if rot else 1e-3)

    def __repr__(self):
        return (f"<ModelGraph {len(self.bodies)} bodies, {len(self.joints)} joints, "
                f"{len(self.springs)} springs, {len(self.contacts)} contacts, "
                f"{len(self.sources)} sources>")

    def summary(self):
        """One line per site."""
        lines = []
        for kind in KINDS:
            for s in self.sites(kind):
                lines.append(f"{kind:8s} {s.path:28s} {s.domain:13s} {s.note}")
        return "\n".join(lines)

