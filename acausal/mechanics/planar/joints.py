"""Revolute and prismatic joints with a 1-D flange across the joint (for a
spring, damper, friction, end stop or drive of the 1-D library). Sign
convention: :mod:`acausal.connectors` (:class:`Frame`, and the mapping of
joints to 1-D flanges)."""

from acausal.lang import Eq, Flange, Parameter, RotFlange, Variable, der

from acausal.errors import ParameterError

from .geometry import rotate
from .partials import PartialJoint

__all__ = ["Revolute", "Prismatic"]


class Revolute(PartialJoint):
    """A pin joint: frame_b turns about frame_a's origin by ``phi``::

        r_b = r_a,  frame_b.phi = frame_a.phi + phi,  axis.phi = phi,
        frame_a.tau = axis.tau (the torque of what is mounted on the axis)

    The 1-D ``axis`` flange carries the joint angle (relative: a rotational
    ``Fixed`` on it stands for frame_a); a torsion spring from such a
    ``Fixed`` to ``axis`` acts on frame_b with ``-c*phi`` and on frame_a with
    ``+c*phi``. End stops: the 1-D library has no rotational stop, so put
    an ``IdealLever`` (``arm`` [m]) on ``axis`` and a translational
    :class:`~acausal.mechanics.contact.EndStop` at ``s_limit = arm *
    phi_limit`` on its ``flange_t``. Unconnected, it carries no torque (a
    free pin). ``support`` is the axis' housing on frame_a (MSL's
    ``support``): ``support.phi = 0`` in the joint's relative coordinates,
    so a 1-D element between ``support`` and ``axis`` (a damper, a drive)
    acts across the joint, as with a rotational ``Fixed`` in its place; the
    element's reaction reaches frame_a through ``frame_a.tau = axis.tau``.

    Parameters: none. States: ``phi`` [rad] joint angle, ``w`` [rad/s] its
    rate (give their starts to choose the states of a loop). Discrete:
    ``drives`` (see :class:`~.partials.PartialJoint`: its loop's dead
    centres are watched and warned of, :mod:`.deadcentre`).
    Connectors: ``frame_a``, ``frame_b``, ``axis`` (optional, RotFlange),
    ``support`` (optional, RotFlange).
    """

    coordinate = "phi"    # watched for dead centres (acausal.mechanics.planar.deadcentre)

    axis = RotFlange("joint angle and the torque across the joint", optional=True)
    support = RotFlange("housing of the axis on frame_a (relative angle 0)", optional=True)
    phi = Variable(0.0, "rad", "joint angle frame_b.phi - frame_a.phi")
    w = Variable(0.0, "rad/s", "joint angular velocity")

    def equations(self):
        a, b = self.frame_a, self.frame_b
        return [Eq(b.x, a.x), Eq(b.y, a.y), Eq(b.phi, a.phi + self.phi),
                Eq(der(self.phi), self.w), Eq(self.axis.phi, self.phi),
                Eq(a.tau, self.axis.tau), Eq(self.support.phi, 0)]


class Prismatic(PartialJoint):
    """A slider: frame_b moves by ``s`` along the unit axis ``(ex, ey)``
    fixed in frame_a's axes, with frame_a's angle::

        r_b = r_a + s R(frame_a.phi) (ex, ey),  frame_b.phi = frame_a.phi,
        axis.s = s,  axis.f = -frame_b.f . R(frame_a.phi) (ex, ey)

    The 1-D ``axis`` flange carries the stroke (relative: a translational
    ``Fixed`` on it stands for frame_a); a spring from such a ``Fixed`` to
    ``axis`` pushes frame_b back with ``-c*s`` along the axis. End stops:
    :class:`~acausal.mechanics.contact.EndStop` on ``axis``. Unconnected,
    it carries no force along the axis (a free slider). ``support`` is the
    axis' housing on frame_a (MSL's ``support``): ``support.s = 0`` in the
    joint's relative coordinates, as a translational ``Fixed`` in its place.

    Parameters: ``ex``, ``ey`` [1] axis direction in frame_a's axes (made
    unit length). States: ``s`` [m] stroke, ``v`` [m/s] its rate. Discrete:
    ``drives`` (see :class:`~.partials.PartialJoint`).
    Connectors: ``frame_a``, ``frame_b``, ``axis`` (optional, Flange),
    ``support`` (optional, Flange).
    """

    coordinate = "s"      # watched for dead centres (acausal.mechanics.planar.deadcentre)

    axis = Flange("stroke and the force along the axis", optional=True)
    support = Flange("housing of the axis on frame_a (relative position 0)", optional=True)
    ex = Parameter(1.0, "1", "axis direction, x in frame_a's axes")
    ey = Parameter(0.0, "1", "axis direction, y in frame_a's axes")
    s = Variable(0.0, "m", "stroke along the axis")
    v = Variable(0.0, "m/s", "stroke rate")

    def __init__(self, **kw):
        super().__init__(**kw)
        ex, ey = self.value("ex"), self.value("ey")
        if all(isinstance(c, (int, float)) for c in (ex, ey)) and ex * ex + ey * ey == 0:
            raise ParameterError(f"Prismatic {self.path or ''}: the axis (ex, ey) is zero")

    def equations(self):
        a, b = self.frame_a, self.frame_b
        n = (self.ex**2 + self.ey**2) ** 0.5
        ux, uy = rotate(a.phi, self.ex / n, self.ey / n)
        return [Eq(b.x, a.x + self.s * ux), Eq(b.y, a.y + self.s * uy),
                Eq(b.phi, a.phi), Eq(der(self.s), self.v), Eq(self.axis.s, self.s),
                Eq(self.axis.f, -(b.fx * ux + b.fy * uy)), Eq(self.support.s, 0)]
