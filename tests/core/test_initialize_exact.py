"""Initial point and re-initialisation details that events rely on.

* A fixed start of a state is imposed exactly (not to least-squares
  round-off): a body that starts at rest is exactly at rest, which a
  stick/slip mode machine needs to tell "at rest" from "moving".
* y' of algebraic unknowns is set to their true rate: IDA keeps algebraic
  components in its error test, so y' = 0 for an algebraic unknown moving
  at a finite rate makes the first step fail at tight tolerances.
"""
import numpy as np

from acausal import Eq, Model, compile_model, time
from acausal.runtime.initialize import initial_point
from acausal.mechanics.translational import Fixed, Mass, Spring


def _cubic_model():
    """A spring-mass plus an implicit algebraic unknown z, z^3 + z = 4 t."""
    m = Model()
    m.mass = Mass(m=1.0, s=0.1, v=0.0)
    m.spring = Spring(c=100.0)
    m.ground = Fixed()
    m.connect(m.ground.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.mass.flange)
    z = m.variable("z", 0.0, "1", "implicit algebraic unknown")
    m.equation(Eq(z ** 3 + z, 4 * time))
    return m


def test_algebraic_rates_at_start():
    cm = compile_model(_cubic_model())
    assert "z" in [s.name for s in cm.dae.y[cm.dae.n_states:]]
    p, d = cm.param_vector(), cm.discrete_start()
    cb = cm.callbacks(p, d)
    y, yp = initial_point(cm, p, d, cb, 0.0)
    k = [s.name for s in cm.dae.y].index("z")
    assert abs(yp[k] - 4.0) < 1e-8          # dz/dt = 4 / (3 z^2 + 1) at z = 0
    res = cm.simulate(t_end=1.0, rtol=1e-10, atol=1e-12, output_step=0.1)
    z = res["z"]
    assert np.max(np.abs(z ** 3 + z - 4 * res.t)) < 1e-8


def test_fixed_state_starts_are_exact():
    from acausal.mechanics.friction import GroundFriction
    from acausal import Component, Flange, Parameter

    class Load(Component):
        flange = Flange("load")
        F = Parameter(0.0, "N", "force along +s")

        def equations(self):
            return [Eq(self.flange.f, -self.F)]

    m = Model()
    m.mass = Mass(m=3.0, s=0.25, v=0.0)
    m.fr = GroundFriction(F_c=10.0, F_s=15.0)
    m.load = Load(F=14.0)
    m.connect(m.mass.flange, m.fr.flange, m.load.flange)
    cm = compile_model(m)
    p, d = cm.param_vector(), cm.discrete_start()
    cb = cm.callbacks(p, d)
    y, yp = initial_point(cm, p, d, cb, 0.0)
    obs = dict(zip(cm.var_names, cb[4](0.0, y, yp)))
    assert obs["mass.s"] == 0.25 and obs["mass.v"] == 0.0
    assert obs["fr.f"] == 14.0
