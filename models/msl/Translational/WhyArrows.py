"""Modelica.Mechanics.Translational.Examples.WhyArrows (MSL 4.0.0), with
the library alone: rods and position sensors show the flanges' positions;
two identical masses of length 2 (the second is called inertia2, as in
MSL) hang on springs attached at their flange_b.

Compared with the reference: inertia2.s, inertia2.v, mass1.s, mass1.v
(tests/msl/test_parts_examples.py).
"""
from acausal import Experiment, Model
from acausal.mechanics.translational import Fixed, Mass, PositionSensor, Rod, Spring

model = Model()
model.fixed = Fixed()
model.rod1 = Rod(L=1)
model.rod2 = Rod(L=1)
model.rod3 = Rod(L=1)
model.positionSensor2 = PositionSensor()
model.positionSensor1 = PositionSensor()
model.positionSensor3 = PositionSensor()
model.fixed1 = Fixed(s0=-1.9)
model.spring1 = Spring(s_rel0=2, c=11)
model.mass1 = Mass(L=2, s=0, v=0, m=1)
model.fixed2 = Fixed(s0=-1.9)
model.spring2 = Spring(s_rel0=2, c=11)
model.inertia2 = Mass(L=2, m=1, s=0, v=0)

model.connect(model.spring1.flange_b, model.mass1.flange_b)
model.connect(model.spring2.flange_b, model.inertia2.flange_b)
model.connect(model.rod3.flange_b, model.positionSensor3.flange)
model.connect(model.rod1.flange_a, model.positionSensor1.flange)
model.connect(model.rod1.flange_b, model.fixed.flange)
model.connect(model.rod3.flange_a, model.fixed.flange)
model.connect(model.fixed.flange, model.rod2.flange_a)
model.connect(model.rod2.flange_b, model.positionSensor2.flange)
model.connect(model.fixed1.flange, model.spring1.flange_a)
model.connect(model.fixed2.flange, model.spring2.flange_a)

experiment = Experiment(t_end=1.0, rtol=1e-6, output_step=5e-4)
