"""Two masses on one massless lever (same side of the pivot), a spring on the
first. Both masses keep their own position variables: the rigid coupling is
resolved by index reduction (Pantelides + dummy derivatives).

Exact: lever.phi = 0.1 cos(w t), w = sqrt(c a^2 / (m1 a^2 + m2 b^2)),
m2.s = b * lever.phi."""
from acausal import Experiment, Model
from acausal.mechanics.levers import TwoArmLever
from acausal.mechanics.translational import Fixed, Mass, Spring

model = Model()
model.lever = TwoArmLever(a=0.1, b=0.3)
model.m1 = Mass(m=2.0, s=0.01, v=0.0)
model.m2 = Mass(m=1.0)
model.spring = Spring(c=1000.0)
model.ground = Fixed()
model.connect(model.ground.flange, model.spring.flange_a)
model.connect(model.spring.flange_b, model.m1.flange, model.lever.flange_a)
model.connect(model.m2.flange, model.lever.flange_b)

experiment = Experiment(t_end=1.0, rtol=1e-8, atol=1e-10, output_step=1e-3)
