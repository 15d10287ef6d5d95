"""A result reads a variable that is one of the DAE's unknowns straight from
y (CompiledModel.y_column); every other variable through the observed
callback. Both must give the same series for every variable."""
import numpy as np

from acausal import Model, compile_model
from acausal.mechanics.translational import Damper, Fixed, Mass, Spring


def test_state_columns_equal_the_observed_variables():
    m = Model()
    m.frame = Fixed()
    m.body = Mass(m=0.5, s=0.01, v=0.0)
    m.spring = Spring(c=200.0)
    m.damper = Damper(d=0.3)
    m.connect(m.frame.flange, m.spring.flange_a, m.damper.flange_a)
    m.connect(m.spring.flange_b, m.damper.flange_b, m.body.flange)
    cm = compile_model(m)
    res = cm.simulate(t_end=0.2, output_step=1e-3)
    direct = {n: np.array(res[n]) for n in cm.var_names}
    assert any(cm.y_column(n) is not None for n in cm.var_names)
    assert any(cm.y_column(n) is None for n in cm.var_names)
    obs = res._observed()
    for k, n in enumerate(cm.var_names):
        np.testing.assert_array_equal(direct[n], obs[:, k], err_msg=n)
