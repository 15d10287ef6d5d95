"""Modelica.Mechanics.Rotational.Examples.RollingWheel (MSL 4.0.0), with
the library alone: a torque step at 0.1 s drives an inertia and an ideal
rolling wheel (radius 1 m) that pushes a 1 kg mass against a quadratic
drag; terminal speed 5 rad/s.

Compared with the reference: inertia.phi, inertia.w
(tests/msl/test_parts_examples.py).
"""
from acausal import Experiment, Model
from acausal.mechanics.rotational import IdealRollingWheel, Inertia, TorqueStep
from acausal.mechanics.translational import Mass, QuadraticSpeedDependentForce

model = Model()
model.idealRollingWheel = IdealRollingWheel(radius=1)
model.inertia = Inertia(J=1, phi=0, w=0)
model.torqueStep = TorqueStep(stepTorque=10, offsetTorque=0, startTime=0.1, useSupport=False)
model.mass = Mass(L=0, m=1)
model.quadraticSpeedDependentForce = QuadraticSpeedDependentForce(
    f_nominal=-10, ForceDirection=False, v_nominal=5)

model.connect(model.torqueStep.flange, model.inertia.flange_a)
model.connect(model.inertia.flange_b, model.idealRollingWheel.flangeR)
model.connect(model.idealRollingWheel.flangeT, model.mass.flange_a)
model.connect(model.quadraticSpeedDependentForce.flange, model.mass.flange_b)

experiment = Experiment(t_end=5.0, rtol=1e-6, output_step=5e-4)
