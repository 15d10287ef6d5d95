"""The command line: JSON output, exit codes and messages of every error path."""
import json
import os
import textwrap

import numpy as np
import pytest
from click.testing import CliRunner

from acausal.cli import main
from tests.faults import helpers as h

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
EX = os.path.join(ROOT, "models", "examples")


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def test_simulate_json_oscillator_matches_closed_form():
    r = run("simulate", os.path.join(EX, "oscillator.py"), "--json")
    assert r.exit_code == 0, r.output
    out = json.loads(r.output)
    assert set(out) == {"final", "events", "measures", "missing", "units", "stats", "status",
                        "error"}
    assert out["error"] is None and out["status"] == "ok" and out["missing"] == {}
    assert out["units"]["final"]["mass.s"] == "m" and out["units"]["time"] == "s"
    assert {"nfev", "steps", "wall_s", "compile_s"} <= set(out["stats"])
    exact = 0.1 * np.cos(10.0)
    assert abs(out["final"]["mass.s"] / exact - 1) < 1e-6
    assert abs(out["final"]["spring.f"] - 100.0 * out["final"]["mass.s"]) < 1e-9


def test_simulate_json_lever_masses_matches_closed_form():
    r = run("simulate", os.path.join(EX, "lever_masses.py"), "--json")
    assert r.exit_code == 0, r.output
    f = json.loads(r.output)["final"]
    w = np.sqrt(1000 * 0.1**2 / (2 * 0.1**2 + 1 * 0.3**2))
    phi = 0.1 * np.cos(w * 1.0)
    assert abs(f["lever.phi"] / phi - 1) < 1e-6
    assert abs(f["m2.s"] / (0.3 * phi) - 1) < 1e-6


def test_simulate_events_and_measures_in_json():
    r = run("simulate", os.path.join(EX, "hertz_impact.py"), "--json")
    out = json.loads(r.output)
    names = [e["name"] for e in out["events"]]
    assert names[0] == "contact.onset" and "contact.release" in names
    assert abs(out["measures"]["contact_period"] / 3.21807e-4 - 1) < 1e-3


def test_set_writes_csv_and_plot(tmp_path):
    csv, png = tmp_path / "r.csv", tmp_path / "r.png"
    r = run("simulate", os.path.join(EX, "oscillator.py"), "--set", "spring.c=400",
            "--t-end", "0.5", "--out", csv, "--plot", png)
    assert r.exit_code == 0, r.output
    head = csv.read_text().splitlines()
    assert head[0].startswith("time [s],") and "mass.s [m]" in head[0].split(",")
    last = dict(zip(head[0].split(","), map(float, head[-1].split(","))))
    assert abs(last["mass.s [m]"] - 0.1 * np.cos(20 * 0.5)) < 1e-6
    assert png.stat().st_size > 1000


def test_variables_lists_units():
    r = run("variables", os.path.join(EX, "oscillator.py"))
    assert r.exit_code == 0
    assert "spring.c" in r.output and "[N/m]" in r.output and "mass.s" in r.output


@pytest.mark.parametrize("args, words", [
    (["--set", "mass.m=-1"], ["mass.m", "must be > 0"]),
    (["--set", "mass.q=1"], ["mass.q"]),
    (["--set", "mass.m"], ["PATH=VALUE"]),
])
def test_bad_set_exits_2(args, words):
    r = run("simulate", os.path.join(EX, "oscillator.py"), *args)
    assert r.exit_code == 2
    for w in words:
        assert w in r.output
    assert "Traceback" not in r.output


def write(tmp_path, text, name="m.py"):
    p = tmp_path / name
    p.write_text(textwrap.dedent(text))
    return p


def test_model_file_syntax_error_names_line(tmp_path):
    p = write(tmp_path, "from acausal import Model\nmodel = Model(\n")
    r = run("simulate", p)
    assert r.exit_code == 2 and f"{p}:" in r.output and "syntax" in r.output


def test_model_file_exception_names_line(tmp_path):
    p = write(tmp_path, """\
        from acausal import Model
        from acausal.mechanics.translational import Mass
        model = Model()
        model.mass = Mass(m=-2.0)
        """)
    r = run("simulate", p)
    assert r.exit_code == 2
    assert f"{p}:4" in r.output and "must be > 0" in r.output


def test_model_file_without_model(tmp_path):
    p = write(tmp_path, "x = 1\n")
    r = run("simulate", p)
    assert r.exit_code == 2 and "'model'" in r.output


def test_unconnected_flange_is_no_error(tmp_path):
    # Modelica's rule: an unconnected flange carries no force
    p = write(tmp_path, """\
        from acausal import Model
        from acausal.mechanics.translational import Mass, Spring
        model = Model()
        model.mass = Mass(m=1.0, s=0.1)
        model.spring = Spring(c=100.0)
        model.connect(model.spring.flange_b, model.mass.flange)
        """)
    r = run("simulate", p)
    assert r.exit_code == 0, r.output


def test_solver_failure_exits_3_names_time_and_keeps_partial_results(tmp_path):
    # m s'' = 1e3 s^3 from s = 1: s blows up at a finite time (~0.056 s)
    p = write(tmp_path, h.CUBIC_BLOWUP)
    out = tmp_path / "partial.csv"
    r = run("simulate", p, "--out", out)
    assert r.exit_code == 3, r.output
    assert "failed at t = 0.05" in r.output and "mass" in r.output
    rows = out.read_text().splitlines()
    assert len(rows) > 20                              # what was computed is kept


def test_sweep_takes_a_fixed_start_value(tmp_path):
    """``--param`` names a fixed start value as ``--set`` does: each point
    equals a run with that start value (the Hertz impact's approach speed)."""
    from acausal.modelfile import run_file
    path = os.path.join(EX, "hertz_impact.py")
    out = tmp_path / "sweep.csv"
    r = run("sweep", path, "--param", "mass.v=0.5:1.0:2", "--measure", "contact_period",
            "--out", out, "--no-progress")
    assert r.exit_code == 0, r.output
    # rows are written as points finish (two workers): compare as a set
    # the header carries the SI units, as the data folders do
    assert out.read_text().splitlines()[0] == "mass.v [m/s],contact_period [s],status,error,wall_s"
    rows = sorted(__import__("csv").DictReader(open(out)), key=lambda r: float(r["mass.v [m/s]"]))
    assert [float(row["mass.v [m/s]"]) for row in rows] == [0.5, 1.0]
    for row in rows:   # the sweep may run the compiled backend: agreement within tolerance
        _, meas = run_file(path, params={"mass.v": float(row["mass.v [m/s]"])})
        assert float(row["contact_period [s]"]) == pytest.approx(meas["contact_period"], rel=1e-7)
    # a rerun resumes from the file with units in its header: nothing recomputed
    again = run("sweep", path, "--param", "mass.v=0.5:1.0:2", "--measure", "contact_period",
                "--out", out, "--no-progress")
    assert again.exit_code == 0 and out.read_text().count("\n") == 3
    bad = run("sweep", path, "--param", "mass.q=0:1:2", "--measure", "contact_period",
              "--out", tmp_path / "bad.csv")
    assert bad.exit_code == 2 and "mass.q" in bad.output
