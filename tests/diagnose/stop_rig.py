"""A mass on a spring hitting a stop, written as a user would with the
library: a 0.1 kg slider on a 400 N/m spring with a light viscous damper,
released at rest below its rest position; it swings up into an elastic end
stop 8 mm above rest, bounces off it a few times and rings down (about
15 cycles at 10 Hz). The spring's stiffness and the damping are the free
parameters a user would calibrate. Used by the blind tests with data from
an independent scipy simulator (tests/diagnose/stop_truth.py)."""
from acausal import Experiment, Model
from acausal.mechanics.contact import EndStop
from acausal.mechanics.translational import Damper, Fixed, Mass, Spring

model = Model()
s_start = model.parameter("s_start", -0.016, "m", "release position (rest is 0)")
model.frame = Fixed()
model.slider = Mass(m=0.1, s=s_start, v=0.0)
model.spring = Spring(c=400.0)
model.damper = Damper(d=0.04)
model.stop = EndStop(s_limit=0.008, side="upper", K=1e7, gamma=1.5, law="beta", beta=5e6)
model.connect(model.frame.flange, model.spring.flange_a, model.damper.flange_a)
model.connect(model.spring.flange_b, model.damper.flange_b, model.slider.flange,
              model.stop.flange)

free_parameters = {"spring.c": (200.0, 800.0), "damper.d": (0.0, 0.5)}

experiment = Experiment(t_end=1.5, rtol=1e-8, atol=1e-11, output_step=5e-4)
