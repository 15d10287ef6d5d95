"""Issue 21, a second battery of other bad inputs and kills: each fault it
found is one class here, so that the next input of that class is covered.

* a model file that ends the command (``sys.exit``), binds a ``stop`` that is
  not a Stop, or an ``rtol`` of 1 or more: one line naming file:line (a
  traceback, or exit 0 with nothing done);
* the model file's ``plot`` or a measure that raises or calls ``sys.exit``:
  one line (a traceback after the run), the other results kept;
* ``--max-wall`` and ``--max-memory`` bound ``simulate`` as a whole, the
  model file's own code included (a file that slept ignored --max-wall 3;
  one that took 6 GB passed --max-memory 1GB);
* an output that is one of the command's inputs, or another output: refused
  before the run (``calibrate --json-file DATA/experiments.csv`` overwrote
  the measured data);
* a write that fails (a full disk): one line, not a traceback;
* ``--set`` of a subnormal value, or of one name twice;
* NaN produced mid-run, trace samples outside the run, a model file's own
  warnings in ``check``: one warning line each;
* a sweep's workers killed (SIGTERM to the process group) while many points
  are queued: no thread traceback.
"""
import math
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest

from . import helpers as h

ROOT = Path(__file__).resolve().parents[2]

SPRING = h.DRIVEN_SPRING


def model_file(tmp_path, extra="", name="spring.py", base=SPRING):
    path = tmp_path / name
    path.write_text(base + extra)
    return path


invoke, one_error_line = h.invoke, h.one_error_line


# ---------------------------------------------------------------------------
# Model files
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("extra, said, line", [
    ("import sys\nsys.exit(0)\n", "called sys.exit(0)", 17),
    ("raise SystemExit('bye')\n", "called sys.exit('bye')", 16),
    ("experiment.stop = 5\n", "experiment stop = 5 must be an acausal.Stop", 12),
    ("experiment = Experiment(t_end=0.1, stop='body.s')\n", "must be an acausal.Stop", 16),
    ("experiment = Experiment(t_end=0.1, rtol=5.0)\n", "rtol = 5.0 is outside 1e-14 to 0.1", 16),
    ("experiment = Experiment(t_end=0.1, rtol=1)\n", "rtol = 1 is outside 1e-14 to 0.1", 16),
    ("experiment = Experiment(t_end=0.1, rtol=0.9)\n", "rtol = 0.9 is outside", 16),
    ("experiment = Experiment(t_end=0.1, rtol=1e-300)\n", "rtol = 1e-300 is outside", 16)])
@pytest.mark.parametrize("command", ["check", "simulate", "variables"])
def test_a_model_file_that_ends_the_command_or_binds_a_bad_experiment(tmp_path, extra, said,
                                                                      line, command):
    """sys.exit(0) in a model file ended the command with exit 0 having done
    nothing; SystemExit('bye') printed 'bye' (exit 1); stop=5 gave an
    AttributeError traceback in every command; rtol=5 passed ``check``."""
    path = model_file(tmp_path, extra)
    err = one_error_line(invoke([command, path]))
    assert said in err and f"{path}:{line}:" in err, err


@pytest.mark.parametrize("plot, said", [
    ("def plot(res, path):\n    raise ValueError('no figure')\n",
     "its plot(result, path) failed: ValueError: no figure"),
    ("def plot():\n    pass\n", "its plot(result, path) failed: TypeError"),
    ("def plot(res, path):\n    import sys\n    sys.exit(5)\n",
     "its plot(result, path) failed: SystemExit: 5")])
def test_a_model_files_plot_that_fails_is_one_line_after_the_results(tmp_path, plot, said):
    path = model_file(tmp_path, plot)
    out = tmp_path / "o.csv"
    err = one_error_line(invoke(["simulate", path, "--out", out, "--plot", tmp_path / "o.png"]))
    assert said in err and str(path) in err, err
    assert len(out.read_text().splitlines()) == 102     # the rows were written first


def test_a_measure_that_calls_sys_exit_is_a_missing_measure(tmp_path):
    path = model_file(tmp_path, "import sys\nmeasures['quit'] = lambda res: sys.exit(4)\n")
    r = invoke(["simulate", path])
    assert r.exit_code == 0, r.output
    assert "quit = missing (SystemExit: 4)" in r.output and "s_end = " in r.output


def test_a_model_files_own_warnings_are_one_line_in_every_command(tmp_path):
    for command in ("check", "variables", "linearize"):   # (a file is read once a process)
        path = model_file(tmp_path, "import warnings\nfor i in range(30):\n"
                                    "    warnings.warn(f'w{i}', RuntimeWarning)\n",
                          name=f"{command}.py")
        r = invoke([command, path])
        args = [command, path]
        assert r.exit_code == 0, r.output
        lines = [ln for ln in r.stderr.splitlines() if "w1" in ln or "warning" in ln.lower()]
        assert len(lines) == 1 and "30 RuntimeWarning" in lines[0], (args, r.stderr)


# ---------------------------------------------------------------------------
# Budgets of the whole command
# ---------------------------------------------------------------------------


def run_cli(args, timeout=120):
    t0 = time.monotonic()
    p = subprocess.run([sys.executable, "-m", "acausal.cli", *map(str, args)],
                       capture_output=True, text=True, timeout=timeout,
                       env=dict(os.environ, PYTHONPATH=str(ROOT)))
    return p, time.monotonic() - t0


@pytest.mark.slow   # 3-10 s: out of the default tier's 5-minute budget
def test_max_wall_bounds_a_model_file_that_never_returns(tmp_path):
    """A model file that slept (a loop, a blocking call) ignored --max-wall:
    the run's own wall limit starts only with the run."""
    path = model_file(tmp_path, base="import time\ntime.sleep(600)\n" + SPRING)
    p, wall = run_cli(["simulate", path, "--max-wall", "2"], timeout=300)
    assert p.returncode == 3, p.stderr
    lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "more than the limit --max-wall 2 s" in lines[0], p.stderr
    assert "nothing computed" in lines[0]
    assert wall < 60          # not the 600 s of the file (imports: seconds on a loaded host)


def test_max_memory_bounds_what_a_model_file_allocates(tmp_path):
    """The run's memory limit covered its rows only: 6 GB taken by the model
    file itself passed --max-memory 1GB with exit 0."""
    path = model_file(tmp_path, base="hog = []\nfor _ in range(60):\n"
                                     "    hog.append(bytearray(50_000_000))\n"
                                     "    import time; time.sleep(0.05)\n" + SPRING)
    p, _ = run_cli(["simulate", path, "--max-memory", "600MB"], timeout=300)
    assert p.returncode == 3, p.stderr
    lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "more than the limit 600 MB (--max-memory)" in lines[0], p.stderr


def test_a_run_within_its_limits_is_unchanged_by_the_watch(tmp_path):
    """The watch over the whole command leaves a run alone: --max-wall is
    still the run's own (it keeps its rows, exit 3, the reason named)."""
    path = model_file(tmp_path, base=SPRING.replace("t_end=0.1", "t_end=1e5").replace(
        "output_step=1e-3", "output_step=0.1"))
    out = tmp_path / "o.csv"
    r = invoke(["simulate", path, "--max-wall", "1", "--out", out, "--max-rows", "1e7"])
    assert r.exit_code == 3, r.output
    assert "by the wall-time limit max_wall = 1 s" in r.stderr, r.stderr
    assert len(out.read_text().splitlines()) > 10


# ---------------------------------------------------------------------------
# Outputs
# ---------------------------------------------------------------------------


def dataset(folder):
    folder.mkdir()
    (folder / "experiments.csv").write_text("name,F [N],s_end [mm]\nE1,1.0,25.0\n")
    return folder


@pytest.mark.parametrize("make", [
    lambda m, d, t: ["simulate", m, "--out", m],
    lambda m, d, t: ["simulate", m, "--out", t / "o.csv", "--plot", t / "o.csv"],
    lambda m, d, t: ["calibrate", m, d, "--fit", "k.c", "--json-file", d / "experiments.csv"],
    lambda m, d, t: ["diagnose", m, d, "--json-file", m, "--report", t / "rep"],
    lambda m, d, t: ["sweep", m, "--param", "k.c=10:20:3", "--measure", "s_end", "--out", m],
    lambda m, d, t: ["linearize", m, "--out", m],
    lambda m, d, t: ["linearize", m, "--out", t / "lin.txt"],
    lambda m, d, t: ["fmu", m, "-o", t / "nodir" / "m.fmu"]])
def test_an_output_that_is_an_input_or_another_output_is_refused_first(tmp_path, make):
    """calibrate --json-file DATA/experiments.csv replaced the measured data
    with the fit's JSON (exit 0); linearize checked its --out only after the
    work."""
    model, data = model_file(tmp_path), dataset(tmp_path / "data")
    before = {p: p.read_bytes() for p in (model, data / "experiments.csv")}
    err = one_error_line(invoke(make(model, data, tmp_path)))
    assert "--" in err or "-o" in err, err
    assert {p: p.read_bytes() for p in before} == before


def test_tolerance_refuses_its_json_on_its_csv(tmp_path):
    model = model_file(tmp_path)
    spec = tmp_path / "spec.csv"
    spec.write_text("name,distribution,a,b,unit\nk.c,normal,40,10%,N/m\n")
    out = tmp_path / "t.csv"
    err = one_error_line(invoke(["tolerance", model, "--spec", spec, "-n", "8", "--out", out,
                                 "--json", out, "--scheduler", "serial", "--no-progress"]))
    assert "the same file as --out" in err, err


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full")
def test_a_write_that_fails_is_one_line(tmp_path):
    """A full disk (/dev/full) gave an OSError traceback after the run."""
    err = one_error_line(invoke(["simulate", model_file(tmp_path), "--out", "/dev/full"]))
    assert "writing the 101 rows failed" in err and "space" in err, err


def test_set_twice_or_subnormal(tmp_path):
    """--set k.c=5e-324 gave a ValueError traceback (value/default
    underflowed to 0 before its log); the same name twice: the last won."""
    path = model_file(tmp_path)
    r = invoke(["simulate", path, "--set", "k.c=5e-324"])
    assert "Traceback" not in r.output and r.exit_code in (0, 3), r.output
    assert "is far from its default 40" in r.stderr and "324" in r.stderr, r.stderr
    err = one_error_line(invoke(["simulate", path, "--set", "k.c=5", "--set", "k.c=6"]))
    assert "k.c is set twice" in err


# ---------------------------------------------------------------------------
# Plausibility
# ---------------------------------------------------------------------------

LOG_OF_NEGATIVE = """
from sympy import Eq, log
from acausal import der
r = model.parameter("r", 10.0, "1/s", "rate")
z = model.variable("z", 1.0, "1", fixed=True)
model.equation(Eq(der(z), -r))
w = model.variable("w", 0.0, "1")
model.equation(Eq(w, log(z)))
"""


def test_nan_produced_mid_run_is_said(tmp_path):
    """log(z) of a z that crosses zero at 0.1 s: w was NaN from there on in
    the CSV, exit 0, and nothing said so."""
    path = model_file(tmp_path, LOG_OF_NEGATIVE.replace("0.1", "0.1")).resolve()
    path.write_text(path.read_text().replace("t_end=0.1", "t_end=0.2"))
    r = invoke(["simulate", path, "--out", tmp_path / "o.csv"])
    assert r.exit_code == 0, r.output
    warn = [ln for ln in r.stderr.splitlines() if "warning" in ln]
    assert len(warn) == 1 and "w is nan from t = 0.101 s on" in warn[0], r.stderr
    r = invoke(["simulate", path])
    assert "w is nan at the end, t = 0.2 s" in r.stderr, r.stderr
    r = invoke(["simulate", model_file(tmp_path, name="fine.py")])
    assert "warning" not in r.stderr, r.stderr


def test_trace_samples_outside_the_run_are_said(tmp_path):
    """A trace to 50 s against a 0.1 s run was fitted against the run's last
    value, without a word; samples before t0 against its first."""
    model = model_file(tmp_path)
    data = dataset(tmp_path / "data")
    (data / "E1.csv").write_text("time [s],body.s [m]\n-1,0\n0,0\n0.05,0.02\n5,0.025\n50,0.025\n")
    r = invoke(["--backend", "sundae", "calibrate", model, data, "--fit", "k.c",
                "--profile", "none"])
    assert r.exit_code == 0, r.output
    warn = [ln for ln in r.stderr.splitlines() if "E1.csv" in ln]
    assert len(warn) == 1, r.stderr
    assert "1 before t0 = 0 s (from -1 s) and 2 after t_end = 0.1 s (to 50 s) of its 5 " \
        "samples lie outside" in warn[0], warn


# ---------------------------------------------------------------------------
# Kills
# ---------------------------------------------------------------------------


@pytest.mark.slow   # 3-10 s: out of the default tier's 5-minute budget
def test_workers_killed_under_a_queue_of_cancelled_tasks_print_no_thread_traceback():
    """A sweep of 200,000 points whose process group got SIGTERM (``timeout``
    sends it to the group): the workers died first, and the pool's manager
    thread, failing every pending future while the command cancelled them,
    died of InvalidStateError with a thread traceback (1 run in 2 at 20 s).
    Here the same race, every time: a queue of 100,000 tasks, the worker
    killed, the futures cancelled."""
    r = subprocess.run([sys.executable, "-c", textwrap.dedent("""
        import time
        import psutil
        from acausal.infra.executor import open_executor
        with open_executor(workers=1) as ex:
            futures = [ex.submit(time.sleep, 30) for _ in range(100_000)]
            time.sleep(0.5)
            for p in psutil.Process().children():
                p.kill()
            ex.cancel(futures)
        print("done")
        """)], capture_output=True, text=True, timeout=300,
        env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert r.returncode == 0 and r.stdout.strip() == "done", r.stderr
    assert "Traceback" not in r.stderr and "InvalidStateError" not in r.stderr, r.stderr


def test_a_stop_requested_between_runs_does_not_stop_the_next_run(tmp_path):
    """A signal (or the watchdog) between two runs of one process left its
    request set, and the next run stopped at its start as 'interrupted'
    (exit 130): the fuzzed command lines, run in one process, met it."""
    from acausal.runtime.hybrid import request_stop
    assert request_stop("between runs") is False
    r = invoke(["simulate", model_file(tmp_path)])
    assert r.exit_code == 0 and "interrupt" not in r.output, r.output


@pytest.mark.parametrize("args, said", [
    (["linearize", "{m}", "--outputs", "body.v,body.v"], "body.v named twice"),
    (["linearize", "{m}", "--at", "body.s=1,body.s=2"], "body.s is given twice"),
    (["tolerance", "{m}", "--spec", "{m}", "-n", "8", "--seed", "-1"], "-1 is not in the range")])
def test_other_values_refused_in_one_line(tmp_path, args, said):
    """--outputs with a name twice and --at with a state twice: the last
    silently won; tolerance --seed -1: a numpy ValueError traceback."""
    m = model_file(tmp_path)
    err = one_error_line(invoke([a.format(m=m) for a in args]))
    assert said in err, err


@pytest.mark.slow
def test_animate_is_held_to_its_memory_limit(tmp_path):
    """Drawing 501 frames of the slider-crank took 899 MB against
    --max-memory 300MB (the limit covered the run's rows only); the
    half-written file is removed (17 s: slow tier)."""
    out = tmp_path / "a.gif"
    p, _ = run_cli(["animate", ROOT / "models" / "examples" / "slider_crank.py", "--out", out,
                    "--frames", "1e6", "--max-memory", "250MB"], timeout=600)
    assert p.returncode == 3, p.stderr
    lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "more than the limit 250 MB (--max-memory)" in lines[0], p.stderr
    assert not out.exists()


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM, signal.SIGHUP])
def test_a_signal_while_the_command_starts_is_one_line(sig):
    """Ctrl-C in the command's first second (its imports) printed a
    KeyboardInterrupt traceback from inside scipy; SIGTERM and SIGHUP ended
    it silently (exit -15, -1)."""
    proc = subprocess.Popen([sys.executable, "-m", "acausal.cli", "check",
                             str(ROOT / "models" / "examples" / "oscillator.py")],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            env=dict(os.environ, PYTHONPATH=str(ROOT)))
    time.sleep(0.4)          # (importing: about a second; later, the command is interrupted)
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=120)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert proc.returncode == 130 and "Traceback" not in err, (proc.returncode, err)
    assert len(lines) == 1 and lines[0].startswith("acausal: interrupted"), err


def test_only_the_command_guards_its_start():
    from acausal.infra.startup import is_command
    assert is_command(["/usr/bin/acausal", "simulate"], [])
    assert is_command(["-m"], ["python", "-m", "acausal.cli", "simulate", "x.py"])
    assert not is_command(["-m"], ["python", "-m", "pytest", "-q"])
    assert not is_command(["script.py"], ["python", "script.py"])


def test_a_parameter_that_makes_the_start_not_finite_is_named(tmp_path):
    """--set crank.rx=1e300 on the slider-crank: the initial Jacobian held
    inf and NaN, and numpy's 'SVD did not converge' ended the command with a
    traceback. Now the parameter is named, as for any value that breaks the
    initial equations."""
    err = one_error_line(invoke(["simulate", ROOT / "models" / "examples" / "slider_crank.py",
                                 "--set", "crank.rx=1e300"]))
    assert "parameter crank.rx = 1e+300 [m] makes the initial equations unsolvable" in err
    assert "not finite at the start values" in err, err


def test_a_subnormal_value_is_far_from_its_default():
    """value / default underflowed to 0 (5e-324 / 40) before its log10: a
    ValueError where the initialisation names suspect parameters."""
    from acausal.runtime.initialize import _far_from
    assert _far_from(5e-324, 40.0) and _far_from(1e300, 1e-300)
    assert not _far_from(41.0, 40.0) and not _far_from(0.0, 40.0)


def test_a_result_is_written_by_blocks_exactly(tmp_path, monkeypatch):
    """Writing 8.9 M rows took 5.4 GB at once (the observed matrix and a copy
    of every column), past the 4 GB limit, and the watchdog then ended the
    write: the interrupted run's rows were lost. The CSV is written by
    blocks; across block boundaries it reads back bit for bit."""
    from acausal.modelfile import run_file
    from acausal.runtime import result as result_module
    model = model_file(tmp_path, LOG_OF_NEGATIVE, base=SPRING.replace("t_end=0.1", "t_end=0.2"))
    res, _ = run_file(str(model))
    monkeypatch.setattr(result_module, "BLOCK_ROWS", 7)      # 201 rows: 29 blocks
    res.to_csv(tmp_path / "o.csv")
    back = np.loadtxt(tmp_path / "o.csv", delimiter=",", skiprows=1)
    assert back.shape == (len(res.t), 1 + len(res.names))
    assert np.array_equal(back[:, 0], res.t)
    for j, n in enumerate(res.names):
        assert np.array_equal(back[:, 1 + j], np.asarray(res[n], dtype=float),
                              equal_nan=True), n
    assert (tmp_path / "o.csv").read_text().count("time [s]") == 1
    name, t, value = res.nonfinite()
    assert name == "w" and t == pytest.approx(0.101) and math.isnan(value)
    assert res.final()["w"] != res.final()["w"] and res.final()["body.s"] == res["body.s"][-1]


@pytest.mark.slow   # 3-10 s: out of the default tier's 5-minute budget
def test_max_wall_bounds_a_measure_that_never_returns(tmp_path):
    """A measure that slept (the model file's code, run after the run)
    ignored --max-wall 5: a hang. The rows are written first; the measures
    then get a --max-wall of their own."""
    path = model_file(tmp_path, "import time\nmeasures['slow'] = lambda res: time.sleep(600)\n")
    out = tmp_path / "o.csv"
    p, wall = run_cli(["simulate", path, "--max-wall", "2", "--out", out], timeout=300)
    assert p.returncode == 3, p.stderr
    lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "more than the limit --max-wall 2 s, while the measures were " \
        "computed: its results were written" in lines[0], p.stderr
    assert wall < 60 and len(out.read_text().splitlines()) == 102
