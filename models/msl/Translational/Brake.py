"""Modelica.Mechanics.Translational.Examples.Brake (MSL 4.0.0), with the
library alone: two masses moving at 1 m/s are braked from 0.1 s on (the
normal force steps to 2 N, mu = 0.5), one brake grounded implicitly, the
other on an explicit fixed support; both decelerate at 1 m/s^2 and stick
at 1.1 s, s = 0.6 m.

Compared with the reference: mass1.s, mass1.v, mass2.s, mass2.v and the
modes and start flags of both brakes (tests/msl/test_friction_examples.py).
"""
from acausal import Experiment, Model
from acausal.blocks.sources import Step
from acausal.mechanics.translational import Brake, Fixed, Mass

model = Model()
model.brake = Brake(fn_max=1, useSupport=False)
model.mass1 = Mass(m=1, s=0, v=1)
model.step = Step(startTime=0.1, height=2)
model.brake1 = Brake(fn_max=1, useSupport=True)
model.mass2 = Mass(m=1, s=0, v=1)
model.fixed = Fixed()

model.connect(model.mass1.flange_b, model.brake.flange_a)
model.connect(model.step.y, model.brake.f_normalized)
model.connect(model.mass2.flange_b, model.brake1.flange_a)
model.connect(model.step.y, model.brake1.f_normalized)
model.connect(model.fixed.flange, model.brake1.support)

experiment = Experiment(t_end=2.0, rtol=1e-6, output_step=5e-4)
