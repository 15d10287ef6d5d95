"""Forward-difference columns as the fits take them today (compiled backend, experiment
tolerance): located-stage columns (STEP=1e-4 of scale, forward) and refine's
(FD_STEP=1e-3 of scale, backward at the upper bound); accuracy against the reference,
full-matrix comparison with the prototype, and wall times (best of 3)."""
from params import *
from acausal.diagnose.stages.fitting import scaled_columns
from acausal.diagnose.stages.locate import STEP
from acausal.studies.calibrate import FD_STEP
from acausal.studies.residuals import sigma
import proto
R = np.load("ref.npz"); pick = [int(i) for i in R["pick"]]
sig = np.concatenate([np.full(e.trace.time.size, sigma(ds, v, ys)) for e in ds.experiments for v, ys in e.trace.signals.items()])
params = [PAR[n] for n in NAMES]
sc = np.array([abs(q.scale) or 1.0 for q in params])
r0 = residuals_of(pair, ds, vals, "compiled").vector
out = {}
for lab, step, inside in (("fd1e-4", STEP, False), ("fd1e-3", FD_STEP, True)):
    best = 1e9
    for rep in range(3):
        t0 = time.perf_counter()
        r0_, Jc = scaled_columns(pair, ds, vals, params, step, "compiled", r0, inside=inside)
        best = min(best, time.perf_counter() - t0)
    Jp = Jc * sig[:, None] / sc[None, :]     # d obs / d p, parameter units
    np.save(f"J_{lab}.npy", Jp)
    out[lab] = (best, Jp)
    print(lab, "best wall of 3 (84 columns, 3 experiments, r0 given):", round(best, 3), "s", flush=True)
    print("   ref errs", " ".join(f"{NAMES[i]}:{np.linalg.norm(Jp[:, i] - R[NAMES[i]+'|0.001'])/np.linalg.norm(R[NAMES[i]+'|0.001']):.1e}" for i in pick))
# timing of the prototype in the same process, best of 3
for q in (2, 3):
    best = 1e9; tmb = None
    for rep in range(3):
        tm = {}
        t0 = time.perf_counter()
        J, st = proto.jacobian(cm, mf, ds, vals, NAMES, PART_VARS, order=q, timing=tm)
        w = time.perf_counter() - t0
        if w < best: best, tmb = w, tm
    print(f"proto BDF{q} best wall of 3:", round(best, 3), {k: round(v, 3) for k, v in tmb.items()})
    print("   ref errs", " ".join(f"{NAMES[i]}:{np.linalg.norm(J[:, i] - R[NAMES[i]+'|0.001'])/np.linalg.norm(R[NAMES[i]+'|0.001']):.1e}" for i in pick))
    for lab in out:
        Jp = out[lab][1]
        nz = np.linalg.norm(J, axis=0) > 1e-8 * np.linalg.norm(J)
        e = np.linalg.norm(J - Jp, axis=0)[nz] / np.linalg.norm(J, axis=0)[nz]
        print(f"   vs {lab}: {nz.sum()} nonzero columns, rel col diff median {np.median(e):.1e} max {e.max():.1e}; whole matrix {np.linalg.norm(J-Jp)/np.linalg.norm(J):.1e}; zero cols max |fd| {np.abs(Jp[:, ~nz]).max() if (~nz).any() else 0:.1e}")
# base-run timing alone
best = 1e9
for rep in range(5):
    t0 = time.perf_counter()
    for e in ds.experiments: proto.base_run(cm, mf, e, vals)
    best = min(best, time.perf_counter() - t0)
print("base runs (3 exps, output_step=0) best of 5:", round(best, 4))
best = 1e9
for rep in range(5):
    t0 = time.perf_counter(); residuals_of(pair, ds, vals, "compiled"); best = min(best, time.perf_counter() - t0)
print("residuals_of (3 exps, output at samples) best of 5:", round(best, 4))
