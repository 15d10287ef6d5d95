"""Early warning of a dead centre: a kinematic loop nearing a configuration
where its joints cannot follow the joint that drives it.

A planar loop closes when the joint rates ``q_i'`` make the twists ``c_i``
sum to zero, ``sum_i q_i' c_i = 0``, with ``c = (1, y, -x)`` for a revolute
at (x, y) and ``c = (0, u_x, u_y)`` for a prismatic along the unit axis u
(world). In a loop of N joints, N - 3 of them drive it (their coordinates
are states of the run: the index reduction chose them) and the other three
follow: their rates are the solution of a 3x3 system whose determinant is
the *minor* of those three columns (Cramer's rule). Where it vanishes the
followers' rates are infinite -- a dead centre: the loop locks, or switches
assembly mode, and the solver fails there (:class:`.loops.LoopSingularityError`).

Taking the first revolute of the three as origin, the minor is the 2x2
determinant of the other two columns' ``(Δy, -Δx)`` (a revolute, Δ its offset
from the origin joint) or ``u`` (a prismatic). Normalised (:func:`minor_sine`)
it is a sine in [-1, 1]: of the bend at the middle one of three revolutes,
or of the angle between a link turned by 90 deg and a slider's axis; three
revolutes in line, or a link at right angles to the axis in the
slider-crank's dead centre, give 0. The first joint of each loop declares one observer root per choice
of three followers, ``sine^2 - DEAD_CENTRE_SIN^2`` falling through 0, armed
only when the other joints of the loop are the ones that drive it (each
joint's ``drives`` discrete, decided at the start from the compiled model's
states). It warns (:class:`DeadCentreWarning`, one line naming the loop,
its joints and the followers) and the run goes on; IDA does not stop for it.
"""
import functools
import itertools
import math
import warnings

import sympy as sp
from sympy import Eq, Piecewise

from acausal.lang import Event

from .geometry import column, minor_sine  # noqa: F401  (public here too)

DEAD_CENTRE_SIN = 0.05   # warn within about 2.9 deg of a dead centre


class DeadCentreWarning(UserWarning):
    """A kinematic loop came within :data:`DEAD_CENTRE_SIN` (about 2.9 deg)
    of a dead centre for the joints that drive it."""


def _root(comp):
    while comp._parent is not None:
        comp = comp._parent
    return comp


def drives(cm, joint_path, coordinate):
    """Whether the joint's coordinate is a state of the compiled model ``cm``
    (or a function of states only): the index reduction chose it to drive."""
    e = cm.resolve(sp.Symbol(f"{joint_path}.{coordinate}"))
    ys = set(cm.dae.y)
    return (e.free_symbols & ys) <= set(cm.dae.y[:cm.dae.n_states])


def monitor_events(joint):
    """The observer roots of every loop whose first joint is ``joint``."""
    from .loops import kinematic_loops
    root = _root(joint)
    evs = []
    for loop in kinematic_loops(root):
        if not loop.joints or loop.joints[0] != joint.path or len(loop.joints) < 4:
            continue
        comps = {p: root.find(p) for p in loop.joints}
        for k, trio in enumerate(itertools.combinations(loop.joints, 3)):
            drivers = [p for p in loop.joints if p not in trio]
            g = _dead_centre_root(tuple(column(comps[p]) for p in trio),
                                  tuple(comps[p].drives for p in drivers))
            if g is None:
                continue
            evs.append(Event(f"{joint.path}.dead_centre{k}", g, -1,
                             _warner(loop, trio, drivers), observer=True))
    return evs


@functools.lru_cache(maxsize=1024)
def _dead_centre_root(cols, drives):
    """The root of three joints' columns ``cols`` armed by the ``drives``
    flags of the others, or None (no revolute among them). Remembered by its
    arguments, which are the same expressions in every model built from one
    mechanism: building the sine (square roots compared in a Piecewise) was
    a third of each planar breaker diagnosis candidate's build."""
    sine = minor_sine(list(cols))
    if sine is None:
        return None
    armed = sp.And(*[Eq(d, 1) for d in drives])
    return Piecewise((sine**2 - DEAD_CENTRE_SIN**2, armed), (1, True))


def _warner(loop, trio, drivers):
    def warn(s):
        warnings.warn(DeadCentreWarning(
            f"kinematic {loop.name} (joints: {', '.join(loop.joints)}) is within "
            f"{math.degrees(math.asin(DEAD_CENTRE_SIN)):.1f} deg of a dead centre at "
            f"t = {s.t:.9g} s: "
            f"{', '.join(trio)} are nearly in line for the driving joint "
            f"{', '.join(drivers)}; the solver fails at the dead centre if the motion "
            f"goes on"), stacklevel=2)
    return warn


def arm_event(joint):
    """At the start, set the joint's ``drives`` discrete (1: its coordinate
    is a state of the run, 0: it follows)."""
    path, coord, flag = joint.path, joint.coordinate, joint.drives

    def decide(s):
        s[flag] = 1 if drives(s.cm, path, coord) else 0

    return Event(f"{path}.decide_drives", Piecewise((1, Eq(flag, -1)), (-1, True)), +1,
                 decide, recheck=True, log=False)
