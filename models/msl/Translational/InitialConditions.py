"""Modelica.Mechanics.Translational.Examples.InitialConditions (MSL 4.0.0),
with the library alone: initial conditions given on relative quantities
(a spring's s_rel, a SpringDamper's s_rel and v_rel) instead of the
masses' states, next to a chain that starts at rest.

Compared with the reference: m1.s, m1.v, m3.s, m3.v, sd1.s_rel,
sd1.v_rel, sd2.s_rel, sd2.v_rel (tests/msl/test_parts_examples.py).
"""
from acausal import Experiment, Model
from acausal.mechanics.translational import Fixed, Mass, Spring, SpringDamper

model = Model()
model.fixed2 = Fixed(s0=1)
model.s2 = Spring(s_rel0=2, c=1e3)
model.m3 = Mass(L=3, s=4.5, v=0, m=1)
model.sd2 = SpringDamper(s_rel0=4, c=111, d=1)
model.m4 = Mass(L=5, s=12.5, v=0, m=1)
model.fixed1 = Fixed(s0=-1)
model.s1 = Spring(s_rel0=1, c=1e3, s_rel=0.5)
model.m1 = Mass(L=1, v=0, m=1)
model.sd1 = SpringDamper(s_rel0=1, c=111, s_rel=1, v_rel=0, d=1)
model.m2 = Mass(L=2, m=1)

model.connect(model.s2.flange_a, model.fixed2.flange)
model.connect(model.s1.flange_a, model.fixed1.flange)
model.connect(model.m1.flange_a, model.s1.flange_b)
model.connect(model.sd1.flange_a, model.m1.flange_b)
model.connect(model.m2.flange_a, model.sd1.flange_b)
model.connect(model.m4.flange_a, model.sd2.flange_b)
model.connect(model.sd2.flange_a, model.m3.flange_b)
model.connect(model.m3.flange_a, model.s2.flange_b)

experiment = Experiment(t_end=5.0, rtol=1e-6, output_step=5e-4)
