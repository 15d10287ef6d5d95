"""Modelica.Mechanics.Rotational.Examples.SimpleGearShift (MSL 4.0.0), with
the library alone: a planetary gear shifts from first gear (ring held by
the brake) to direct drive (the clutch locks sun and ring) while a ramp
moves the normal force from the brake to the clutch between 2 and 2.1 s.

    torqueStep -> engine -> sun of idealPlanetary; carrier -> load <- quadratic drag
    clutch between sun and ring; brake on the ring

Compared with the reference: clutch.phi_rel, clutch.w_rel, engine.phi,
engine.w, load.phi, load.w and the modes and start flags of brake and
clutch (tests/msl/test_friction_examples.py).
"""
from acausal import Experiment, Model
from acausal.blocks.math import Feedback
from acausal.blocks.sources import Constant, Ramp
from acausal.mechanics.rotational import (Brake, Clutch, IdealPlanetary, Inertia,
                                          QuadraticSpeedDependentTorque, TorqueStep)

model = Model()
model.torqueStep = TorqueStep(offsetTorque=0, startTime=0.5, stepTorque=20)
model.engine = Inertia(J=1)
model.idealPlanetary = IdealPlanetary(ratio=75 / 50)
model.load = Inertia(J=10, phi=0, w=0)
model.quadraticSpeedDependentTorque = QuadraticSpeedDependentTorque(
    w_nominal=10.471975511966, tau_nominal=-20)
model.clutch = Clutch(cgeo=2, fn_max=100, phi_rel=0, w_rel=0)
model.brake = Brake(cgeo=2, fn_max=100)
model.feedback = Feedback()
model.const1 = Constant(k=1)
model.ramp = Ramp(height=1, offset=0, startTime=2, duration=0.1)

model.connect(model.torqueStep.flange, model.engine.flange_a)
model.connect(model.quadraticSpeedDependentTorque.flange, model.load.flange_b)
model.connect(model.feedback.y, model.brake.f_normalized)
model.connect(model.engine.flange_b, model.idealPlanetary.sun)
model.connect(model.idealPlanetary.sun, model.clutch.flange_a)
model.connect(model.idealPlanetary.ring, model.clutch.flange_b)
model.connect(model.idealPlanetary.ring, model.brake.flange_a)
model.connect(model.idealPlanetary.carrier, model.load.flange_a)
model.connect(model.const1.y, model.feedback.u1)
model.connect(model.ramp.y, model.feedback.u2, model.clutch.f_normalized)

experiment = Experiment(t_end=5.0, rtol=1e-6, output_step=5e-3)
