"""Stage 1: from a model tree to one flat list of equations.

Collects every component's parameters, variables, discrete values, equations,
events and assertions under dotted paths, and expands connections into node
equations (see :mod:`acausal.connectors` for the sign convention).
"""

import sympy as sp

from ..lang.component import Model
from ..lang.connectors import SignalPort
from ..lang.declare import Discrete, Parameter, Start, TimeEvent, Variable
from ..errors import ConnectionError_, ModelError
from ..lang.symbols import base_and_order, time
from .flat import Equation, Flat, ParamInfo, VarInfo  # noqa: F401  (public here too)
from .timeevents import find_time_switches


def _label(comp):
    return comp.path or "(top)"


def flatten(model):
    """Flatten ``model`` (a :class:`Model`) into a :class:`Flat`."""
    if not isinstance(model, Model):
        raise ModelError(f"expected a Model, got {type(model).__name__}")
    flat = Flat()
    comps = list(model.walk())
    for comp in comps:
        _declare(flat, comp)
    known = _known_names(flat)
    for comp in comps:
        _relocate_values(flat, comp, known)
    for comp in comps:
        _equations(flat, comp, known)
    bound = _bindings(flat, comps, known)
    _connections(flat, model, comps, bound)
    flat.time_switches = find_time_switches(flat)
    return flat


def _declare(flat, comp):
    path = comp.path
    flat.owners[path] = type(comp).__name__
    for name, d in comp.declarations().items():
        sym = comp.symbol(name)
        if isinstance(d, Parameter):
            flat.params[sym.name] = ParamInfo(sym, comp.value(name), d, path)
        elif isinstance(d, Variable):
            flat.variables[sym.name] = VarInfo(sym, comp.start(name), d.unit, d.desc, path,
                                               unit_declared=d.unit_declared,
                                               nominal=comp.nominal(name))
        elif isinstance(d, Discrete):
            flat.discretes[sym.name] = VarInfo(sym, Start(d.start, True), d.unit, d.desc, path,
                                               unit_declared=d.unit_declared)
    for name, ctype in comp.connectors().items():
        port = comp.port(name)
        if isinstance(port, SignalPort):
            sym = port.symbol
            flat.variables[sym.name] = VarInfo(sym, Start(0.0, False), ctype.unit, ctype.desc,
                                               path, True, unit_declared=ctype.unit_declared)
            continue
        for decls, syms in zip(ctype.pairs(), port.pairs()):
            for (vname, unit, desc), sym in zip(decls, syms):
                flat.variables[sym.name] = VarInfo(sym, Start(0.0, False), unit, desc, path,
                                                   True)


def relocate(expr, comp, known, start=None):
    """Give symbols their full paths. An expression built inside a model's
    constructor, before the model was attached to its parent, names symbols
    relative to that model (``body.phi`` instead of ``hook.body.phi``): each
    unknown name is looked up under the paths of ``comp``'s ancestors,
    nearest first."""
    if not isinstance(expr, sp.Basic):
        return expr
    subs = {}
    for s in expr.free_symbols:
        if s == time:
            continue
        base, k = base_and_order(s)
        if base.name in known:
            continue
        node = start if start is not None else comp
        while node is not None:
            p = node.path
            cand = f"{p}.{base.name}" if p else base.name
            if cand in known:
                new = sp.Symbol(cand)
                for _ in range(k):
                    new = sp.Symbol(f"der({new.name})")
                subs[s] = new
                break
            node = node._parent
    return expr.xreplace(subs) if subs else expr


def _relocate_values(flat, comp, known):
    """Parameter values and start values were given by whoever built the
    component: its parent model (``Mass(m=ma)`` inside a sub-model), or the
    model itself for its own declarations (``self.parameter(...)``)."""
    pre = f"{comp.path}." if comp.path else ""
    own = comp._extra
    for name in comp.declarations():
        full = pre + name
        start = comp if name in own else (comp._parent or comp)
        info = flat.params.get(full)
        if info is not None and not info.decl.structural:
            info.value = relocate(info.value, comp, known, start)
        vinfo = flat.variables.get(full)
        if vinfo is not None and isinstance(vinfo.start.value, sp.Basic):
            vinfo.start = Start(relocate(vinfo.start.value, comp, known, start),
                                vinfo.start.fixed)


def _equations(flat, comp, known):
    path = comp.path
    for i, eq in enumerate(comp.gather("equations")):
        if isinstance(eq, sp.Equality):
            expr = eq.lhs - eq.rhs
        else:
            expr = sp.sympify(eq)
        if expr == 0 or expr is sp.true:
            continue
        expr = relocate(expr, comp, known)
        for s in expr.free_symbols:
            base, _ = base_and_order(s)
            if s != time and base.name not in known:
                raise ModelError(
                    f"equation {i + 1} of {_label(comp)} ({type(comp).__name__}) uses "
                    f"{s.name!r}, which is not a variable or parameter of the model",
                    component=path, variable=s.name)
        flat.equations.append(Equation(expr, path, f"equation {i + 1} ({type(comp).__name__})"))
    for k, eq in enumerate(comp.gather("initial_equations")):
        _initial_equation(flat, comp, known, k, eq)
    for ev in comp.gather("events"):
        ev.owner = path
        if isinstance(ev, TimeEvent):
            flat.time_events.append(ev)
            continue
        ev.expr = relocate(ev.expr, comp, known)
        flat.events.append(ev)
    for a in comp.gather("assertions"):
        a.owner = path
        a.expr = relocate(a.expr, comp, known)
        flat.assertions.append(a)


def _initial_equation(flat, comp, known, k, eq):
    """An initial equation ``lhs = rhs`` (Modelica's ``initial equation``):
    a variable ``<path>._initial<k>`` = lhs - rhs at every time, with the
    fixed start 0, so the initialisation imposes it at the start only."""
    path = comp.path
    expr = eq.lhs - eq.rhs if isinstance(eq, sp.Equality) else sp.sympify(eq)
    expr = relocate(expr, comp, known)
    sym = sp.Symbol(f"{path}._initial{k}" if path else f"_initial{k}")
    flat.variables[sym.name] = VarInfo(sym, Start(0.0, True), "1",
                                       f"initial equation {k + 1}: {expr} = 0 at the start",
                                       path, unit_declared=False, internal=True)
    known.add(sym.name)
    flat.equations.append(Equation(sym - expr, path,
                                   f"initial equation {k + 1} ({type(comp).__name__})"))


def _bindings(flat, comps, known):
    """Equations of the inputs bound to expressions (``Position(s_ref=...)``);
    returns the paths of those inputs."""
    bound = set()
    for comp in comps:
        for name, expr in comp._bindings.items():
            port = comp.port(name)
            expr = relocate(expr, comp, known, comp._parent or comp)
            for s in expr.free_symbols:
                if s != time and base_and_order(s)[0].name not in known:
                    raise ModelError(f"input {port.path} is bound to {expr}, which uses "
                                     f"{s.name!r}: not a variable or parameter of the model",
                                     component=comp.path, variable=s.name)
            flat.equations.append(Equation(port.symbol - expr, comp.path,
                                           f"binding of input {name}"))
            bound.add(port.path)
    return bound


def _known_names(flat):
    return set(flat.params) | set(flat.variables) | set(flat.discretes)


def _connections(flat, model, comps, bound=frozenset()):
    parent = {}

    def find(p):
        while parent[p] is not p:
            parent[p] = parent[parent[p]]
            p = parent[p]
        return p

    ports = {}
    for comp in comps:
        for name in comp.connectors():
            port = comp.port(name)
            ports[id(port)] = port
            parent[port] = port
    for comp in comps:
        if not isinstance(comp, Model):
            continue
        for group in comp._connections:
            first = group[0]
            for p in group:
                if id(p) not in ports:
                    raise ModelError(
                        f"connect() in {_label(comp)}: {p.path} is not part of this model",
                        component=p.path)
                if type(p.ctype).domain != type(first.ctype).domain:
                    raise ConnectionError_(
                        f"connect() in {_label(comp)}: cannot connect {first.path} "
                        f"({type(first.ctype).__name__}) to {p.path} ({type(p.ctype).__name__})",
                        component=p.path)
                ra, rb = find(first), find(p)
                if ra is not rb:
                    parent[rb] = ra
    sets = {}
    for port in parent:
        sets.setdefault(find(port), []).append(port)
    dangling = []
    for members in sets.values():
        members.sort(key=lambda p: p.path)
        if isinstance(members[0], SignalPort):
            dangling += _signal_node(flat, members, bound)
            continue
        if len(members) == 1:
            # Modelica's rule: an unconnected connector's through variables
            # are zero; the check lists it (flat.unconnected), it is no error
            for _, through in members[0].pairs():
                flat.equations.append(Equation(through, members[0].path,
                                               "unconnected connector (no force)"))
            if not members[0].ctype.optional:
                flat.unconnected.append(members[0].path)
            continue
        where = "connect(" + ", ".join(p.path for p in members) + ")"
        for k, (a0, _) in enumerate(members[0].pairs()):
            for p in members[1:]:
                flat.equations.append(Equation(p.pairs()[k][0] - a0, where,
                                               "connection (across equal)"))
            flat.equations.append(Equation(sp.Add(*[p.pairs()[k][1] for p in members]),
                                           where, "connection (through sum to zero)"))
    if dangling:
        dangling.sort()
        if len(dangling) == 1:
            msg = (f"{dangling[0]}: input not connected (connect it to an output, e.g. a "
                   "signal source's y)")
        else:
            msg = "inputs not connected: " + ", ".join(dangling) + \
                " (connect each to an output, e.g. a signal source's y)"
        raise ConnectionError_(msg, component=dangling[0])


def _signal_node(flat, members, bound):
    """Equations of a node of signal connectors: every input equals the one
    source of the node (its output, or an input bound to an expression).
    Returns the inputs of a node without a source (not connected)."""
    sources = [p for p in members if p.causality == "output" or p.path in bound]
    inputs = [p for p in members if p not in sources]
    if len(sources) > 1:
        a, b = sources[:2]
        if a.path in bound or b.path in bound:
            what = [f"input {p.path} (bound to an expression)" if p.path in bound
                    else f"output {p.path}" for p in (a, b)]
            msg = f"{what[0]} and {what[1]} are connected to each other"
        else:
            msg = f"outputs {a.path} and {b.path} are connected to each other"
        raise ConnectionError_(msg + ": a signal has one source (connect an output to inputs "
                               "only)", component=b.path)
    if not sources:
        return [p.path for p in inputs]
    src = sources[0].symbol
    where = "connect(" + ", ".join(p.path for p in members) + ")"
    for p in inputs:
        flat.equations.append(Equation(p.symbol - src, where, "connection (input = output)"))
    return []
