"""A model whose every variable is explicit (all motion prescribed) has
nothing for IDA to integrate: it runs all the same, its variables evaluated
on the output grid (it used to be refused with "nothing to integrate")."""
import numpy as np
import pytest
import sympy as sp

from acausal import Model, compile_model, time
from acausal.mechanics.translational import Mass, Position


@pytest.mark.parametrize("backend", ["sundae", "compiled"])
def test_fully_prescribed_model_runs(backend):
    model = Model()
    model.drive = Position(s=0.1 * sp.sin(3 * time))
    model.mass = Mass(m=2.0)
    model.connect(model.drive.flange, model.mass.flange)
    cm = compile_model(model, cache=False)
    assert cm.dae.n_states == 0
    res = cm.simulate(t_end=1.0, backend=backend)
    t = res.t
    assert len(t) == 501 and res.stats["backend"] == backend
    assert np.max(np.abs(res["mass.v"] - 0.3 * np.cos(3 * t))) < 1e-12
    # the support pushes the mass: flange.f = m*a = -1.8 sin(3t)
    assert np.max(np.abs(res["mass.flange.f"] + 1.8 * np.sin(3 * t))) < 1e-12
