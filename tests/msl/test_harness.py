"""tests/msl/harness.py: on a synthetic reference folder (always), and the
vendored MSL reference files checked against experiments.csv (skipped where
the files are not present; see data/msl_reference/README.md)."""
import re

import numpy as np
import pytest

from tests.msl import harness
from tests.msl.harness import assert_matches, compare, experiments, load_reference, settings

HEADER = ("library,example,model,StartTime,StopTime,Tolerance,Interval,ref_StartTime,"
          "ref_StopTime,ref_Tolerance,ref_Interval,ref_method,ref_points,compared,"
          "reference,msl_source")


@pytest.fixture
def fake_reference(tmp_path, monkeypatch):
    """A reference folder with one example: x = sin(2 pi t), mode 1 -> 0 at 0.5."""
    (tmp_path / "Translational").mkdir()
    t = np.sort(np.concatenate([np.linspace(0, 1, 201), [0.5]]))
    x = np.sin(2 * np.pi * t)
    mode = np.where(t > 0.5, 0, 1)
    mode[np.searchsorted(t, 0.5) + 1] = 0          # the second point at 0.5 is after
    with open(tmp_path / "Translational" / "Fake.csv", "w") as fh:
        fh.write("time,body.x,body.mode\n")
        for row in zip(t, x, mode):
            fh.write(",".join(repr(float(v)) for v in row) + "\n")
    (tmp_path / "experiments.csv").write_text(
        HEADER + "\nTranslational,Fake,Modelica.Fake,,1.0,,0.005,0,1,1e-06,0.005,Dassl,202,"
        "body.x body.mode,Translational/Fake.csv,Modelica/Fake.mo\n")
    monkeypatch.setenv(harness.ENV, str(tmp_path))
    return t, x, mode


def test_settings_and_names(fake_reference):
    s = settings("Translational/Fake")
    assert s.name == "Translational.Fake" and s.stop_time == 1.0 and s.interval == 0.005
    assert s.tolerance is None and s.compared == ("body.x", "body.mode")
    assert harness.canonical("Fake") == "Translational.Fake"
    with pytest.raises(KeyError, match="no MSL example"):
        settings("Nope")


def test_a_matching_result_passes_with_names_and_functions(fake_reference):
    t = np.linspace(0, 1, 1001)
    res = {"time": t, "mass.s": np.sin(2 * np.pi * t),
           "friction.mode_code": np.where(t >= 0.5, 0.0, 1.0)}
    cmp = assert_matches("Fake", res, {"body.x": "mass.s",
                                       "body.mode": lambda r: r["friction.mode_code"]})
    assert cmp.passed and set(cmp.results) == {"body.x", "body.mode"}


def test_a_failure_names_signal_time_value_and_tube(fake_reference):
    t = np.linspace(0, 1, 1001)
    res = {"time": t, "mass.s": 1.01 * np.sin(2 * np.pi * t),
           "body.mode": np.where(t >= 0.6, 0.0, 1.0)}
    with pytest.raises(AssertionError) as err:
        assert_matches("Fake", res, {"body.x": "mass.s"})
    text = str(err.value)
    assert text.splitlines()[0] == "Translational.Fake: 0 of 2 compared signals inside the tube"
    assert re.search(r"body.x \(read as mass.s\): \d+ of 1001 points outside the tube; "
                     r"worst at t = 0\.[27]\d* s: value -?1\.00\d*, tube \[", text)
    assert "body.mode: " in text and "tube [" in text


def test_missing_signal_fails_and_skips_are_listed(fake_reference):
    t = np.linspace(0, 1, 1001)
    res = {"time": t, "body.x": np.sin(2 * np.pi * t)}
    cmp = compare("Fake", res)
    assert not cmp.passed and "body.mode" in cmp.missing
    assert "body.mode: missing from the result" in cmp.message()
    cmp = compare("Fake", res, skip={"body.mode": "no mode in this port"})
    assert cmp.passed and "skipped: no mode in this port" in cmp.message()
    with pytest.raises(KeyError, match="not 'body.y'"):
        compare("Fake", res, {"body.y": "x"})


def test_a_failed_simulation_says_so(fake_reference):
    class Stopped(dict):
        status = "failed"
        message = "IDA failed at t = 0.3"
    t = np.linspace(0, 0.3, 301)
    res = Stopped(time=t, **{"body.x": np.sin(2 * np.pi * t), "body.mode": np.ones(t.size)})
    cmp = compare("Fake", res)
    assert not cmp.passed
    assert "the simulation ended failed: IDA failed at t = 0.3" in cmp.message()
    assert "does not cover" in cmp.message()


# -- the vendored reference files ---------------------------------------------------

EXAMPLES = ["Translational." + e for e in
            "Oscillator Damper SignConvention InitialConditions Accelerate Friction "
            "ElastoGap Sensors WhyArrows Brake Vehicle".split()] + \
           ["Rotational." + e for e in
            "First FirstGrounded Friction Backlash OneWayClutch RollingWheel "
            "LossyGearDemo2 SimpleGearShift".split()] + \
           ["MultiBody.Pendulum", "MultiBody.DoublePendulum"]
# ported after issue #23, not listed in it (tests/msl/test_unlisted_examples.py)
UNLISTED = ["Rotational." + e for e in
            "ElasticBearing CoupledClutches LossyGearDemo1 LossyGearDemo3 "
            "OneWayClutchDisengaged".split()] + ["Translational.PreLoad"]


def test_experiments_csv_lists_the_21_examples_and_the_unlisted_ones():
    table = experiments()
    assert sorted(table) == sorted(EXAMPLES + UNLISTED)
    for s in table.values():
        assert s.ref_tolerance == 1e-6 and s.ref_method == "Dassl"
        assert s.start_time == 0.0 and s.stop_time > 0
        assert s.interval is None or s.ref_interval == pytest.approx(s.interval / 2)


@pytest.mark.parametrize("name", EXAMPLES + UNLISTED)
def test_reference_file_has_the_compared_signals_and_passes_itself(name):
    harness.reference_or_skip(name)
    s = settings(name)
    t, ref = load_reference(name)
    assert tuple(ref) == s.compared
    assert t[0] == s.start_time and t[-1] == pytest.approx(s.stop_time)
    assert np.all(np.diff(t) >= 0)
    cmp = assert_matches(name, {"time": t, **ref})
    assert len(cmp.results) == len(s.compared)
