"""Kinematic loops of a planar model and the message when one cannot close.

The frames joined by ``connect`` form nodes; every fixed frame is the world
node; every rigid link or joint (a part whose class says ``loop_role = "link"`` or
``"joint"``, as :class:`~.partials.PartialRigidLink` does) is
an edge between the nodes of its two frames (line forces constrain nothing).
A spanning tree of that graph leaves one independent (fundamental) loop per
edge outside the tree (Wittenburg's graph-theoretic treatment of multibody
systems): loop k is that edge plus the tree path between its ends.
"""
from dataclasses import dataclass

from acausal.lang.component import Model
from acausal.lang.connectors import Frame
from acausal.errors import AcausalError, InitializationError, SolverError



class LoopClosureError(InitializationError):
    """A kinematic loop cannot be assembled at the start (a link too short or
    too long for the others): the message names the loop and its joints."""


class LoopSingularityError(SolverError):
    """The solver failed in a kinematic loop: most likely a singular
    configuration (dead centre: links aligned, where the loop locks or
    switches assembly mode). The message names the loop and its joints."""


@dataclass(frozen=True)
class Loop:
    """One independent kinematic loop: its links and joints (paths, in
    order around the loop) and the frame nodes it passes through."""

    links: tuple
    joints: tuple
    nodes: frozenset

    @property
    def name(self):
        return "loop " + " - ".join(self.links)


def _nodes(model):
    """Frame port path -> node id (fixed frames share the node 'world')."""
    parent = {}

    def find(p):
        while parent[p] != p:
            parent[p] = parent[parent[p]]
            p = parent[p]
        return p

    for comp in model.walk():
        for name, ctype in comp.connectors().items():
            if isinstance(ctype, Frame):
                path = comp.port(name).path
                parent.setdefault(path, path)
                if getattr(comp, "loop_role", None) == "ground":
                    parent.setdefault("world", "world")
                    parent[find(path)] = find("world")
    for m in model.walk():
        if isinstance(m, Model):
            for group in m._connections:
                frames = [p.path for p in group if isinstance(p.ctype, Frame)]
                for p in frames[1:]:
                    parent[find(p)] = find(frames[0])
    return {p: find(p) for p in parent}


def kinematic_loops(model):
    """The independent kinematic loops of ``model`` (a list of :class:`Loop`)."""
    node = _nodes(model)
    edges = [(c.path, node[c.frame_a.path], node[c.frame_b.path], c)
             for c in model.walk() if getattr(c, "loop_role", None) in ("link", "joint")]
    adj, tree, loops = {}, {}, []
    for path, a, b, c in edges:
        if a == b:
            loops.append(((path,), {a}))
            continue
        ra, rb = _root(tree, a), _root(tree, b)
        if ra != rb:
            tree[ra] = rb
            adj.setdefault(a, []).append((b, path))
            adj.setdefault(b, []).append((a, path))
        else:
            chain, nodes = _path(adj, a, b)
            loops.append(((path,) + chain, nodes))
    kinds = {p: c for p, _, _, c in edges}
    return [Loop(links, tuple(p for p in links if kinds[p].loop_role == "joint"),
                 frozenset(nodes)) for links, nodes in loops]


def _root(tree, x):
    while x in tree:
        x = tree[x]
    return x


def _path(adj, a, b):
    """Edge paths and nodes of the tree path from a to b (depth first)."""
    stack, seen = [(a, (), (a,))], {a}
    while stack:
        n, chain, nodes = stack.pop()
        if n == b:
            return chain, set(nodes)
        for m, e in adj.get(n, []):
            if m not in seen:
                seen.add(m)
                stack.append((m, chain + (e,), nodes + (m,)))
    return (), {a, b}


def loop_of(model, paths):
    """The first loop that contains a component among ``paths`` (a link or
    joint of the loop, or a component attached at one of its frame nodes)."""
    loops = kinematic_loops(model)
    if not loops:
        return None
    node = _nodes(model)
    for path in paths:
        for loop in loops:
            if path in loop.links:
                return loop
        comp_nodes = {n for p, n in node.items() if p.startswith(path + ".")}
        for loop in loops:
            if comp_nodes & loop.nodes - {"world"}:
                return loop
    return None


def closure_error(model, paths, detail=""):
    """A :class:`LoopClosureError` naming the loop through ``paths`` (the
    components whose equations could not be met), or None."""
    loop = loop_of(model, paths)
    if loop is None:
        return None
    joints = ", ".join(loop.joints) or "none"
    return LoopClosureError(
        f"kinematic {loop.name} cannot close at the start (joints: {joints}): the links "
        f"cannot reach each other with these lengths and start angles{detail}")


NOT_DEAD_SIN = 0.2   # the followers' sine above this (about 11.5 deg): no dead centre


def singularity_error(model, paths, message, t, result):
    """The error when the solver failed in a component of a kinematic loop
    (``paths``), or None when no loop holds one. A
    :class:`LoopSingularityError` (a dead centre) unless the loop's
    following joints are known to be far from one at the failure
    (:func:`follower_sine` of at least :data:`NOT_DEAD_SIN`): then a
    :class:`~acausal.errors.SolverError` that names the loop and says the
    failure is numerical. Measured: a crank-rocker whose hook spins at 24
    rad/s stopped at atol 1e-12 with its followers' sine at -0.94 (the
    transmission angle's sine 0.79), where the coupler's acceleration
    passes through zero among terms of 600 rad/s^2, and had been reported
    as "most likely a dead centre"."""
    loop = loop_of(model, paths)
    if loop is None:
        return None
    joints = ", ".join(loop.joints) or "none"
    sine = follower_sine(model, loop, result)
    where = dict(t=t, component=paths[0] if paths else None, result=result)
    if sine is not None and abs(sine) >= NOT_DEAD_SIN:
        return SolverError(
            f"the solver failed in kinematic {loop.name} (joints: {joints}) at t = {t:.9g} s, "
            f"which is not near a dead centre there (its following joints bend with sine "
            f"{sine:.2g}): a numerical failure, e.g. an absolute tolerance below the rounding "
            f"of a variable that passes through zero among large terms; {message}", **where)
    seen = "" if sine is None else f" (its following joints bend with sine {sine:.2g})"
    return LoopSingularityError(
        f"kinematic {loop.name} (joints: {joints}) reached a singular configuration at "
        f"t = {t:.9g} s{seen}, most likely a dead centre (links aligned: the loop locks or "
        f"switches assembly mode there); {message}", **where)


def follower_sine(model, loop, result):
    """The normalised minor (:func:`.deadcentre.minor_sine`: 0 at a dead
    centre) of the loop's three following joints (``drives`` = 0) at the
    last point of ``result``; None when it cannot be told (no result, not
    three followers, a value missing)."""
    from .geometry import column, minor_sine
    if result is None or len(loop.joints) < 4 or not len(result.t):
        return None
    try:
        comps = [model.find(p) for p in loop.joints]
        followers = [c for c in comps if float(result[str(c.drives)][-1]) == 0.0]
        if len(followers) != 3:
            return None
        sine = minor_sine([column(c) for c in followers])
        if sine is None:
            return None
        value = sine.subs({sym: float(result[sym.name][-1]) for sym in sine.free_symbols})
        return float(value)
    except (AcausalError, AttributeError, KeyError, TypeError, ValueError):
        return None
