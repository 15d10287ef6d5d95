"""Modelica.Mechanics.Rotational.Examples.LossyGearDemo1 (MSL 4.0.0), with
the library alone: a gear whose efficiency (0.5 both ways) makes the
motion stick. A sine torque (10 N*m, 1 Hz) drives Inertia1 through the
gear (ratio 2) against a load ramping from -10 to -5 N*m over 2 s on
Inertia2. Inertia2's angle and speed carry MSL's nominal values (1e-3 rad,
1e-2 rad/s).

Compared with the reference: Inertia2.phi, Inertia2.w, gear.mode
(tests/msl/test_unlisted_examples.py).
"""
from acausal import Experiment, Model
from acausal.blocks.sources import Ramp, Sine
from acausal.mechanics.rotational import Fixed, Inertia, LossyGear, Torque

model = Model()
model.gear = LossyGear(ratio=2, lossTable=[[0, 0.5, 0.5, 0, 0]], useSupport=True)
model.Inertia1 = Inertia(J=1)
model.Inertia2 = Inertia(J=1.5, phi=0, w=0).with_nominal(phi=1e-3, w=1e-2)
model.torque1 = Torque(useSupport=True)
model.torque2 = Torque(useSupport=True)
model.DriveSine = Sine(amplitude=10, f=1)
model.load = Ramp(height=5, duration=2, offset=-10)
model.fixed = Fixed()

model.connect(model.Inertia1.flange_b, model.gear.flange_a)
model.connect(model.gear.flange_b, model.Inertia2.flange_a)
model.connect(model.torque1.flange, model.Inertia1.flange_a)
model.connect(model.torque2.flange, model.Inertia2.flange_b)
model.connect(model.DriveSine.y, model.torque1.tau)
model.connect(model.load.y, model.torque2.tau)
model.connect(model.fixed.flange, model.gear.support)
model.connect(model.fixed.flange, model.torque1.support)
model.connect(model.fixed.flange, model.torque2.support)

experiment = Experiment(t_end=0.5, rtol=1e-6, output_step=5e-4)
