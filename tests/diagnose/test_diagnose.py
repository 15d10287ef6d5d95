"""Blind cases: synthetic data from a truth with a hidden extension; the
diagnosis sees only the nominal model file and the data folder.

Fast tier (CI): a small blind case and a null case on the latch striker
with the library restricted to three hypotheses at the latch's two bodies
(six candidates), and the command line. The slow tier (``pytest -m slow``) runs every
hypothesis of the library on the breaker and on the latch striker, and
counts false positives over noise-only datasets.
"""
import json
import os
import pickle

import pytest
from click.testing import CliRunner

from acausal.cli import main
from acausal.runtime.model import CompiledModel
from acausal.diagnose.problem import FitSettings
from acausal.diagnose.report.markdown import write_report
from acausal.diagnose.report.result import summary
from acausal.diagnose.run import diagnose, run_stages
from acausal.diagnose.synth import synthesize

HERE = os.path.dirname(__file__)
LATCH = os.path.abspath(os.path.join(HERE, "..", "..", "models", "latch_striker.py"))
FAST = ["coulomb_friction", "quadratic_damping", "constant_load"]
# the fast tier's fits: two Latin-hypercube starts, the best refined (the
# full method's defaults are 4 and 2: slow tier and command-line default)
LIGHT = FitSettings(lhs=2, refine=1)
LIGHT_CLI = ["--starts", "2", "--refine", "1"]
KEYS = {"discrepancy", "cause", "location", "equivalent_causes", "parameters", "ranking",
        "gain", "extended_model", "causes", "unexplained", "next_experiment", "profile_ci95",
        "cause_class", "notes", "failed", "verdict"}


def _latch_data(folder, seed, **kw):
    return synthesize(LATCH, folder, conditions={"F_coil": [20.0, 32.0, 45.0]},
                      traces=["latch.s"], sample_rate=20e3, noise={"latch.s": 5e-6},
                      resolution={"latch.s": 5e-6}, units={"time": "ms", "latch.s": "mm"},
                      free_jitter=0.1, seed=seed, **kw)


@pytest.fixture(scope="module")
def blind(tmp_path_factory):
    d = tmp_path_factory.mktemp("blind")
    truth = _latch_data(d / "data", 11, hypothesis="coulomb_friction", location="latch",
                        effect=(6.0, 6.0))
    # the stages, then the report from a pickled copy of the result with the
    # simulator disabled: the result is picklable and the report a pure view
    res = run_stages(LATCH, d / "data", out_dir=d / "out", workers=2, progress=False,
                     hypotheses=FAST, settings=LIGHT, families=False)
    res = pickle.loads(pickle.dumps(res))

    def no_simulation(*a, **k):
        raise AssertionError("the report simulated")
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(CompiledModel, "simulate", no_simulation)
        write_report(d / "out", res)
    out = summary(res)
    (d / "out" / "diagnosis.json").write_text(json.dumps(out, indent=1))
    return truth, out, d / "out"


def test_blind_case_names_the_hidden_cause(blind):
    truth, out, folder = blind
    assert set(out) == KEYS
    assert out["discrepancy"] is True
    assert out["cause"] == truth.hypothesis and out["location"] == truth.location
    name = "hyp_cf.F"
    got = out["parameters"][name]
    assert got["value"] == pytest.approx(truth.values[name], rel=0.25)
    lo, hi = got["ci95"]
    assert lo < got["value"] < hi
    assert out["gain"]["after"]["heldout"] <= 2.0
    assert out["gain"]["after"]["heldout"] < out["gain"]["before"]["heldout"]
    assert len(out["ranking"]) == 6
    assert out["ranking"][0] == {"cause": "coulomb_friction", "location": "latch",
                                 "aicc": out["ranking"][0]["aicc"],
                                 "heldout_rmse": out["ranking"][0]["heldout_rmse"],
                                 "heldout_whitened": out["ranking"][0]["heldout_whitened"],
                                 "heldout_directional": out["ranking"][0]["heldout_directional"]}
    # the whitened held-out error never exceeds the plain one; its part within
    # the parameters' directions: one statistic per experiment, on the cause's
    # and the free parameters' columns, a p-value for a right law
    assert 0.5 < out["ranking"][0]["heldout_whitened"] <= out["ranking"][0]["heldout_rmse"]
    dirn = out["ranking"][0]["heldout_directional"]
    assert len(dirn["folds"]) >= 2
    assert all(1 <= f["dof"] <= 6 and f["stat"] >= 0 for f in dirn["folds"].values())
    assert 0.01 <= dirn["p"] <= 1.0 and dirn["worst"] in dirn["folds"]
    assert out["extended_model"] and os.path.exists(out["extended_model"])
    assert out["causes"] == [{"cause": "coulomb_friction", "location": "latch",
                              "family": "friction", "member": "coulomb_friction",
                              "parameters": {name: out["parameters"][name]},
                              "equivalent_sites": [], "site_reason": None}]
    assert out["unexplained"]["value"] is False
    # one member in the class (or several cause classes and no condition declared):
    # the next experiment says so instead of a null
    nxt = out["next_experiment"]
    assert nxt["members"][0] == "coulomb_friction at latch"
    assert nxt["computed"] is (len(nxt["members"]) > 1)
    assert set(out["profile_ci95"]) == set(out["parameters"])
    for p in out["profile_ci95"].values():
        assert p["of"] == "coulomb_friction at latch" and p["ci95"][0] < p["value"]


def test_blind_case_report(blind):
    _, out, folder = blind
    text = (folder / "report.md").read_text()
    assert "cause: coulomb_friction at `latch`" in text
    for png in ("residuals.png", "ranking.png", "fitted.png"):
        assert (folder / png).stat().st_size > 1000
    assert json.loads((folder / "diagnosis.json").read_text()) == out


def test_null_case_and_command_line(tmp_path):
    _latch_data(tmp_path / "data", 12)
    r = CliRunner().invoke(main, ["diagnose", LATCH, str(tmp_path / "data"), "--json",
                                  str(tmp_path / "out.json"), "--report",
                                  str(tmp_path / "rep"), "--workers", "2", "--no-progress",
                                  "--hypotheses", ",".join(FAST), *LIGHT_CLI])
    assert r.exit_code == 0, r.output
    out = json.loads((tmp_path / "out.json").read_text())
    assert set(out) == KEYS
    assert out["discrepancy"] is False
    assert out["cause"] is None and out["location"] is None
    assert out["extended_model"] is None and out["equivalent_causes"] == []
    assert out["gain"]["after"] == out["gain"]["before"]
    assert "no significant discrepancy" in r.output
    assert "No significant discrepancy" in (tmp_path / "rep" / "report.md").read_text()


def test_command_line_bad_input(tmp_path):
    r = CliRunner().invoke(main, ["diagnose", LATCH, str(tmp_path / "none")])
    assert r.exit_code == 2
    assert "experiments.csv: file not found" in r.output
    _latch_data(tmp_path / "data", 13)
    r = CliRunner().invoke(main, ["diagnose", LATCH, str(tmp_path / "data"),
                                  "--hypotheses", "gremlins", "--no-progress"])
    assert r.exit_code == 2
    assert "unknown hypothesis 'gremlins'" in r.output
    r = CliRunner().invoke(main, ["diagnose", LATCH, str(tmp_path / "data"), "--workers",
                                  "0", "--no-progress"])
    assert r.exit_code == 2 and "workers" in r.output


def test_extended_model_runs_with_the_fitted_values(blind):
    """The written model file reproduces the fitted model's simulation."""
    from acausal.modelfile import compile_file, run_file
    truth, out, folder = blind
    mf, cm = compile_file(out["extended_model"])
    vals = {p.name: p.default for p in cm.params}
    for name, d in out["parameters"].items():
        assert vals[name] == pytest.approx(d["value"], rel=1e-12)
    res, meas = run_file(out["extended_model"], params={"F_coil": 32.0})
    assert meas["trip_time"] > 0


# ---------------------------------------------------------------------------
# Slow tier: every hypothesis on two mechanisms, and false positives
# ---------------------------------------------------------------------------

BREAKER = os.path.abspath(os.path.join(HERE, "..", "..", "models", "breaker_24kv.py"))
SETUPS = {
    # hook angle (0.02 deg steps) and armature travel (10 um steps) at 50 kHz
    "breaker": dict(path=BREAKER, conditions={"v_impact": [3.3, 3.5, 3.8, 4.0, 4.2, 4.5]},
                    traces=["hook.phi", "armature.mass.s"], sample_rate=50e3,
                    noise={"hook.phi": 3e-4, "armature.mass.s": 1e-5},
                    resolution={"hook.phi": 3.5e-4, "armature.mass.s": 1e-5},
                    units={"time": "ms", "hook.phi": "deg", "armature.mass.s": "mm"}),
    "latch": dict(path=LATCH, conditions={"F_coil": [20.0, 28.0, 36.0, 45.0]},
                  traces=["plunger.s", "latch.s"], sample_rate=20e3,
                  noise={"plunger.s": 5e-6, "latch.s": 5e-6},
                  resolution={"plunger.s": 5e-6, "latch.s": 5e-6},
                  units={"time": "ms", "plunger.s": "mm", "latch.s": "mm"}),
}
# (model, hypothesis, location, effect): the effect is the RMS change the hidden
# extension makes to the data in noise-floor units; where the library's bound
# on the parameter caps it (a stiffer wipe spring, a flexible contact arm) 5.
SLOW_CASES = [
    ("breaker", "coulomb_friction", "hook.body", 8.0),
    ("breaker", "quadratic_damping", "hook.body", 8.0),
    ("breaker", "constant_load", "armature.mass", 8.0),
    ("breaker", "hardening_spring", "main_shaft.wipe_spring", 5.0),
    ("breaker", "clearance", "contact", 8.0),
    ("breaker", "flexible_link", "hook.body:hook.arm3", 5.0),
    ("breaker", "position_dependent_force", "armature.coil", 8.0),
    ("breaker", "contact_damping_law", "contact", 8.0),
    ("latch", "coulomb_friction", "latch", 8.0),
    ("latch", "quadratic_damping", "plunger", 8.0),
    ("latch", "constant_load", "plunger", 8.0),
    # the return spring: within the library's bound (cubic force at most the
    # linear force at the typical deflection) the latch spring's cubic term
    # changes the data by only 0.9 floor units, too little for a blind case
    ("latch", "hardening_spring", "ret", 8.0),
    ("latch", "clearance", "contact", 8.0),
    ("latch", "flexible_link", "latch:contact", 8.0),
    ("latch", "position_dependent_force", "coil", 8.0),
    ("latch", "contact_damping_law", "contact", 8.0),
]


def blind_case(tmp, model, hyp, loc, effect=8.0, seed=0, **kw):
    """Synthesize (truth hidden), diagnose, and return (truth, summary, details)."""
    setup = SETUPS[model]
    truth = synthesize(setup["path"], tmp / "data", hypothesis=hyp, location=loc,
                       effect=None if hyp is None else (effect, effect), free_jitter=0.1,
                       seed=seed, **{k: v for k, v in setup.items() if k != "path"})
    out = diagnose(setup["path"], tmp / "data", out_dir=tmp / "out", workers=2,
                   progress=False, **kw)
    details = json.loads((tmp / "out" / "candidates.json").read_text())
    return truth, out, details


@pytest.mark.slow
@pytest.mark.parametrize("model,hyp,loc,effect", SLOW_CASES,
                         ids=[f"{m}-{h}" for m, h, _, _ in SLOW_CASES])
def test_blind_every_hypothesis(tmp_path, model, hyp, loc, effect):
    truth, out, details = blind_case(tmp_path, model, hyp, loc, effect=effect,
                                     seed=100 + SLOW_CASES.index((model, hyp, loc, effect)))
    first = next(iter(truth.values))
    row = next(c for c in details["candidates"] if (c["cause"], c["location"]) == (hyp, loc))
    print(f"BLIND {model} {hyp} at {loc}: effect {truth.effect:.2f}; named "
          f"{out['cause']} at {out['location']}, class {out['equivalent_causes']}; "
          f"{first} truth {truth.values[first]:.4g} fitted {row['values'][first]:.4g} "
          f"ci {row['ci95'][first]}; held-out {out['gain']['before']['heldout']:.3f} -> "
          f"{out['gain']['after']['heldout']:.3f}; {details['timing']['total_s']:.0f} s")
    assert truth.effect > 4.0            # the hidden effect matters against the noise
    assert out["discrepancy"] is True
    members = [(out["cause"], out["location"])] + [(e["cause"], e["location"])
                                                  for e in out["equivalent_causes"]]
    assert (hyp, loc) in members, (members, out["ranking"][:3])
    assert row["values"][first] == pytest.approx(truth.values[first], rel=0.25)
    assert out["gain"]["after"]["heldout"] <= 2.0


@pytest.mark.slow
def test_false_positive_rate_on_null_datasets(tmp_path):
    """12 noise-only datasets on the latch striker, the full library: fewer
    than 10 % may declare a discrepancy (alpha = 0.01)."""
    hits = []
    for seed in range(12):
        d = tmp_path / f"n{seed}"
        _, out, _ = blind_case(d, "latch", None, None, seed=500 + seed, exact_cv=False,
                               plots=False)
        hits.append(out["discrepancy"])
        print(f"NULL seed {500 + seed}: discrepancy {out['discrepancy']}, "
              + ", ".join(f"{p['name']} p {p['p_value']:.3g}"
                          for p in json.loads((d / "out" / "candidates.json").read_text())
                          ["decision"]["parts"]))
        assert out["cause"] is None or out["discrepancy"]
    assert sum(hits) / len(hits) < 0.10, hits


# ---------------------------------------------------------------------------
# The report's measured data (issue acceptance: the command runs and writes
# its files); the fast tier restricts the library to two candidates, the
# slow tier runs the full library as a new user would.
# ---------------------------------------------------------------------------

REPORT_DATA = os.path.abspath(os.path.join(HERE, "..", "..", "data", "report_24kv"))


def _report_diagnosis(tmp_path, *restrict):
    r = CliRunner().invoke(main, ["diagnose", BREAKER, REPORT_DATA, "--json-file",
                                  str(tmp_path / "out.json"), "--report", str(tmp_path / "rep"),
                                  "--workers", "2", "--no-progress", *restrict])
    assert r.exit_code == 0, r.output
    out = json.loads((tmp_path / "out.json").read_text())
    assert set(out) == KEYS
    assert (tmp_path / "rep" / "report.md").stat().st_size > 1000
    # six 0.1 ms THRT readings and one contact period: a discrepancy may be
    # found, but no cause can be named with confidence. Since issue 24 (a
    # name must explain the held-out data) that is no discrepancy, weak
    # evidence, or "not explained by the library" when the best candidate's
    # held-out error is above what noise alone reaches (the restricted
    # library: constant load at the hook, 3.9 floors against 2.19)
    assert out["cause"] is None
    report = (tmp_path / "rep" / "report.md").read_text()
    verdict = out["verdict"]
    assert verdict["kind"] in ("no_discrepancy", "weak", "not_explained"), verdict
    assert (verdict["kind"] == "no_discrepancy") == (out["discrepancy"] is False)
    if verdict["kind"] == "weak":
        assert "evidence is weak" in report
    if verdict["kind"] == "not_explained":
        assert "Discrepancy not explained by the library" in report
        if any(r["code"] == "heldout" for r in verdict["reasons"]):
            assert verdict["heldout_rmse"] > verdict["heldout_threshold"]["rms"]
            assert all(c["heldout_rmse"] > verdict["heldout_threshold"]["rms"]
                       for c in verdict["candidates"] if c["heldout_rmse"] is not None)
    before, after = out["gain"]["before"], out["gain"]["after"]
    assert after["train"] <= before["train"] + 1e-9
    return out


@pytest.mark.slow   # 2-3 min on 2 cores: the six-voltage calibration dominates
def test_report_data_diagnosis_restricted(tmp_path):
    out = _report_diagnosis(tmp_path, "--hypotheses", "flexible_link,constant_load",
                            "--locations", "hook.body,hook.body:cam")
    allowed = {("flexible_link", "hook.body:cam"), ("constant_load", "hook.body")}
    rows = [(r["cause"], r["location"]) for r in out["ranking"]]
    # both singles fitted; any pair the search added is made of them alone
    assert allowed <= set(rows)
    for cause, location in rows:
        assert set(zip(cause.split("+"), location.split("+"))) <= allowed


@pytest.mark.slow
def test_report_data_diagnosis_full_library(tmp_path):
    out = _report_diagnosis(tmp_path)
    from acausal.diagnose.run import candidates
    offered = {(h, loc) for h, loc, _ in candidates(BREAKER)[2]}
    assert len(offered) == 20
    # every candidate the model graph offers is fitted and ranked; family
    # members and pairs (the best single leaves misfit) come on top of them
    singles = {(r["cause"], r["location"]) for r in out["ranking"] if "+" not in r["cause"]}
    assert offered <= singles


@pytest.mark.slow   # 25-30 s on 2 cores (a LocalCluster beside the fits); the sweep's Dask test stays in the default tier
def test_candidate_fits_on_a_dask_cluster_match_local_processes(tmp_path):
    """``--scheduler ADDRESS``: the same fits through Dask give the same
    diagnosis as the local process pool (the fits are deterministic)."""
    distributed = pytest.importorskip("distributed")
    _latch_data(tmp_path / "data", 14, hypothesis="constant_load", location="plunger",
                effect=(6.0, 6.0))
    kw = dict(progress=False, hypotheses=["constant_load", "quadratic_damping"],
              locations=["plunger"], plots=False, settings=LIGHT)
    local = diagnose(LATCH, tmp_path / "data", out_dir=tmp_path / "local", workers=2, **kw)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        r = CliRunner().invoke(main, ["diagnose", LATCH, str(tmp_path / "data"), "--json",
                                      str(tmp_path / "dask.json"), "--report",
                                      str(tmp_path / "dask"), "--scheduler",
                                      cluster.scheduler_address, "--no-progress",
                                      "--hypotheses", "constant_load,quadratic_damping",
                                      "--locations", "plunger", *LIGHT_CLI])
    assert r.exit_code == 0, r.output
    remote = json.loads((tmp_path / "dask.json").read_text())
    assert remote["cause"] == local["cause"] == "constant_load"
    assert remote["ranking"] == local["ranking"]
    assert remote["parameters"] == local["parameters"]
