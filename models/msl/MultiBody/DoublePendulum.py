"""Modelica.Mechanics.MultiBody.Examples.Elementary.DoublePendulum (MSL
4.0.0), ported to the plane with the library alone.

Two steel boxes (length 0.5 m, width = height = 0.06 m, density 7700
kg/m^3: 13.86 kg each) hang in a chain from revolute joints; the first
joint, at the world's origin, has a rotational damper (0.1 N*m*s/rad) on
its axis. Both joints start at phi = 0 (the boxes horizontal, along +x) and
at rest (fixed, as MSL's ``phi(fixed=true)``, ``w(fixed=true)``), and the
chain falls under the world's standard gravity (9.80665 m/s^2 along -y)
for 3 s::

    world o-- revolute1 (damper) --[ boxBody1 ]-- revolute2 --[ boxBody2 ]

MSL -> here: ``inner World world`` -> :class:`World`;
``Joints.Revolute`` -> planar :class:`Revolute` (axis z; ``revolute2``'s
axis flange is not used, so it carries no torque);
``Parts.BodyBox(r={0.5,0,0}, width=0.06)`` -> :class:`BodyBox` with
``rx = 0.5`` (length |r| = 0.5 m, height = width, density 7700: the mass
and the inertia about z follow from them as in MSL);
``Rotational.Components.Damper`` -> ``rotational.Damper``, between
``revolute1.support`` and ``revolute1.axis``. The reference compares
``revolute1.phi``, ``revolute1.w``, ``revolute2.phi`` and ``revolute2.w``
(``revolute2.phi`` relative to box 1, as in MSL).
"""
from acausal import Experiment, Model
from acausal.mechanics import rotational as rot
from acausal.mechanics.planar import BodyBox, Revolute, World

model = Model()
model.world = World()
model.revolute1 = Revolute(phi=0.0, w=0.0)
model.damper = rot.Damper(d=0.1)
model.boxBody1 = BodyBox(rx=0.5, ry=0.0, width=0.06)
model.revolute2 = Revolute(phi=0.0, w=0.0)
model.boxBody2 = BodyBox(rx=0.5, ry=0.0, width=0.06)
model.connect(model.damper.flange_b, model.revolute1.axis)
model.connect(model.revolute1.support, model.damper.flange_a)
model.connect(model.revolute1.frame_b, model.boxBody1.frame_a)
model.connect(model.revolute2.frame_b, model.boxBody2.frame_a)
model.connect(model.boxBody1.frame_b, model.revolute2.frame_a)
model.connect(model.world.frame_b, model.revolute1.frame_a)

# MSL: experiment(StopTime=3); the reference run: DASSL, tolerance 1e-6,
# output every 0.6 ms
experiment = Experiment(t_end=3.0, rtol=1e-8, atol=1e-10, output_step=6e-4)
