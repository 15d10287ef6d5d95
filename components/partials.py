"""Partial models that own the connector equations, so that a leaf
component is only its parameters and its law (Modelica's PartialCompliant /
PartialRigid). Sign convention: see :mod:`acausal.connectors`."""
from sympy import Eq

from acausal import Component, Flange, RotFlange, Variable


class PartialCompliant(Component):
    """Two translational flanges and the force between them.

    States: ``s_rel`` [m] = flange_b.s - flange_a.s; ``f`` [N] force at
    flange_b (positive = the element is pulled apart, i.e. in tension).
    Connectors: ``flange_a``, ``flange_b``.
    """

    flange_a = Flange("left flange")
    flange_b = Flange("right flange")
    s_rel = Variable(0.0, "m", "relative displacement flange_b.s - flange_a.s")
    f = Variable(0.0, "N", "force at flange_b (tension positive)")

    def equations(self):
        return [Eq(self.s_rel, self.flange_b.s - self.flange_a.s),
                Eq(self.flange_b.f, self.f),
                Eq(self.flange_a.f, -self.f)]


class PartialRotCompliant(Component):
    """Two rotational flanges and the torque between them.

    States: ``phi_rel`` [rad] = flange_b.phi - flange_a.phi; ``tau`` [N*m]
    torque at flange_b. Connectors: ``flange_a``, ``flange_b``.
    """

    flange_a = RotFlange("left flange")
    flange_b = RotFlange("right flange")
    phi_rel = Variable(0.0, "rad", "relative angle flange_b.phi - flange_a.phi")
    tau = Variable(0.0, "N*m", "torque at flange_b")

    def equations(self):
        return [Eq(self.phi_rel, self.flange_b.phi - self.flange_a.phi),
                Eq(self.flange_b.tau, self.tau),
                Eq(self.flange_a.tau, -self.tau)]


class PartialRigid(Component):
    """A translational body with one flange: position ``s`` [m] and velocity
    ``v`` [m/s]; ``flange.f`` is the sum of the forces applied on it."""

    flange = Flange("the body's flange (all forces act here)")
    s = Variable(0.0, "m", "absolute position")
    v = Variable(0.0, "m/s", "absolute velocity")

    def equations(self):
        from acausal import der
        return [Eq(self.flange.s, self.s), Eq(der(self.s), self.v)]


class PartialRotRigid(Component):
    """A rotating body with one flange: angle ``phi`` [rad] and angular
    velocity ``w`` [rad/s]; ``flange.tau`` is the sum of applied torques."""

    flange = RotFlange("the body's flange (all torques act here)")
    phi = Variable(0.0, "rad", "absolute angle")
    w = Variable(0.0, "rad/s", "absolute angular velocity")

    def equations(self):
        from acausal import der
        return [Eq(self.flange.phi, self.phi), Eq(der(self.phi), self.w)]
