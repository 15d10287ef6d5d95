"""MSL MultiBody.Examples.Elementary.Pendulum and DoublePendulum, ported to
the plane with the library alone (models/msl/MultiBody/), against the
Modelica Association's reference results (Dymola, MSL 4.0.0) by csv-compare's
tube: 1e-3 of each signal's range and of the time span. Each runs on both
backends, at the model file's tolerance and at MSL's own (rtol 1e-6).
Skipped where the reference files are absent (data/msl_reference/README.md)."""
from pathlib import Path

import pytest

from acausal.modelfile import compile_file
from tests.msl.harness import assert_matches, reference_or_skip, settings

MODELS = Path(__file__).resolve().parents[2] / "models" / "msl" / "MultiBody"


@pytest.mark.parametrize("backend", ["sundae", "compiled"])
@pytest.mark.parametrize("rtol", [None, 1e-6], ids=["file", "msl"])
@pytest.mark.parametrize("example", ["Pendulum", "DoublePendulum"])
def test_multibody_example_matches_the_reference(example, rtol, backend):
    name = f"MultiBody.{example}"
    reference_or_skip(name)
    mf, cm = compile_file(MODELS / f"{example}.py")
    s = settings(name)
    opts = mf.experiment.run_options()
    assert opts["t_end"] == s.stop_time
    if rtol is not None:                  # MSL's (DASSL's) default tolerance
        opts.update(rtol=rtol, atol=rtol * 1e-2)
    res = cm.simulate(backend=backend, **opts)
    cmp = assert_matches(name, res)
    assert set(cmp.results) == set(s.compared)


def test_the_tube_tells_a_wrong_gravity_apart():
    """The comparison can fail: the pendulum under 9.5 m/s^2 (not the
    world's standard 9.80665) leaves the reference's tube."""
    reference_or_skip("MultiBody.Pendulum")
    mf, cm = compile_file(MODELS / "Pendulum.py")
    res = cm.simulate(params={"world.g": 9.5}, **mf.experiment.run_options())
    with pytest.raises(AssertionError, match="rev.phi"):
        assert_matches("MultiBody.Pendulum", res)
