"""Planar (2-D) multibody mechanics: frames, bodies, joints, line forces and
adaptors to the 1-D flanges. Sign convention and the picture of a frame:
:mod:`acausal.connectors` (:class:`~acausal.connectors.Frame`).

One small module per kind: :mod:`.partials` (connector equations, the
rigid body's Newton-Euler law), :mod:`.world` (World: the world frame and
gravity; a model without one is gravity-free), :mod:`.parts` (Fixed, Body,
FixedTranslation, FixedRotation), :mod:`.bodies` (BodyShape, BodyBox,
BodyCylinder), :mod:`.joints` (Revolute, Prismatic), :mod:`.forces` (Spring, Damper, SpringDamper between frames),
:mod:`.adaptors` (frame <-> rotational / translational flange),
:mod:`.contact` (a circle against a line or a circle) and :mod:`.polyline`
(a circle against a polyline profile). The package re-exports the world,
parts, bodies, joints, line forces and adaptors.
"""
from .world import World
from .parts import Fixed, Body, FixedTranslation, FixedRotation
from .bodies import BodyShape, BodyBox, BodyCylinder
from .joints import Revolute, Prismatic
from .forces import Spring, Damper, SpringDamper
from .adaptors import ShaftAdaptor, AxisAdaptor

__all__ = ["World", "Fixed", "Body", "FixedTranslation", "FixedRotation", "BodyShape",
           "BodyBox", "BodyCylinder", "Revolute", "Prismatic", "Spring", "Damper", "SpringDamper",
           "ShaftAdaptor", "AxisAdaptor"]
