"""Model.disconnect: a connector leaves its node, the rest stays joined."""
import numpy as np
import pytest

from acausal import Model, ModelError, compile_model
from acausal.mechanics.translational import Fixed, Force, Mass, Spring


class Sub(Model):
    """A mass on a spring to ground; the mass flange is exposed as ``flange``."""

    def __init__(self, **kw):
        super().__init__(**kw)
        self.mass = Mass(m=1.0, s=0.1, v=0.0)
        self.spring = Spring(c=100.0)
        self.ground = Fixed()
        self.connect(self.ground.flange, self.spring.flange_a)
        self.connect(self.spring.flange_b, self.mass.flange)
        self.flange = self.mass.flange


def test_disconnect_keeps_the_rest_of_the_node_joined():
    m = Model()
    m.sub = Sub()
    m.push = Force(f=5.0)
    m.extra = Spring(c=300.0)
    m.ground = Fixed()
    # the spring reaches the mass only through push.flange: a-b and b-c
    m.connect(m.sub.flange, m.push.flange)
    m.connect(m.push.flange, m.extra.flange_b)
    m.connect(m.ground.flange, m.extra.flange_a)
    out = m.disconnect(m.push.flange)
    assert [p.path for p in out] == ["extra.flange_b", "sub.mass.flange"]
    assert all(m.push.flange not in g for mm in m.walk() if isinstance(mm, Model)
               for g in mm._connections)
    # the force is now dangling: give it a mass of its own
    m.m2 = Mass(m=1.0)
    m.connect(m.push.flange, m.m2.flange)
    res = compile_model(m).simulate(t_end=1.0, rtol=1e-9, atol=1e-11, output_step=0.01)
    w = np.sqrt(400.0)                               # both springs still on sub.mass
    assert np.max(np.abs(res["sub.mass.s"] - 0.1 * np.cos(w * res.t))) < 1e-7
    assert np.max(np.abs(res["m2.s"] - 2.5 * res.t ** 2)) < 1e-7   # 5 N on 1 kg


def test_disconnect_inside_a_submodel_and_errors():
    m = Model()
    m.sub = Sub()
    out = m.disconnect(m.sub.spring.flange_b)
    assert [p.path for p in out] == ["sub.mass.flange"]
    assert m.sub._connections == [(m.sub.ground.flange, m.sub.spring.flange_a)]
    with pytest.raises(ModelError, match="not a connector"):
        m.disconnect(m.sub.mass)
