"""Does the cam follower (nominal, and with the generic term at each body node) have
events during its experiments? (no data needed: the model file's experiment, w0 10..40)"""
import os
import time, numpy as np
from acausal.modelfile import compile_file
from acausal.diagnose.library import generic as gen
P = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))), "tests", "diagnose", "independent", "cam_follower.py")
mf, cm = compile_file(P)
print("nominal: unknowns", len(cm.dae.y), "states", cm.dae.n_states, "events", cm.events, "n_roots", cm.n_roots, "dynamic discretes", cm.dynamic_discretes())
for w0 in (10.0, 40.0):
    res = cm.simulate(params={"w0": w0}, backend="compiled", t_end=2.0, rtol=1e-8, atol=1e-10, output_step=0)
    print(f"  w0={w0}: steps {res.t.size-1} events {res.stats.get('events')} nfev {res.stats.get('nfev')} njev {res.stats.get('njev')}")
for node in ("cam", "follower"):
    try:
        mf2, cm2 = gen.build_at(P, node, 65, 17)
        print(f"generic term at {node}: unknowns {len(cm2.dae.y)} states {cm2.dae.n_states} events {len(cm2.events)} n_roots {cm2.n_roots}")
        for w0 in (10.0, 40.0):
            res = cm2.simulate(params={"w0": w0}, backend="compiled", t_end=2.0, rtol=1e-8, atol=1e-10, output_step=0)
            print(f"  w0={w0}: steps {res.t.size-1} events {res.stats.get('events')}")
    except Exception as exc:
        print("build failed at", node, type(exc).__name__, str(exc)[:200])
