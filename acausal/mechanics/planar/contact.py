"""Contact from geometry: a circle (a roller, a pin, a ball) centred on
frame_b against a profile attached to frame_a -- a straight line
(:class:`CircleLineContact`), a circle, outside or inside it
(:class:`CircleCircleContact`), or a polyline (:class:`CirclePolylineContact`,
module :mod:`.polyline`) -- with the impact laws of
:mod:`acausal.mechanics.contact` (Hertz force, Hunt-Crossley / Lankarani-
Nikravesh / Flores damping, onset and separation events, no adhesion) along
the profile's normal and Coulomb friction along its tangent. Sign convention:
:mod:`acausal.connectors` (:class:`Frame`)::

                      frame_b (circle centre, radius R)
                        ( o )
               n ^       \\_/  contact point c = r_b - R n
                 |  t
     ============+--->========  the profile (here a line) on frame_a:
                 p              unit normal n towards the circle, t = (-n_y, n_x)

* the leaf gives the geometry: the unit normal ``n`` (world axes, from the
  profile towards the circle centre) and the indentation ``delta`` (> 0 in
  contact); :class:`PartialCircleContact` owns the rest;
* the force on the circle is ``F = fc n + ft t`` at c, the profile's body
  gets ``-F`` at c (forces into the component: ``frame_b.f = -F``,
  ``frame_a.f = +F``, with the moments of F about each frame);
* ``ft = -mu fc tanh(v_t / v_reg)``: Coulomb friction against the slip
  velocity ``v_t`` of the circle's point c over the profile's, regularised
  below ``v_reg`` (so a rolling circle creeps by about ``v_reg``).
"""
from sympy import sqrt, tanh

from acausal.lang import Eq, Parameter, Variable, der

from ..contact import PartialContact
from .geometry import rotate
from .partials import PartialTwoFrames

__all__ = ["PartialCircleContact", "CircleLineContact", "CircleCircleContact"]


class PartialCircleContact(PartialContact, PartialTwoFrames):
    """A circle of radius ``R`` centred on frame_b against a profile on
    frame_a: the force and friction equations for the normal and indentation
    that the leaf's ``geometry()`` returns (see the module docstring).

    Parameters: ``R`` [m] circle radius (>= 0), ``mu`` [1] Coulomb friction
    coefficient (>= 0), ``v_reg`` [m/s] regularisation speed of the friction
    (> 0), and those of :class:`~acausal.mechanics.contact.PartialContact`
    (``K``, ``gamma``, ``e``, ``law``...). States: ``v_t`` [m/s] slip
    velocity, ``ft`` [N] friction force on the circle along t, ``n_x``,
    ``n_y`` [1] the unit normal (world), and those of PartialContact
    (``delta``, ``delta_dot``, ``fc``, ``mode``...).
    Connectors: ``frame_a`` (the profile's body), ``frame_b`` (circle centre).
    """

    R = Parameter(0.01, "m", "circle radius", min=0.0)
    mu = Parameter(0.0, "1", "Coulomb friction coefficient", min=0.0)
    v_reg = Parameter(1e-4, "m/s", "friction regularisation speed", min=0.0, min_open=True)

    v_t = Variable(0.0, "m/s", "slip velocity of the circle over the profile along t")
    ft = Variable(0.0, "N", "friction force on the circle along t")
    n_x = Variable(0.0, "1", "contact normal (profile to circle), world x")
    n_y = Variable(1.0, "1", "contact normal (profile to circle), world y")

    def geometry(self):
        """((nx, ny), delta): the world unit normal from the profile towards
        the circle centre and the indentation, as expressions (the leaf's)."""
        raise NotImplementedError

    def equations(self):
        a, b = self.frame_a, self.frame_b
        (nx_expr, ny_expr), delta = self.geometry()
        nx, ny = self.n_x, self.n_y          # named once: the leaf's normal may be long
        tx, ty = -ny, nx
        cx, cy = b.x - self.R * nx, b.y - self.R * ny        # contact point
        wa, wb = der(a.phi), der(b.phi)
        # velocities of c on the circle and on the profile's body (w x r)
        vcx = der(b.x) + wb * self.R * ny - (der(a.x) - wa * (cy - a.y))
        vcy = der(b.y) - wb * self.R * nx - (der(a.y) + wa * (cx - a.x))
        Fx = self.fc * nx + self.ft * tx
        Fy = self.fc * ny + self.ft * ty
        return [Eq(self.delta, delta), Eq(nx, nx_expr), Eq(ny, ny_expr),
                Eq(self.v_t, vcx * tx + vcy * ty),
                Eq(self.ft, -self.mu * self.fc * tanh(self.v_t / self.v_reg)),
                Eq(b.fx, -Fx), Eq(b.fy, -Fy), Eq(a.fx, Fx), Eq(a.fy, Fy),
                Eq(b.tau, -((cx - b.x) * Fy - (cy - b.y) * Fx)),
                Eq(a.tau, (cx - a.x) * Fy - (cy - a.y) * Fx)]

    def drawing_points(self, res):
        """The circle centre along a result (for :mod:`acausal.animate`)."""
        import numpy as np
        p = self.path
        bx, by = res[f"{p}.frame_b.x"], res[f"{p}.frame_b.y"]
        return np.stack([np.column_stack([bx, by])], axis=1)


def in_world(res, frame, local):
    """Points (n, 2) given in a frame's axes, in the world along a result:
    an array (n_times, n, 2)."""
    import numpy as np
    x, y, phi = (np.asarray(res[f"{frame}.{k}"])[:, None] for k in ("x", "y", "phi"))
    c, s = np.cos(phi), np.sin(phi)
    return np.stack([x + c * local[:, 0] - s * local[:, 1],
                     y + s * local[:, 0] + c * local[:, 1]], axis=2)


class CircleLineContact(PartialCircleContact):
    """A circle of radius ``R`` centred on frame_b against a straight line
    fixed in frame_a: through ``p = r_a + R(phi_a) (px, py)`` with unit
    normal ``n = R(phi_a) (nx, ny)`` towards the free side;
    ``delta = R - n . (r_b - p)``.

    Parameters: ``px``, ``py`` [m] a point of the line in frame_a's axes,
    ``nx``, ``ny`` [1] the line's normal towards the free side in frame_a's
    axes (made unit), and those of :class:`PartialCircleContact` (``R``,
    ``mu``, ``v_reg``, ``K``, ``e``, ``law``...). States: those of
    PartialCircleContact. Connectors: ``frame_a`` (the line's body),
    ``frame_b`` (circle centre).
    """

    px = Parameter(0.0, "m", "point of the line, x in frame_a's axes")
    py = Parameter(0.0, "m", "point of the line, y in frame_a's axes")
    nx = Parameter(0.0, "1", "line normal (free side), x in frame_a's axes")
    ny = Parameter(1.0, "1", "line normal (free side), y in frame_a's axes")

    def geometry(self):
        a, b = self.frame_a, self.frame_b
        k = sqrt(self.nx**2 + self.ny**2)
        n = rotate(a.phi, self.nx / k, self.ny / k)
        px, py = rotate(a.phi, self.px, self.py)
        dist = n[0] * (b.x - a.x - px) + n[1] * (b.y - a.y - py)
        return n, self.R - dist


class CircleCircleContact(PartialCircleContact):
    """A circle of radius ``R`` centred on frame_b against a circle of
    radius ``Ra`` centred at ``(px, py)`` in frame_a's axes, with ``d`` the
    distance between the centres:

    * ``inside = False`` (two convex bodies: a roller on a cam disc, two
      balls): ``delta = R + Ra - d``, the normal points from a's centre to
      b's;
    * ``inside = True`` (a pin in a hole, a ball in a ring, ``Ra > R``):
      ``delta = d - (Ra - R)``, the normal points from b's centre back to
      a's (the wall pushes the circle inwards).

    The normal is undefined when the centres coincide (``d = 0``), which an
    inside contact reaches only when the pin is exactly centred: start it
    off centre or in contact.

    Parameters: ``Ra`` [m] radius of frame_a's circle (>= 0; 0 is a point),
    ``px``, ``py`` [m] its centre in frame_a's axes, ``inside``
    (structural: False or True), and those of :class:`PartialCircleContact`.
    States: ``d`` [m] distance between the centres, and those of
    PartialCircleContact. Connectors: ``frame_a`` (the body of the circle
    Ra), ``frame_b`` (centre of the circle R).
    """

    Ra = Parameter(0.01, "m", "radius of frame_a's circle", min=0.0)
    px = Parameter(0.0, "m", "centre of frame_a's circle, x in frame_a's axes")
    py = Parameter(0.0, "m", "centre of frame_a's circle, y in frame_a's axes")
    inside = Parameter(False, "1", "circle R inside circle Ra (a pin in a hole)",
                       structural=True, choices=(False, True))

    d = Variable(0.02, "m", "distance between the circle centres")

    def drawing_profile(self, res):
        """Frame_a's circle (48 points) in the world along a result (for
        :mod:`acausal.animate`)."""
        import numpy as np
        p, u = self.path, np.linspace(0, 2 * np.pi, 49)
        ra, cx, cy = (float(res[f"{p}.{k}"][0]) for k in ("Ra", "px", "py"))
        local = np.column_stack([cx + ra * np.cos(u), cy + ra * np.sin(u)])
        return in_world(res, f"{p}.frame_a", local)

    def geometry(self):
        a, b = self.frame_a, self.frame_b
        px, py = rotate(a.phi, self.px, self.py)
        dx, dy = b.x - a.x - px, b.y - a.y - py
        if self.inside:
            return (-dx / self.d, -dy / self.d), self.d - (self.Ra - self.R)
        return (dx / self.d, dy / self.d), self.R + self.Ra - self.d

    def equations(self):
        a, b = self.frame_a, self.frame_b
        px, py = rotate(a.phi, self.px, self.py)
        return [Eq(self.d, sqrt((b.x - a.x - px)**2 + (b.y - a.y - py)**2))]
