"""Issue 21, the fourth pass: what the last session left failing and a new
battery of bad inputs and kills (``faults21c``).

* SIGKILL of the command left a model file's own processes running (no
  handler runs): a watchdog process forked first thing ends them;
"""
import os
import signal
import subprocess
import sys
import time

import numpy as np
import psutil
import pytest

from acausal.infra import descendants

from . import helpers as h

ROOT = h.ROOT


# -- SIGKILL: no process outlives the command ------------------------------------------------

SPAWNING = """\
import os, subprocess, time
from pathlib import Path
""" + h.SPRING_IMPORTS + """
child = subprocess.Popen(["sleep", "300"])
# a grandchild whose parent (the shell) ends at once: an orphan
orphan = subprocess.run(["sh", "-c", "sleep 301 >/dev/null 2>&1 & echo $!"],
                        capture_output=True, text=True).stdout.strip()
# one in a session (and process group) of its own
alone = subprocess.run(["sh", "-c", "setsid sleep 302 >/dev/null 2>&1 & echo $!"],
                       capture_output=True, text=True).stdout.strip()
Path({pids!r}).write_text(f"{{child.pid}} {{orphan}} {{alone}}")
time.sleep(120)
""" + h.SPRING_MODEL + """experiment = Experiment(t_end=1.0)
measures = {{"s_end": Measure(lambda res: res.final()["body.s"], unit="m")}}
"""


def _alive(pid):
    try:
        return psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


def _spawning_command(tmp_path, command):
    pids = tmp_path / "pids.txt"
    model = tmp_path / "spawning.py"
    model.write_text(SPAWNING.format(pids=str(pids)))
    data = tmp_path / "data"
    data.mkdir()
    (data / "experiments.csv").write_text("name,s_end [m]\nE1,0.1\n")
    args = {"simulate": ["simulate", model],
            "sweep": ["sweep", model, "--param", "k.c=10:20:3", "--measure", "s_end",
                      "--out", tmp_path / "s.csv"],
            "calibrate": ["calibrate", model, data, "--fit", "k.c"],
            "diagnose": ["diagnose", model, data, "--report", tmp_path / "rep"],
            "fmu": ["fmu", model, "-o", tmp_path / "m.fmu"]}[command]
    return h.cli(args, h.env(tmp_path / "log")), pids


@pytest.mark.parametrize("command", [
    "simulate", *(pytest.param(c, marks=pytest.mark.slow)
                  for c in ("sweep", "calibrate", "diagnose", "fmu"))])
def test_sigkill_of_the_command_leaves_no_process_of_its_model_file(tmp_path, command):
    """A model file's ``sleep 300``, a shell's orphaned background ``sleep``
    and a ``setsid sleep`` outlived a SIGKILL of the command (no handler
    runs): the watchdog ends them within a second or so, and ends itself.
    A process of the command's own group that is not its descendant (here
    a sibling ``sleep``) is left alone: the watchdog never kills a group."""
    sibling = subprocess.Popen(["sleep", "60"])     # the test's, in the same process group
    proc, pids = _spawning_command(tmp_path, command)
    started = []
    try:
        h.wait_for(lambda: pids.exists() and len(pids.read_text().split()) == 3, proc)
        started = [int(p) for p in pids.read_text().split()]
        watchdogs = [p for p in psutil.Process(proc.pid).children()
                     if p.name() == descendants.WATCHDOG_NAME.decode()]
        assert len(watchdogs) == 1
        time.sleep(3 * descendants.POLL_S)     # a poll has seen them
        proc.kill()
        proc.communicate(timeout=60)
        deadline = time.monotonic() + 5.0
        while any(map(_alive, started + [watchdogs[0].pid])) and time.monotonic() < deadline:
            time.sleep(0.05)
        assert not [p for p in started if _alive(p)]
        assert not _alive(watchdogs[0].pid), "the watchdog outlived its work"
        assert sibling.poll() is None, "a process outside the command was killed"
    finally:
        sibling.kill()
        sibling.wait()
        for p in started:
            try:
                os.kill(p, signal.SIGKILL)
            except OSError:
                pass


def test_the_watchdog_never_signals_a_pid_given_to_another_process():
    """A recorded pid whose start time differs is another process now."""
    other = subprocess.Popen(["sleep", "30"])
    try:
        real = descendants._start_time(other.pid)
        assert real is not None
        descendants._finish({other.pid: real + 1}, os.getpid())    # same pid, other start
        time.sleep(0.1)
        assert other.poll() is None
        descendants._finish({other.pid: real}, os.getpid())
        assert other.wait(timeout=5) == -signal.SIGTERM
    finally:
        other.kill()
        other.wait()


def test_the_watchdog_ends_when_its_command_ends_normally(tmp_path):
    """A command that ends by itself takes its watchdog along, at once."""
    r = subprocess.run([sys.executable, "-c", """
import os, sys, time
sys.argv = ["acausal"]
import numpy as np
import psutil
from acausal.infra import descendants
print(descendants.watchdog_pid())
"""], capture_output=True, text=True, timeout=120, env=h.env(tmp_path / "log"))
    pid = int(r.stdout.split()[-1])
    deadline = time.monotonic() + 5.0
    while _alive(pid) and time.monotonic() < deadline:
        time.sleep(0.02)
    assert not _alive(pid)


# -- a million-point grid: arrays, an honest estimate, resume -------------------------------

from acausal.infra.executor import open_executor       # noqa: E402
from acausal.studies.sweep import Journal, grid, run_sweep   # noqa: E402


def _counting_task(calls, stop_after):
    def task(point):
        calls.append(point)
        if len(calls) > stop_after:
            raise KeyboardInterrupt
        return {"m": point["a"] * 1000 + point["b"]}
    return task


def test_a_million_point_grid_is_two_arrays_and_starts_at_once(tmp_path):
    """1000 x 1000 points: the grid holds two arrays (2.9 s to prepare as a
    million dicts, 4.75 GB estimated, refused), its first point runs
    within a fraction of a second, and an interrupted run resumes from the
    checkpoint alone (the CSV lost, as after SIGKILL) at the next point in
    grid order, saying how many were done."""
    import tracemalloc
    a, b = np.linspace(3, 5, 1000), np.linspace(0.1, 0.3, 1000)
    tracemalloc.start()
    g = grid([("a", a), ("b", b)])
    assert len(g) == 1_000_000 and tracemalloc.get_traced_memory()[1] < 1e6
    tracemalloc.stop()
    assert g[1001] == {"a": float(a[1]), "b": float(b[1])} and g.place(g.key(1001)) == 1001
    out = tmp_path / "s.csv"
    calls = []
    start = time.perf_counter()
    with open_executor("serial") as ex, pytest.raises(KeyboardInterrupt):
        run_sweep(_counting_task(calls, 1500), g, out, executor=ex, measures=["m"],
                  progress=False)
    assert time.perf_counter() - start < 5.0
    out.unlink()                       # only the checkpoint is left, as after a SIGKILL
    seen, calls = [], []
    with open_executor("serial") as ex, pytest.raises(KeyboardInterrupt):
        run_sweep(_counting_task(calls, 0), g, out, executor=ex, measures=["m"],
                  progress=False, journal=Journal(on_resume=lambda d, n: seen.append((d, n))))
    assert seen == [(1500, 1_000_000)]
    assert calls == [g[1500]]          # the next point, nothing done twice


def test_a_grid_resumed_after_a_kill_has_every_point_once(tmp_path):
    """Interrupted twice at random points (the CSV lost once, as after
    SIGKILL), then finished: every point of the 2-D grid once, in grid
    order, with its own value."""
    g = grid([("a", np.arange(40.0)), ("b", np.arange(50.0))])
    out, done = tmp_path / "s.csv", []
    for stop, lose_csv in ((700, True), (333, False)):
        calls = []
        with open_executor("serial") as ex, pytest.raises(KeyboardInterrupt):
            run_sweep(_counting_task(calls, stop), g, out, executor=ex, measures=["m"],
                      progress=False)
        done += calls[:-1]
        if lose_csv:
            out.unlink()
    calls = []
    with open_executor("serial") as ex:
        rows = run_sweep(_counting_task(calls, 10**9), g, out, executor=ex, measures=["m"],
                         progress=False)
    done += calls
    assert sorted((p["a"], p["b"]) for p in done) == [(p["a"], p["b"]) for p in g]
    assert [(r["a"], r["b"]) for r in rows] == [(p["a"], p["b"]) for p in g]
    assert all(r["m"] == r["a"] * 1000 + r["b"] for r in rows)
    written = np.loadtxt(out, delimiter=",", skiprows=1, usecols=(0, 1, 2))
    np.testing.assert_array_equal(written[:, 2], written[:, 0] * 1000 + written[:, 1])
    assert len(written) == len(g)


def test_the_sweep_memory_estimate_is_not_below_what_a_grid_uses(tmp_path):
    """The estimate per finished point (SWEEP_POINT_BASE + SWEEP_POINT_BYTES
    per column) against the memory a finished grid's rows really hold in
    the main process at their peak (CSV cells and returned rows; traced
    allocations, per point between a 500- and a 2,500-point grid)."""
    import tracemalloc
    from acausal.cli import SWEEP_POINT_BASE, SWEEP_POINT_BYTES

    def peak(n):
        g = grid([("a", np.linspace(1, 2, n // 50)), ("b", np.linspace(3, 4, 50))])
        tracemalloc.start()
        with open_executor("serial") as ex:
            rows = run_sweep(_counting_task([], 10**9), g, tmp_path / f"s{n}.csv", executor=ex,
                             measures=["m"], progress=False)
            held = tracemalloc.get_traced_memory()[1]     # the peak: cells and rows at once
        tracemalloc.stop()
        assert len(rows) == n
        return held
    per_point = (peak(2500) - peak(500)) / 2000
    estimate = SWEEP_POINT_BASE + SWEEP_POINT_BYTES * (2 + 1 + 3)
    print(f"{per_point:.0f} B per point, estimate {estimate} B")
    assert per_point < estimate, (per_point, estimate)


# -- a signal while the command ends -----------------------------------------------------------

LATE_ATEXIT = h.spring_file("""\
import atexit, time
from pathlib import Path


def late():
    Path({marker!r}).write_text("x")
    time.sleep(1.5)


atexit.register(late)
experiment = Experiment(t_end=0.1)
""")


@pytest.mark.slow   # 3-10 s: out of the default tier's 5-minute budget
def test_a_sigterm_while_the_command_ends_is_one_line_and_keeps_the_result(tmp_path):
    """A SIGTERM while the command was ending (here: in a model file's
    atexit function) raised KeyboardInterrupt inside it, a traceback; one
    after the interpreter had put back the default handlers killed it
    silently (exit 143). Now: one line, the command's own exit code, the
    result written."""
    marker, out = tmp_path / "marker", tmp_path / "o.csv"
    model = tmp_path / "late.py"
    model.write_text(LATE_ATEXIT.format(marker=str(marker)))
    proc = h.cli(["simulate", model, "--out", out], h.env(tmp_path / "log"))
    h.wait_for(marker.exists, proc)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 0, err
    assert err.strip().splitlines() == [
        "acausal: SIGTERM while the command was ending, its work done: its results are kept"]
    assert len(out.read_text().splitlines()) > 10


def test_the_last_act_of_the_command_holds_the_stop_signals():
    """After the command's last atexit function a stop signal is ignored:
    the process ends with its own code, not by SIGTERM (numpy's threads
    running: blocking the signal in the main thread alone let it kill)."""
    r = subprocess.run([sys.executable, "-c", """
import os, signal
import numpy as np
np.dot(np.ones((300, 300)), np.ones((300, 300)))   # its threads started
from acausal.infra import startup
signal.signal(signal.SIGTERM, signal.SIG_DFL)   # as Python leaves it at its very end
startup._ignore_stop_signals()
os.kill(os.getpid(), signal.SIGTERM)
print("still here")
"""], capture_output=True, text=True, timeout=120, env=dict(os.environ, PYTHONPATH=str(ROOT)))
    assert r.returncode == 0 and r.stdout.strip() == "still here", (r.returncode, r.stderr)


# -- what the last session noticed and left alone ---------------------------------------------

from click.testing import CliRunner     # noqa: E402

from acausal.cli import main            # noqa: E402


invoke = h.invoke


def one_error_line(r, code=2):
    """:func:`helpers.one_error_line`, and that line alone on stderr."""
    line = h.one_error_line(r, code)
    assert r.stderr.strip().splitlines() == [line], r.stderr
    return line


def test_a_model_with_no_components_is_refused(tmp_path):
    """``model = Model()`` and nothing else 'simulated' 500 steps of nothing, exit 0."""
    path = tmp_path / "empty.py"
    path.write_text("from acausal import Experiment, Model\nmodel = Model()\n"
                    "experiment = Experiment(t_end=0.1)\n")
    line = one_error_line(invoke(["simulate", path]))
    assert f"{path}:2: 'model' has no components and no equations" in line


@pytest.mark.parametrize("atol, ok", [(1e-300, False), (1e-21, False), (1e-20, True),
                                      (1e3, True), (1e4, False), ({"body.s": 1e-30}, False)])
def test_an_experiments_atol_has_the_command_lines_range(tmp_path, atol, ok):
    """--atol refused values outside 1e-20..1e3 (SI) that Experiment(atol=...)
    in a model file took (the library's own calls still take any value)."""
    path = tmp_path / "m.py"
    path.write_text(h.spring_file(f"experiment = Experiment(t_end=0.01, atol={atol!r})\n"))
    r = invoke(["simulate", path])
    if ok:
        assert r.exit_code == 0, r.output
    else:
        assert "is outside 1e-20 to 1000 (SI units)" in one_error_line(r)


def test_output_to_a_pipe_its_reader_closed_ends_quietly_as_sigpipe_does(tmp_path):
    """``acausal variables m | head -1`` exited 1 quietly (click's own
    handling). Now as a Unix tool killed by SIGPIPE: no word, status 141
    (``set -o pipefail`` sees that the output was not all read)."""
    proc = subprocess.Popen([sys.executable, "-m", "acausal.cli", "variables",
                             str(ROOT / "models" / "breaker_24kv.py")], env=h.env(tmp_path / "l"),
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    proc.stdout.close()     # the reader is gone before the first line
    err = proc.stderr.read().decode()
    assert proc.wait(timeout=120) == 141 and not err.strip(), (proc.returncode, err)


EXITING = h.spring_file("""\
import atexit, os
experiment = Experiment(t_end=0.01)


@atexit.register
def bye():
    os._exit(7)


def boom():
    raise ValueError("late")


atexit.register(boom)
""")


def test_a_model_files_exit_functions_are_one_line_each(tmp_path):
    """``os._exit(7)`` in a model file's atexit function ended the command
    with 7, silently (and skipped the command's own end); an exception in
    one was a traceback."""
    path = tmp_path / "m.py"
    path.write_text(EXITING)
    proc = h.cli(["simulate", path], h.env(tmp_path / "log"))
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 0, err
    lines = err.strip().splitlines()
    at = {text: i for i, text in enumerate(EXITING.splitlines(), 1)}
    assert lines == [   # (a decorated function's line is its decorator's)
        f"acausal: warning: {path}:{at['def boom():']}: the model file's exit function boom() "
        "failed: ValueError: late: ignored",
        f"acausal: warning: {path}:{at['@atexit.register']}: the model file's exit function "
        "bye() called os._exit(7): ignored"], err


# -- a fourth battery: bad inputs and kills no earlier battery tried ---------------------------
# (each fixed fault with the line it gave before; the inputs that were already
# one clear line are listed in the session's report)

BATTERY_SPRING = h.DRIVEN_SPRING


@pytest.fixture
def bspring(tmp_path):
    path = tmp_path / "spring.py"
    path.write_text(BATTERY_SPRING)
    return path


def _folder(tmp_path, experiments, **files):
    d = tmp_path / "data"
    d.mkdir()
    (d / "experiments.csv").write_text(experiments)
    for name, text in files.items():
        (d / name).write_text(text)
    return d


@pytest.mark.parametrize("experiments, said", [
    # calibrate said "every experiment is marked 'validate'; nothing to calibrate to"
    ("name,F [N],s_end [mm]\n", "experiments.csv:1: no experiments: a header and no rows"),
    # "column 'name': bad experiment name ''"
    ("name,F,s_end\n,N,mm\nE1,1,25\n", "experiments.csv:2: column 'name': a row of units under "
     "the header: write each unit in its header, in brackets ('F [N]')")])
def test_a_data_folder_wrong_in_a_new_way_is_one_line_saying_what(tmp_path, bspring,
                                                                    experiments, said):
    data = _folder(tmp_path, experiments)
    line = one_error_line(invoke(["calibrate", bspring, data, "--fit", "k.c"]))
    assert said in line, line


@pytest.mark.parametrize("kind", ["folder", "fifo"])
@pytest.mark.parametrize("name", ["experiments.csv", "E1.csv"])
def test_a_data_file_that_is_a_folder_or_a_pipe_is_named_so(tmp_path, bspring, kind, name):
    """'file not found' for a file that is there (a folder, a named pipe)."""
    data = _folder(tmp_path, "name,F [N],s_end [mm]\nE1,1.0,25.0\n")
    (data / name).unlink(missing_ok=True)
    (data / name).mkdir() if kind == "folder" else os.mkfifo(data / name)
    line = one_error_line(invoke(["calibrate", bspring, data, "--fit", "k.c"]))
    assert f"{data / name}: " + ("a folder, not a file" if kind == "folder" else
                                 "not a regular file (a CSV file is expected)") in line, line


@pytest.fixture
def tiny_disk(tmp_path):
    """A 64 kB tmpfs (a full disk), else /dev/full's folder is no use: skip."""
    where = tmp_path / "full"
    where.mkdir()
    r = subprocess.run(["mount", "-t", "tmpfs", "-o", "size=64k", "tmpfs", str(where)],
                       capture_output=True)
    if r.returncode != 0:
        pytest.skip("no tmpfs can be mounted here (not root)")
    (where / "filler").write_bytes(b"x" * 60_000)
    yield where
    subprocess.run(["umount", str(where)], capture_output=True)


def test_a_full_disk_is_named_with_the_file_not_standard_output(tmp_path, bspring, tiny_disk):
    """--plot and a sweep's --out on a full disk said 'the output could not
    be written to standard output' (the catch-all for stdout's errors)."""
    long = tmp_path / "long.py"
    long.write_text(BATTERY_SPRING.replace("t_end=0.1", "t_end=5.0"))
    line = one_error_line(invoke(["simulate", long, "--plot", tiny_disk / "o.png"]))
    assert line == f"acausal: error: --plot {tiny_disk / 'o.png'}: writing failed: No space " \
        "left on device", line
    out = tiny_disk / "s.csv"
    line = one_error_line(invoke(["sweep", bspring, "--param", "k.c=10:150:300", "--measure",
                                  "s_end", "--out", out, "--workers", "1", "--no-progress"]))
    assert f"--out {out}: writing failed: No space left on device; the points finished " \
        f"before are in {out} and {out}.partial/" in line, line


@pytest.mark.parametrize("damage, said", [
    ("binary", "is not a sweep's CSV (UnicodeDecodeError"),           # was a traceback
    ("partial is a file", ".partial, where the finished work is kept, is a file, not a "
                          "folder: move it away")])                    # FileExistsError
def test_a_damaged_resume_file_is_one_line(tmp_path, bspring, damage, said):
    out = tmp_path / "s.csv"
    if damage == "binary":
        out.write_bytes(b"\x00\x01garbage\xff\xfe\n")
    else:
        (tmp_path / "s.csv.partial").write_text("not a folder")
    line = one_error_line(invoke(["sweep", bspring, "--param", "k.c=10:20:3", "--measure",
                                  "s_end", "--out", out, "--workers", "1", "--no-progress"]))
    assert said in line, line


def test_a_resumed_csv_cut_mid_line_is_said_as_the_sweeps_own_warning(tmp_path, bspring):
    """It was counted among 'the numerical libraries warned during the run'."""
    out = tmp_path / "s.csv"
    out.write_text("k.c,s_end,status,error,wall_s\n10.0,0.01,ok,,0.1\n15.0,0.0")
    r = invoke(["sweep", bspring, "--param", "k.c=10:20:3", "--measure", "s_end", "--out", out,
                "--workers", "1", "--no-progress"])
    assert r.exit_code == 0, r.output
    lines = r.stderr.strip().splitlines()
    assert lines[-1] == f"acausal: warning: {out}: dropped an incomplete last line (a run " \
        "killed while writing it); that point will be recomputed", r.stderr
    assert not any("numerical libraries" in ln for ln in lines), r.stderr


POOL = """\
import multiprocessing, time
from pathlib import Path
pool = multiprocessing.get_context("fork").Pool(2)
waiting = pool.map_async(time.sleep, [300, 300])
Path({pids!r}).write_text(" ".join(str(p.pid) for p in pool._pool))
time.sleep(120)
""" + h.SPRING_IMPORTS + h.SPRING_MODEL


def test_a_model_files_forked_pool_ends_without_a_traceback(tmp_path):
    """A model file's multiprocessing pool (forked: the command's stop
    handlers inherited) printed two KeyboardInterrupt tracebacks on the
    command's stderr when the watchdog ended it after a SIGKILL."""
    pids, model = tmp_path / "pids", tmp_path / "pool.py"
    model.write_text(POOL.format(pids=str(pids)))
    proc = h.cli(["simulate", model], h.env(tmp_path / "log"))
    h.wait_for(lambda: pids.exists() and len(pids.read_text().split()) == 2, proc)
    workers = [int(p) for p in pids.read_text().split()]
    time.sleep(3 * descendants.POLL_S)
    proc.kill()
    _, err = proc.communicate(timeout=60)
    deadline = time.monotonic() + 5.0
    while any(map(_alive, workers)) and time.monotonic() < deadline:
        time.sleep(0.05)
    assert not [p for p in workers if _alive(p)]
    assert "Traceback" not in err and not err.strip(), err


@pytest.mark.parametrize("command", [["simulate"], ["animate", "--out", "{t}/a.gif"]])
def test_a_bad_memory_limit_in_the_environment_is_one_line(tmp_path, bspring, command):
    """ACAUSAL_MAX_MEMORY=lots was read before simulate's (and animate's)
    own error handling: a UsageError traceback."""
    args = [command[0], bspring] + [a.format(t=tmp_path) for a in command[1:]]
    r = CliRunner().invoke(main, [str(a) for a in args], env={"ACAUSAL_MAX_MEMORY": "lots"})
    assert one_error_line(r) == "acausal: error: ACAUSAL_MAX_MEMORY 'lots': expected a size " \
        "such as 4GB, 512MB or 2e9 (bytes)"


def test_a_model_file_leaves_no_recursion_limit_umask_or_alarm_behind(tmp_path):
    """sys.setrecursionlimit(30) in a model file gave a RecursionError
    traceback from the command's next import; os.umask(0o777) wrote the
    results unreadable; signal.alarm(1) killed the command a second later
    (exit 142, no word)."""
    path = tmp_path / "m.py"
    path.write_text(h.spring_file("import inspect, os, signal, sys\n"
                                  "sys.setrecursionlimit(len(inspect.stack()) + 20)\n"
                                  "os.umask(0o777)\nsignal.alarm(1)\n"
                                  "experiment = Experiment(t_end=0.01)\n"))
    depth, mask = sys.getrecursionlimit(), os.umask(0o022)
    os.umask(mask)
    out = tmp_path / "o.csv"
    r = invoke(["simulate", path, "--out", out])
    assert r.exit_code == 0, r.output
    assert sys.getrecursionlimit() == depth and os.umask(mask) == mask
    assert signal.getitimer(signal.ITIMER_REAL) == (0.0, 0.0)
    assert out.stat().st_mode & 0o777 == 0o666 & ~mask


@pytest.mark.parametrize("params, ok", [
    (["k.c=10,20", "F=1,2", "body.m=0.1,0.2"], False), (["F=1", "k.c=10,20", "body.m=0.1,0.2"], False),
    pytest.param(["k.c=10,20", "F=1", "body.m=0.1,0.2"], True, marks=pytest.mark.slow)])
def test_a_sweep_plot_that_cannot_be_drawn_is_refused_before_the_sweep(tmp_path, bspring,
                                                                        params, ok):
    """Three varied parameters and --plot ran the whole sweep, then said
    'rows vary in [...]; pass by=' (the Python API's advice), exit 2."""
    args = ["sweep", bspring, "--measure", "s_end", "--out", tmp_path / "s.csv", "--plot",
            tmp_path / "s.png", "--workers", "1", "--no-progress"]
    for p in params:
        args += ["--param", p]
    r = invoke(args)
    if ok:
        assert r.exit_code == 0 and (tmp_path / "s.png").exists(), r.output
    else:
        assert "a line per value of one other, but this sweep also varies" in one_error_line(r)
        assert not (tmp_path / "s.csv").exists()


def test_a_model_file_that_asks_for_input_is_one_line_not_a_hang(tmp_path):
    """``input()`` in a model file waited forever on the harness's open
    stdin (a hang); the command gives the file an empty one."""
    path = tmp_path / "asks.py"
    path.write_text(h.spring_file("answer = input('stiffness? ')\n"
                                  "experiment = Experiment(t_end=0.1)\n"))
    p = subprocess.Popen([sys.executable, "-m", "acausal.cli", "simulate", str(path)],
                         env=dict(os.environ, PYTHONPATH=str(h.ROOT)), stdin=subprocess.PIPE,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        p.wait(timeout=60)      # stdin left open, as a harness or a terminal would
    finally:
        if p.poll() is None:
            p.kill()
    err = p.stderr.read()
    p.stdin.close()
    p.stdout.close()
    p.stderr.close()
    assert p.returncode == 2, (p.returncode, err)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and "Traceback" not in err, err
    assert f"{path}:" in lines[0] and "EOFError" in lines[0] and "no standard input" in lines[0]
