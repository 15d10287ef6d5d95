"""A slider on a return spring with a light viscous damper, written as a
user would with the library: 0.5 kg released at rest from ``s_start`` and
ringing down at about 3.2 Hz for 1 s. The spring's rate and the damper's
coefficient are the free parameters a user would calibrate. Used by the
stick-slip blind tests with data from an independent, event-driven scipy
simulator (tests/diagnose/stick_truth.py), in which dry friction in the
guide stops the slider and holds it against its spring."""
from acausal import Experiment, Model
from acausal.mechanics.translational import Damper, Fixed, Mass, Spring

model = Model()
s_start = model.parameter("s_start", 0.04, "m", "release position of the slider")
model.frame = Fixed()
model.slider = Mass(m=0.5, s=s_start, v=0.0)
model.spring = Spring(c=200.0)
model.damper = Damper(d=0.05)
model.connect(model.frame.flange, model.spring.flange_a, model.damper.flange_a)
model.connect(model.spring.flange_b, model.damper.flange_b, model.slider.flange)

free_parameters = {"spring.c": (100.0, 400.0), "damper.d": (0.0, 0.5)}
conditions = {"s_start": (0.01, 0.05, "m")}
experiment = Experiment(t_end=1.0, rtol=1e-8, atol=1e-11, output_step=1e-3)
