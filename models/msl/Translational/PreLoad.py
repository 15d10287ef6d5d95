"""Modelica.Mechanics.Translational.Examples.PreLoad (MSL 4.0.0), with the
library alone: a spool held in its housing by a preloaded spring between
two spring plates, with ElastoGap contacts (c = 1e6 N/m, d = 250 N*s/m)
between the plates and the housing (outer, gap 1.5 mm) and between the
plates and the spool's collars (inner, gap 1 mm). A slow sine force (150 N,
0.01 Hz) pushes the spool against viscous friction (2500 N*s/m).

    fixedLe -- outerContactA -- springPlateA -- spring -- springPlateB -- outerContactB -- housing -- fixedLe
                                springPlateA -- rod1 -- innerContactA -- rod3 -- rod4 -- innerContactB -- rod2 -- springPlateB
                                spool (at rod4.flange_a) <- force;  friction (Damper) from fixedLe to rod3

Compared with the reference: friction.v_rel, innerContactA.s_rel,
innerContactB.s_rel, outerContactA.v_rel, outerContactB.s_rel,
outerContactB.v_rel (tests/msl/test_unlisted_examples.py).
"""
from acausal import Experiment, Model
from acausal.blocks.sources import Sine
from acausal.mechanics.translational import Damper, ElastoGap, Fixed, Force, Mass, Rod, Spring

model = Model()
model.innerContactA = ElastoGap(c=1000e3, d=250, s_rel0=0.001)
model.innerContactB = ElastoGap(c=1000e3, d=250, s_rel0=0.001)
model.spool = Mass(L=0.19, m=0.150, s=0.01475, v=0)
model.fixedLe = Fixed(s0=-0.0955)
model.springPlateA = Mass(m=10e-3, L=0.002, s=-0.093, v=0)
model.springPlateB = Mass(m=10e-3, s=-0.06925, L=0.002, v=0)
model.spring = Spring(c=20e3, s_rel0=0.025)
model.outerContactA = ElastoGap(c=1000e3, d=250, s_rel0=0.0015)
model.outerContactB = ElastoGap(c=1000e3, d=250, s_rel0=0.0015)
model.rod1 = Rod(L=0.007)
model.friction = Damper(d=2500)
model.force = Force()
model.housing = Rod(L=0.0305)
model.rod3 = Rod(L=0.00575)
model.rod4 = Rod(L=0.00575)
model.rod2 = Rod(L=0.007)
model.sineForce = Sine(amplitude=150, f=0.01)

model.connect(model.outerContactA.flange_b, model.springPlateA.flange_a)
model.connect(model.springPlateA.flange_b, model.spring.flange_a)
model.connect(model.spring.flange_b, model.springPlateB.flange_a)
model.connect(model.springPlateB.flange_b, model.outerContactB.flange_a)
model.connect(model.outerContactB.flange_b, model.housing.flange_b)
model.connect(model.springPlateA.flange_b, model.rod1.flange_a)
model.connect(model.innerContactA.flange_a, model.rod3.flange_a)
model.connect(model.innerContactA.flange_b, model.rod1.flange_b)
model.connect(model.rod2.flange_a, model.innerContactB.flange_a)
model.connect(model.rod4.flange_b, model.innerContactB.flange_b)
model.connect(model.friction.flange_b, model.rod3.flange_a)
model.connect(model.rod3.flange_b, model.rod4.flange_a)
model.connect(model.rod2.flange_b, model.springPlateB.flange_a)
model.connect(model.spool.flange_a, model.rod4.flange_a)
model.connect(model.sineForce.y, model.force.f)
model.connect(model.force.flange, model.spool.flange_a)
model.connect(model.outerContactA.flange_a, model.fixedLe.flange)
model.connect(model.housing.flange_a, model.fixedLe.flange)
model.connect(model.friction.flange_a, model.fixedLe.flange)

experiment = Experiment(t_end=100.0, rtol=1e-6, output_step=5e-2)
