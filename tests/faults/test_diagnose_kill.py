"""`acausal diagnose` keeps its finished fits: killed by SIGKILL midway, it
leaves no worker behind, and the same command resumes from the checkpoint
(``<report>/checkpoint/``) instead of fitting again."""
import json
import random
import signal
from pathlib import Path

import numpy as np
import pytest

from acausal.checkpoint import Checkpoint
from acausal.diagnose.fitting import Fit
from acausal.diagnose.run import _run_tasks
from acausal.executor import open_executor

from . import helpers as h

STUB = "tests.diagnose.stub_library"


def _record(x, log):
    log.append(x)
    fit = Fit(names=["a"], values={"a": x}, cost=x * x, residuals=np.array([x, -x]),
              jacobian=np.eye(2)[:, :1], groups=["E1", "E2"], signals=["s", "s"],
              ci95={"a": (x - 1.0, x + 1.0)}, n_sim=3, wall_s=0.5)
    return dict(hyp="h", location="mass", fit=fit, loo={"E1": np.array([x])}, error=None,
                wall_s=0.25)


def test_run_tasks_takes_stored_fits_and_stores_new_ones(tmp_path):
    """The diagnosis hook in isolation: a fit in the store is not recomputed,
    a new one is stored as it finishes and reads back equal."""
    store = Checkpoint(tmp_path / "checkpoint", "k", types=(Fit,))
    log = []
    calls = [(_record, (float(x), log)) for x in range(4)]
    keys = [f"fit {x}" for x in range(4)]
    with open_executor("serial") as ex:
        first = _run_tasks(ex, calls[:2], "t", False, store, keys[:2])
        with open(store.path, "ab") as f:
            f.write(b"0123456789abcdef {\"key\": \"fit 2\", \"val")  # a kill mid-write
        again = _run_tasks(ex, calls, "t", False, store, keys)
    assert log == [0.0, 1.0, 2.0, 3.0]          # 0 and 1 were not fitted twice
    for a, b in zip(first + again[2:], again):
        assert a["fit"].values == b["fit"].values and a["fit"].ci95 == b["fit"].ci95
        np.testing.assert_array_equal(a["fit"].residuals, b["fit"].residuals)
        np.testing.assert_array_equal(a["loo"]["E1"], b["loo"]["E1"])
    assert store.load().keys() == set(keys) and store.ignored == 0


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
    files = list((report / "checkpoint").glob("*.jsonl"))
    return {k: v for p in files for k, v in h.valid_lines(p, (Fit,))[0].items()}


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
    assert "nominal" in kept and len(kept) >= stop_after
    assert not (report / "report.md").exists()

    proc = h.cli(args, h.env(tmp_path / "log"))
    _, stderr = proc.communicate(timeout=900)
    assert proc.returncode == 0, stderr
    out = json.loads((tmp_path / "out.json").read_text())
    assert (out["cause"], out["location"]) == (truth.hypothesis, truth.location)
    details = json.loads((report / "candidates.json").read_text())
    # the fits the killed run finished were taken over, not redone: same wall time to the bit
    assert details["nominal"]["wall_s"] == kept["nominal"]["fit"].wall_s
    for c in details["candidates"]:
        key = f"fit {c['cause']} {c['location']}"
        if key in kept:
            assert c["wall_s"] == kept[key]["fit"].wall_s
    assert not (report / "checkpoint").exists()  # complete: the checkpoint is gone
