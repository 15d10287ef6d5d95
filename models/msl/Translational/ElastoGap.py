"""Modelica.Mechanics.Translational.Examples.ElastoGap (MSL 4.0.0), with the
library alone: a mass between two SpringDampers and a mass between two
ElastoGaps, both starting at 2 m, against the right anchor.

Compared with the reference: elastoGap1.v_rel, elastoGap2.s_rel,
springDamper1.v_rel, springDamper2.s_rel (tests/msl/test_parts_examples.py).
"""
from acausal import Experiment, Model, guess
from acausal.mechanics.translational import ElastoGap, Fixed, Mass, Rod, SpringDamper

model = Model()
model.fixed = Fixed()
model.rod1 = Rod(L=2)
model.rod2 = Rod(L=2)
model.springDamper1 = SpringDamper(c=10, s_rel0=1, s_rel=guess(1), d=1.5)
model.springDamper2 = SpringDamper(c=10, s_rel0=1, s_rel=guess(1), d=1.5)
model.mass1 = Mass(s=2, L=0, m=1, v=0)
model.elastoGap1 = ElastoGap(c=10, s_rel=guess(1.5), s_rel0=1.5, d=1.5)
model.elastoGap2 = ElastoGap(c=10, s_rel=guess(1.5), s_rel0=1.5, d=1.5)
model.mass2 = Mass(s=2, L=0, m=1, v=0)

model.connect(model.rod1.flange_b, model.fixed.flange)
model.connect(model.fixed.flange, model.rod2.flange_a)
model.connect(model.springDamper1.flange_a, model.rod1.flange_a)
model.connect(model.springDamper2.flange_b, model.rod2.flange_b)
model.connect(model.springDamper1.flange_b, model.mass1.flange_a)
model.connect(model.mass1.flange_b, model.springDamper2.flange_a)
model.connect(model.rod1.flange_a, model.elastoGap1.flange_a)
model.connect(model.rod2.flange_b, model.elastoGap2.flange_b)
model.connect(model.elastoGap1.flange_b, model.mass2.flange_a)
model.connect(model.mass2.flange_b, model.elastoGap2.flange_a)

experiment = Experiment(t_end=5.0, rtol=1e-6, output_step=5e-3)
