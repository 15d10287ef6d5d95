"""`acausal sweep` killed mid-run (SIGKILL, SIGTERM): no worker outlives it,
no finished point is lost, no row is corrupt, and the same command resumes."""
import csv
import math
import random
import signal

import numpy as np
import pytest

from . import helpers as h

N = 12
MASSES = np.linspace(1.0, 2.0, N)


def closed_form(m, t=2.0):
    w = math.sqrt(100.0 / m)
    return 0.1 * math.cos(w * t), -0.1 * w * math.sin(w * t)


def sweep_args(model, out):
    return ["sweep", model, "--param", f"mass.m=1:2:{N}", "--measure", "s_end,v_end",
            "--out", out, "--workers", "2", "--no-progress"]


def read_rows(path):
    with open(path, newline="") as f:   # header "name [unit]": keyed by name
        return [{k.split(" [")[0]: v for k, v in r.items()} for r in csv.DictReader(f)]


def finished_after_kill(out):
    """Masses a killed run had finished: in its CSV (atomic, so every row is
    whole) or in the checkpoint (checksummed lines)."""
    done = set()
    if out.exists():
        rows = read_rows(out)
        assert all(r["status"] in ("ok", "failed") and r["wall_s"] for r in rows)
        done |= {float(r["mass.m"]) for r in rows}
    partial = out.with_name(out.name + ".partial")
    for path in partial.glob("*.jsonl"):
        records, bad = h.valid_lines(path)
        assert bad <= 1  # at most the line being written when killed
        done |= {float(v["mass.m"]) for v in records.values()}
    return done


def checkpoint_records(out):
    files = list(out.with_name(out.name + ".partial").glob("*.jsonl"))
    return sum(len(h.valid_lines(p)[0]) for p in files)


# ~10-25 s on a busy 2-core machine (two command starts, each importing sympy
# and compiling in two workers): kept in the default tier, it is the acceptance test
def test_sweep_sigkill_leaves_no_worker_and_resumes(tmp_path):
    model = h.copy_model("osc_sweep_model.py", tmp_path / "model")
    out = tmp_path / "res" / "sweep.csv"
    stop_after = random.Random().randint(1, N - 4)   # a random moment
    proc = h.cli(sweep_args(model, out), h.env(tmp_path / "log1", sleep=0.15))
    h.wait_for(lambda: checkpoint_records(out) >= stop_after, proc)
    alive, _ = h.kill_tree_check(proc, signal.SIGKILL)
    assert not alive, f"workers left running after SIGKILL: {alive}"
    first = finished_after_kill(out)
    assert stop_after <= len(first) < N

    proc = h.cli(sweep_args(model, out), h.env(tmp_path / "log2"))
    stdout, stderr = proc.communicate(timeout=300)
    assert proc.returncode == 0, stderr
    again = h.logged(tmp_path / "log2")
    assert set(again).isdisjoint(first)              # nothing finished is redone ...
    assert len(again) == N - len(first)              # ... and only once
    rows = read_rows(out)
    assert sorted(float(r["mass.m"]) for r in rows) == pytest.approx(MASSES, abs=0)
    for r in rows:
        s, v = closed_form(float(r["mass.m"]))
        assert r["status"] == "ok"
        assert float(r["s_end"]) == pytest.approx(s, abs=1e-6)
        assert float(r["v_end"]) == pytest.approx(v, abs=1e-5)
    assert not out.with_name(out.name + ".partial").exists()  # done: checkpoint removed


@pytest.mark.slow  # two command starts (~15 s on a busy 2-core machine)
def test_sweep_sigterm_stops_workers_and_says_how_to_resume(tmp_path):
    model = h.copy_model("osc_sweep_model.py", tmp_path / "model")
    out = tmp_path / "sweep.csv"
    proc = h.cli(sweep_args(model, out), h.env(tmp_path / "log", sleep=0.3))
    h.wait_for(lambda: checkpoint_records(out) >= 1, proc)
    alive, stderr = h.kill_tree_check(proc, signal.SIGTERM)
    assert not alive, f"workers left running after SIGTERM: {alive}"
    assert proc.returncode == 130, stderr
    assert "run the same command again to resume" in stderr
    done = finished_after_kill(out)
    assert 1 <= len(done) < N
    assert len(read_rows(out)) == len(done)          # the CSV was written on the way out
