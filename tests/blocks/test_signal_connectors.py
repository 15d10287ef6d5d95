"""Causal signal connectors (RealInput/RealOutput): connect(output, inputs)
makes each input equal to the output; two outputs in one node and an input
in no node with an output are errors naming them."""
import pytest

from acausal import Model, compile_model
from acausal.blocks.interfaces import SISO, SO
from acausal.errors import ConnectionError_
from acausal.lang import Component, Eq, Flange, Parameter, RealInput, time
from acausal.mechanics.translational import Mass


class _Lin(SO):
    """y = k*time (a test block)."""
    k = Parameter(2.0, "1", "slope")

    def equations(self):
        return [Eq(self.y, self.k * time)]


class _Gain(SISO):
    """y = k*u (a test block)."""
    k = Parameter(3.0, "1", "gain")

    def equations(self):
        return [Eq(self.y, self.k * self.u)]


class _Push(Component):
    """Applies the input force on its flange (a test component)."""
    f = RealInput("force", unit="N")
    flange = Flange("flange")

    def equations(self):
        return [Eq(self.flange.f, -self.f)]


def test_a_chain_of_blocks_drives_a_mass():
    m = Model()
    m.src, m.g, m.push = _Lin(), _Gain(), _Push()
    m.mass = Mass(m=2.0, s=0.0, v=0.0)
    m.connect(m.src.y, m.g.u)
    m.connect(m.g.y, m.push.f)
    m.connect(m.push.flange, m.mass.flange)
    res = compile_model(m, cache=False).simulate(t_end=1.0, rtol=1e-9, atol=1e-12)
    # m s'' = 6 t  ->  s = t^3 / 2
    assert abs(res["mass.s"][-1] - 0.5) < 1e-7
    assert abs(res["push.f"][-1] - 6.0) < 1e-12
    assert abs(res.at("g.u", 0.5) - 1.0) < 1e-9


def test_one_output_feeds_several_inputs():
    m = Model()
    m.src, m.g1, m.g2 = _Lin(), _Gain(k=1.0), _Gain(k=-1.0)
    m.push1, m.push2 = _Push(), _Push()
    m.m1, m.m2 = Mass(m=1.0, s=0.0, v=0.0), Mass(m=1.0, s=0.0, v=0.0)
    m.connect(m.src.y, m.g1.u, m.g2.u)
    m.connect(m.g1.y, m.push1.f)
    m.connect(m.g2.y, m.push2.f)
    m.connect(m.push1.flange, m.m1.flange)
    m.connect(m.push2.flange, m.m2.flange)
    res = compile_model(m, cache=False).simulate(t_end=1.0, rtol=1e-9, atol=1e-12)
    # s'' = +-2 t  ->  s = +-t^3/3
    assert abs(res["m1.s"][-1] - 1 / 3) < 1e-7 and abs(res["m2.s"][-1] + 1 / 3) < 1e-7


def test_unconnected_input_is_named():
    m = Model()
    m.clutch = _Push()
    m.mass = Mass(m=1.0)
    m.connect(m.clutch.flange, m.mass.flange)
    with pytest.raises(ConnectionError_) as err:
        compile_model(m, cache=False)
    assert str(err.value).startswith("clutch.f: input not connected")


def test_inputs_joined_without_an_output_are_not_connected():
    m = Model()
    m.a, m.b = _Gain(), _Gain()
    m.connect(m.a.u, m.b.u)
    with pytest.raises(ConnectionError_, match=r"inputs not connected: a\.u, b\.u"):
        compile_model(m, cache=False)


def test_two_outputs_connected_is_an_error_naming_both():
    m = Model()
    m.a, m.b, m.g = _Lin(), _Lin(), _Gain()
    m.connect(m.a.y, m.g.u)
    m.connect(m.b.y, m.g.u)
    with pytest.raises(ConnectionError_, match=r"outputs a\.y and b\.y are connected"):
        compile_model(m, cache=False)


def test_a_signal_cannot_be_connected_to_a_flange():
    m = Model()
    m.a, m.push = _Lin(), _Push()
    with pytest.raises(ConnectionError_, match="cannot connect"):
        m.connect(m.a.y, m.push.flange)
        compile_model(m, cache=False)


def test_a_signal_port_stands_for_its_variable():
    g = _Gain()
    m = Model()
    m.g = g
    assert str(2 * g.u) == "2*g.u" and str(g.u - g.y) == "g.u - g.y"
    assert g.u.symbol.name == "g.u"
