"""Tests of acausal.data: the report's dataset, units, errors, write/load round trip."""
import csv
import math
from pathlib import Path

import numpy as np
import pytest

from acausal.data import (DataError, Dataset, MeasuredExperiment, Instrument, Trace,
                          load_dataset, write_dataset)

ROOT = Path(__file__).resolve().parents[2]
REPORT = ROOT / "data" / "report_24kv"
PARAMETERS = {"v_impact": "m/s"}
MEASURES = {"thrt": "s", "contact_period": "s"}


def make(folder: Path, **files: str) -> Path:
    """Write files given as keyword name=text (``experiments`` -> experiments.csv)."""
    folder.mkdir(parents=True, exist_ok=True)
    for stem, text in files.items():
        (folder / f"{stem}.csv").write_text(text)
    return folder


# --- the report's measurements -----------------------------------------------

def test_report_dataset_in_si():
    data = load_dataset(REPORT, parameters=PARAMETERS, measures=MEASURES)
    assert [e.name for e in data.experiments] == [
        "V090", "V100", "V110", "V120", "V130", "V140"]
    assert data.condition_names == ["v_impact"]
    assert data.measure_names == ["thrt", "contact_period"]
    v110 = data.experiment("V110")
    assert v110.conditions == {"v_impact": pytest.approx(3.8)}
    assert v110.measures["thrt"] == pytest.approx(1.9e-3, rel=1e-12)
    assert v110.measures["contact_period"] == pytest.approx(3e-4, rel=1e-12)
    assert all("contact_period" not in e.measures
               for e in data.experiments if e.name != "V110")
    assert [e.conditions["v_impact"] for e in data.experiments] == pytest.approx(
        [3.3, 3.5, 3.8, 4.0, 4.2, 4.5])
    assert data.instrument["thrt"].resolution == pytest.approx(1e-4, rel=1e-12)
    assert data.instrument["contact_period"].resolution == pytest.approx(1e-4)
    assert data.instrument["thrt"].floor() == pytest.approx(1e-4 / math.sqrt(12))


def test_report_dataset_matches_table2_copy():
    data = load_dataset(REPORT, parameters=PARAMETERS, measures=MEASURES)
    with open(ROOT / "data" / "report" / "table2_thrt.csv") as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    for row in rows:
        e = data.experiment(f"V{int(row['voltage_V']):03d}")
        assert e.conditions["v_impact"] == pytest.approx(float(row["impact_velocity_m_s"]))
        assert e.measures["thrt"] == pytest.approx(float(row["measured_thrt_ms"]) * 1e-3)


# --- units ---------------------------------------------------------------------

def test_unit_conversion(tmp_path):
    make(tmp_path,
         experiments="name,gap [mm],angle [deg],t [ms],e [-],K [N/mm**1.5]\n"
                     "a,2,90,1.5,0.7,1\n",
         a="time [ms],hook.phi [deg],x [mm]\n0,0,1\n0.5,180,2\n",
         instrument="signal,unit,resolution,noise_std\n"
                    "t,ms,0.1,0.05\nhook.phi,deg,0.5,\nx,,1e-6,2e-6\n")
    data = load_dataset(tmp_path, parameters={"gap": "m", "angle": "rad", "e": "",
                                              "K": "N/m**1.5"},
                        measures={"t": "s"}, variables={"hook.phi": "rad", "x": "m"})
    a = data.experiment("a")
    assert a.conditions["gap"] == pytest.approx(2e-3)
    assert a.conditions["angle"] == pytest.approx(math.pi / 2)
    assert a.conditions["e"] == pytest.approx(0.7)
    assert a.conditions["K"] == pytest.approx(1e3 ** 1.5)
    assert a.measures["t"] == pytest.approx(1.5e-3)
    assert a.trace.time == pytest.approx([0.0, 5e-4])
    assert a.trace.signals["hook.phi"] == pytest.approx([0.0, math.pi])
    assert a.trace.signals["x"] == pytest.approx([1e-3, 2e-3])
    assert data.instrument["t"].resolution == pytest.approx(1e-4)
    assert data.instrument["t"].noise_std == pytest.approx(5e-5)
    assert data.instrument["hook.phi"].resolution == pytest.approx(math.radians(0.5))
    assert data.instrument["hook.phi"].noise_std == 0.0
    assert data.instrument["x"].floor() == pytest.approx(math.hypot(2e-6, 1e-6 / math.sqrt(12)))


def test_roles_without_mappings(tmp_path):
    make(tmp_path, experiments="name,v_impact,thrt\na,3,\n")
    assert load_dataset(tmp_path).experiment("a").measures == {"v_impact": 3.0}
    only_measures = load_dataset(tmp_path, measures=["thrt"]).experiment("a")
    assert (only_measures.conditions, only_measures.measures) == ({"v_impact": 3.0}, {})


def test_comments_and_blank_lines_keep_line_numbers(tmp_path):
    make(tmp_path, experiments="# a comment\n\nname,v\n# another, with a comma\na,1\n\nb,2\n")
    data = load_dataset(tmp_path, parameters=["v"], measures=[])
    assert [(e.name, e.line) for e in data.experiments] == [("a", 5), ("b", 7)]


# --- errors: file, line and column in every message --------------------------

EXP = "name,v [m/s],thrt [ms]\n"
CASES = {
    "no name column": (dict(experiments="id,v\na,1\n"), "experiments", 1, "name",
                       "missing column"),
    "duplicate name": (dict(experiments=EXP + "a,1,2\nb,1,2\na,1,3\n"), "experiments",
                       4, "name", "duplicate experiment 'a' (first on line 2)"),
    "unknown column": (dict(experiments="name,v,foo\na,1,2\n"), "experiments", 1,
                       "foo", "unknown parameter or measure 'foo'"),
    "wrong unit": (dict(experiments="name,v,thrt [m]\na,1,2\n"), "experiments", 1,
                   "thrt", "wrong unit: 'thrt [m]' is a length, 'thrt' is a time [s]"),
    "angle unit": (dict(experiments="name,v [deg],thrt\na,1,2\n"), "experiments", 1,
                   "v", "wrong unit: 'v [deg]' is an angle, 'v' is a velocity [m/s]"),
    "bad unit": (dict(experiments="name,v [m/],thrt\na,1,2\n"), "experiments", 1, "v",
                 "cannot read unit [m/]"),
    "undefined unit": (dict(experiments="name,v [furlongs/fortnite],thrt\na,1,2\n"),
                       "experiments", 1, "v", "cannot read unit"),
    "bad header": (dict(experiments="name,v [m/s,thrt\na,1,2\n"), "experiments", 1,
                   "v [m/s", "cannot read header"),
    "duplicate column": (dict(experiments="name,v,v\na,1,2\n"), "experiments", 1, "v",
                         "duplicate column"),
    "nan": (dict(experiments=EXP + "a,1,2\nb,1,nan\n"), "experiments", 3, "thrt",
            "'nan' is not a finite number"),
    "inf": (dict(experiments=EXP + "a,-inf,2\n"), "experiments", 2, "v",
            "'-inf' is not a finite number"),
    "not a number": (dict(experiments=EXP + "a,1,2\nb,fast,2\n"), "experiments", 3,
                     "v", "not a number: 'fast'"),
    "too few cells": (dict(experiments=EXP + "a,1\n"), "experiments", 2, "thrt",
                      "row has 2 cells, header has 3"),
    "too many cells": (dict(experiments=EXP + "a,1,2,3\n"), "experiments", 2, None,
                       "row has 4 cells, header has 3"),
    "missing condition": (dict(experiments=EXP + "a,1,2\nb,,2\n"), "experiments", 3,
                          "v", "missing value"),
    "bad name": (dict(experiments=EXP + "instrument,1,2\n"), "experiments", 2, "name",
                 "bad experiment name 'instrument'"),
    "trace without time": (dict(experiments=EXP + "a,1,2\n", a="t,x\n0,1\n"), "a", 1,
                           "time", "missing column"),
    "trace without samples": (dict(experiments=EXP + "a,1,2\n", a="time,x\n"), "a", 1,
                              None, "no samples"),
    "unknown variable": (dict(experiments=EXP + "a,1,2\n", a="time,x,y\n0,1,2\n"), "a",
                         1, "y", "unknown variable 'y'"),
    "time unit": (dict(experiments=EXP + "a,1,2\n", a="time [m],x\n0,1\n"), "a", 1,
                  "time", "wrong unit: 'time [m]' is a length, 'time' is a time [s]"),
    "time not increasing": (dict(experiments=EXP + "a,1,2\n",
                                 a="time [ms],x\n0,1\n# c\n1,1\n1,2\n3,2\n"), "a", 5,
                            "time", "time does not increase (0.001 s after 0.001 s)"),
    "empty trace cell": (dict(experiments=EXP + "a,1,2\n", a="time,x\n0,1\n1,\n"), "a",
                         3, "x", "missing value"),
    "orphan trace": (dict(experiments=EXP + "a,1,2\n", b="time,x\n0,1\n"), "b", None,
                     None, "trace of unknown experiment 'b'"),
    "instrument signal": (dict(experiments=EXP + "a,1,2\n",
                               instrument="signal,resolution\nthrt,1e-4\nfoo,1\n"),
                          "instrument", 3, "signal", "unknown signal 'foo'"),
    "instrument unit": (dict(experiments=EXP + "a,1,2\n",
                             instrument="signal,unit,resolution\nthrt,mm,0.1\n"),
                        "instrument", 2, "unit",
                        "wrong unit: 'mm' is a length, 'thrt' is a time [s]"),
    "instrument header unit": (dict(experiments=EXP + "a,1,2\n",
                                    instrument="signal,noise_std [V]\nthrt,0.1\n"),
                               "instrument", 2, "noise_std",
                               "wrong unit: 'noise_std [V]' is a voltage, 'thrt' is a time [s]"),
    "instrument two units": (dict(experiments=EXP + "a,1,2\n",
                                  instrument="signal,unit,resolution [ms]\nthrt,ms,1\n"),
                             "instrument", 1, "unit",
                             "give units in the 'unit' column or in the headers, not both"),
    "instrument column": (dict(experiments=EXP + "a,1,2\n",
                               instrument="signal,precision\nthrt,1\n"), "instrument",
                          1, "precision", "unknown column"),
    "bad use": (dict(experiments="name,v,thrt,use\na,1,2,\nb,1,2,check\n"), "experiments",
                3, "use", "use 'check': expected 'calibrate' or 'validate'"),
    "use with unit": (dict(experiments="name,v,thrt,use [s]\na,1,2,\n"), "experiments",
                      1, "use", "the use column takes no unit"),
    "negative resolution": (dict(experiments=EXP + "a,1,2\n",
                                 instrument="signal,resolution\nthrt,-1\n"),
                            "instrument", 2, "resolution", "negative resolution"),
}


@pytest.mark.parametrize("case", CASES)
def test_error_names_file_line_column(tmp_path, case):
    files, stem, line, column, reason = CASES[case]
    make(tmp_path, **files)
    with pytest.raises(DataError) as info:
        load_dataset(tmp_path, parameters={"v": "m/s"}, measures={"thrt": "s"},
                     variables={"x": "m"})
    err, path = info.value, tmp_path / f"{stem}.csv"
    assert (err.file, err.line, err.column) == (path, line, column)
    where = str(path) + ("" if line is None else f":{line}") + ": "
    where += "" if column is None else f"column '{column}': "
    assert str(err).startswith(where + reason), str(err)


def test_data_error_pickles_with_its_location():
    import pickle
    err = pickle.loads(pickle.dumps(DataError("missing value", Path("a.csv"), 3, "v")))
    assert (err.file, err.line, err.column, str(err)) == (
        Path("a.csv"), 3, "v", "a.csv:3: column 'v': missing value")


def test_missing_experiments_file(tmp_path):
    with pytest.raises(DataError, match="file not found") as info:
        load_dataset(tmp_path / "nowhere")
    assert str(info.value).startswith(str(tmp_path / "nowhere" / "experiments.csv"))


# --- writing -------------------------------------------------------------------

def _dataset() -> Dataset:
    time = np.linspace(0.0, 2e-3, 5)
    trace = Trace(time, {"hook.phi": np.radians([0.0, 1.0, 2.5, 4.0, 5.0]),
                         "armature.v": np.array([3.8, 3.0, 2.0, 1.1, 0.4])})
    experiments = [
        MeasuredExperiment("V110", {"v_impact": 3.8, "contact.K": 6.25e8},
                   {"thrt": 1.9e-3, "contact_period": 3e-4}, trace),
        MeasuredExperiment("V120", {"v_impact": 4.0, "contact.K": 6.25e8}, {"thrt": 1.7e-3},
                   use="validate"),
    ]
    instrument = {"thrt": Instrument("thrt", 1e-4),
                  "hook.phi": Instrument("hook.phi", math.radians(0.1), 1e-3)}
    return Dataset(None, experiments, instrument)


@pytest.mark.parametrize("units", [None, {"thrt": "ms", "contact_period": "ms",
                                          "time": "ms", "hook.phi": "deg",
                                          "contact.K": "N/mm"}])
def test_round_trip(tmp_path, units):
    original = _dataset()
    write_dataset(tmp_path / "out", original, units)
    loaded = load_dataset(tmp_path / "out", parameters=["v_impact", "contact.K"],
                          measures={"thrt": "s", "contact_period": "s"},
                          variables={"hook.phi": "rad", "armature.v": "m/s"})
    assert loaded.condition_names == original.condition_names
    assert loaded.measure_names == original.measure_names
    for a, b in zip(original.experiments, loaded.experiments):
        assert (a.name, a.use, a.conditions, a.measures) == (
            b.name, b.use, pytest.approx(b.conditions, rel=1e-14),
            pytest.approx(b.measures, rel=1e-14))
        assert (a.trace is None) == (b.trace is None)
    a, b = original.experiments[0].trace, loaded.experiments[0].trace
    assert b.time == pytest.approx(a.time, rel=1e-14)
    assert b.signals.keys() == a.signals.keys()
    for name in a.signals:
        assert b.signals[name] == pytest.approx(a.signals[name], rel=1e-14)
    assert loaded.instrument.keys() == original.instrument.keys()
    for signal, i in original.instrument.items():
        j = loaded.instrument[signal]
        assert (j.resolution, j.noise_std) == pytest.approx((i.resolution, i.noise_std),
                                                            rel=1e-14)
    if units is None:  # SI written with repr(): exact
        assert loaded.experiments[0].measures == original.experiments[0].measures
    else:
        assert "thrt [ms]" in (tmp_path / "out" / "experiments.csv").read_text()


def test_write_rejects_missing_condition(tmp_path):
    data = Dataset(None, [MeasuredExperiment("a", {"v": 1.0}), MeasuredExperiment("b", {})])
    with pytest.raises(DataError, match="'b' lacks a condition"):
        write_dataset(tmp_path, data)
