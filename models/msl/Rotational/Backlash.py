"""Modelica.Mechanics.Rotational.Examples.Backlash (MSL 4.0.0), with the
library alone: three inertias released from 90 degrees, on a
SpringDamper, an ElastoBacklash and an ElastoBacklash2 (backlash pi/4).

Compared with the reference: elastoBacklash.phi_rel, elastoBacklash.w_rel,
springDamper.phi_rel, springDamper.w_rel (tests/msl/test_parts_examples.py).
"""
from acausal import Experiment, Model
from acausal.mechanics.rotational import (ElastoBacklash, ElastoBacklash2, Fixed, Inertia,
                                          SpringDamper)

model = Model()
model.fixed1 = Fixed()
model.springDamper = SpringDamper(c=20e3, d=50, phi_nominal=1)
model.inertia1 = Inertia(J=5, w=0, phi=1.570796326794897)
model.fixed2 = Fixed()
model.elastoBacklash = ElastoBacklash(c=20e3, d=50, b=0.7853981633974483, phi_nominal=1)
model.inertia2 = Inertia(J=5, w=0, phi=1.570796326794897)
model.fixed3 = Fixed()
model.elastoBacklash2 = ElastoBacklash2(c=20e3, d=50, phi_nominal=1, b=0.78539816339745)
model.inertia3 = Inertia(J=5, w=0, phi=1.570796326794897)

model.connect(model.springDamper.flange_b, model.inertia1.flange_a)
model.connect(model.elastoBacklash.flange_b, model.inertia2.flange_a)
model.connect(model.fixed1.flange, model.springDamper.flange_a)
model.connect(model.fixed2.flange, model.elastoBacklash.flange_a)
model.connect(model.elastoBacklash2.flange_b, model.inertia3.flange_a)
model.connect(model.fixed3.flange, model.elastoBacklash2.flange_a)

experiment = Experiment(t_end=1.0, rtol=1e-6, output_step=5e-4)
