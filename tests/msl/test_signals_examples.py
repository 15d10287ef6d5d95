"""MSL examples of the signal and kinematic-source lane, ported with the
library alone (models/msl/...), against the Modelica Association's
reference results (MSL 4.0.0, Dymola, DASSL at rtol 1e-6): csv-compare's
tube, 1e-3 of each signal's range and of the time span
(tests/msl/harness.py), on both backends at MSL's own rtol 1e-6.

Measured worst deviation from the reference (our result interpolated at
the reference's times), as a fraction of the signal's range, rtol 1e-6,
both backends alike: Translational.Accelerate accelerate.s 1.4e-11,
accelerate.v 5.6e-17 (the reference itself is t^2/2 and t to that order).
Skipped where the reference files are absent (data/msl_reference/README.md).
"""
import os

import numpy as np
import pytest

from acausal import compile_model
from acausal.modelfile import load_model_file
from tests.msl.harness import assert_matches, load_reference, reference_or_skip

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
EXAMPLES = ["Translational.Accelerate"]
_compiled = {}


def model_file(name):
    lib, example = name.split(".")
    return os.path.join(ROOT, "models", "msl", lib, f"{example}.py")


def simulate(name, backend, **kw):
    if name not in _compiled:
        mf = load_model_file(model_file(name))
        _compiled[name] = (mf, compile_model(mf.model))
    mf, cm = _compiled[name]
    opts = dict(mf.experiment.run_options(), **kw)
    res = cm.simulate(backend=backend, **opts)
    assert res.status == "ok", res.message
    return mf, res


def deviation(name, res):
    """Signal -> max |ours - reference| / range of the reference, at the
    reference's time points."""
    t, ref = load_reference(name)
    out = {}
    for sig, y in ref.items():
        ours = np.interp(t, res.t, res[sig])
        out[sig] = float(np.max(np.abs(ours - y)) / max(np.ptp(y), 1e-300))
    return out


@pytest.mark.parametrize("backend", ["sundae", "compiled"])
@pytest.mark.parametrize("name", EXAMPLES)
def test_example_inside_the_reference_tube(name, backend):
    reference_or_skip(name)
    mf, res = simulate(name, backend)
    assert mf.experiment.rtol == 1e-6          # MSL's own tolerance
    assert_matches(name, res)
    assert max(deviation(name, res).values()) < 1e-6


def test_accelerate_is_the_closed_form():
    """Independent of the reference: s = t^2/2, v = t (a_ref = 1 m/s2)."""
    _, res = simulate("Translational.Accelerate", "sundae", rtol=1e-10, atol=1e-12)
    assert np.max(np.abs(res["accelerate.s"] - res.t ** 2 / 2)) < 1e-10
    assert np.max(np.abs(res["accelerate.v"] - res.t)) < 1e-10
    assert np.max(np.abs(res["mass.s"] - res.t ** 2 / 2 - 0.5)) < 1e-10   # centre: L/2 ahead


def test_model_files_use_the_library_alone():
    for name in EXAMPLES:
        with open(model_file(name)) as fh:
            text = fh.read()
        assert "class " not in text and "def " not in text, name
