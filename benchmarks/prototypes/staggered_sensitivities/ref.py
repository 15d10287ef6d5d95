"""Reference columns: central differences on tight runs (rtol 1e-10, atol 1e-12),
at two steps (1e-3 and 1e-2 of each scale) for a handful of parameters."""
from params import *
from acausal.studies.residuals import sigma
J = np.load("J_bdf2.npy")
norms = np.linalg.norm(J, axis=0)
order = np.argsort(-norms)
pick = [0, 1] + [int(i) for i in order[2:5]] + [int(i) for i in order[20:23]]   # 3 strongest weights, 3 middling
pick = sorted(set(pick) - {0, 1}); pick = [0, 1] + pick
print("picked", [(NAMES[i], float(norms[i])) for i in pick])
def obs(params, rtol, atol):
    rows = []
    for e in ds.experiments:
        o = run_options(mf, e); o.update(rtol=rtol, atol=atol)
        res = cm.simulate(params={**params, **e.conditions}, backend="compiled", **o)
        for var in e.trace.signals:
            rows.append(np.interp(e.trace.time, res.t, res[var]))
    return np.concatenate(rows)
out = {}
t0 = time.perf_counter()
for i in pick:
    nm = NAMES[i]; sc = abs(PAR[nm].scale)
    for rel in (1e-4, 1e-3, 1e-2):
        h = rel * sc
        cp = obs({**vals, nm: vals[nm] + h}, 1e-10, 1e-12)
        cmn = obs({**vals, nm: vals[nm] - h}, 1e-10, 1e-12)
        out[f"{nm}|{rel}"] = (cp - cmn) / (2 * h)
print("ref wall", time.perf_counter() - t0)
np.savez("ref.npz", pick=np.array(pick), **out)
for i in pick:
    nm = NAMES[i]
    a, b = out[f"{nm}|0.001"], out[f"{nm}|0.01"]
    print(f"{nm:10s} |col|={np.linalg.norm(a):.4g}  ref step1e-3 vs 1e-2 rel diff {np.linalg.norm(a-b)/np.linalg.norm(a):.2e}  proto-BDF2 rel err {np.linalg.norm(J[:,i]-a)/np.linalg.norm(a):.2e}")
for i in pick:
    nm = NAMES[i]
    a, b = out[f"{nm}|0.0001"], out[f"{nm}|0.001"]
    print(f"{nm:10s} ref step1e-4 vs 1e-3 rel diff {np.linalg.norm(a-b)/np.linalg.norm(a):.2e}")
