"""Harmonic oscillator: a 1 kg mass on a 100 N/m spring to ground.

Exact solution: mass.s = 0.1 cos(10 t)."""
from acausal import Experiment, Model
from acausal.mechanics.translational import Fixed, Mass, Spring

model = Model()
model.mass = Mass(m=1.0, s=0.1, v=0.0)
model.spring = Spring(c=100.0, s_rel0=0.0)
model.ground = Fixed()
model.connect(model.ground.flange, model.spring.flange_a)
model.connect(model.spring.flange_b, model.mass.flange)

experiment = Experiment(t_end=1.0, rtol=1e-8, atol=1e-10, output_step=1e-3)
