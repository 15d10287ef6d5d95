"""The MSL examples ported with the library alone (models/msl/Translational,
models/msl/Rotational) against the Modelica Association's reference results
(MSL 4.0.0, Dymola, DASSL at rtol 1e-6): csv-compare's tube, 1e-3 of each
signal's range and of the time span (tests/msl/harness.py), on both
backends, at the model files' tolerance, MSL's own rtol 1e-6.

Skipped where the reference files are absent (see data/msl_reference/README.md).
Measured worst deviation of each compared signal, as a fraction of its
range, at the reference's regular output points, rtol 1e-6 (the two
backends agree to the digits shown): 4.0e-4 (Oscillator: an undamped
resonance whose reference is 4.8e-4 off an rtol-1e-13 scipy solution, ours
8e-5), 5.7e-5 (Damper), 1.4e-11 (SignConvention), 3.1e-5
(InitialConditions), 1.5e-5 (Sensors), 2.8e-6 (WhyArrows), 2.5e-5
(ElastoGap), 6.9e-7 (Vehicle), 2.2e-4 (First and FirstGrounded: the
reference's inertia3.w is 3.1e-4 off an rtol-1e-12 scipy solution),
2.5e-5 (Backlash), 6.5e-7 (RollingWheel).
"""
import os

import numpy as np
import pytest

from acausal import compile_model
from acausal.modelfile import load_model_file
from tests.msl.harness import assert_matches, reference_or_skip

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

EXAMPLES = [
    "Translational.Oscillator", "Translational.Damper", "Translational.SignConvention",
    "Translational.InitialConditions", "Translational.Sensors", "Translational.WhyArrows",
    "Translational.ElastoGap", "Translational.Vehicle",
    "Rotational.First", "Rotational.FirstGrounded", "Rotational.Backlash",
    "Rotational.RollingWheel",
]

_compiled = {}


def model_file(name):
    lib, example = name.split(".")
    return os.path.join(ROOT, "models", "msl", lib, f"{example}.py")


def simulate(name, backend):
    """The example's model file simulated with its experiment on ``backend``."""
    if name not in _compiled:
        mf = load_model_file(model_file(name))
        _compiled[name] = (mf, compile_model(mf.model))
    mf, cm = _compiled[name]
    res = cm.simulate(backend=backend, **mf.experiment.run_options())
    assert res.status == "ok", res.message
    return mf, res


@pytest.mark.parametrize("backend", ["sundae", "compiled"])
@pytest.mark.parametrize("name", EXAMPLES)
def test_example_inside_the_reference_tube(name, backend):
    reference_or_skip(name)
    mf, res = simulate(name, backend)
    assert mf.experiment.rtol == 1e-6          # MSL's own tolerance
    assert_matches(name, res)


def test_every_listed_example_has_a_model_file_with_the_library_alone():
    """No component class is defined in a model file: each is built from
    acausal's library."""
    for name in EXAMPLES:
        with open(model_file(name)) as fh:
            text = fh.read()
        assert "class " not in text and "def " not in text, name


def test_sensors_example_reads_the_mass():
    """Translational.Sensors: the sensors on the mass read its flange_a
    (s - 1/2), its flange_b (s + 1/2), its speed and acceleration; the
    force and multi sensors, in series with the force, read the driving
    force (MSL's sign, f = flange_a.f) and the power entering the mass
    (exactly: the forces are the residual's)."""
    _, res = simulate("Translational.Sensors", "sundae")
    s, v = res["mass.s"], res["mass.v"]
    f = 10 * np.sin(2 * np.pi * 4 * res.t)
    assert np.max(np.abs(res["positionSensor1.s"] - (s - 0.5))) < 1e-12
    assert np.max(np.abs(res["positionSensor2.s"] - (s + 0.5))) < 1e-12
    assert np.max(np.abs(res["speedSensor1.v"] - v)) < 1e-12
    # the acceleration is der(v) from IDA's interpolating polynomial at the
    # output points (measured 8.8e-5 N/kg at rtol 1e-6), not the residual's
    assert np.max(np.abs(res["accSensor1.a"] - f)) < 2e-4
    assert np.max(np.abs(res["forceSensor.f"] - f)) < 1e-9
    assert np.max(np.abs(res["multiSensor.f"] - f)) < 1e-9
    assert np.max(np.abs(res["multiSensor.v"] - v)) < 1e-12
    assert np.max(np.abs(res["multiSensor.power"] - f * v)) < 1e-9
