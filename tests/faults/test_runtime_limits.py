"""What a long, stiff, chattering or failing run gives back (issue 9, item 8):
bounded output, wall and step limits naming the component whose events
dominate, a progress bar, measures reported missing instead of failing the
run, JSON with an error field and the partial result, a plot of it, and
``sweep --measure a,b``.

The models are written here: a block dragged through a spring over a
friction pad (stick-slip, one event pair per cycle), a mass on a spring,
and a mass pushed by a quintic force (finite-time blow-up)."""
import json
import math
import os
import resource
import subprocess
import sys
import textwrap
import time

import numpy as np
import pytest
from click.testing import CliRunner

from acausal import LimitError, SolverError
from acausal.cli import main
from acausal.modelfile import compile_file

from . import helpers as h

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

DRAG = """\
    from acausal import Experiment, Model, time
    from acausal.mechanics.friction import GroundFriction
    from acausal.mechanics.translational import Mass, Position, Spring

    model = Model()
    V = model.parameter("V", 2.0, "m/s", "drive speed", min=0.0, min_open=True)
    model.block = Mass(m=0.01, s=0.0, v=0.0)
    model.spring = Spring(c=1e4)
    model.drive = Position(s=V * time)
    model.pad = GroundFriction(F_c=4.0, F_s=6.0)
    model.connect(model.drive.flange, model.spring.flange_b)
    model.connect(model.spring.flange_a, model.block.flange, model.pad.flange)
    experiment = Experiment(t_end=50.0, rtol=1e-9, atol=1e-11, output_step=1e-3)

    def first_slip(res):
        return res.event_times("pad.break_forward")[0]

    measures = {"first_slip": first_slip, "s_end": lambda res: res.final()["block.s"]}
    """

SPRING = h.spring_file("""\
experiment = Experiment(t_end=1.0, rtol=1e-8, atol=1e-10, output_step=1e-3)
measures = {"s_end": lambda res: res.final()["body.s"],
            "v_end": lambda res: res.final()["body.v"]}
""")

BLOWUP = """\
    from acausal import Experiment, Model
    from acausal.mechanics.translational import Force, Mass
    model = Model()
    model.body = Mass(m=1.0, s=1.0, v=0.0)
    model.push = Force(f=lambda s: 1e5 * s**5)
    model.connect(model.push.flange, model.body.flange)
    experiment = Experiment(t_end=1.0, output_step=1e-4)
    measures = {"s_max": lambda res: float(max(res["body.s"]))}
    """


def write(folder, name, text):
    path = folder / name
    path.write_text(textwrap.dedent(text))
    return str(path)


def run_cli(args, timeout=300):
    """The command in a fresh process (stdout as the OS sees it)."""
    return subprocess.run([sys.executable, "-m", "acausal.cli", *map(str, args)],
                          env=dict(os.environ, PYTHONPATH=ROOT), capture_output=True,
                          text=True, timeout=timeout)


# -- bounded output --------------------------------------------------------------


def _vm_bytes():
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) * 1024 for line in f if line.startswith("VmSize:"))


@pytest.mark.skipif(not os.path.exists("/proc/self/status"), reason="needs Linux /proc")
def test_huge_output_grid_is_refused_before_allocating(tmp_path):
    """`simulate --t-end 1e6` of a 1 ms output grid asked for 1e9 rows and grew
    to 20 GB; now it stops at once with a message. The run gets 2 GB more
    address space than the test process has (a MemoryError otherwise)."""
    model = write(tmp_path, "spring.py", SPRING)
    compile_file(model)
    soft, hard = resource.getrlimit(resource.RLIMIT_AS)
    resource.setrlimit(resource.RLIMIT_AS, (_vm_bytes() + 2 * 2 ** 30, hard))
    try:
        r = CliRunner().invoke(main, ["simulate", model, "--t-end", "1e6"])
    finally:
        resource.setrlimit(resource.RLIMIT_AS, (soft, hard))
    assert r.exit_code == 2, r.output     # refused before the run: a usage error
    assert "1e+09 rows" in r.output and "max_rows" in r.output


@pytest.mark.parametrize("backend", ["sundae", pytest.param("compiled", marks=pytest.mark.slow)])
def test_stored_rows_are_bounded_while_running(tmp_path, backend):
    """(The compiled backend calls no Python residual: it checks the limits
    each time its output buffer fills.)"""
    _, cm = compile_file(write(tmp_path, "spring.py", SPRING))
    with pytest.raises(LimitError, match="max_rows"):
        cm.simulate(t_end=10.0, output_step=1e-3, max_rows=5000,   # 10001 rows asked for
                    backend=backend)
    with pytest.raises(LimitError, match="max_rows = 3000") as info:
        cm.simulate(t_end=1e3, output_step=0, max_rows=3000,       # every solver step
                    backend=backend)
    assert len(info.value.result.t) <= 3000
    assert info.value.result.stats["backend"] == backend


# -- wall and step limits, progress --------------------------------------------------------


def test_wall_limit_keeps_the_partial_result_and_names_the_chattering_component(tmp_path):
    _, cm = compile_file(write(tmp_path, "drag.py", DRAG))
    t0 = time.perf_counter()
    with pytest.raises(LimitError) as info:
        cm.simulate(t_end=50.0, output_step=1e-3, max_wall=1.5)
    took = time.perf_counter() - t0
    err = info.value
    assert took < 1.25 * 1.5 + 1.0 + 2.0      # the hard stop, plus margin for a busy machine
    assert "max_wall = 1.5 s" in str(err) and "in pad" in str(err)
    assert err.component == "pad"
    res = err.result
    assert res.status == "stopped" and 0 < res.t[-1] < 50.0 and len(res.events) > 2
    # the partial result is a correct solution: the block sticks until the spring
    # holds F_s = 6 N, i.e. at t = F_s / (c V) = 6 / (1e4 * 2) s
    assert res.event_times("pad.break_forward")[0] == pytest.approx(6 / 2e4, rel=1e-6)


def test_step_limit(tmp_path):
    _, cm = compile_file(write(tmp_path, "drag.py", DRAG))
    with pytest.raises(LimitError, match="max_total_steps = 3000") as info:
        cm.simulate(t_end=50.0, output_step=1e-3, max_total_steps=3000)
    res = info.value.result
    assert 3000 < res.stats["steps"] <= 1.25 * 3000 + 1000
    assert info.value.component == "pad" and res.t[-1] > 0


def test_windows_do_not_change_the_solution(tmp_path):
    """A watched run (cut into windows) matches the closed form as a plain one does."""
    _, cm = compile_file(write(tmp_path, "spring.py", SPRING))
    w = math.sqrt(100.0 / 4.0)
    for kw in ({}, {"max_wall": 60.0}, {"max_total_steps": 10 ** 6}):
        res = cm.simulate(t_end=3.0, output_step=1e-3, rtol=1e-9, atol=1e-12, **kw)
        assert len(res.t) == 3001
        np.testing.assert_allclose(res.t, np.linspace(0, 3, 3001), rtol=0, atol=1e-12)
        np.testing.assert_allclose(res["body.s"], 0.2 * np.cos(w * res.t), rtol=0, atol=1e-7)


def test_progress_bar_on_stderr(tmp_path, capsys, monkeypatch):
    import acausal.runtime.hybrid as sim

    monkeypatch.setattr(sim, "PROGRESS_DELAY_S", 0.0)
    _, cm = compile_file(write(tmp_path, "spring.py", SPRING))
    shown = cm.simulate(t_end=1.0, output_step=1e-3, progress=True)
    err = capsys.readouterr().err
    assert "simulate:" in err and "100%" in err and "t = 1/1 s" in err
    plain = cm.simulate(t_end=1.0, output_step=1e-3)
    assert capsys.readouterr().err == ""
    assert shown.stats["steps"] == plain.stats["steps"]      # the bar does not touch the run
    np.testing.assert_allclose(shown["body.s"], plain["body.s"], rtol=0, atol=1e-15)


# -- missing measures ------------------------------------------------------------------


def test_measure_without_its_event_is_missing_and_the_rest_is_kept(tmp_path):
    model = write(tmp_path, "drag.py", DRAG)
    r = CliRunner().invoke(main, ["simulate", model, "--set", "V=1e-9", "--t-end", "0.5",
                                  "--json"])
    assert r.exit_code == 0, r.output
    out = json.loads(r.stdout)      # (stderr warns: V = 1e-9 m/s is 9 decades off its default)
    assert "far from its default" in r.stderr
    assert out["error"] is None and out["measures"]["first_slip"] is None
    assert "IndexError" in out["missing"]["first_slip"]
    assert out["measures"]["s_end"] == pytest.approx(0.0, abs=1e-12)   # stuck all along
    r = CliRunner().invoke(main, ["simulate", model, "--set", "V=1e-9", "--t-end", "0.5"])
    assert r.exit_code == 0 and "first_slip = missing (IndexError" in r.output


# -- solver failure: JSON and plot --------------------------------------------------------


@pytest.mark.slow   # 3-10 s: out of the default tier's 5-minute budget
def test_solver_failure_json_has_error_and_partial_result(tmp_path):
    model = write(tmp_path, "blowup.py", BLOWUP)
    r = run_cli(["simulate", model, "--json"])
    assert r.returncode == 3, r.stderr
    out = json.loads(r.stdout)            # stdout is one JSON object, nothing else
    assert out["error"]["type"] == "SolverError" and out["status"] == "failed"
    # s'' = 1e5 s^5, s(0) = 1: blow-up at t* = int_1^inf ds / sqrt(1e5/3 (s^6 - 1)) = 3.854e-3 s
    assert out["error"]["t"] == pytest.approx(3.854e-3, rel=0.02)
    assert out["error"]["component"] == "body"
    assert out["final"]["body.s"] > 1e3
    assert not [ln for ln in r.stderr.splitlines() if ln.lstrip().startswith("[IDA")]
    if out["stats"]["backend"] == "sundae":   # SUNDIALS' own line is in the message
        assert "(SUNDIALS: [IDA" in out["error"]["message"]


def test_solver_failure_plots_what_was_computed(tmp_path):
    model = write(tmp_path, "blowup.py", BLOWUP)
    png = tmp_path / "partial.png"
    r = CliRunner().invoke(main, ["simulate", model, "--plot", str(png)])
    assert r.exit_code == 3 and "failed at t = 0.003" in r.output
    assert png.stat().st_size > 5000


# -- sweep --measure a,b ---------------------------------------------------------------------


def test_sweep_measure_takes_a_list(tmp_path):
    model = write(tmp_path, "spring.py", SPRING)
    out = tmp_path / "s.csv"
    r = CliRunner().invoke(main, ["sweep", model, "--param", "body.m=1,4", "--measure",
                                  "s_end,v_end", "--out", str(out), "--workers", "1",
                                  "--no-progress"])
    assert r.exit_code == 0, r.output
    rows = out.read_text().splitlines()
    assert rows[0] == "body.m [kg],s_end,v_end,status,error,wall_s"   # plain functions: no unit
    for line in rows[1:]:
        m, s, v = map(float, line.split(",")[:3])
        w = math.sqrt(100.0 / m)
        assert s == pytest.approx(0.2 * math.cos(w), abs=1e-6)
        assert v == pytest.approx(-0.2 * w * math.sin(w), abs=1e-5)
