"""A two-mass chain, written as a user would with the library::

    ground --(k1, d1)-- m1 --(k2, d2)-- m2

m2 is pulled out by ``x2_start`` and released with m1 at rest; both ring
down (two modes, 7 and 13 Hz) for 1.5 s. The first spring's stiffness and
damper are the free parameters a user would calibrate. Two similar nodes
(m1, m2) make the location the hard part. Used by the blind tests with
data from an independent scipy simulator (tests/diagnose/two_mass_truth.py)."""
from acausal import Experiment, Model
from acausal.mechanics.translational import Damper, Fixed, Mass, Spring

model = Model()
x2_start = model.parameter("x2_start", 0.012, "m", "release offset of m2")
model.ground = Fixed()
model.m1 = Mass(m=0.5, s=0.0, v=0.0)
model.m2 = Mass(m=0.2, s=x2_start, v=0.0)
model.k1 = Spring(c=2000.0)
model.d1 = Damper(d=1.0)
model.k2 = Spring(c=800.0)
model.d2 = Damper(d=0.2)
model.connect(model.ground.flange, model.k1.flange_a, model.d1.flange_a)
model.connect(model.k1.flange_b, model.d1.flange_b, model.m1.flange, model.k2.flange_a,
              model.d2.flange_a)
model.connect(model.k2.flange_b, model.d2.flange_b, model.m2.flange)

free_parameters = {"k1.c": (1000.0, 4000.0), "d1.d": (0.0, 5.0)}
conditions = {"x2_start": (0.004, 0.02, "m")}
experiment = Experiment(t_end=1.5, rtol=1e-7, atol=1e-10, output_step=5e-4)
