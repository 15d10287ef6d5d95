"""A 1-D oscillator for the kill-and-resume tests: mass.s = 0.1 cos(sqrt(c/m) t).

Its measure ``s_end`` leaves a marker file per call in ``$ACAUSAL_TEST_LOG``
(the mass, so a test can tell which points a run computed) and sleeps a
little, so that a sweep is still running when the test kills it.
"""
import os
import time
import uuid

from acausal import Experiment, Model
from acausal.mechanics.translational import Fixed, Mass, Spring

model = Model()
model.mass = Mass(m=1.0, s=0.1, v=0.0)
model.spring = Spring(c=100.0, s_rel0=0.0)
model.ground = Fixed()
model.connect(model.ground.flange, model.spring.flange_a)
model.connect(model.spring.flange_b, model.mass.flange)
experiment = Experiment(t_end=2.0, rtol=1e-9, atol=1e-11, output_step=1e-2)


def _s_end(res):
    log = os.environ.get("ACAUSAL_TEST_LOG")
    if log:
        with open(os.path.join(log, uuid.uuid4().hex), "w") as f:
            f.write(repr(float(res["mass.m"][0])))
    time.sleep(float(os.environ.get("ACAUSAL_TEST_SLEEP", "0")))
    return res.final()["mass.s"]


measures = {"s_end": _s_end, "v_end": lambda res: res.final()["mass.v"]}
