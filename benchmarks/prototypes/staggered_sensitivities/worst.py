"""The columns where the prototype and the forward differences disagree most:
tight central-difference reference there (step 1e-3 of scale; 1e-2 as a check)."""
from params import *
J = np.load("J_q3_exp.npy"); F4 = np.load("J_fd1e-4.npy"); F3 = np.load("J_fd1e-3.npy")
nrm = np.linalg.norm(J, axis=0); nz = nrm > 1e-8 * np.linalg.norm(J)
e4 = np.where(nz, np.linalg.norm(J - F4, axis=0) / np.where(nz, nrm, 1), 0)
e3 = np.where(nz, np.linalg.norm(J - F3, axis=0) / np.where(nz, nrm, 1), 0)
pick = sorted(set(np.argsort(-e4)[:3].tolist() + np.argsort(-e3)[:3].tolist()))
def obs(params):
    rows = []
    for e in ds.experiments:
        o = run_options(mf, e); o.update(rtol=1e-10, atol=1e-12)
        res = cm.simulate(params={**params, **e.conditions}, backend="compiled", **o)
        rows += [np.interp(e.trace.time, res.t, res[v]) for v in e.trace.signals]
    return np.concatenate(rows)
print("col  |col|/max|col|  proto-vs-ref  fd1e-4-vs-ref  fd1e-3-vs-ref  ref(1e-3 vs 1e-2)")
for i in pick:
    nm = NAMES[i]; sc = abs(PAR[nm].scale)
    refs = {}
    for rel in (1e-3, 1e-2):
        h = rel * sc
        refs[rel] = (obs({**vals, nm: vals[nm] + h}) - obs({**vals, nm: vals[nm] - h})) / (2 * h)
    a = refs[1e-3]; na = np.linalg.norm(a)
    print(f"{nm:8s} {nrm[i]/nrm.max():.1e}  {np.linalg.norm(J[:,i]-a)/na:.1e}  {np.linalg.norm(F4[:,i]-a)/na:.1e}  {np.linalg.norm(F3[:,i]-a)/na:.1e}  {np.linalg.norm(refs[1e-2]-a)/na:.1e}")
# distribution over all nonzero columns
print("all nonzero cols:", nz.sum(), " proto vs fd1e-3 rel diff quartiles", np.percentile(e3[nz], [25, 50, 75, 100]).round(4), " vs fd1e-4", np.percentile(e4[nz], [25, 50, 75, 100]).round(4))
print("zero columns (knots never reached):", [NAMES[i] for i in np.where(~nz)[0]][:20], "...", (~nz).sum())
