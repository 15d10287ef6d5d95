"""A driven mass-spring-damper for the diagnosis kill-and-resume test: the
smallest model the diagnosis can fit (one body, a free spring rate).

The force ``F`` is the experimental condition; ``spring.c`` is free. When
``$ACAUSAL_TEST_SLEEP`` is set, every simulation of it sleeps that long
(an observer-free way to make the fits slow enough to be killed midway).
"""
import os
import time

from acausal import Experiment, Model
from acausal.mechanics.translational import Damper, Fixed, Force, Mass, Spring

model = Model()
F = model.parameter("F", 1.0, "N", "drive force", min=0.0)
model.frame = Fixed()
model.mass = Mass(m=0.1, s=0.0, v=0.0)
model.spring = Spring(c=40.0, s_rel0=0.0)
model.damper = Damper(d=0.4)
model.drive = Force(f=F)
model.connect(model.frame.flange, model.spring.flange_a, model.damper.flange_a)
model.connect(model.spring.flange_b, model.damper.flange_b, model.mass.flange,
              model.drive.flange)
experiment = Experiment(t_end=0.3, rtol=1e-7, atol=1e-10, output_step=2e-3)
free_parameters = {"spring.c": (10.0, 160.0)}


def _s_end(res):
    time.sleep(float(os.environ.get("ACAUSAL_TEST_SLEEP", "0")))
    return res.final()["mass.s"]


measures = {"s_end": _s_end}
