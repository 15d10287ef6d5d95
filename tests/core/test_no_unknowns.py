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


def test_a_stateless_model_whose_equations_lose_their_solution_fails_clearly():
    """x^2 = 1 - t/T has no real solution after T: the run stops there with a
    SolverError naming the equation, its partial result kept."""
    from acausal.errors import SolverError
    from acausal.lang import Component, Eq, Parameter, Variable

    class _Root(Component):
        T = Parameter(0.5, "s", "time the solution disappears")
        x = Variable(1.0, "1", "a root of x^2 = 1 - t/T")

        def equations(self):
            return [Eq(self.x ** 2, 1 - time / self.T)]

    m = Model()
    m.r = _Root()
    cm = compile_model(m, cache=False)
    assert cm.dae.n_states == 0 and len(cm.dae.y) == 1
    with pytest.raises(SolverError, match=r"no solution .*equation 1 \(_Root\) of r") as err:
        cm.simulate(t_end=1.0)
    res = err.value.result
    assert 0.5 <= res.t[-1] <= 0.5 + 2e-3      # the first output point past T
    ok = res.t < 0.49
    assert np.max(np.abs(res["r.x"][ok] - np.sqrt(1 - res.t[ok] / 0.5))) < 1e-9
