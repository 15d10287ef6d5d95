"""Modelica.Mechanics.Rotational.Examples.LossyGearDemo3 (MSL 4.0.0), with
the library alone: two small inertias (1e-3 kg*m2) turning at 10 rad/s
through a lossy gear (ratio 1, efficiencies 0.25, bearing friction 0.625
and 2.5 N*m), unloaded until a 1 N*m torque steps onto Inertia2 at 0.5 s.
The motion decelerates to rest and sticks (the case that failed in an
earlier LossyGear).

Compared with the reference: Inertia2.phi, Inertia2.w, gear.mode
(tests/msl/test_unlisted_examples.py).
"""
from acausal import Experiment, Model, guess
from acausal.blocks.sources import Step
from acausal.mechanics.rotational import Inertia, LossyGear, Torque

model = Model()
model.gear = LossyGear(ratio=1, lossTable=[[0, 0.25, 0.25, 0.625, 2.5]])
model.Inertia1 = Inertia(J=0.001, w=guess(10))
model.torque1 = Torque()
model.torque2 = Torque()
model.step = Step(height=0)
model.step1 = Step(startTime=0.5, height=1, offset=0)
model.Inertia2 = Inertia(J=0.001, phi=0, w=10)

model.connect(model.Inertia1.flange_b, model.gear.flange_a)
model.connect(model.torque1.flange, model.Inertia1.flange_a)
model.connect(model.step.y, model.torque1.tau)
model.connect(model.gear.flange_b, model.Inertia2.flange_a)
model.connect(model.Inertia2.flange_b, model.torque2.flange)
model.connect(model.step1.y, model.torque2.tau)

experiment = Experiment(t_end=1.0, rtol=1e-6, output_step=5e-4)
