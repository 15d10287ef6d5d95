"""Every model file in models/ runs through the command line (the example
scripts are part of the documentation; this keeps them working)."""
import glob
import json
import os

import pytest
from click.testing import CliRunner

from acausal.cli import main

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
FILES = sorted(glob.glob(os.path.join(ROOT, "models", "**", "*.py"), recursive=True))
FILES = [f for f in FILES if not os.path.basename(f).startswith("_")]


@pytest.mark.parametrize("path", FILES, ids=[os.path.relpath(f, ROOT) for f in FILES])
def test_model_file_runs(path):
    r = CliRunner().invoke(main, ["simulate", path, "--json"])
    assert r.exit_code == 0, r.output
    out = json.loads(r.output)
    assert out["final"] and out["stats"]["steps"] > 0
    for name, value in out["measures"].items():
        assert value == value, name          # no NaN measure
