"""Acceptance of ``acausal sweep`` on the real breaker model, through the CLI,
on a Dask LocalCluster (two worker processes, ``--scheduler ADDRESS``):
the results equal sequential simulations, a rerun with the same ``--out``
computes nothing, and a point that makes the model invalid is recorded as
failed while the others finish. The timing acceptance (21 points on 2
cores) is benchmarks/sweep_breaker.py, not a test: the machine is shared."""
import csv
import os

import numpy as np
import pytest
from click.testing import CliRunner

from acausal.infra import executor as executor_mod
from acausal.cli import main
from acausal.modelfile import run_file

distributed = pytest.importorskip("distributed")

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MODEL = os.path.join(ROOT, "models", "breaker_24kv.py")
SPEEDS = np.linspace(3.3, 4.5, 5)


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as c:
        yield c


@pytest.fixture
def submissions(monkeypatch):
    """Count the tasks the sweep hands to the executor."""
    calls = []
    real = executor_mod.Executor.submit

    def counting(self, fn, *args, **kw):
        calls.append(args)
        return real(self, fn, *args, **kw)

    monkeypatch.setattr(executor_mod.Executor, "submit", counting)
    return calls


def sweep(out, scheduler, *params):
    args = ["sweep", MODEL, "--measure", "thrt", "--out", str(out), "--scheduler", scheduler,
            "--no-progress"]
    for p in params:
        args += ["--param", p]
    result = CliRunner().invoke(main, args, catch_exceptions=False)
    assert result.exit_code == 0, result.output
    return result.output


def rows(out):
    """The CSV's rows keyed by column name (the header is ``name [unit]``)."""
    with open(out, newline="") as f:
        reader = csv.DictReader(f)
        assert reader.fieldnames[0] == "v_impact [m/s]"
        return [{k.split(" [")[0]: v for k, v in r.items()} for r in reader]


def test_sweep_on_dask_equals_sequential_runs_and_resumes(cluster, submissions, tmp_path):
    out = tmp_path / "thrt.csv"
    # at the report's K (the model file defaults to the project's 6.17e8)
    text = sweep(out, cluster.scheduler_address, "v_impact=3.3:4.5:5", "contact.K=6.25e8")
    assert "5 points, 0 failed" in text
    assert len(submissions) == 5
    got = {float(r["v_impact"]): r for r in rows(out)}
    assert sorted(got) == pytest.approx(list(SPEEDS), abs=0)
    for v in SPEEDS:
        row = got[float(v)]
        assert row["status"] == "ok" and row["error"] == ""
        # same code, same numbers: the worker's run equals an in-process one
        ref = run_file(MODEL, params={"v_impact": v, "contact.K": 6.25e8})[1]["thrt"]
        assert float(row["thrt"]) == pytest.approx(ref, abs=1e-12)
    # Table 2's calculated column at 3.3 and 4.5 m/s (docs/breaker_model.md)
    assert float(got[3.3]["thrt"]) * 1e3 == pytest.approx(2.556, abs=1e-3)
    assert float(got[4.5]["thrt"]) * 1e3 == pytest.approx(1.460, abs=1e-3)

    before = out.read_bytes()
    submissions.clear()
    text = sweep(out, cluster.scheduler_address, "v_impact=3.3:4.5:5", "contact.K=6.25e8")
    assert "5 points, 0 failed" in text
    assert submissions == []                      # resumed: nothing recomputed
    assert out.read_bytes() == before             # and nothing appended


def test_a_point_outside_the_parameter_bounds_is_refused_before_the_sweep(submissions,
                                                                          tmp_path):
    """v_impact = 0 violates the parameter's bound (> 0): the sweep is refused
    with the model's message before any point runs (issue 21: it used to run
    and fail point by point). Points that fail while running are still
    recorded and the sweep goes on (tests/core/test_sweep.py)."""
    out = tmp_path / "bad.csv"
    r = CliRunner().invoke(main, ["sweep", MODEL, "--measure", "thrt", "--out", str(out),
                                  "--no-progress", "--param", "v_impact=3.8,0,4.5"])
    assert r.exit_code == 2, r.output
    assert "v_impact = 0 [m/s] must be > 0" in r.output and len(r.output.splitlines()) == 1
    assert submissions == [] and not out.exists()
