"""Prototype on the 13-unknown cam DAE (generic term at the cam beside stick-slip
friction), w0 = 40: a single mode after the initial event at t = 0. Sensitivities of
cam.phi and follower.s on a 201-point grid against tight central differences."""
import time, numpy as np
import proto
mf, cm, vals, cond = proto.cam_case(w0=40.0)
p0 = cm.param_vector({**vals, **cond})
names = ["spring.c", "bearing.d", "hyp_ssf.tau", "gen.a3", "gen.a8", "gen.b2", "gen.b6"]
print({n: float(p0[cm.param_index(n)]) for n in names})
res = cm.simulate(params={**vals, **cond}, backend="compiled", t_end=2.0, rtol=1e-8, atol=1e-10, output_step=0)
print("steps", res.t.size - 1, "rows with d != d[-1]:", int(np.sum(np.any(res.d != res.d[-1], axis=1))), "events", res.events)
tq = np.linspace(0, 2.0, 201)
sig = ["cam.phi", "follower.s"]
for q in (2, 3):
    t0 = time.perf_counter()
    st = proto.Setup(cm, vals, cond, names, {"a": "cam.phi", "b": "cam.w"}, d=res.d[-1])
    S, SP = proto.sweep(st, res, q)
    Sq = proto.hermite(res.t, S, SP, tq); yq = proto.hermite(res.t, res.y, res.yp, tq)
    ypq = np.array([np.interp(tq, res.t, res.yp[:, j]) for j in range(st.n)]).T
    J = np.vstack([proto.observed_rows(st, v, tq, yq, ypq, Sq) for v in sig])
    print(f"BDF{q} prototype {time.perf_counter()-t0:.2f} s")
    if q == 2: J2 = J
proto.reference_table(cm, vals, cond, names, tq, sig, {"BDF2": J2, "BDF3": J})
