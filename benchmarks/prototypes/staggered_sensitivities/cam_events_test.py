"""Sensitivities through the stick-slip mode changes of the cam (w0 = 10: 6 reversals),
with and without the jump, against tight central differences."""
import time, numpy as np
import proto, events_proto
mf, cm, vals, cond = proto.cam_case(w0=10.0)
names = ["spring.c", "bearing.d", "hyp_ssf.tau", "gen.a0", "gen.a1"]
res = cm.simulate(params={**vals, **cond}, backend="compiled", t_end=2.0, rtol=1e-8, atol=1e-10, output_step=0)
print("steps", res.t.size - 1, "events", len(res.events))
tq = np.linspace(0, 2.0, 201)
sig = ["cam.phi", "follower.s"]
Js = {}
for jumps in (False, True):
    t0 = time.perf_counter()
    S, SP = events_proto.sweep_events(cm, res, vals, cond, names, {"a": "cam.phi", "b": "cam.w"}, order=3, jumps=jumps)
    # sample: avoid interpolating across the duplicated event rows: use the rows' own left limits
    keep = np.r_[np.diff(res.t) > 0, True]
    t_, S_, SP_, y_, yp_ = res.t[keep], S[keep], SP[keep], res.y[keep], res.yp[keep]
    Sq = proto.hermite(t_, S_, SP_, tq); yq = proto.hermite(t_, y_, yp_, tq)
    ypq = np.array([np.interp(tq, t_, yp_[:, j]) for j in range(y_.shape[1])]).T
    st = proto.Setup(cm, vals, cond, names, {"a": "cam.phi", "b": "cam.w"}, d=res.d[-1])
    Js[jumps] = np.vstack([proto.observed_rows(st, v, tq, yq, ypq, Sq) for v in sig])
    print("jumps", jumps, f"{time.perf_counter()-t0:.2f} s")
proto.reference_table(cm, vals, cond, names, tq, sig, {"nojump": Js[False], "jump": Js[True]})
