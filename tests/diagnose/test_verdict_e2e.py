"""Issue 24's verdict end to end, on a slider whose data come from an
independent scipy simulator (hand-written equations, no code shared with
the project's models): a force the library has no law for (a detent:
periodic in the position, several cycles over the stroke) is "not
explained by the library", not "weak"; the same slider without it stays
"no discrepancy"; drag that is viscous and quadratic at once, fitted by
the power law alone, is "not explained" with the exponent flagged as a
mixture of laws; plain viscous damping fitted by Coulomb + viscous
friction is named with the Coulomb level flagged as undetermined (each
parameter judged against its own neutral value). Each of these was "weak"
before issue 24. (A strong single cause that must still be named: the
slider of tests/diagnose/test_outputs.py, whose verdict kind is checked
there.)"""
import json
import os

import numpy as np
import pytest
from scipy import integrate

from acausal.data import Dataset, Instrument, MeasuredExperiment, Trace, write_dataset
from acausal.diagnose.problem import FitSettings
from acausal.diagnose.report.markdown import markdown
from acausal.diagnose.report.result import summary
from acausal.diagnose.run import run_stages

HERE = os.path.dirname(__file__)
SLIDER = os.path.join(HERE, "slider_model.py")
MASS, STIFF = 1.0, 100.0          # the truth's mass and spring rate
FLOOR = 1e-4                      # position noise [m]
TIMES = np.arange(0.0, 0.25 + 1e-12, 2.5e-3)
STARTS = (("a", 0.1), ("b", 0.075), ("c", 0.05))
LIGHT = FitSettings(max_nfev=20, lhs=1, refine=1, windows=(1.0,), evals_per_param=10)
HYPS = ["coulomb_friction", "constant_load", "quadratic_damping"]


def detent(A, lam):
    """A detent of amplitude A [N] and pitch lam [m]: A sin(2 pi s / lam)."""
    return lambda s, v: A * np.sin(2 * np.pi * s / lam)


def truth(s0, force, times):
    """m s'' = -k s + force(s, v) (``force`` None: nothing more), released
    at rest from s0."""
    def f(_, y):
        extra = 0.0 if force is None else force(y[0], y[1])
        return [y[1], (-STIFF * y[0] + extra) / MASS]
    sol = integrate.solve_ivp(f, (0.0, times[-1]), [s0, 0.0], t_eval=times, method="DOP853",
                              rtol=1e-11, atol=1e-13)
    return sol.y[0]


def _data(folder, force, seed, starts=STARTS):
    rng = np.random.default_rng(seed)
    exps = [MeasuredExperiment(name, dict(s0=s0, v0=0.0), {},
                               Trace(TIMES, {"mass.s": truth(s0, force, TIMES)
                                             + FLOOR * rng.standard_normal(TIMES.size)}))
            for name, s0 in starts]
    write_dataset(folder, Dataset(str(folder), exps,
                                  {"mass.s": Instrument("mass.s", 0.0, FLOOR)}))


def _diagnose(tmp_path, force, seed, hypotheses=HYPS, starts=STARTS):
    _data(tmp_path / "data", force, seed, starts)
    res = run_stages(SLIDER, tmp_path / "data", out_dir=tmp_path / "out", scheduler="serial",
                     progress=False, hypotheses=hypotheses, settings=LIGHT, generic=False,
                     pairs=False, families=False, profile=False, design=False, views=False)
    return res, json.loads(json.dumps(summary(res)))


@pytest.mark.slow
def test_a_detent_outside_the_library_is_not_explained_not_weak(tmp_path):
    """A 0.5 N detent of 10 mm pitch: the best library candidate leaves the
    held-out data well beyond the threshold noise alone reaches, so the
    verdict is "not explained by the library" with the candidates and their
    held-out errors, and no weak reason. (Before issue 24 this case was
    "evidence weak".)"""
    res, out = _diagnose(tmp_path, detent(0.5, 0.01), 3)
    v = out["verdict"]
    print(f"\nverdict {v['kind']}: {[r['text'] for r in v['reasons']]}; "
          f"held-out {out['gain']['before']['heldout']:.3f} -> "
          f"{out['gain']['after']['heldout']:.3f}; threshold {v['heldout_threshold']['rms']:.4f}")
    assert out["discrepancy"] is True
    assert v["kind"] == "not_explained" and out["unexplained"]["value"] is True
    assert out["cause"] is None and out["causes"] == []
    assert [r["code"] for r in v["reasons"]] == ["heldout"]
    t = v["heldout_threshold"]
    assert t["n"] == 3 * TIMES.size and t["experiments"] == 3
    assert 1.0 < t["rms"] < 1.4
    assert v["heldout_rmse"] > t["rms"]
    assert [c["kind"] for c in v["candidates"]] == ["single"] * 3
    assert {c["cause"] for c in v["candidates"]} == set(HYPS)
    assert res.ranking.weak == []
    text = markdown(res)
    assert "**Discrepancy not explained by the library.**" in text
    assert "evidence is weak" not in text


def test_the_same_slider_without_the_detent_stays_without_discrepancy(tmp_path):
    res, out = _diagnose(tmp_path, None, 4)
    assert out["discrepancy"] is False
    assert out["verdict"]["kind"] == "no_discrepancy" and out["verdict"]["reasons"] == []
    assert out["unexplained"]["value"] is False and out["cause"] is None
    # the held-out error of data the model explains is within the threshold
    assert out["gain"]["before"]["heldout"] <= out["verdict"]["heldout_threshold"]["rms"]


@pytest.mark.slow
def test_two_drag_laws_at_once_are_a_mixture_not_a_power_law(tmp_path):
    """f = -0.5 v - 3 v|v| over starts of 0.1, 0.03 and 0.01 m (speeds over
    a 10:1 range): the power law fits the training data to 4.7 floors with
    n = 1.59 [1.53, 1.65], away from both standard laws, and misses the
    held-out experiments (15.7 floors): not explained, "a mixture of laws?"
    (before: "weak", the best leaving 4.8x the floor)."""
    res, out = _diagnose(tmp_path, lambda s, v: -0.5 * v - 3.0 * v * abs(v), 5,
                         ["power_drag", "quadratic_damping", "coulomb_friction"],
                         (("a", 0.1), ("b", 0.03), ("c", 0.01)))
    v = out["verdict"]
    assert v["kind"] == "not_explained" and out["cause"] is None
    (law,) = v["laws"]
    assert law["cause"] == "power_drag" and law["parameter"] == "hyp_pd.n"
    lo, hi = law["ci95"]
    assert 1.0 < lo < hi < 2.0 and "mixture of laws" in v["reasons"][0]["text"]
    assert v["heldout_rmse"] > 3 * v["heldout_threshold"]["rms"]
    assert "A mixture of laws?" in markdown(res)


def test_viscous_damping_is_named_with_its_coulomb_level_flagged(tmp_path):
    """Plain viscous damping, b = 0.8 N*s/m (12 floors), with Coulomb +
    viscous friction in the library: b is determined to about 1 % and the
    Coulomb level F ~ 0 is not. Judged parameter by parameter, the cause is
    named and F flagged undetermined (before: "poorly determined, 332 %",
    from F alone)."""
    res, out = _diagnose(tmp_path, lambda s, v: -0.8 * v, 5,
                         ["coulomb_viscous_friction", "constant_load"])
    v = out["verdict"]
    assert v["kind"] == "named" and out["cause"] == "coulomb_viscous_friction"
    assert out["parameters"]["hyp_cvf.b"]["value"] == pytest.approx(0.8, rel=0.03)
    (flag,) = v["undetermined"]
    assert flag["name"] == "hyp_cvf.F" and flag["neutral"] == 0.0
    assert flag["ci95"][0] < 0.0 < flag["ci95"][1]
    assert out["gain"]["after"]["heldout"] <= v["heldout_threshold"]["rms"]
    assert "Undetermined" in markdown(res)


if __name__ == "__main__":    # pragma: no cover
    pytest.main([__file__, "-s"])
