"""Modelica.Mechanics.Translational.Examples.Oscillator (MSL 4.0.0), with
the library alone: two masses of length 1 on springs, driven by a sine
force at their resonance (15.9155 Hz, 100 rad/s), the second one damped.

Compared with the reference: damper1.s_rel, damper1.v_rel, mass1.s,
mass1.v (tests/msl/test_parts_examples.py).
"""
from acausal import Experiment, Model
from acausal.blocks import Sine
from acausal.mechanics.translational import Damper, Fixed, Force, Mass, Spring

model = Model()
model.mass1 = Mass(L=1, s=-0.5, v=0, m=1)
model.spring1 = Spring(s_rel0=1, c=10000)
model.fixed1 = Fixed(s0=1)
model.force1 = Force()
model.sine1 = Sine(f=15.9155)
model.mass2 = Mass(L=1, s=-0.5, v=0, m=1)
model.spring2 = Spring(s_rel0=1, c=10000)
model.fixed2 = Fixed(s0=1)
model.force2 = Force()
model.sine2 = Sine(f=15.9155)
model.damper1 = Damper(d=10)

model.connect(model.mass1.flange_b, model.spring1.flange_a)
model.connect(model.spring2.flange_a, model.damper1.flange_a)
model.connect(model.mass2.flange_b, model.spring2.flange_a)
model.connect(model.damper1.flange_b, model.spring2.flange_b)
model.connect(model.sine1.y, model.force1.f)
model.connect(model.sine2.y, model.force2.f)
model.connect(model.spring1.flange_b, model.fixed1.flange)
model.connect(model.force2.flange, model.mass2.flange_a)
model.connect(model.force1.flange, model.mass1.flange_a)
model.connect(model.spring2.flange_b, model.fixed2.flange)

experiment = Experiment(t_end=1.0, rtol=1e-6, output_step=5e-4)
