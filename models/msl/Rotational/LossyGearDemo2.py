"""Modelica.Mechanics.Rotational.Examples.LossyGearDemo2 (MSL 4.0.0), with
the library alone: a lossy gear (ratio 2, mesh efficiency 0.5 both ways)
and a bearing friction in series, between a sine drive torque (10 N*m,
1 Hz) and a ramped load torque (-10 N*m rising by 2.5 N*m/s).

    torque1 -> bearingFriction -> Inertia1 -> gear -> Inertia2 <- torque2

When both stick, the holding torques are not determined (MSL: "there is
no unique solution"): the machine keeps the gear locked and lets the
bearing start at its sliding level in the direction of its least-squares
share (acausal.mechanics.frictionmodes).

Compared with the reference: Inertia2.phi, Inertia2.w and the modes and
start flags of bearingFriction and gear (tests/msl/test_friction_examples.py).
"""
from acausal import Experiment, Model
from acausal.blocks.sources import Ramp, Sine
from acausal.mechanics.rotational import BearingFriction, Fixed, Inertia, LossyGear, Torque

model = Model()
model.gear = LossyGear(ratio=2, lossTable=[[0, 0.5, 0.5, 0, 0]], useSupport=True)
model.Inertia1 = Inertia(J=1)
model.Inertia2 = Inertia(J=1.5, phi=0, w=0)
model.torque1 = Torque(useSupport=True)
model.torque2 = Torque(useSupport=True)
model.DriveSine = Sine(amplitude=10, f=1)
model.load = Ramp(height=5, duration=2, offset=-10)
model.bearingFriction = BearingFriction(tau_pos=[[0, 0.5], [1, 1]], useSupport=True)
model.fixed = Fixed()

model.connect(model.torque2.flange, model.Inertia2.flange_b)
model.connect(model.Inertia2.flange_a, model.gear.flange_b)
model.connect(model.gear.flange_a, model.Inertia1.flange_b)
model.connect(model.Inertia1.flange_a, model.bearingFriction.flange_b)
model.connect(model.bearingFriction.flange_a, model.torque1.flange)
model.connect(model.DriveSine.y, model.torque1.tau)
model.connect(model.load.y, model.torque2.tau)
model.connect(model.gear.support, model.fixed.flange)
model.connect(model.fixed.flange, model.torque2.support)
model.connect(model.fixed.flange, model.bearingFriction.support)
model.connect(model.torque1.support, model.fixed.flange)

experiment = Experiment(t_end=0.5, rtol=1e-6, output_step=5e-4)
