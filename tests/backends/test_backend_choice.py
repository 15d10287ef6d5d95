"""Choosing the backend: res.stats says which ran; an unknown name is one
clear AcausalError."""
import os

import pytest

from acausal.errors import AcausalError
from acausal.modelfile import compile_file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OSC = os.path.join(ROOT, "models", "examples", "oscillator.py")


def test_stats_name_the_backend_and_unknown_names_are_refused():
    _, cm = compile_file(OSC)
    res = cm.simulate(t_end=0.01, backend="sundae")
    assert res.stats["backend"] == "sundae"
    with pytest.raises(AcausalError, match="unknown backend 'nope'"):
        cm.simulate(t_end=0.01, backend="nope")


def test_cli_backend_choice_and_per_command_default(monkeypatch):
    """--backend on the group or on simulate chooses; simulate defaults to the
    library's default; the environment is restored after the command."""
    import json

    from click.testing import CliRunner

    from acausal.runtime.backends import compiled_available
    from acausal.cli import main
    monkeypatch.delenv("ACAUSAL_BACKEND", raising=False)
    runner = CliRunner()
    ran = {}
    for args in (["simulate"], ["simulate", "--backend", "compiled"],
                 ["--backend", "compiled", "simulate"]):
        out = runner.invoke(main, args[:-1] + [args[-1], OSC, "--t-end", "0.01", "--json"]
                            if args[0] != "simulate" else
                            [args[0], OSC, "--t-end", "0.01", "--json"] + args[1:])
        assert out.exit_code == 0, out.output
        ran[" ".join(args)] = json.loads(out.output)["stats"]["backend"]
        assert "ACAUSAL_BACKEND" not in os.environ
    compiled = "compiled" if compiled_available() is None else "sundae"
    assert ran == {"simulate": "sundae", "simulate --backend compiled": compiled,
                   "--backend compiled simulate": compiled}


def test_commands_of_many_runs_default_to_compiled(monkeypatch, tmp_path):
    """calibrate, sweep and diagnose run many simulations of each model and
    default to the compiled backend (measured faster, agreement tested),
    which their simulations see through ACAUSAL_BACKEND; simulate keeps the
    reference (test above)."""
    from click.testing import CliRunner

    import acausal.diagnose.run as run
    from acausal.cli import MANY_RUNS, main
    monkeypatch.delenv("ACAUSAL_BACKEND", raising=False)
    seen = []

    def fake(*a, **k):
        seen.append(os.environ.get("ACAUSAL_BACKEND"))
        raise KeyboardInterrupt
    monkeypatch.setattr(run, "diagnose", fake)
    CliRunner().invoke(main, ["diagnose", OSC, str(tmp_path)])
    assert seen == ["compiled"] and "ACAUSAL_BACKEND" not in os.environ
    assert MANY_RUNS == {"calibrate", "sweep", "diagnose", "tolerance"}
