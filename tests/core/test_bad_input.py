"""Bad input, tried as a new user would (issue 9, item 8): every bad data
folder, parameter value or model ends in one line naming what is wrong and
where, with exit 2 on the command line; a valid trace beside the data is
calibrated and reported.

The model of these tests is a mass launched at ``v0`` against a spring to
ground, ``s(t) = v0 / w * sin(w t)`` with ``w = sqrt(c / m)``; the data are
written from that closed form, not by the code under test.
"""
import json
import math
import os

import numpy as np
import pytest
from click.testing import CliRunner

from acausal import ParameterError, compile_model
from acausal.cli import main
from acausal.errors import AcausalError, DataError, InitializationError, ModelError, SolverError
from acausal.mechanics.translational import Fixed, Mass, Spring

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MASS, C_TRUE, T_END = 2.0, 80.0, 0.1

MODEL = '''\
"""A mass launched at v0 against a spring to ground."""
from acausal import Experiment, Model
from acausal.mechanics.translational import Fixed, Mass, Spring

model = Model()
v0 = model.parameter("v0", 1.0, "m/s", "launch speed", min=0.0)
model.mass = Mass(m=2.0, s=0.0, v=v0)
model.spring = Spring(c=50.0, s_rel0=0.0)
model.ground = Fixed()
model.connect(model.ground.flange, model.spring.flange_a)
model.connect(model.spring.flange_b, model.mass.flange)
experiment = Experiment(t_end=0.1, rtol=1e-10, atol=1e-13, output_step=1e-3)
measures = {"s_end": lambda res: float(res["mass.s"][-1])}
measure_units = {"s_end": "m"}
conditions = ["v0"]
free_parameters = {"spring.c": (1.0, 1000.0)}
'''


def exact_s(v0, t, c=C_TRUE):
    w = math.sqrt(c / MASS)
    return v0 / w * np.sin(w * np.asarray(t))


@pytest.fixture(scope="module")
def model_file(tmp_path_factory):
    path = tmp_path_factory.mktemp("model") / "launch.py"
    path.write_text(MODEL)
    return path


def good_folder(folder, trace=False):
    """A valid dataset: two launch speeds, s_end in mm; optionally a trace
    of mass.s for V1 (time in ms, position in mm)."""
    folder.mkdir(parents=True, exist_ok=True)
    rows = [f"V{k},{v0},{exact_s(v0, T_END) * 1e3:.12g}" for k, v0 in ((1, 1.0), (2, 2.0))]
    (folder / "experiments.csv").write_text(
        "# launches\nname,v0 [m/s],s_end [mm]\n" + "\n".join(rows) + "\n")
    if trace:
        t = np.linspace(0.0, T_END, 21)
        lines = [f"{a * 1e3:.12g},{b * 1e3:.12g}" for a, b in zip(t, exact_s(1.0, t))]
        (folder / "V1.csv").write_text("time [ms],mass.s [mm]\n" + "\n".join(lines) + "\n")
    return folder


def run(*args):
    return CliRunner().invoke(main, [str(a) for a in args])


def one_line_error(r):
    """The CLI gave exit 2 and exactly one line on stderr, no traceback."""
    assert r.exit_code == 2, (r.exit_code, r.output, r.exception)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    assert "Traceback" not in r.output
    return lines[0]


def _edit(name, old, new):
    def apply(folder):
        p = folder / name
        p.write_text(p.read_text().replace(old, new, 1))
    return apply


def _write(name, text):
    def apply(folder):
        (folder / name).write_text(text)
    return apply


def _latin1(folder):
    p = folder / "experiments.csv"
    p.write_bytes(p.read_bytes().replace(b"# launches", "# lancés".encode("latin-1")))


def _remove(folder):
    (folder / "experiments.csv").unlink()


# (mutation, words the one line must contain)
BAD_FOLDERS = {
    "non-numeric cell": (_edit("experiments.csv", "V1,1.0", "V1,fast"),
                         ["experiments.csv:3", "v0", "not a number"]),
    "empty file": (_write("experiments.csv", ""), ["experiments.csv", "empty"]),
    "missing experiments.csv": (_remove, ["experiments.csv", "not found"]),
    "duplicate names": (_edit("experiments.csv", "V2,", "V1,"),
                        ["experiments.csv:4", "duplicate experiment 'V1'"]),
    "unknown column": (lambda f: (f / "experiments.csv").write_text("\n".join(
        x + (",colour" if x.startswith("name") else ",1" if x.startswith("V") else "")
        for x in (f / "experiments.csv").read_text().splitlines())),
        ["experiments.csv:2", "colour", "unknown"]),
    "unknown unit": (_edit("experiments.csv", "[mm]", "[smoots2]"),
                     ["experiments.csv:2", "smoots2"]),
    "short row": (_edit("experiments.csv", "V2,2.0,", "V2,"), ["experiments.csv:4", "cells"]),
    "semicolons": (lambda f: (f / "experiments.csv").write_text(
        (f / "experiments.csv").read_text().replace(",", ";")),
        ["experiments.csv:2", "';'"]),
    "nan cell": (_edit("experiments.csv", "V1,1.0", "V1,nan"),
                 ["experiments.csv:3", "v0", "finite"]),
    "bad trace": (_write("V1.csv", "time [ms],mass.s [mm]\n0,0\n2,1\n1,2\n"),
                  ["V1.csv:4", "time does not increase"]),
    "orphan trace": (_write("V9.csv", "time [ms],mass.s [mm]\n0,0\n"), ["V9.csv", "V9"]),
    "latin-1 byte": (_latin1, ["experiments.csv:1", "UTF-8"]),
    "wrong dimension of a measure": (_edit("experiments.csv", "s_end [mm]", "s_end [kg]"),
                                     ["experiments.csv:2", "column 's_end'", "a mass",
                                      "a length"]),
    "wrong dimension of a condition": (_edit("experiments.csv", "v0 [m/s]", "v0 [N]"),
                                       ["experiments.csv:2", "column 'v0'", "a force"]),
    "no condition the model declares": (
        lambda f: (f / "experiments.csv").write_text(
            f"name,s_end [mm]\nV1,{exact_s(1.0, T_END) * 1e3}\n"),
        ["experiments.csv:1", "v0"]),
}


@pytest.mark.parametrize("case", sorted(BAD_FOLDERS))
def test_calibrate_bad_folder_is_one_line_exit_2(tmp_path, model_file, case):
    mutate, words = BAD_FOLDERS[case]
    folder = good_folder(tmp_path / "data")
    mutate(folder)
    line = one_line_error(run("calibrate", model_file, folder, "--fit", "spring.c"))
    for w in words:
        assert w in line, (w, line)


def test_bad_folder_is_a_data_error_with_its_location(tmp_path, model_file):
    from acausal.studies.calibrate import model_dataset
    folder = good_folder(tmp_path / "data")
    _edit("experiments.csv", "s_end [mm]", "s_end [kg]")(folder)
    with pytest.raises(DataError) as info:
        model_dataset(str(model_file), folder)
    err = info.value
    assert isinstance(err, AcausalError)
    assert (os.path.basename(err.file), err.line, err.column) == ("experiments.csv", 2, "s_end")


def test_calibrate_with_a_trace_reports_the_fit(tmp_path, model_file):
    """A valid trace beside the scalar data: the fit finds the spring that
    made the data, and the report shows the trace's residual (it crashed
    with a TypeError after the fit, losing the result)."""
    folder = good_folder(tmp_path / "data", trace=True)
    r = run("calibrate", model_file, folder, "--fit", "spring.c")
    assert r.exit_code == 0, (r.output, r.exception)
    line = next(x for x in r.output.splitlines() if x.strip().startswith("spring.c ="))
    c = float(line.split("=")[1].split()[0])
    assert abs(c / C_TRUE - 1) < 1e-5, line
    assert "mass.s rms" in r.output and "over 21 samples" in r.output
    j = run("calibrate", model_file, folder, "--fit", "spring.c", "--json")
    assert j.exit_code == 0, (j.output, j.exception)
    out = json.loads(j.stdout)
    assert len(out["residuals"]["V1"]["mass.s"]) == 21
    assert abs(out["values"]["spring.c"] / C_TRUE - 1) < 1e-5


@pytest.mark.parametrize("spec", ["spring.c=inf", "mass.m=inf", "mass.m=nan", "v0=-inf",
                                  "spring.c=1e999"])
def test_non_finite_set_is_refused_naming_the_parameter(model_file, spec):
    line = one_line_error(run("simulate", model_file, "--set", spec))
    assert spec.split("=")[0] in line and "finite" in line


@pytest.mark.parametrize("value", [math.inf, -math.inf, math.nan])
def test_non_finite_parameters_refused_by_the_api(value):
    m = spring_mass_model()
    cm = compile_model(m)
    for name in ("mass.m", "spring.c"):
        with pytest.raises(ParameterError, match=name) as info:
            cm.simulate(params={name: value}, t_end=0.01)
        assert info.value.variable == name
    with pytest.raises(ParameterError, match="finite"):
        Mass(m=value)
    with pytest.raises(ParameterError, match="finite"):
        Spring(c=value)
    with pytest.raises(ParameterError, match="start value .*s"):
        Mass(m=1.0, s=value)


def spring_mass_model():
    from acausal import Model
    m = Model()
    m.mass = Mass(m=1.0, s=0.1, v=0.0)
    m.spring = Spring(c=100.0)
    m.ground = Fixed()
    m.connect(m.ground.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.mass.flange)
    return m


def test_mass_tied_to_a_wall_runs_and_a_contradicting_start_is_named():
    # a fully prescribed model runs (Modelica does); a fixed start that the
    # prescribed motion contradicts is named, and the message says why
    from acausal import Model
    for s0 in (0.0, 0.1):
        m = Model()
        m.mass = Mass(m=1.0, s=s0, v=0.0)
        m.wall = Fixed()
        m.connect(m.wall.flange, m.mass.flange)
        cm = compile_model(m, cache=False)
        if s0 == 0.0:
            res = cm.simulate(t_end=0.1)
            assert max(abs(res["mass.s"])) == 0.0 and max(abs(res["mass.flange.f"])) == 0.0
            continue
        with pytest.raises(InitializationError) as info:
            cm.simulate(t_end=0.1)
        msg = str(info.value)
        assert "mass.s = 0.1" in msg and "prescribed" in msg


def test_absurd_parameter_named_instead_of_inconsistent_starts():
    """The breaker with a 1e30 N/m wipe spring or a 1e-30 kg armature made
    the initialisation report 'inconsistent fixed start values'; the
    message names the parameter.

    A 1e-30 kg*m^2 hook was a third case until the compiler ordered its
    symbols by name (it had followed their string hashes): it is the
    massless-hook limit, which the deterministic ordering integrates to the
    same end as a 1e-12 hook, whereas the earlier orderings failed in the
    initialisation or in IDA depending on the value (1e-20, 1e-30, 1e-40
    each differently), at a reciprocal condition number of 1e-16."""
    from acausal.modelfile import compile_file
    mf, cm = compile_file(os.path.join(ROOT, "models", "breaker_24kv.py"))
    opts = mf.experiment.run_options()
    light = [cm.simulate(params={"hook.Jh": j}, **opts).t[-1] for j in (1e-12, 1e-30)]
    # the same end within the integration's tolerance (rtol relative: 1.4e-11 s;
    # the two runs' steps differ on the compiled backend, 3.3e-12 s apart)
    assert abs(light[1] - light[0]) < opts["rtol"] * light[0]
    for name, value in (("main_shaft.kw", 1e30), ("armature.ma", 1e-30)):
        # the initialisation fails (InitializationError) or, when it still
        # solves, the integration does (SolverError): either names the parameter
        with pytest.raises((InitializationError, SolverError)) as info:
            cm.simulate(params={name: value}, **opts)
        assert f"parameter {name} = {value:g}" in str(info.value), str(info.value)
        assert info.value.variable == name


def test_cli_shows_a_bug_as_a_traceback_with_exit_1(tmp_path, model_file, monkeypatch):
    """Only AcausalError is a user error: a bug (here a ValueError raised by
    a hypothesis library as it is imported) exits 1 with its traceback,
    instead of posing as a user error with exit 2 (diagnose caught every
    ValueError)."""
    (tmp_path / "buggy_library.py").write_text("raise ValueError('a bug in the library')\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    folder = good_folder(tmp_path / "data")
    r = run("diagnose", model_file, folder, "--library", "buggy_library", "--no-progress",
            "--report", tmp_path / "report")
    assert r.exit_code == 1, (r.output, r.exception)
    assert isinstance(r.exception, ValueError)
    missing = run("diagnose", model_file, folder, "--library", "no_such_library_xyz",
                  "--no-progress", "--report", tmp_path / "report")
    assert "no_such_library_xyz" in one_line_error(missing)


@pytest.mark.parametrize("edit, words", [
    (("thrt [ms]", "thrt [kg]"), ["column 'thrt'", "a mass", "a time"]),
    (("v_impact [m/s],", ""), ["v_impact", "sets none of the model's conditions"]),
])
def test_breaker_refuses_the_wrong_data_of_the_issue(tmp_path, edit, words):
    """The issue's two cases on the report's own data: a 'thrt [kg]' header
    (accepted, gave hook.bh = 1 +- 2000) and a missing v_impact column (every
    experiment ran at the default)."""
    from acausal.studies.calibrate import model_dataset
    src = os.path.join(ROOT, "data", "report_24kv")
    for name in ("experiments.csv", "instrument.csv"):
        text = open(os.path.join(src, name), encoding="utf-8").read()
        if name == "experiments.csv":
            text = text.replace(*edit)
            if edit[0].startswith("v_impact"):   # drop the column's cells too
                text = "\n".join(",".join(x.split(",")[:1] + x.split(",")[2:])
                                 if x.startswith("V") else x for x in text.splitlines())
        (tmp_path / name).write_text(text, encoding="utf-8")
    with pytest.raises(DataError) as info:
        model_dataset(os.path.join(ROOT, "models", "breaker_24kv.py"), tmp_path)
    msg = str(info.value)
    assert msg.startswith(f"{tmp_path / 'experiments.csv'}:{info.value.line}: ")
    for w in words:
        assert w in msg, msg
