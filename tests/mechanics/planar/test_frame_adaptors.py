"""The planar frame connector (flattening, optional connectors) and the
adaptors to 1-D flanges, against closed forms."""
import numpy as np
import pytest
import sympy as sp

from acausal import AcausalError, Model, compile_model
from acausal.lang.connectors import Frame
from acausal.compiler.flatten import flatten
from acausal.mechanics import rotational as rot
from acausal.mechanics import translational as tr
from acausal.mechanics.planar.adaptors import AxisAdaptor, ShaftAdaptor
from acausal.mechanics.planar.joints import Revolute
from acausal.mechanics.planar.parts import Body, Fixed


def test_frame_connection_gives_three_across_and_three_through_equations():
    m = Model()
    m.a = Fixed(x0=1.0)
    m.b = Body()
    m.connect(m.a.frame, m.b.frame)
    flat = flatten(m)
    conn = [e for e in flat.equations if e.origin.startswith("connect(")]
    assert len(conn) == 6
    exprs = {sp.srepr(e.expr) for e in conn}
    for v in ("x", "y", "phi"):
        assert sp.srepr(sp.Symbol(f"b.frame.{v}") - sp.Symbol(f"a.frame.{v}")) in exprs
    for v in ("fx", "fy", "tau"):
        assert sp.srepr(sp.Symbol(f"a.frame.{v}") + sp.Symbol(f"b.frame.{v}")) in exprs
    units = {n: flat.variables[n].unit for n in flat.variables if n.startswith("a.frame.")}
    assert units == {"a.frame.x": "m", "a.frame.y": "m", "a.frame.phi": "rad",
                     "a.frame.fx": "N", "a.frame.fy": "N", "a.frame.tau": "N*m"}


def test_frame_cannot_be_connected_to_a_flange():
    m = Model()
    m.a = Fixed()
    m.s = rot.Fixed()
    m.connect(m.a.frame, m.s.flange)
    with pytest.raises(AcausalError, match="cannot connect"):
        flatten(m)


def test_frame_port_names_its_variables_and_has_no_single_across():
    m = Model()
    m.a = Fixed()
    assert m.a.frame.tau == sp.Symbol("a.frame.tau")
    assert [str(a) for a, _ in m.a.frame.pairs()] == ["a.frame.x", "a.frame.y", "a.frame.phi"]
    with pytest.raises(AcausalError, match="several"):
        m.a.frame.across
    assert Frame.domain == "planar"


def test_unconnected_optional_flange_carries_nothing():
    m = Model()
    m.g = Fixed()
    m.pin = Revolute()
    m.connect(m.g.frame, m.pin.frame_a)
    m.b = Body(m=1.0, I=2.0, w=3.0, phi=0.0)
    m.connect(m.pin.frame_b, m.b.frame)
    res = compile_model(m).simulate(t_end=1.0, rtol=1e-10, atol=1e-12, output_step=0.1)
    # a free pin: no torque, the body spins on at 3 rad/s
    assert np.max(np.abs(res["pin.axis.tau"])) < 1e-12
    assert np.max(np.abs(res["b.phi"] - 3.0 * res.t)) < 1e-9


def test_shaft_adaptor_passes_a_torque_to_the_body():
    """A 1-D torsion spring on the world turns the body through the adaptor:
    I phi'' = -c phi, and the body's centre takes no force (stays put)."""
    m = Model()
    m.b = Body(m=2.0, I=0.5, phi=0.3, w=0.0, x=1.0, y=-2.0, vx=0.0, vy=0.0)
    m.ad = ShaftAdaptor()
    m.spring = rot.TorsionSpring(c=8.0)
    m.wall = rot.Fixed()
    m.connect(m.b.frame, m.ad.frame)
    m.connect(m.ad.flange, m.spring.flange_b)
    m.connect(m.wall.flange, m.spring.flange_a)
    res = compile_model(m).simulate(t_end=2.0, rtol=1e-10, atol=1e-12, output_step=0.01)
    om = np.sqrt(8.0 / 0.5)
    assert np.max(np.abs(res["b.phi"] - 0.3 * np.cos(om * res.t))) < 1e-8
    assert np.max(np.abs(res["b.x"] - 1.0)) < 1e-12 and np.max(np.abs(res["b.y"] + 2.0)) < 1e-12
    # torque into the frame side = minus torque into the flange side
    assert np.max(np.abs(res["ad.frame.tau"] + res["ad.flange.tau"])) < 1e-12


def test_axis_adaptor_oblique_spring_with_gravity():
    """A body on a 1-D spring along a 30 deg world axis, with gravity: along
    the axis it oscillates about c*s = -m g sin(30 deg), across the axis it
    falls freely (the adaptor takes no force across the axis)."""
    a = np.radians(30.0)
    ex, ey = np.cos(a), np.sin(a)
    mass, c, g, s0 = 0.5, 50.0, 9.81, 0.1
    m = Model()
    m.b = Body(m=mass, I=1.0, g=g, x=s0 * ex, y=s0 * ey, vx=0.0, vy=0.0, phi=0.0, w=0.0)
    m.ad = AxisAdaptor(ex=2 * ex, ey=2 * ey)        # normalised by the component
    m.spring = tr.Spring(c=c)
    m.wall = tr.Fixed()
    m.connect(m.b.frame, m.ad.frame)
    m.connect(m.ad.flange, m.spring.flange_b)
    m.connect(m.wall.flange, m.spring.flange_a)
    res = compile_model(m).simulate(t_end=1.0, rtol=1e-10, atol=1e-12, output_step=0.01)
    t = res.t
    s_eq = -mass * g * np.sin(a) / c
    s = s_eq + (s0 - s_eq) * np.cos(np.sqrt(c / mass) * t)
    n = -0.5 * g * np.cos(a) * t**2                  # across the axis (normal (-ey, ex))
    x, y = res["b.x"], res["b.y"]
    assert np.max(np.abs(ex * x + ey * y - s)) < 1e-8
    assert np.max(np.abs(-ey * x + ex * y - n)) < 1e-8
    assert np.max(np.abs(res["ad.flange.s"] - s)) < 1e-8
