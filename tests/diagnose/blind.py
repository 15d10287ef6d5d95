"""Shared runner of the blind cases (tests/diagnose/test_blind_*.py): write
the data with an independent truth module (``write``, ``effect_floors``),
run the full diagnosis on the user's model file, print one line and, when
``ACAUSAL_BLIND_LOG`` names a file, append the case's verdict, numbers and
wall time to it as a JSON line (docs/diagnosis.md's table is made from it)."""
import json
import os
import time

from acausal.diagnose.run import diagnose


def run_case(model, truth, tmp_path, effect, value=None, seed=3, name=None, **kw):
    """(summary, details, effect in floors) of one blind case."""
    truth.write(tmp_path / "data", effect, value, seed=seed)
    t0 = time.perf_counter()
    out = diagnose(model, tmp_path / "data", out_dir=tmp_path / "out", workers=2,
                   progress=False, **kw)
    wall = time.perf_counter() - t0
    det = json.loads((tmp_path / "out" / "candidates.json").read_text())
    floors = truth.effect_floors(effect, value) if effect is not None else 0.0
    row = dict(case=name or str(effect), model=os.path.basename(model), effect=effect,
               value=value, seed=seed, floors=floors, discrepancy=out["discrepancy"],
               causes=out["causes"], unexplained=out["unexplained"], gain=out["gain"],
               weak=det.get("weak_evidence"), ranking=out["ranking"][:4], wall_s=wall,
               located=[{k: t.get(k) for k in ("node", "S", "aicc", "heldout_rmse")}
                        for t in det.get("located") or []][:3])
    print(f"BLIND {row['case']} ({row['model']}, seed {seed}): effect {floors:.0f} floors; "
          f"discrepancy {out['discrepancy']}; named {[(c['cause'], c['location']) for c in out['causes']]}; "
          f"unexplained {out['unexplained']}; held-out {out['gain']['before']['heldout']:.3f}"
          f" -> {out['gain']['after']['heldout']:.3f}; weak {row['weak']}; {wall:.0f} s")
    log = os.environ.get("ACAUSAL_BLIND_LOG")
    if log:
        with open(log, "a") as fh:
            fh.write(json.dumps(row, default=str) + "\n")
    return out, det, floors


def named(out):
    """{(cause, location)} of the named causes."""
    return {(c["cause"], c["location"]) for c in out["causes"]}


def values(out):
    """{parameter: fitted value} over the named causes."""
    return {k: v["value"] for c in out["causes"] for k, v in c["parameters"].items()}


def velocity_shape_error(term, law, v_max):
    """How far the located term's velocity part is from the truth's extra
    force ``law(v)`` (the force the truth adds on the body, along +s):
    (relative RMS error, roughness ratio) over |v| <= v_max. Both are
    compared after removing their least-squares constant and linear parts,
    which the free parameters (a damper's coefficient) and the position
    part's constant share with the term. Roughness: the RMS second
    difference of the fitted part over that of the truth, on the knots."""
    import numpy as np

    from acausal.diagnose.library import generic
    GENERIC, shape = generic.GENERIC, generic.shape
    N_V = generic.resolution(term["values"], GENERIC.prefix)[1]   # the chosen resolution
    sh = shape(term["values"], GENERIC.prefix, term["ranges"], n=401)
    v, fv = sh["v"], sh["f_v"]
    m = np.abs(v) <= v_max
    v, fv = v[m], fv[m]
    truth = np.array([law(x) for x in v])
    A = np.vstack([np.ones_like(v), v]).T

    def detrend(y):
        return y - A @ np.linalg.lstsq(A, y, rcond=None)[0]
    a, b = detrend(fv), detrend(truth)
    err = float(np.sqrt(np.mean((a - b) ** 2)) / np.sqrt(np.mean(b ** 2)))
    knots = np.linspace(term["ranges"][2], term["ranges"][3], N_V)
    bw = np.array([term["values"][f"{GENERIC.prefix}.b{j}"] for j in range(N_V)])
    tw = np.array([law(x) for x in knots])
    rough = float(np.sqrt(np.mean(np.diff(bw, 2) ** 2)) / np.sqrt(np.mean(np.diff(tw, 2) ** 2)))
    return err, rough
