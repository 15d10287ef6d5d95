"""Fixed frame, rigid body and rigid (massless) link. Sign convention:
:mod:`acausal.connectors` (:class:`Frame`). Bodies with two frames and
shapes (BodyShape, BodyBox, BodyCylinder): :mod:`.bodies`; the world and
gravity: :mod:`.world`."""

from acausal.lang import Eq, Parameter

from .geometry import rotate
from .partials import PartialBody, PartialOneFrame, PartialRigidLink

__all__ = ["Fixed", "Body", "FixedTranslation", "FixedRotation"]


class Fixed(PartialOneFrame):
    """A frame fixed in the world at ``(x0, y0)`` with angle ``phi0``.

    Parameters: ``x0``, ``y0`` [m] position, ``phi0`` [rad] angle.
    Connectors: ``frame``.
    """

    loop_role = "ground"  # its frame is the world node of the kinematic graph
    x0 = Parameter(0.0, "m", "world x of the frame")
    y0 = Parameter(0.0, "m", "world y of the frame")
    phi0 = Parameter(0.0, "rad", "angle of the frame")

    def equations(self):
        fr = self.frame
        return [Eq(fr.x, self.x0), Eq(fr.y, self.y0), Eq(fr.phi, self.phi0)]


class Body(PartialBody, PartialOneFrame):
    """A rigid body whose frame sits at its centre of mass (attach joints
    elsewhere on it with :class:`FixedTranslation`, or use :class:`BodyShape`,
    whose frames sit anywhere on the body)::

        m der(vx) = frame.fx + m g ux,  m der(vy) = frame.fy + m g uy,
        I der(w) = frame.tau

    Gravity ``g`` acts along the world's direction ``(ux, uy)`` (-y by
    default); ``g`` is the model's :class:`~.world.World`'s unless given
    here (0 without a World; see :class:`~.partials.PartialBody`).

    Parameters: ``m`` [kg] mass (> 0), ``I`` [kg*m^2] moment of inertia about
    the centre of mass (> 0), ``g`` [m/s^2] gravity on the body (>= 0; default
    the world's). States: ``x``, ``y`` [m], ``phi`` [rad], ``vx``, ``vy`` [m/s],
    ``w`` [rad/s]. Connectors: ``frame`` (at the centre of mass).
    """

    def frames(self):
        return [(self.frame, (0, 0))]


class FixedTranslation(PartialRigidLink):
    """A massless rigid link: frame_b sits at ``(rx, ry)`` from frame_a in
    frame_a's own axes, with the same angle::

        r_b = r_a + R(frame_a.phi) (rx, ry),   frame_b.phi = frame_a.phi

    Parameters: ``rx``, ``ry`` [m] position of frame_b in frame_a's axes.
    Connectors: ``frame_a``, ``frame_b``.
    """

    rx = Parameter(1.0, "m", "x of frame_b in frame_a's axes")
    ry = Parameter(0.0, "m", "y of frame_b in frame_a's axes")

    def equations(self):
        a, b = self.frame_a, self.frame_b
        dx, dy = rotate(a.phi, self.rx, self.ry)
        return [Eq(b.x, a.x + dx), Eq(b.y, a.y + dy), Eq(b.phi, a.phi)]


class FixedRotation(PartialRigidLink):
    """A massless rigid link that also turns the frame: frame_b sits at
    ``(rx, ry)`` from frame_a in frame_a's axes and is turned by ``angle``
    about z (MSL's ``Parts.FixedRotation`` with ``n = {0, 0, 1}``)::

        r_b = r_a + R(frame_a.phi) (rx, ry),   frame_b.phi = frame_a.phi + angle

    Parameters: ``rx``, ``ry`` [m] position of frame_b in frame_a's axes,
    ``angle`` [rad] rotation of frame_b from frame_a (counter-clockwise).
    Connectors: ``frame_a``, ``frame_b``.
    """

    rx = Parameter(0.0, "m", "x of frame_b in frame_a's axes")
    ry = Parameter(0.0, "m", "y of frame_b in frame_a's axes")
    angle = Parameter(0.0, "rad", "rotation of frame_b from frame_a about z")

    def equations(self):
        a, b = self.frame_a, self.frame_b
        dx, dy = rotate(a.phi, self.rx, self.ry)
        return [Eq(b.x, a.x + dx), Eq(b.y, a.y + dy), Eq(b.phi, a.phi + self.angle)]
