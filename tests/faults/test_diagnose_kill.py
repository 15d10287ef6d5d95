"""`acausal diagnose` keeps its finished fits: killed by SIGKILL midway, it
leaves no worker behind, and the same command resumes from the checkpoint
(``<report>/checkpoint/``) instead of fitting again."""
import json
import random
import signal
from pathlib import Path

import numpy as np
import pytest

from dataclasses import dataclass

from acausal.diagnose.stages.resume import FitStore, task_key
from acausal.diagnose.stages.chain import run_tasks
from acausal.infra.executor import open_executor

from . import helpers as h

STUB = "tests.diagnose.stub_library"
LOG = []


@dataclass(frozen=True)
class _Task:
    x: float


def _fit(task):
    LOG.append(task.x)
    return dict(values={"a": task.x}, residuals=np.array([task.x, -task.x]), wall_s=0.25 * task.x)


def test_run_tasks_takes_stored_fits_and_stores_new_ones(tmp_path):
    """The diagnosis hook in isolation: a fit in the store is not recomputed,
    a new one is stored as it finishes and reads back equal, and a record
    cut by a kill mid-write is ignored."""
    model, data = tmp_path / "model.py", tmp_path / "data"
    model.write_text("x = 1\n")
    data.mkdir()
    LOG.clear()
    tasks = [_Task(float(x)) for x in range(4)]
    store = FitStore(tmp_path / "rep", model, data, {"o": 1})
    with open_executor("serial") as ex:
        first = run_tasks(ex, _fit, tasks[:2], "t", False, store)
        with open(store.checkpoint.path, "ab") as f:
            f.write(b"0123456789abcdef {\"key\": \"_Task 2\", \"val")  # a kill mid-write
        store = FitStore(tmp_path / "rep", model, data, {"o": 1})   # the rerun
        again = run_tasks(ex, _fit, tasks, "t", False, store)
    assert LOG == [0.0, 1.0, 2.0, 3.0]          # 0 and 1 were not fitted twice
    for a, b in zip(first + again[2:], again):
        assert a["values"] == b["values"] and a["wall_s"] == b["wall_s"]
        np.testing.assert_array_equal(a["residuals"], b["residuals"])
    assert set(store.checkpoint.load()) == {task_key(t) for t in tasks}
    other = FitStore(tmp_path / "rep", model, data, {"o": 2})   # other options: afresh
    assert other.get(tasks[0]) is None


@pytest.fixture(scope="module")
def dataset(tmp_path_factory):
    from acausal.diagnose.synth import synthesize

    d = tmp_path_factory.mktemp("msd")
    model = h.copy_model("msd_diag_model.py", d / "model")
    truth = synthesize(model, d / "data", conditions={"F": [0.5, 1.0, 2.0]}, traces=["mass.s"],
                       sample_rate=200, noise={"mass.s": 1e-5}, resolution={"mass.s": 1e-6},
                       free_jitter=0.1, seed=3, library=STUB, hypothesis="quadratic_damping",
                       location="mass", effect=(6.0, 6.0))
    return model, d / "data", truth


def _records(report):
    """task key -> stored fit result, over the report's checkpoint files."""
    import base64
    import pickle
    files = list((report / "checkpoint").glob("*.jsonl"))
    return {k: pickle.loads(base64.b64decode(v))
            for p in files for k, v in h.valid_lines(p)[0].items()}


@pytest.mark.slow  # three minutes of fits on a busy 2-core machine (about 40 s per run)
def test_diagnose_sigkill_leaves_no_worker_and_resumes(tmp_path, dataset):
    model, data, truth = dataset
    report = tmp_path / "rep"
    args = ["diagnose", model, data, "--report", report, "--workers", "2", "--no-progress",
            "--library", STUB, "--json", tmp_path / "out.json"]
    stop_after = random.Random().randint(1, 3)  # the nominal fit, and 0-2 candidates
    proc = h.cli(args, h.env(tmp_path / "log"))
    h.wait_for(lambda: len(_records(report)) >= stop_after, proc, timeout=600)
    alive, _ = h.kill_tree_check(proc, signal.SIGKILL)
    assert not alive, f"workers left running after SIGKILL: {alive}"
    kept = _records(report)
    assert len(kept) >= stop_after
    assert not (report / "report.md").exists()

    proc = h.cli(args, h.env(tmp_path / "log"))
    _, stderr = proc.communicate(timeout=900)
    assert proc.returncode == 0, stderr
    out = json.loads((tmp_path / "out.json").read_text())
    assert (out["cause"], out["location"]) == (truth.hypothesis, truth.location)
    details = json.loads((report / "candidates.json").read_text())
    # the fits the killed run finished were taken over, not redone: same wall time to the bit
    walls = {details["nominal"]["wall_s"]} | {c["wall_s"] for c in details["candidates"]}
    for r in kept.values():
        assert r.fit.wall_s in walls
    assert not (report / "checkpoint").exists()  # complete: the checkpoint is gone
