"""Events in a located model beside a friction cause (the term beside coulomb_friction
at the motor of the geared drive; and at the cam of the cam follower): mode changes
during the experiment."""
import os
import numpy as np
from acausal.diagnose.library import generic as gen
from acausal.diagnose.library.hypotheses import HYPOTHESES
HYP = "stick_slip_friction"
for path, node, conds, F in ((os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))), "tests", "diagnose", "independent", "geared_drive.py"), "motor", [{"tau_m": 0.05}, {"tau_m": 0.2}], None),
                          (os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))), "tests", "diagnose", "independent", "cam_follower.py"), "cam", [{"w0": 10.0}, {"w0": 40.0}], None)):
    mf, cm = gen.build_at(path, node, 17, 17, beside=(HYP, node), hypotheses=HYPOTHESES)
    fr = [str(s) for s in cm.param_syms if not str(s).startswith("gen.")][-4:]
    print(path.split("/")[-1], "beside coulomb at", node, ": unknowns", len(cm.dae.y), "events", len(cm.events), [e.name for e in cm.events][:8], "friction params", fr)
    for c in conds:
        res = cm.simulate(params=c, backend="compiled", t_end=mf.experiment.t_end, rtol=1e-8, atol=1e-10, output_step=0)
        print("   ", c, "steps", res.t.size - 1, "events", res.stats.get("events"))
