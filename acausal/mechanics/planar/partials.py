"""Partial planar models that own the frame equations (Modelica
PlanarMechanics' PartialTwoFrames idea), so that a leaf is its parameters and
its law. Sign convention: :mod:`acausal.connectors` (:class:`Frame`)."""
from sympy import sqrt

from acausal.lang import Component, Discrete, Eq, Variable
from acausal.lang.connectors import Frame


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
