"""A slider on a spring, written as a user would, for the fast tests of the
diagnosis's JSON (tests/diagnose/test_outputs.py): 1 kg on a spring whose
rate is free, released from a start position and velocity that are the
experiment's conditions, with their ranges declared for the next
experiment's search."""
from acausal import Experiment, Model
from acausal.mechanics.translational import Fixed, Mass, Spring

model = Model()
s0 = model.parameter("s0", 0.1, "m", "start position of the slider")
v0 = model.parameter("v0", 0.0, "m/s", "start velocity of the slider")
model.frame = Fixed()
model.mass = Mass(m=1.0, s=s0, v=v0)
model.spring = Spring(c=90.0, s_rel0=0.0)
model.connect(model.frame.flange, model.spring.flange_a)
model.connect(model.spring.flange_b, model.mass.flange)
experiment = Experiment(t_end=0.25, rtol=1e-8, atol=1e-11, output_step=2e-3)
free_parameters = {"spring.c": (50.0, 200.0)}
conditions = {"s0": (-0.1, 0.1, "m"), "v0": (-1.0, 1.0, "m/s")}
