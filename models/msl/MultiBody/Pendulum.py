"""Modelica.Mechanics.MultiBody.Examples.Elementary.Pendulum (MSL 4.0.0),
ported to the plane with the library alone.

A body of 1 kg hangs from a revolute joint at the world's origin, its
centre of mass 0.5 m out along the joint's frame_b x axis; a rotational
damper (0.1 N*m*s/rad) sits on the joint's axis, between its support and
its axis. It starts horizontal and at rest (phi = 0, w = 0: fixed, as
MSL's ``phi(fixed=true)``, ``w(fixed=true)``) and swings under the
world's standard gravity (9.80665 m/s^2 along -y) for 5 s.

    world.frame_b o-- rev (damper on its axis) --o frame_a  body  (centre of mass at 0.5 m)

MSL -> here: ``inner World world`` -> :class:`World` (found by every body
as its ``outer`` world); ``Joints.Revolute(n={0,0,1}, useAxisFlange=true)``
-> planar :class:`Revolute` (its axis is the world's z); ``Parts.Body(m=1,
r_CM={0.5,0,0})`` with MSL's default ``I_33 = 0.001`` kg*m^2 ->
:class:`BodyShape` with frame_a at the joint and its centre of mass at
``r_CM_x = 0.5`` m (frame_b left free); ``Rotational.Components.Damper``
-> ``rotational.Damper``. The reference compares ``rev.phi`` and ``rev.w``.
"""
from acausal import Experiment, Model
from acausal.mechanics import rotational as rot
from acausal.mechanics.planar import BodyShape, Revolute, World

model = Model()
model.world = World()
model.rev = Revolute(phi=0.0, w=0.0)
model.damper = rot.Damper(d=0.1)
model.body = BodyShape(m=1.0, I=0.001, r_CM_x=0.5, r_CM_y=0.0)
model.connect(model.world.frame_b, model.rev.frame_a)
model.connect(model.damper.flange_b, model.rev.axis)
model.connect(model.rev.support, model.damper.flange_a)
model.connect(model.body.frame_a, model.rev.frame_b)

# MSL: experiment(StopTime=5); the reference run: DASSL, tolerance 1e-6,
# output every 1 ms
experiment = Experiment(t_end=5.0, rtol=1e-8, atol=1e-10, output_step=1e-3)
