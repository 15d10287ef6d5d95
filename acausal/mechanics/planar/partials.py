"""Partial planar models that own the frame equations (Modelica
PlanarMechanics' PartialTwoFrames idea), so that a leaf is its parameters and
its law. Sign convention: :mod:`acausal.connectors` (:class:`Frame`)."""
from sympy import sqrt

from acausal.lang import Component, Discrete, Eq, Parameter, Variable, der
from acausal.lang.connectors import Frame

from .geometry import rotate
from .world import gravity_of


class PartialOneFrame(Component):
    """One planar frame. Connectors: ``frame``."""

    frame = Frame("the component's frame")


class PartialTwoFrames(Component):
    """Two planar frames. Connectors: ``frame_a``, ``frame_b``."""

    frame_a = Frame("first frame")
    frame_b = Frame("second frame")


class PartialRigidLink(PartialTwoFrames):
    """Two frames held by a massless part: whatever the leaf says about the
    positions, the forces balance and the torques balance about frame_a::

        frame_a.f + frame_b.f = 0
        frame_a.tau + frame_b.tau + (r_b - r_a) x frame_b.f = 0

    (``r`` the frame origins in the world). A leaf adds three position
    equations (and its own variables' laws)."""

    loop_role = "link"   # an edge of the kinematic graph (acausal.mechanics.planar.loops)

    def equations(self):
        a, b = self.frame_a, self.frame_b
        return [Eq(a.fx + b.fx, 0), Eq(a.fy + b.fy, 0),
                Eq(a.tau + b.tau + (b.x - a.x) * b.fy - (b.y - a.y) * b.fx, 0)]

    def initialization_failure(self, model, paths, detail=""):
        """A :class:`~.loops.LoopClosureError` naming the kinematic loop
        through the components ``paths`` whose equations the start could not
        meet, or None (see :func:`acausal.initialize.initial_point`)."""
        from .loops import closure_error
        return closure_error(model, paths, detail)

    def solver_failure(self, model, paths, message, t, result):
        """A :class:`~.loops.LoopSingularityError` when the solver failed in
        a component of a kinematic loop (see :func:`acausal.simulate`)."""
        from .loops import singularity_error
        return singularity_error(model, paths, message, t, result)


class PartialJoint(PartialRigidLink):
    """A joint (an edge of the kinematic graph with a coordinate of its own,
    named by the leaf's ``coordinate``: "phi" or "s"). Its loops' dead
    centres are watched (:mod:`.deadcentre`): discrete ``drives`` (1 when
    the joint's coordinate is a state of the run, 0 when it follows the
    others; -1 until the start has decided)."""

    loop_role = "joint"   # named when its loop cannot close
    coordinate = None
    diagnosis_site = "joint"      # what acausal.diagnose may extend here: across the joint,
    diagnosis_flange = "axis"     # on its 1-D axis flange (relative coordinates)

    @property
    def flange(self):
        """The joint's 1-D ``axis`` under the name the diagnosis uses for the
        flange of a joint site (acausal.diagnose.graph)."""
        return self.port("axis")

    drives = Discrete(-1, "1", "1: the coordinate drives its loop (a state), 0: it follows")

    def events(self):
        from .deadcentre import arm_event, monitor_events
        return [arm_event(self)] + monitor_events(self)


class PartialLineForce(PartialTwoFrames):
    """A force ``f`` [N] along the line from frame_a to frame_b (tension
    positive: it pulls the frames together), no torque::

        frame_b.(fx, fy) = f * (dx, dy) / s,  frame_a.(fx, fy) = -frame_b.(fx, fy)

    States: ``s`` [m] distance between the frame origins (> 0), ``f`` [N].
    The leaf gives the law of ``f``."""

    s = Variable(1.0, "m", "distance between the frame origins")
    f = Variable(0.0, "N", "force along the line, tension positive")

    def equations(self):
        a, b = self.frame_a, self.frame_b
        dx, dy = b.x - a.x, b.y - a.y
        return [Eq(self.s, sqrt(dx**2 + dy**2)),
                Eq(b.fx * self.s, self.f * dx), Eq(b.fy * self.s, self.f * dy),
                Eq(a.fx, -b.fx), Eq(a.fy, -b.fy),
                Eq(a.tau, 0), Eq(b.tau, 0)]


def _world_g(body):
    """The default of a body's ``g``: its world's ``g``, or 0 without a world."""
    return gravity_of(body)[0]


class PartialBody(Component):
    """A rigid body in the plane: its centre of mass (x, y), angle phi and
    their rates are its states, and the frames of the leaf (:meth:`frames`)
    sit at fixed offsets from the centre of mass, in the body's axes. This
    partial owns the frames' equations and the Newton-Euler law::

        frame.(x, y) = (x, y) + R(phi) o,   frame.phi = phi    (each frame, offset o)
        m der(vx) = sum frame.fx + m g ux
        m der(vy) = sum frame.fy + m g uy
        I der(w)  = sum (frame.tau + (R(phi) o) x frame.f)

    Gravity: magnitude ``g`` along the unit direction ``(ux, uy)`` of the
    model's :class:`~.world.World` (found as Modelica's ``outer world``); by
    default ``g`` is the world's, so ``world.g`` sets it for every body, and
    a body given its own ``g`` overrides it (``g = 0``: no gravity on this
    body). Without a World: ``g = 0`` unless given, direction -y (see
    :mod:`.world`).

    Parameters: ``m`` [kg] mass (> 0), ``I`` [kg*m^2] moment of inertia
    about the centre of mass (> 0), ``g`` [m/s^2] gravity on this body (>=
    0; default the world's). States: ``x``, ``y`` [m] centre of mass,
    ``phi`` [rad] angle, ``vx``, ``vy`` [m/s], ``w`` [rad/s].
    """

    diagnosis_site = "body"   # listed by acausal.diagnose; its loads act through its joints

    m = Parameter(1.0, "kg", "mass", min=0.0, min_open=True)
    I = Parameter(1.0, "kg*m^2", "moment of inertia about the centre of mass",  # noqa: E741
                  min=0.0, min_open=True)
    g = Parameter(_world_g, "m/s^2", "gravity acceleration on the body, along the world's "
                  "direction (default: the world's g)", min=0.0)

    x = Variable(0.0, "m", "world x of the centre of mass")
    y = Variable(0.0, "m", "world y of the centre of mass")
    phi = Variable(0.0, "rad", "angle of the body")
    vx = Variable(0.0, "m/s", "velocity along x")
    vy = Variable(0.0, "m/s", "velocity along y")
    w = Variable(0.0, "rad/s", "angular velocity")

    def frames(self):
        """[(frame port, (ox, oy)), ...]: the leaf's frames and their
        origins' offsets from the centre of mass in the body's axes."""
        raise NotImplementedError

    def equations(self):
        eqs, fx, fy, tau = [], 0, 0, 0
        for fr, (ox, oy) in self.frames():
            if ox == 0 and oy == 0:
                eqs += [Eq(fr.x, self.x), Eq(fr.y, self.y)]
            else:
                dx, dy = rotate(self.phi, ox, oy)
                eqs += [Eq(fr.x, self.x + dx), Eq(fr.y, self.y + dy)]
                tau += dx * fr.fy - dy * fr.fx
            eqs.append(Eq(fr.phi, self.phi))
            fx, fy, tau = fx + fr.fx, fy + fr.fy, tau + fr.tau
        _, (ux, uy) = gravity_of(self)
        m = self.m
        return eqs + [Eq(der(self.x), self.vx), Eq(der(self.y), self.vy),
                      Eq(der(self.phi), self.w),
                      Eq(m * der(self.vx), fx + m * self.g * ux),
                      Eq(m * der(self.vy), fy + m * self.g * uy),
                      Eq(self.I * der(self.w), tau)]
