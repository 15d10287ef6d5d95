"""Tests for acausal.sweep and acausal.executor (small and fast: 2 shared cores)."""

import csv
import functools
import math
import os
import re
import sys

import numpy as np
import pytest

from acausal.infra.executor import clear_worker_cache, open_executor, worker_cache
from acausal.studies.sweep import SweepAborted, grid, parse_param, plot_sweep, run_sweep
from tests.core import sweep_tasks
from acausal.errors import UsageError


def read_csv(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def xs(n):
    return grid([("x", np.arange(n, dtype=float))])


@pytest.fixture
def log_dir(tmp_path):
    d = tmp_path / "calls"
    d.mkdir()
    return d


# ---------------------------------------------------------------------------
# parse_param / grid
# ---------------------------------------------------------------------------


@pytest.mark.parametrize(
    "spec, name, values",
    [
        ("v_impact=3.0:5.0:21", "v_impact", np.linspace(3.0, 5.0, 21)),
        ("k=1,2,5", "k", [1.0, 2.0, 5.0]),
        ("k=3", "k", [3.0]),
        (" contact.K = 1e5, 2.5e6 ", "contact.K", [1e5, 2.5e6]),
        ("x=1:-1:3", "x", [1.0, 0.0, -1.0]),
        ("x=2:2:1", "x", [2.0]),
    ],
)
def test_parse_param_good(spec, name, values):
    got_name, got = parse_param(spec)
    assert got_name == name
    assert got.dtype == float
    np.testing.assert_array_equal(got, values)


def test_parse_param_range_is_inclusive():
    _, v = parse_param("v_impact=3.0:5.0:21")
    assert len(v) == 21 and v[0] == 3.0 and v[-1] == 5.0


@pytest.mark.parametrize(
    "spec",
    ["x", "=1", "1x=2", "x.=1", "x=", "x=1:2", "x=1:2:3:4", "x=1:2:0", "x=1:2:-1", "x=1:2:2.5",
     "x=1:2:n", "x=a", "x=1,,2", "x=1,", "x=1,nan", "x=inf", "x=1:2:1", "x=1,1"],
)
def test_parse_param_bad_names_the_spec(spec):
    with pytest.raises(UsageError, match=re.escape(repr(spec))):
        parse_param(spec)


def test_parse_param_count_message():
    with pytest.raises(UsageError, match="integer >= 1"):
        parse_param("x=0:1:0")
    with pytest.raises(UsageError, match="integer >= 1"):
        parse_param("x=0:1:2.5")


def test_grid_order_last_parameter_fastest():
    points = grid([("a", [1, 2]), ("b.c", np.array([10.0, 20.0, 30.0]))])
    assert points == [
        {"a": 1.0, "b.c": 10.0}, {"a": 1.0, "b.c": 20.0}, {"a": 1.0, "b.c": 30.0},
        {"a": 2.0, "b.c": 10.0}, {"a": 2.0, "b.c": 20.0}, {"a": 2.0, "b.c": 30.0},
    ]
    assert all(type(v) is float for p in points for v in p.values())
    with pytest.raises(UsageError, match="repeat"):
        grid([("a", [1]), ("a", [2])])


# ---------------------------------------------------------------------------
# executors
# ---------------------------------------------------------------------------


def test_serial_executor_is_lazy_and_ordered(log_dir):
    task = functools.partial(sweep_tasks.logged, log_dir=log_dir)
    with open_executor("serial") as ex:
        futures = [ex.submit(task, p) for p in xs(3)]
        assert sweep_tasks.calls(log_dir) == []  # nothing ran at submit
        results = [f.result()["y"] for f in ex.as_completed(futures)]
    assert results == [0.0, 1.0, 4.0]


def test_serial_future_keeps_task_exception(log_dir):
    task = functools.partial(sweep_tasks.logged, log_dir=log_dir, fail_x=(1.0,))
    with open_executor("serial") as ex:
        fut = ex.submit(task, {"x": 1.0})
        assert isinstance(fut.exception(), ValueError)
        with pytest.raises(ValueError):
            fut.result()


def test_process_pool_executor_runs_tasks():
    with open_executor(workers=2) as ex:
        assert ex.kind == "processes" and ex.workers == 2
        futures = [ex.submit(pow, 2, n) for n in range(5)]
        assert sorted(f.result() for f in ex.as_completed(futures)) == [1, 2, 4, 8, 16]


@pytest.mark.parametrize(
    "scheduler, workers, error",
    [("bogus", None, UsageError), ("serial", 2, UsageError), (None, 0, UsageError), (42, None, TypeError)],
)
def test_open_executor_rejects_bad_arguments(scheduler, workers, error):
    with pytest.raises(error):
        open_executor(scheduler, workers)


def test_missing_dask_gives_install_hint(monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # makes `import distributed` fail
    with pytest.raises(UsageError, match=r"acausal\[dask\]"):
        with open_executor("tcp://127.0.0.1:8786"):
            pass


def test_worker_cache_builds_once_per_process(log_dir):
    calls = []
    clear_worker_cache()
    try:
        assert worker_cache("k", lambda: calls.append(1) or "v") == "v"
        assert worker_cache("k", lambda: calls.append(1) or "w") == "v"
        assert calls == [1]
    finally:
        clear_worker_cache()


def test_worker_cache_reused_across_points_in_pool(tmp_path, log_dir):
    task = functools.partial(sweep_tasks.cached_token, log_dir=log_dir)
    with open_executor(workers=2) as ex:
        rows = run_sweep(task, xs(8), tmp_path / "s.csv", executor=ex, measures=["token", "pid"], progress=False)
    factories = list(log_dir.glob("*.factory"))
    assert 1 <= len(factories) <= 2  # once per worker process, not once per point
    tokens_by_pid = {}
    for r in rows:
        tokens_by_pid.setdefault(r["pid"], set()).add(r["token"])
    assert all(len(t) == 1 for t in tokens_by_pid.values())


# ---------------------------------------------------------------------------
# run_sweep
# ---------------------------------------------------------------------------


def test_sweep_on_process_pool(tmp_path):
    points = grid([("x", [1.0, 2.0, 3.0]), ("k", [0.0, 0.5])])
    out = tmp_path / "sub" / "sweep.csv"
    with open_executor(workers=2) as ex:
        rows = run_sweep(sweep_tasks.square, points, out, executor=ex, measures=["y"], progress=False)
    assert [(r["x"], r["k"]) for r in rows] == [(p["x"], p["k"]) for p in points]
    assert [r["y"] for r in rows] == [p["x"] ** 2 + p["k"] for p in points]
    assert all(r["status"] == "ok" and r["error"] == "" and r["wall_s"] >= 0 for r in rows)
    lines = read_csv(out)
    assert list(lines[0]) == ["x", "k", "y", "status", "error", "wall_s"]
    assert len(lines) == len(points)


def test_failed_points_are_recorded_and_do_not_stop_the_sweep(tmp_path, log_dir):
    task = functools.partial(sweep_tasks.logged, log_dir=log_dir, fail_x=(1.0, 3.0))
    with open_executor(workers=2) as ex:
        rows = run_sweep(task, xs(5), tmp_path / "s.csv", executor=ex, measures=["y", "tag"], progress=False)
    assert [r["status"] for r in rows] == ["ok", "failed", "ok", "failed", "ok"]
    assert rows[1]["error"] == "ValueError: bad point x=1.0"  # one line
    assert math.isnan(rows[1]["y"]) and math.isnan(rows[1]["tag"])
    assert rows[2]["y"] == 4.0 and rows[2]["tag"] == "x2"
    assert len(sweep_tasks.calls(log_dir)) == 5


def test_bad_task_results_fail_the_point(tmp_path):
    with open_executor("serial") as ex:
        rows = run_sweep(sweep_tasks.square, xs(2), tmp_path / "s.csv", executor=ex, measures=["nope"], progress=False)
    assert [r["status"] for r in rows] == ["failed", "failed"]
    assert rows[0]["error"].startswith("UsageError")


def test_resume_after_keyboard_interrupt_serial(tmp_path, log_dir):
    out = tmp_path / "s.csv"
    with open_executor("serial") as ex:
        task = functools.partial(sweep_tasks.logged, log_dir=tmp_path, fail_x=(1.0,), interrupt_x=3.0)
        with pytest.raises(KeyboardInterrupt):
            run_sweep(task, xs(6), out, executor=ex, measures=["y"], progress=False)
        assert [float(r["x"]) for r in read_csv(out)] == [0.0, 1.0, 2.0]  # finished points were saved
        rows = run_sweep(functools.partial(sweep_tasks.logged, log_dir=log_dir), xs(6), out,
                         executor=ex, measures=["y"], progress=False)
    assert sorted(c["x"] for c in sweep_tasks.calls(log_dir)) == [3.0, 4.0, 5.0]  # ok and failed not redone
    assert [r["status"] for r in rows] == ["ok", "failed", "ok", "ok", "ok", "ok"]
    assert len(read_csv(out)) == 6


def test_resume_after_interrupt_in_a_pool_worker(tmp_path, log_dir):
    out, first, second = tmp_path / "s.csv", log_dir / "1", log_dir / "2"
    first.mkdir()
    second.mkdir()
    with open_executor(workers=2) as ex:
        task = functools.partial(sweep_tasks.logged, log_dir=first, interrupt_x=4.0)
        with pytest.raises(KeyboardInterrupt):
            run_sweep(task, xs(10), out, executor=ex, measures=["y"], progress=False)
    saved = {float(r["x"]) for r in read_csv(out)}
    assert 4.0 not in saved and all(r["status"] == "ok" for r in read_csv(out))
    with open_executor(workers=2) as ex:
        task = functools.partial(sweep_tasks.logged, log_dir=second)
        rows = run_sweep(task, xs(10), out, executor=ex, measures=["y"], progress=False)
    redone = sorted(c["x"] for c in sweep_tasks.calls(second))
    assert redone == sorted(set(np.arange(10.0)) - saved)
    assert [r["y"] for r in rows] == [x * x for x in range(10)]


def test_resume_from_partial_csv_on_pool(tmp_path, log_dir):
    out = tmp_path / "s.csv"
    points = grid([("x", [0.1, 0.2, 0.3]), ("k", [1.0, 2.0])])
    with open_executor("serial") as ex:  # "first half": every other point
        run_sweep(sweep_tasks.square, points[::2], out, executor=ex, measures=["y"], progress=False)
    task = functools.partial(sweep_tasks.logged, log_dir=log_dir)
    with open_executor(workers=2) as ex:
        rows = run_sweep(task, points, out, executor=ex, measures=["y"], progress=False)
    assert sorted((c["x"], c["k"]) for c in sweep_tasks.calls(log_dir)) == sorted(
        (p["x"], p["k"]) for p in points[1::2])
    assert [(r["x"], r["k"]) for r in rows] == [(p["x"], p["k"]) for p in points]
    assert rows[0]["y"] == 0.1 ** 2 + 1.0  # from the first run (square adds k; logged does not)
    assert rows[1]["y"] == 0.1 ** 2


def test_rerun_of_finished_sweep_computes_nothing(tmp_path, log_dir):
    out = tmp_path / "s.csv"
    task = functools.partial(sweep_tasks.logged, log_dir=log_dir)
    with open_executor("serial") as ex:
        first = run_sweep(task, xs(3), out, executor=ex, measures=["y", "tag"], progress=False)
        again = run_sweep(task, xs(3), out, executor=ex, measures=["tag", "y"], progress=False)
    assert len(sweep_tasks.calls(log_dir)) == 3
    assert again == first


def test_existing_csv_with_other_columns_is_refused(tmp_path):
    out = tmp_path / "s.csv"
    with open_executor("serial") as ex:
        run_sweep(sweep_tasks.square, xs(2), out, executor=ex, measures=["y"], progress=False)
        before = out.read_text()
        with pytest.raises(UsageError, match="columns"):
            run_sweep(sweep_tasks.square, xs(2), out, executor=ex, measures=["z"], progress=False)
        with pytest.raises(UsageError, match="columns"):
            run_sweep(sweep_tasks.square, grid([("x", [1]), ("k", [1])]), out, executor=ex,
                      measures=["y"], progress=False)
    assert out.read_text() == before


def test_incomplete_last_line_is_dropped_and_recomputed(tmp_path, log_dir):
    out = tmp_path / "s.csv"
    out.write_text("x,y,status,error,wall_s\n0.0,0.0,ok,,0.1\n1.0,1.")  # crash mid-write
    task = functools.partial(sweep_tasks.logged, log_dir=log_dir)
    with open_executor("serial") as ex, pytest.warns(RuntimeWarning, match="incomplete"):
        rows = run_sweep(task, xs(2), out, executor=ex, measures=["y"], progress=False)
    assert [c["x"] for c in sweep_tasks.calls(log_dir)] == [1.0]
    assert [r["y"] for r in rows] == [0.0, 1.0]
    assert len(read_csv(out)) == 2


def test_unpicklable_task_is_refused_for_process_pool(tmp_path):
    with open_executor(workers=1) as ex, pytest.raises(TypeError, match="picklable"):
        run_sweep(lambda p: {"y": 1.0}, xs(1), tmp_path / "s.csv", executor=ex, measures=["y"], progress=False)


def test_executor_failure_aborts_without_recording(tmp_path):
    class Broken:
        """Executor stand-in whose futures fail (as a broken pool's would)."""

        needs_pickle = False

        def submit(self, fn, *args):
            from concurrent.futures import Future
            fut = Future()
            fut.set_exception(RuntimeError("pool broke"))
            return fut

        def as_completed(self, futures):
            return iter(futures)

        def cancel(self, futures):
            pass

    out = tmp_path / "s.csv"
    with pytest.raises(SweepAborted, match="pool broke"):
        run_sweep(sweep_tasks.square, xs(3), out, executor=Broken(), measures=["y"], progress=False)
    assert read_csv(out) == []


def test_progress_bar_goes_to_stderr(tmp_path, capsys):
    with open_executor("serial") as ex:
        run_sweep(sweep_tasks.square, xs(3), tmp_path / "s.csv", executor=ex, measures=["y"], progress=True)
    captured = capsys.readouterr()
    assert "3/3" in captured.err and captured.out == ""


# ---------------------------------------------------------------------------
# Dask
# ---------------------------------------------------------------------------


def test_sweep_on_dask_local_cluster(tmp_path, log_dir):
    distributed = pytest.importorskip("distributed")
    task = functools.partial(sweep_tasks.logged, log_dir=log_dir, fail_x=(2.0,))
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  dashboard_address=None) as cluster:
        with open_executor(cluster) as ex:  # cluster object
            assert ex.kind == "dask"
            rows = run_sweep(task, xs(3), tmp_path / "s.csv", executor=ex, measures=["y"], progress=False)
        with open_executor(cluster.scheduler_address) as ex:  # address string
            rows = run_sweep(task, xs(5), tmp_path / "s.csv", executor=ex, measures=["y"], progress=False)
    assert [r["status"] for r in rows] == ["ok", "ok", "failed", "ok", "ok"]
    assert [r["y"] for r in rows if r["status"] == "ok"] == [0.0, 1.0, 9.0, 16.0]
    assert len(sweep_tasks.calls(log_dir)) == 5


# ---------------------------------------------------------------------------
# plot
# ---------------------------------------------------------------------------


def test_plot_sweep_2d_with_failures(tmp_path, log_dir):
    pyplot_loaded = "matplotlib.pyplot" in sys.modules
    points = grid([("x", [0.0, 1.0, 2.0, 3.0]), ("k", [1.0, 2.0])])
    task = functools.partial(sweep_tasks.logged, log_dir=log_dir, fail_x=(2.0,))
    with open_executor("serial") as ex:
        rows = run_sweep(task, points, tmp_path / "s.csv", executor=ex, measures=["y"], progress=False)
    png = plot_sweep(rows, "x", "y", tmp_path / "y.png")
    assert png.stat().st_size > 1000
    plot_sweep(list(rows), "x", "y", tmp_path / "y2.png", by="k")  # plain list: by= explicit
    with pytest.raises(UsageError, match="by="):
        plot_sweep(list(rows), "x", "y", tmp_path / "y3.png")
    assert ("matplotlib.pyplot" in sys.modules) == pyplot_loaded  # no pyplot state touched


def test_dask_worker_process_reuses_worker_cache(tmp_path, log_dir):
    distributed = pytest.importorskip("distributed")
    task = functools.partial(sweep_tasks.cached_token, log_dir=log_dir)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as cluster:
        with open_executor(cluster) as ex:
            rows = run_sweep(task, xs(4), tmp_path / "s.csv", executor=ex, measures=["token", "pid"],
                             progress=False)
    assert {r["pid"] for r in rows} != {float(os.getpid())}  # ran in the worker process
    assert len({r["token"] for r in rows}) == 1 and len(list(log_dir.glob("*.factory"))) == 1


def test_benchmark_script_runs_on_tiny_points():
    from benchmarks import sweep_scaling

    task = functools.partial(sweep_scaling.spin, loops=1000)
    result = sweep_scaling.measure_scaling(task, xs(4), ["value"], workers=2)
    assert result["points"] == 4 and result["ratio"] > 0 and result["startup_s"] >= 0
    assert "ratio parallel/(sequential/2)" in sweep_scaling.report(result)
