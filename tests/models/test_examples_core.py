"""The core example model files against the closed forms in their
docstrings, run with their own Experiment (rtol 1e-8, atol 1e-10)."""
import os

import numpy as np
import pytest

from acausal.modelfile import run_file

EXAMPLES = os.path.join(os.path.dirname(__file__), "..", "..", "models", "examples")


def test_oscillator_final_value():
    """mass.s = 0.1 cos(10 t) at t = 1."""
    res, _ = run_file(os.path.join(EXAMPLES, "oscillator.py"))
    final = res.final()
    assert res.t[-1] == pytest.approx(1.0, abs=1e-12)
    assert final["mass.s"] == pytest.approx(0.1 * np.cos(10.0), rel=1e-6)      # measured 6.8e-7
    assert final["mass.v"] == pytest.approx(-1.0 * np.sin(10.0), rel=1e-6)


def test_lever_masses_final_value():
    """lever.phi = 0.1 cos(w t), w = sqrt(c a^2 / (m1 a^2 + m2 b^2)),
    m2.s = b * lever.phi, at t = 1."""
    res, _ = run_file(os.path.join(EXAMPLES, "lever_masses.py"))
    final = res.final()
    a, b, m1, m2, c = 0.1, 0.3, 2.0, 1.0, 1000.0
    w = np.sqrt(c * a * a / (m1 * a * a + m2 * b * b))
    assert res.t[-1] == pytest.approx(1.0, abs=1e-12)
    assert final["lever.phi"] == pytest.approx(0.1 * np.cos(w), rel=1e-6)      # measured 2.2e-7
    assert final["m2.s"] == pytest.approx(b * 0.1 * np.cos(w), rel=1e-6)
    assert final["m1.s"] == pytest.approx(a * 0.1 * np.cos(w), rel=1e-6)
