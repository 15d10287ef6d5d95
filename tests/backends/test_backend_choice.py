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


@pytest.mark.parametrize("cc", ["false", None])
def test_calibrate_says_once_when_its_model_cannot_run_in_c(tmp_path, cc):
    """calibrate (and diagnose) run on the compiled backend; a model that
    cannot be built in C (here a C compiler that always fails) runs on
    sundae, 3-20x slower: one note line says so and why, and the fit is
    still right. With a working compiler there is no note. (MSL's
    OneWayClutch had fallen back so for a printer's ``true``, unseen.)"""
    import json
    import shutil

    import numpy as np
    from click.testing import CliRunner

    from acausal.cli import main
    from acausal.data import Dataset, Instrument, MeasuredExperiment, Trace, write_dataset
    from acausal.runtime.backends import compiled_available

    if cc is None and compiled_available() is not None:
        pytest.skip(compiled_available())
    model = tmp_path / "slider.py"            # a model (and library) of this test's own
    shutil.copy(os.path.join(ROOT, "tests", "diagnose", "slider_model.py"), model)
    t = np.linspace(0.0, 0.25, 200)
    rng = np.random.default_rng(1)
    exps = [MeasuredExperiment(f"R{k}", {"s0": s0}, {}, Trace(
        t, {"mass.s": s0 * np.cos(np.sqrt(120.0) * t) + rng.normal(0.0, 1e-5, t.size)}))
        for k, s0 in enumerate((0.1, -0.07))]
    write_dataset(tmp_path / "data", Dataset(None, exps, {"mass.s": Instrument(
        "mass.s", noise_std=1e-5)}))
    env = {"ACAUSAL_CACHE": str(tmp_path / "cache"), "CC": cc}
    r = CliRunner(env=env).invoke(main, ["calibrate", str(model), str(tmp_path / "data"),
                                         "--fit", "spring.c", "--json"])
    assert r.exit_code == 0, r.output
    notes = [ln for ln in r.stderr.splitlines() if "compiled backend unavailable" in ln]
    if cc is None:
        assert notes == []
    else:
        assert len(notes) == 1, r.stderr
        assert str(model) in notes[0] and "the C compiler failed" in notes[0] \
            and "run on sundae" in notes[0]
        assert "exit status 1, no message" in notes[0]     # `false` prints nothing
    fitted = json.loads(r.stdout)["values"]["spring.c"]
    fitted = fitted["value"] if isinstance(fitted, dict) else fitted
    assert abs(fitted - 120.0) / 120.0 < 1e-3
