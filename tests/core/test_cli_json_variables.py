"""The CLI mends of issue 24: ``--json`` prints one JSON object on every
command and ``--json-file FILE`` writes it (``diagnose --json FILE``, the
old form, still writes FILE with one deprecation line); ``acausal
variables`` filters (``--states``, ``--match``) and marks states and
positions."""
import json
import os

from click.testing import CliRunner

from acausal.cli import main

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SLIDER_CRANK = os.path.join(ROOT, "models", "examples", "slider_crank.py")
OSC = os.path.join(ROOT, "models", "examples", "oscillator.py")

SUMMARY = {"discrepancy": False, "unexplained": {"value": False}, "cause": None,
           "ranking": [], "equivalent_causes": [], "extended_model": None,
           "gain": {"before": {"train": 1.0, "heldout": 1.0},
                    "after": {"train": 1.0, "heldout": 1.0}}}


def _stub_diagnosis(monkeypatch, tmp_path):
    """The command line around a diagnosis that returns SUMMARY at once
    (the diagnosis itself is tested elsewhere)."""
    import acausal.diagnose.run as run
    monkeypatch.setattr(run, "diagnose", lambda *a, **k: dict(SUMMARY))
    (tmp_path / "data").mkdir()
    return [OSC, str(tmp_path / "data"), "--report", str(tmp_path / "rep"), "--no-progress"]


def test_diagnose_json_prints_and_json_file_writes(monkeypatch, tmp_path):
    args = _stub_diagnosis(monkeypatch, tmp_path)
    r = CliRunner().invoke(main, ["diagnose", *args, "--json"])
    assert r.exit_code == 0, r.output
    assert json.loads(r.stdout) == SUMMARY
    out = tmp_path / "s.json"
    r = CliRunner().invoke(main, ["diagnose", *args, "--json-file", str(out)])
    assert r.exit_code == 0, r.output
    assert json.loads(out.read_text()) == SUMMARY
    assert "deprecated" not in r.output


def test_diagnose_old_json_file_form_still_writes_with_one_deprecation_line(monkeypatch,
                                                                             tmp_path):
    args = _stub_diagnosis(monkeypatch, tmp_path)
    out = tmp_path / "old.json"
    r = CliRunner().invoke(main, ["diagnose", *args, "--json", str(out)])
    assert r.exit_code == 0, r.output
    assert json.loads(out.read_text()) == SUMMARY
    lines = [x for x in r.stderr.splitlines() if "deprecated" in x]
    assert len(lines) == 1 and f"--json-file {out}" in lines[0]
    assert "no significant discrepancy" in r.stdout


def test_variables_states_and_match():
    r = CliRunner().invoke(main, ["variables", "--states", SLIDER_CRANK])
    assert r.exit_code == 0, r.output
    lines = [x for x in r.stdout.splitlines() if x.startswith("  ")]
    names = {x.split()[0] for x in lines}
    assert {"flywheel.phi", "flywheel.w", "crank_pin.phi", "crank_pin.w"} <= names
    assert "guide.s" not in names and "slider.vx" not in names   # follow the loop
    assert all(x.split()[-1] in ("state", "position") for x in lines)
    assert "crank_pin.phi " in r.stdout and "state position" in r.stdout
    assert "PARAMETERS" not in r.stdout
    every = CliRunner().invoke(main, ["variables", SLIDER_CRANK]).stdout
    assert len(lines) < len(every.splitlines()) / 5
    r = CliRunner().invoke(main, ["variables", "--match", "guide.*", SLIDER_CRANK])
    shown = [x.split()[0] for x in r.stdout.splitlines() if x.startswith("  ")]
    assert shown and all(n.startswith("guide.") for n in shown)
    assert any(x.startswith("  guide.s ") and x.endswith("position")
               for x in r.stdout.splitlines())
