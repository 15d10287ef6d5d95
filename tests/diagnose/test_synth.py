"""The synthetic-data generator: instrument reading (noise, rounding, rate),
the dataset format, the hidden extension and its magnitude."""
import os

import numpy as np
import pytest

from acausal.studies.calibrate import model_dataset
from acausal.diagnose.synth import synthesize
from acausal.modelfile import compile_file
from acausal.errors import UsageError

HERE = os.path.dirname(__file__)
LATCH = os.path.join(HERE, "..", "..", "models", "latch_striker.py")
STUB = "tests.diagnose.stub_library"
COND = {"F_coil": [20.0, 30.0, 40.0]}


def test_null_dataset_reads_like_the_instrument(tmp_path):
    q, s = 4e-6, 6e-6
    truth = synthesize(LATCH, tmp_path, conditions=COND, traces=["latch.s"],
                       measures=["trip_time"], sample_rate=20e3,
                       noise={"latch.s": s, "trip_time": 2e-5},
                       resolution={"latch.s": q, "trip_time": 1e-5},
                       units={"time": "ms", "latch.s": "mm", "trip_time": "ms"}, seed=4)
    assert truth.hypothesis is None and truth.values == {} and truth.effect == 0.0
    assert sorted(os.listdir(tmp_path)) == ["E01.csv", "E02.csv", "E03.csv",
                                            "experiments.csv", "instrument.csv"]
    ds = model_dataset(LATCH, tmp_path)
    assert [e.conditions["F_coil"] for e in ds.experiments] == COND["F_coil"]
    assert ds.instrument["latch.s"].resolution == pytest.approx(q)
    assert ds.instrument["latch.s"].noise_std == pytest.approx(s)
    mf, cm = compile_file(LATCH)
    errs = []
    for e in ds.experiments:
        tr = e.trace
        assert np.allclose(np.diff(tr.time), 5e-5)              # 20 kHz
        y = tr.signals["latch.s"]
        assert np.allclose(y / q, np.round(y / q), atol=1e-6)   # rounded to q
        res = cm.simulate(params={**truth.free, **e.conditions}, **mf.experiment.run_options())
        assert tr.time[-1] <= res.t[-1] + 1e-12
        errs.append(y - np.interp(tr.time, res.t, res["latch.s"]))
        assert e.measures["trip_time"] / 1e-5 == pytest.approx(
            round(e.measures["trip_time"] / 1e-5), abs=1e-6)
    err = np.concatenate(errs)
    floor = ds.instrument["latch.s"].floor()
    assert abs(np.mean(err)) < 4 * floor / np.sqrt(err.size)
    assert np.std(err) == pytest.approx(floor, rel=0.15)


def test_free_parameters_jittered_within_bounds(tmp_path):
    t = synthesize(LATCH, tmp_path, conditions=COND, measures=["trip_time"],
                   noise={"trip_time": 1e-5}, free_jitter=0.3, seed=5)
    mf, _ = compile_file(LATCH)
    for name, (lo, hi) in mf.free.items():
        assert lo <= t.free[name] <= hi
    assert t.free["latch_damper.d"] != 4.0


def test_effect_is_solved_for(tmp_path):
    t = synthesize(LATCH, tmp_path, conditions=COND, hypothesis="quadratic_damping",
                   location="latch", effect=(4.0, 4.0), traces=["latch.s"],
                   sample_rate=20e3, noise={"latch.s": 5e-6}, seed=6, library=STUB)
    assert t.location == "latch"
    assert t.effect == pytest.approx(4.0, rel=0.03)
    assert t.values["quadratic_damping__latch"] > 0


def test_magnitude_range_and_seed(tmp_path):
    kw = dict(conditions=COND, hypothesis="constant_load", location="plunger",
              magnitude=(0.5, 2.0), sign=-1.0, measures=["trip_time"],
              noise={"trip_time": 1e-5}, seed=7, library=STUB)
    a = synthesize(LATCH, tmp_path / "a", **kw)
    b = synthesize(LATCH, tmp_path / "b", **kw)
    v = a.values["constant_load__plunger"]
    assert -2.0 <= v <= -0.5
    assert a.values == b.values
    assert (tmp_path / "a" / "experiments.csv").read_text() == \
        (tmp_path / "b" / "experiments.csv").read_text()


def test_bad_requests(tmp_path):
    with pytest.raises(UsageError, match="at least one measure or trace"):
        synthesize(LATCH, tmp_path, conditions=COND)
    with pytest.raises(UsageError, match="sample_rate"):
        synthesize(LATCH, tmp_path, conditions=COND, traces=["latch.s"])
    with pytest.raises(UsageError, match="no measure 'thrt'"):
        synthesize(LATCH, tmp_path, conditions=COND, measures=["thrt"])
    with pytest.raises(UsageError, match="values, magnitude or effect"):
        synthesize(LATCH, tmp_path, conditions=COND, measures=["trip_time"],
                   hypothesis="constant_load", location="latch", library=STUB)


def test_a_truth_whose_law_reduces_to_another_member_names_it():
    """Stribeck friction drawn with no static excess is Coulomb friction (and
    Coulomb + viscous with b = 0): naming either names the truth; with a
    static excess it is neither (benchmarks/detection_power.py's judgement)."""
    from acausal.diagnose.synth import Truth, same_law_members
    slider = os.path.join(HERE, "slider_model.py")
    read = dict(conditions={"s0": [0.1, -0.05], "v0": [0.0, 0.3]}, traces=["mass.s"],
                sample_rate=500.0, noise={"mass.s": 1e-4})
    free = {"spring.c": 90.0}
    plain = Truth("stribeck_friction", "mass", {"hyp_sf.F": 2.0, "hyp_sf.dF": 0.0,
                                                "hyp_sf.v_s": 0.05}, free)
    assert sorted(same_law_members(slider, plain, **read)) == [
        ("coulomb_friction", "mass"), ("coulomb_viscous_friction", "mass")]
    excess = Truth("stribeck_friction", "mass", {"hyp_sf.F": 2.0, "hyp_sf.dF": 1.0,
                                                 "hyp_sf.v_s": 0.05}, free)
    assert same_law_members(slider, excess, **read) == []
    assert same_law_members(slider, Truth("constant_load", "mass", {"hyp_cl.F": 1.0},
                                          free), **read) == []
    assert same_law_members(slider, Truth(None, None), **read) == []


@pytest.mark.parametrize("hyp, seed", [("stribeck_friction", 3), ("coulomb_viscous_friction", 4),
                                       ("power_drag", 5)])
def test_a_family_member_truth_is_its_own_law_at_the_requested_effect(tmp_path, hyp, seed):
    """A member's truth has its own parameters away from the values at
    which it reduces to its family's head (Stribeck's static excess > 0,
    the viscous term b > 0, the drag exponent n != 2), the magnitude ones in
    proportion to the first, and the effect solved for with all of them."""
    from acausal.diagnose.synth import same_law_members
    slider = os.path.join(HERE, "slider_model.py")
    read = dict(conditions={"s0": [0.1, -0.05], "v0": [0.0, 0.3]}, traces=["mass.s"],
                sample_rate=500.0, noise={"mass.s": 1e-4})
    t = synthesize(slider, tmp_path, hypothesis=hyp, location="mass", effect=(6.0, 6.0),
                   seed=seed, **read)
    assert t.effect == pytest.approx(6.0, rel=0.03)
    v = {k.partition(".")[2]: x for k, x in t.values.items()}
    if hyp == "stribeck_friction":
        assert v["F"] > 0 and v["dF"] > 0
    elif hyp == "coulomb_viscous_friction":
        assert v["F"] > 0 and v["b"] > 0
    else:
        assert v["c"] > 0 and abs(v["n"] - 2.0) > 0.2
    # the truth's law does not reduce to another member of its family
    assert same_law_members(slider, t, **read) == []
