"""Random lossless mechanical networks for the property tests: a topology
(clusters and springs) drawn by hypothesis, the acausal model built from it
(in any declaration order), and, independently, its equations of motion
written here by hand.

A network is a list of *clusters*, each moving with one generalised
coordinate ``q`` (small-angle levers, so everything is linear):

* ``mass``: a mass ``m``; ``q`` is its position; one point, ``s = q``.
* ``lever``: a massless two-arm lever (arms ``a``, ``b``) with a mass on
  each arm; ``q`` is the lever angle; points ``s = a q`` and ``s = b q``;
  inertia ``m1 a^2 + m2 b^2``.
* ``gear``: an inertia ``J1`` geared (``phi1 = ratio * phi2``) to an inertia
  ``J2``, a torsion spring ``ct`` from ``J2`` to the frame, and a lever arm
  ``arm`` on ``J1`` giving one massless point ``s = arm q``; ``q`` is
  ``phi1``; inertia ``J1 + J2 / ratio^2``; potential ``ct (q / ratio)^2 / 2``.

Springs (free length 0, no preload) join two points, or a point and the
frame. Hand-assembled: ``M q'' = -K q`` with ``M`` diagonal and
``K = sum c g g^T``, ``g`` the gradient of the spring's length in ``q``.
"""
from dataclasses import dataclass

import numpy as np
from hypothesis import strategies as st

from acausal import Model, guess
from acausal.mechanics.levers import IdealGear, IdealLever, TwoArmLever
from acausal.mechanics.rotational import Fixed as RotFixed
from acausal.mechanics.rotational import Inertia, TorsionSpring
from acausal.mechanics.translational import Fixed, Mass, Spring

KINDS = ("mass", "lever", "gear")
N_POINTS = {"mass": 1, "lever": 2, "gear": 1}
GROUND = -1


@dataclass(frozen=True)
class Topology:
    kinds: tuple          # kind of each cluster
    springs: tuple        # (point index or GROUND, point index)

    def points(self):
        """(cluster, slot) of every point, in index order."""
        return [(k, j) for k, kind in enumerate(self.kinds) for j in range(N_POINTS[kind])]


@st.composite
def topologies(draw, max_clusters=2, max_springs=3):
    kinds = tuple(draw(st.lists(st.sampled_from(KINDS), min_size=1, max_size=max_clusters)))
    n = sum(N_POINTS[k] for k in kinds)
    ends = st.tuples(st.integers(GROUND, n - 1), st.integers(0, n - 1)).filter(
        lambda e: e[0] != e[1])
    springs = draw(st.lists(ends, min_size=1, max_size=max_springs))
    # a connector must be connected: a mass or a gear's arm point that no
    # drawn spring reaches gets a spring to the frame (a lever's points hold
    # its masses)
    used = {i for e in springs for i in e}
    own = [kind for kind in kinds for _ in range(N_POINTS[kind])]
    springs += [(GROUND, i) for i in range(n) if i not in used and own[i] != "lever"]
    return Topology(kinds, tuple(springs))


@st.composite
def values(draw, topo):
    """Parameter values and start values (q0, qd0) of every cluster."""
    pos = st.floats(0.5, 2.0)
    out = {"clusters": [], "c": [draw(st.floats(20.0, 500.0)) for _ in topo.springs]}
    for kind in topo.kinds:
        v = dict(q0=draw(st.floats(-1.0, 1.0)), qd0=draw(st.floats(-1.0, 1.0)))
        if kind == "mass":
            v.update(m=draw(pos))
        elif kind == "lever":
            v.update(m1=draw(pos), m2=draw(pos), a=draw(st.floats(0.2, 1.0)),
                     b=draw(st.floats(-1.0, -0.2) | st.floats(0.2, 1.0)))
        else:
            v.update(J1=draw(st.floats(0.05, 0.5)), J2=draw(st.floats(0.05, 0.5)),
                     ratio=draw(st.floats(0.5, 3.0)), ct=draw(st.floats(5.0, 50.0)),
                     arm=draw(st.floats(0.2, 1.0)))
        out["clusters"].append(v)
    if all(abs(v["q0"]) < 0.05 and abs(v["qd0"]) < 0.05 for v in out["clusters"]):
        out["clusters"][0]["q0"] = 0.5          # something moves
    return out


# -- the acausal model -------------------------------------------------------------
def _cluster_parts(k, kind):
    """(name, component) of cluster ``k`` with placeholder values (the real
    ones are run-time parameters and start values, see :func:`overrides`)."""
    p = f"k{k}_"
    if kind == "mass":
        return [(p + "m", Mass(m=1.0, s=0.0, v=0.0))]
    if kind == "lever":
        return [(p + "lever", TwoArmLever(a=0.5, b=0.5)),
                (p + "ma", Mass(m=1.0, s=0.0, v=0.0)),
                (p + "mb", Mass(m=1.0, s=guess(0.0), v=guess(0.0)))]
    return [(p + "J1", Inertia(J=0.1, phi=0.0, w=0.0)), (p + "gear", IdealGear(ratio=2.0)),
            (p + "J2", Inertia(J=0.1, phi=guess(0.0), w=guess(0.0))),
            (p + "ts", TorsionSpring(c=10.0)), (p + "arm", IdealLever(arm=0.5))]


def _cluster_links(m, k, kind):
    """Connections inside cluster ``k`` and its point flanges."""
    p = f"k{k}_"
    g = getattr
    if kind == "mass":
        return [], [g(m, p + "m").flange]
    if kind == "lever":
        lever = g(m, p + "lever")
        return ([(lever.flange_a, g(m, p + "ma").flange),
                 (lever.flange_b, g(m, p + "mb").flange)],
                [lever.flange_a, lever.flange_b])
    return ([(g(m, p + "J1").flange, g(m, p + "gear").flange_a, g(m, p + "arm").flange_r),
             (g(m, p + "gear").flange_b, g(m, p + "J2").flange, g(m, p + "ts").flange_b),
             (m.rot_ground.flange, g(m, p + "ts").flange_a)],
            [g(m, p + "arm").flange_t])


def build(topo, order=None):
    """The acausal model of ``topo``. ``order`` (a permutation of the
    component list, and of the connections) sets the declaration order."""
    parts = [(n, c) for k, kind in enumerate(topo.kinds) for n, c in _cluster_parts(k, kind)]
    parts += [(f"sp{j}", Spring(c=1.0)) for j in range(len(topo.springs))]
    if any(a == GROUND for a, _ in topo.springs):
        parts += [("ground", Fixed())]
    if "gear" in topo.kinds:
        parts += [("rot_ground", RotFixed())]
    rng = np.random.default_rng(order) if order is not None else None
    if rng is not None:
        parts = [parts[i] for i in rng.permutation(len(parts))]
    m = Model()
    for name, comp in parts:
        m.add(name, comp)
    links, points = [], []
    for k, kind in enumerate(topo.kinds):
        inner, pts = _cluster_links(m, k, kind)
        links += inner
        points += pts
    for j, (a, b) in enumerate(topo.springs):
        sp = getattr(m, f"sp{j}")
        links.append((m.ground.flange if a == GROUND else points[a], sp.flange_a))
        links.append((sp.flange_b, points[b]))
    if rng is not None:
        links = [tuple(links[i][::-1]) if rng.random() < 0.5 else links[i]
                 for i in rng.permutation(len(links))]
    for ports in links:
        m.connect(*ports)
    return m


def overrides(topo, vals):
    """The run-time parameters and fixed start values of a drawn network."""
    out = {f"sp{j}.c": c for j, c in enumerate(vals["c"])}
    for k, (kind, v) in enumerate(zip(topo.kinds, vals["clusters"])):
        p = f"k{k}_"
        if kind == "mass":
            out.update({p + "m.m": v["m"], p + "m.s": v["q0"], p + "m.v": v["qd0"]})
        elif kind == "lever":
            out.update({p + "lever.a": v["a"], p + "lever.b": v["b"], p + "ma.m": v["m1"],
                        p + "mb.m": v["m2"], p + "ma.s": v["a"] * v["q0"],
                        p + "ma.v": v["a"] * v["qd0"]})
        else:
            out.update({p + "J1.J": v["J1"], p + "J2.J": v["J2"], p + "gear.ratio": v["ratio"],
                        p + "ts.c": v["ct"], p + "arm.arm": v["arm"],
                        p + "J1.phi": v["q0"], p + "J1.w": v["qd0"]})
    return out


# -- energy, from a result's variables --------------------------------------------
def energy(topo, vals, res):
    """Kinetic plus potential energy [J] at every output time."""
    e = np.zeros(len(res.t))
    for k, (kind, v) in enumerate(zip(topo.kinds, vals["clusters"])):
        p = f"k{k}_"
        if kind == "mass":
            e += 0.5 * v["m"] * res[p + "m.v"] ** 2
        elif kind == "lever":
            e += 0.5 * v["m1"] * res[p + "ma.v"] ** 2 + 0.5 * v["m2"] * res[p + "mb.v"] ** 2
        else:
            e += 0.5 * v["J1"] * res[p + "J1.w"] ** 2 + 0.5 * v["J2"] * res[p + "J2.w"] ** 2
            e += 0.5 * v["ct"] * res[p + "ts.phi_rel"] ** 2
    for j, c in enumerate(vals["c"]):
        e += 0.5 * c * res[f"sp{j}.s_rel"] ** 2
    return e


# -- the hand-assembled equations of motion ----------------------------------------
def point_gains(topo, vals):
    """d(point position)/dq_k of every point: (cluster k, gain)."""
    out = []
    for k, (kind, v) in enumerate(zip(topo.kinds, vals["clusters"])):
        if kind == "mass":
            out.append((k, 1.0))
        elif kind == "lever":
            out += [(k, v["a"]), (k, v["b"])]
        else:
            out.append((k, v["arm"]))
    return out


def mass_stiffness(topo, vals):
    """(M, K) of ``M q'' = -K q``."""
    n = len(topo.kinds)
    M, K = np.zeros((n, n)), np.zeros((n, n))
    for k, (kind, v) in enumerate(zip(topo.kinds, vals["clusters"])):
        if kind == "mass":
            M[k, k] = v["m"]
        elif kind == "lever":
            M[k, k] = v["m1"] * v["a"] ** 2 + v["m2"] * v["b"] ** 2
        else:
            M[k, k] = v["J1"] + v["J2"] / v["ratio"] ** 2
            K[k, k] += v["ct"] / v["ratio"] ** 2
    gains = point_gains(topo, vals)
    for (a, b), c in zip(topo.springs, vals["c"]):
        g = np.zeros(n)
        kb, gb = gains[b]
        g[kb] += gb
        if a != GROUND:
            ka, ga = gains[a]
            g[ka] -= ga
        K += c * np.outer(g, g)
    return M, K


def hand_solution(topo, vals, t):
    """q(t) at the times ``t`` (rows), from scipy's DOP853 at rtol 1e-12."""
    from scipy.integrate import solve_ivp
    M, K = mass_stiffness(topo, vals)
    A = np.linalg.solve(M, K)
    n = len(topo.kinds)
    x0 = [v["q0"] for v in vals["clusters"]] + [v["qd0"] for v in vals["clusters"]]
    sol = solve_ivp(lambda _, x: np.concatenate([x[n:], -A @ x[:n]]), (t[0], t[-1]), x0,
                    method="DOP853", rtol=1e-12, atol=1e-14, dense_output=True)
    return sol.sol(t)[:n].T


def point_names(topo):
    """The result variable holding each point's position."""
    out = []
    for k, kind in enumerate(topo.kinds):
        p = f"k{k}_"
        out += {"mass": [p + "m.s"], "lever": [p + "ma.s", p + "mb.s"],
                "gear": [p + "arm.flange_t.s"]}[kind]
    return out
