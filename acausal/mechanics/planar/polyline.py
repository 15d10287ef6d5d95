"""A circle against a polyline profile attached to a body (a cam flank, a
latch face with a nose, a stepped guide).

Design (why events and not a smooth distance)
---------------------------------------------
The profile is one contact: the circle touches it at one point at a time,
the point nearest to its centre. That point lies on one *feature* of the
polyline -- a segment's interior or a vertex -- and each feature has an exact
indentation: ``delta = R - (c - P_k) . n_k`` on segment k (the line through
it), ``delta = R - |c - P_k|`` at vertex k (a circle of radius 0). The
feature is a discrete value, ``feature`` (vertex k = ``2k``, segment k =
``2k + 1``), and the equations use only its formula, so each is exact and
smooth where it holds. The feature changes only at an event, where the
centre crosses the border of the feature's region (the Voronoi cell of the
feature among its neighbours)::

     vertex k (convex: a right turn, seen along the polyline)
                 .   cell of vertex k (between the two normals)
      segment k-1 .  /
      ------------ P_k           free side: to the left of the direction
                     \\  segment k     P_0 -> P_1 -> ... (n_k = rot90(t_k))
                      \\

* convex vertex k: segment k-1 <-> vertex k when ``(c - P_k) . t_{k-1}``
  crosses 0, vertex k <-> segment k when ``(c - P_k) . t_k`` crosses 0;
* straight or concave vertex k (a left turn): segment k-1 <-> segment k
  on the bisector, ``(c - P_k) . (t_{k-1} + t_k)`` through 0 (there the two
  lines are equally far);
* the ends P_0 and P_N are vertices (a rounded edge).

The distance is continuous with a continuous gradient across the border of
a convex vertex, so the force is too (the same contact keeps its mode and
impact velocity). Each border has a small hysteresis ``switch_tol`` (1e-10
m by default): the switch happens that far past the border, where the two
formulas differ by ``switch_tol^2 / (2 d)``, so that a root located a
rounding error early cannot switch back and forth. The action sets the
feature to the nearest one (computed from the centre's position, so the
start, when ``feature = -1``, finds it in one step too).

Limits (documented, not checked while running): only the neighbours of the
current feature are watched, so the profile must not come back within the
circle's reach of itself (a groove narrower than the circle, a U): use two
contacts, one per flank. In a concave corner the circle touches one flank
at a time (the nearer): a ball resting in a V groove needs one contact per
flank. A polyline that turns back on itself (a turn of 180 deg) is refused.
"""
import math

from sympy import Eq, Piecewise, sqrt

from acausal.lang import Discrete, Event, Parameter, Variable
from acausal.errors import ParameterError

from .contact import PartialCircleContact
from .geometry import rotate

__all__ = ["CirclePolylineContact", "Profile"]


class Profile:
    """The numbers of a polyline (structural: fixed at compile time): its
    vertices ``P``, unit tangents ``t`` and normals ``n`` (free side) of
    each segment, lengths ``L`` and which interior vertices are convex."""

    def __init__(self, points, where=""):
        try:
            P = [(float(x), float(y)) for x, y in points]
        except (TypeError, ValueError):
            raise ParameterError(f"{where}: points must be (x, y) pairs [m], got {points!r}",
                                 component=where) from None
        if len(P) < 2 or not all(math.isfinite(v) for p in P for v in p):
            raise ParameterError(f"{where}: points needs at least two finite (x, y) vertices "
                                 f"[m], got {points!r}", component=where)
        self.P, self.t, self.n, self.L = P, [], [], []
        for k in range(len(P) - 1):
            dx, dy = P[k + 1][0] - P[k][0], P[k + 1][1] - P[k][1]
            L = math.hypot(dx, dy)
            if L == 0:
                raise ParameterError(f"{where}: segment {k} has zero length (vertices {k} and "
                                     f"{k + 1} coincide at {P[k]})", component=where)
            self.t.append((dx / L, dy / L))
            self.n.append((-dy / L, dx / L))
            self.L.append(L)
        self.convex = [False] * len(P)
        for k in range(1, len(P) - 1):
            (ax, ay), (bx, by) = self.t[k - 1], self.t[k]
            if math.hypot(ax + bx, ay + by) < 1e-9:
                raise ParameterError(f"{where}: the polyline turns back on itself at vertex "
                                     f"{k} {P[k]}", component=where)
            self.convex[k] = ax * by - ay * bx < 0      # a right turn

    @property
    def n_segments(self):
        return len(self.L)

    def nearest(self, x, y):
        """The feature (vertex k = 2k, segment k = 2k + 1) nearest to the
        point (x, y) of frame_a's axes."""
        best = []
        for k, (px, py) in enumerate(self.P):
            best.append((math.hypot(x - px, y - py), 2 * k))
        for k in range(self.n_segments):
            (px, py), (tx, ty), (nx, ny) = self.P[k], self.t[k], self.n[k]
            u = (x - px) * tx + (y - py) * ty
            if 0.0 <= u <= self.L[k]:
                best.append((abs((x - px) * nx + (y - py) * ny), 2 * k + 1))
        return min(best)[1]


class CirclePolylineContact(PartialCircleContact):
    """A circle of radius ``R`` centred on frame_b against a polyline fixed
    in frame_a (design, pictures and limits: the module docstring). The free
    side is to the left of the direction P_0 -> P_1 -> ... (vertices from
    left to right: the free side is up).

    Parameters: ``points`` (structural) [m] the vertices ``((x0, y0), (x1,
    y1), ...)`` in frame_a's axes, ``switch_tol`` [m] hysteresis of a feature
    switch (> 0), and those of :class:`~.contact.PartialCircleContact`
    (``R``, ``mu``, ``v_reg``, ``K``, ``e``, ``law``...).
    States: ``xl``, ``yl`` [m] the circle centre in frame_a's axes, those of
    PartialCircleContact. Discrete: ``feature`` (nearest feature: vertex k =
    2k, segment k = 2k + 1; -1 until the start has located it).
    Connectors: ``frame_a`` (the profile's body), ``frame_b`` (circle centre).
    """

    points = Parameter(((-0.05, 0.0), (0.05, 0.0)), "m",
                       "vertices (x, y) in frame_a's axes, free side on the left",
                       structural=True)
    switch_tol = Parameter(1e-10, "m", "hysteresis of a feature switch", min=0.0,
                           min_open=True)

    xl = Variable(0.0, "m", "circle centre, x in frame_a's axes")
    yl = Variable(0.0, "m", "circle centre, y in frame_a's axes")
    feature = Discrete(-1, "1", "nearest feature: vertex k = 2k, segment k = 2k + 1")

    def __init__(self, **kw):
        super().__init__(**kw)
        self.profile    # check the points now, naming the component

    @property
    def profile(self):
        """The polyline's :class:`Profile` (from ``points``)."""
        return Profile(self.points, self.path or type(self).__name__)

    def drawing_profile(self, res):
        """The polyline in the world along a result (for :mod:`acausal.animate`)."""
        import numpy as np
        from .contact import in_world
        return in_world(res, f"{self.path}.frame_a", np.array(self.profile.P))

    def _local(self):
        """The centre relative to each vertex, in frame_a's axes."""
        return [(self.xl - px, self.yl - py) for px, py in self.profile.P]

    def geometry(self):
        pr, rel = self.profile, self._local()
        f = self.feature
        nl, dl = [], []          # (local normal, delta) per feature
        for k, (rx, ry) in enumerate(rel):
            dist = sqrt(rx**2 + ry**2)
            nl.append(((rx / dist, ry / dist), Eq(f, 2 * k)))
            dl.append((self.R - dist, Eq(f, 2 * k)))
            if k < pr.n_segments:
                nx, ny = pr.n[k]
                nl.append(((nx, ny), Eq(f, 2 * k + 1)))
                dl.append((self.R - (rx * nx + ry * ny), Eq(f, 2 * k + 1)))
        # feature -1 (before the start located it): no contact
        delta = Piecewise(*dl, (-1, True))
        nxl = Piecewise(*[(n[0], c) for n, c in nl], (0, True))
        nyl = Piecewise(*[(n[1], c) for n, c in nl], (1, True))
        return rotate(self.frame_a.phi, nxl, nyl), delta

    def equations(self):
        a, b = self.frame_a, self.frame_b
        dx, dy = b.x - a.x, b.y - a.y
        return [Eq(self.xl, rotate(-a.phi, dx, dy)[0]), Eq(self.yl, rotate(-a.phi, dx, dy)[1])]

    def _borders(self):
        """(feature, root expression, direction) of every border crossing
        that leaves a feature's cell (past the hysteresis)."""
        pr, rel, tol = self.profile, self._local(), self.switch_tol
        along = [(rx * tx + ry * ty) for (rx, ry), (tx, ty) in zip(rel, pr.t)]     # b_k
        back = [None] + [(rx * tx + ry * ty) for (rx, ry), (tx, ty)                # a_k
                         in zip(rel[1:], pr.t)]
        out = []
        for k in range(pr.n_segments):           # segment k = 2k + 1
            out += [(2 * k + 1, along[k] + tol, -1), (2 * k + 1, back[k + 1] - tol, +1)]
            for j, sign in ((k, -1), (k + 1, +1)):
                if 0 < j < pr.n_segments and not pr.convex[j]:
                    (ax, ay), (bx, by) = pr.t[j - 1], pr.t[j]
                    h = rel[j][0] * (ax + bx) + rel[j][1] * (ay + by)
                    out.append((2 * k + 1, h - sign * tol, sign))
        for k in range(len(pr.P)):               # vertex k = 2k
            if k > 0:
                out.append((2 * k, back[k] + tol, -1))
            if k < pr.n_segments:
                out.append((2 * k, along[k] - tol, +1))
        return out

    def events(self):
        p, f, pr = self.path, self.feature, self.profile
        xl, yl = self.xl, self.yl

        def locate(s):
            s[f] = pr.nearest(s[xl], s[yl])

        evs = [Event(f"{p}.locate", Piecewise((1, Eq(f, -1)), (-1, True)), +1, locate,
                     recheck=True)]
        for i, (feat, g, sign) in enumerate(self._borders()):
            evs.append(Event(f"{p}.switch{i}", Piecewise((g, Eq(f, feat)), (-sign, True)),
                             sign, locate, recheck=True))
        return evs
