"""The independent scipy breaker (tests/diagnose/breaker_scipy.py, written
from the report's equations) against the project's model file compiled by
acausal (models/breaker_24kv.py through tests/diagnose/breaker_truth.py):
two codes that share no simulation code must give the same traces, with
and without the blind cases' hidden effects. Measured 2026-11-23: the hook
angle and the armature travel agree to 2.3e-9 and 3.1e-9 relative at the
model's output times, the release time to 1e-11 s. Measured 2026-11-26
with the blind cases' own effects alone (3.3, 3.8, 4.5 m/s): the
threshold torque (8 N*m) to 2.7e-9 relative, Hunt-Crossley (e 0.74) to
4.8e-9, the release to 1.2e-11 s."""
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import breaker_scipy  # noqa: E402
import breaker_truth  # noqa: E402


def _agreement(v, effect=None, backend=None, rtol=1e-10):
    ind = breaker_scipy.simulate(v, effect, rtol=rtol)
    ref = breaker_truth.simulate(v, effect, backend=backend)
    t = ref.t[ref.t < ind.t_release]
    errs = [np.max(np.abs(ind.at(t, s) - ref[s][:t.size])) / np.max(np.abs(ref[s]))
            for s in breaker_scipy.SIGNALS]
    return errs, ind.t_release - ref.t[-1]


@pytest.mark.slow
def test_independent_breaker_agrees_with_the_compiled_model():
    """On the reference backend, and the scipy side at rtol 1e-8 (3.5e-9
    relative measured, the release to 7e-12 s); the cases below run the
    default backend at rtol 1e-10. Slow tier: 4 s in a fresh test run (it
    compiles the breaker first), and the default tier is near its budget."""
    errs, dt = _agreement(3.8, backend="sundae", rtol=1e-8)
    assert max(errs) < 1e-7
    assert abs(dt) < 1e-9


@pytest.mark.slow
@pytest.mark.parametrize("effect", [
    {"hook_coulomb": 1.0, "coil_slope": 2e4},
    {"hunt_crossley": 0.74, "hook_drag": 8e-4},
    {"hunt_crossley": 0.74},
    {"hook_threshold": 8.0},
])
def test_independent_breaker_agrees_with_hidden_effects(effect):
    for v in (3.3, 4.5):
        errs, dt = _agreement(v, effect)
        assert max(errs) < 1e-7
        assert abs(dt) < 1e-9
