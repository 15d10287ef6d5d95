"""Prototype accuracy against the tight central-difference reference, per BDF order,
on the experiment-tolerance base run (rtol 1e-8) and on a tight base (rtol 1e-10)."""
from params import *
import proto
R = np.load("ref.npz"); pick = [int(i) for i in R["pick"]]
res_tab = {}
for base_kw, lab in (({}, "base rtol1e-8"), (dict(rtol=1e-10, atol=1e-12), "base rtol1e-10")):
    for q in (1, 2, 3, 4, 5):
        J, st = proto.jacobian(cm, mf, ds, vals, NAMES, PART_VARS, order=q, base_kw=base_kw)
        np.save(f"J_q{q}_{'tight' if base_kw else 'exp'}.npy", J)
        errs = []
        for i in pick:
            a = R[f"{NAMES[i]}|0.001"]
            errs.append(np.linalg.norm(J[:, i] - a) / np.linalg.norm(a))
        print(lab, "BDF", q, "steps", [s["steps"] for s in st], " ".join(f"{NAMES[i]}:{e:.1e}" for i, e in zip(pick, errs)), flush=True)
