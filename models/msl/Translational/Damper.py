"""Modelica.Mechanics.Translational.Examples.Damper (MSL 4.0.0), with the
library alone: three 1 kg masses thrown at 10 m/s against a Damper, a
Damper parallel to a Spring, and a SpringDamper (each mass's flange_a is
unconnected).

Compared with the reference: damper1, damper2 and springDamper3's s_rel
and v_rel (tests/msl/test_parts_examples.py).
"""
from acausal import Experiment, Model
from acausal.mechanics.translational import Damper, Fixed, Mass, Spring, SpringDamper

model = Model()
model.mass1 = Mass(L=1, s=3, v=10, m=1)
model.damper1 = Damper(d=25)
model.fixed1 = Fixed(s0=4.5)
model.mass2 = Mass(L=1, s=3, v=10, m=1)
model.damper2 = Damper(d=25)
model.fixed2 = Fixed(s0=4.5)
model.mass3 = Mass(L=1, s=3, v=10, m=1)
model.fixed3 = Fixed(s0=4.5)
model.spring2 = Spring(s_rel0=1, c=1)
model.springDamper3 = SpringDamper(s_rel0=1, d=25, c=1)

model.connect(model.mass1.flange_b, model.damper1.flange_a)
model.connect(model.mass2.flange_b, model.damper2.flange_a)
model.connect(model.damper2.flange_b, model.spring2.flange_b)
model.connect(model.damper2.flange_a, model.spring2.flange_a)
model.connect(model.mass3.flange_b, model.springDamper3.flange_a)
model.connect(model.damper1.flange_b, model.fixed1.flange)
model.connect(model.damper2.flange_b, model.fixed2.flange)
model.connect(model.springDamper3.flange_b, model.fixed3.flange)

experiment = Experiment(t_end=1.0, rtol=1e-6, output_step=5e-4)
