"""Contact from geometry: a circle (a roller, a pin, a ball) on frame_b
against a straight line (a flat face, a latch face) fixed on frame_a, with
the impact laws of :mod:`acausal.mechanics.contact` (Hertz force, Hunt-
Crossley / Lankarani-Nikravesh / Flores damping, onset and separation
events, no adhesion) along the line's normal and Coulomb friction along its
tangent. Sign convention: :mod:`acausal.connectors` (:class:`Frame`)::

                      frame_b (circle centre, radius R)
                        ( o )
               n ^       \\_/  contact point c = r_b - R n
                 |  t
     ============+--->========  the line: through p = r_a + R(phi_a) (px, py),
                 p              normal n = R(phi_a) (nx, ny) (unit), t = (-n_y, n_x)

* ``delta = R - n . (r_b - p)``: indentation (> 0 in contact);
* the force on the circle is ``F = fc n + ft t`` at c, the line's body gets
  ``-F`` at c (forces into the component: ``frame_b.f = -F``,
  ``frame_a.f = +F``, with the moments of F about each frame);
* ``ft = -mu fc tanh(v_t / v_reg)``: Coulomb friction against the slip
  velocity ``v_t`` of the circle's point c over the line's, regularised below
  ``v_reg`` (so a rolling circle creeps by about ``v_reg``).
"""
from sympy import sqrt, tanh

from acausal import Eq, Parameter, Variable, der

from ..contact import PartialContact
from .partials import PartialTwoFrames, rotate

__all__ = ["CircleLineContact"]


class CircleLineContact(PartialContact, PartialTwoFrames):
    """A circle of radius ``R`` centred on frame_b against a line fixed in
    frame_a (see the module docstring for the picture).

    Parameters: ``R`` [m] circle radius (>= 0), ``px``, ``py`` [m] a point
    of the line in frame_a's axes, ``nx``, ``ny`` [1] the line's normal
    towards the free side in frame_a's axes (made unit), ``mu`` [1] Coulomb
    friction coefficient (>= 0), ``v_reg`` [m/s] regularisation speed of the
    friction (> 0), and those of :class:`~acausal.mechanics.contact.PartialContact`
    (``K``, ``gamma``, ``e``, ``law``...). States: ``v_t`` [m/s] slip
    velocity, ``ft`` [N] friction force on the circle along t, and those of
    PartialContact (``delta``, ``delta_dot``, ``fc``, ``mode``...).
    Connectors: ``frame_a`` (the line's body), ``frame_b`` (circle centre).
    """

    R = Parameter(0.01, "m", "circle radius", min=0.0)
    px = Parameter(0.0, "m", "point of the line, x in frame_a's axes")
    py = Parameter(0.0, "m", "point of the line, y in frame_a's axes")
    nx = Parameter(0.0, "1", "line normal (free side), x in frame_a's axes")
    ny = Parameter(1.0, "1", "line normal (free side), y in frame_a's axes")
    mu = Parameter(0.0, "1", "Coulomb friction coefficient", min=0.0)
    v_reg = Parameter(1e-4, "m/s", "friction regularisation speed", min=0.0, min_open=True)

    v_t = Variable(0.0, "m/s", "slip velocity of the circle over the line along t")
    ft = Variable(0.0, "N", "friction force on the circle along t")

    def equations(self):
        a, b = self.frame_a, self.frame_b
        k = sqrt(self.nx**2 + self.ny**2)
        n = rotate(a.phi, self.nx / k, self.ny / k)
        t = (-n[1], n[0])
        px, py = rotate(a.phi, self.px, self.py)
        dist = n[0] * (b.x - a.x - px) + n[1] * (b.y - a.y - py)
        cx, cy = b.x - self.R * n[0], b.y - self.R * n[1]        # contact point
        wa, wb = der(a.phi), der(b.phi)
        # velocities of c on the circle and on the line's body (w x r)
        vcx = der(b.x) + wb * self.R * n[1] - (der(a.x) - wa * (cy - a.y))
        vcy = der(b.y) - wb * self.R * n[0] - (der(a.y) + wa * (cx - a.x))
        Fx = self.fc * n[0] + self.ft * t[0]
        Fy = self.fc * n[1] + self.ft * t[1]
        return [Eq(self.delta, self.R - dist),
                Eq(self.v_t, vcx * t[0] + vcy * t[1]),
                Eq(self.ft, -self.mu * self.fc * tanh(self.v_t / self.v_reg)),
                Eq(b.fx, -Fx), Eq(b.fy, -Fy), Eq(a.fx, Fx), Eq(a.fy, Fy),
                Eq(b.tau, -((cx - b.x) * Fy - (cy - b.y) * Fx)),
                Eq(a.tau, (cx - a.x) * Fy - (cy - a.y) * Fx)]

    def drawing_points(self, res):
        """The circle centre and the contact point along a result (for
        :mod:`acausal.animate`)."""
        import numpy as np
        p = self.path
        bx, by = res[f"{p}.frame_b.x"], res[f"{p}.frame_b.y"]
        return np.stack([np.column_stack([bx, by])], axis=1)
