"""Fixed frame, rigid body and rigid (massless) link. Sign convention:
:mod:`acausal.connectors` (:class:`Frame`)."""

from acausal.lang import Eq, Parameter, Variable, der

from .geometry import rotate
from .partials import PartialOneFrame, PartialRigidLink

__all__ = ["Fixed", "Body", "FixedTranslation"]


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


class Body(PartialOneFrame):
    """A rigid body whose frame sits at its centre of mass (attach joints
    elsewhere on it with :class:`FixedTranslation`)::

        m der(vx) = frame.fx,  m der(vy) = frame.fy - m g,  I der(w) = frame.tau

    Gravity ``g`` acts along -y of the world (0 switches it off).

    Parameters: ``m`` [kg] mass (> 0), ``I`` [kg*m^2] moment of inertia about
    the centre of mass (> 0), ``g`` [m/s^2] gravity along -y (>= 0).
    States: ``x``, ``y`` [m], ``phi`` [rad], ``vx``, ``vy`` [m/s], ``w``
    [rad/s]. Connectors: ``frame`` (at the centre of mass).
    """

    diagnosis_site = "body"   # listed by acausal.diagnose; its loads act through its joints

    m = Parameter(1.0, "kg", "mass", min=0.0, min_open=True)
    I = Parameter(1.0, "kg*m^2", "moment of inertia about the centre of mass",  # noqa: E741
                  min=0.0, min_open=True)
    g = Parameter(0.0, "m/s^2", "gravity along -y of the world", min=0.0)

    x = Variable(0.0, "m", "world x of the centre of mass")
    y = Variable(0.0, "m", "world y of the centre of mass")
    phi = Variable(0.0, "rad", "angle of the body")
    vx = Variable(0.0, "m/s", "velocity along x")
    vy = Variable(0.0, "m/s", "velocity along y")
    w = Variable(0.0, "rad/s", "angular velocity")

    def equations(self):
        fr = self.frame
        return [Eq(fr.x, self.x), Eq(fr.y, self.y), Eq(fr.phi, self.phi),
                Eq(der(self.x), self.vx), Eq(der(self.y), self.vy), Eq(der(self.phi), self.w),
                Eq(self.m * der(self.vx), fr.fx),
                Eq(self.m * der(self.vy), fr.fy - self.m * self.g),
                Eq(self.I * der(self.w), fr.tau)]


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
