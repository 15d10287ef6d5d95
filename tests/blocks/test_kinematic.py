"""Kinematic sources (MSL Position, Speed, Accelerate, Move; translational
and rotational) against closed forms and an independent scipy solution of
their filters; models whose whole motion is prescribed (no states) run."""
import numpy as np
import pytest
import sympy as sp
from scipy.integrate import solve_ivp

from acausal import Model, compile_model, time
from acausal.blocks import Constant, Ramp, Sine
from acausal.errors import ConnectionError_
from acausal.lang import Component, Eq, Event, Flange
from acausal.mechanics import rotational as rot
from acausal.mechanics.translational import (Accelerate, Fixed, Mass, Move, Position, Speed,
                                             Spring)

W = 2 * np.pi * 2.0     # the reference sine: 0.1 m at 2 Hz


def driven(source, connect_input=None, m=2.0):
    model = Model()
    model.src = source
    model.mass = Mass(m=m)
    model.connect(model.src.flange, model.mass.flange)
    if connect_input is not None:
        model.sine = Sine(amplitude=0.1, f=2.0)
        model.connect(model.sine.y, getattr(model.src, connect_input))
    return compile_model(model, cache=False)


@pytest.mark.parametrize("backend", ["sundae", "compiled"])
def test_exact_position_has_no_states_and_the_exact_force(backend):
    cm = driven(Position(exact=True), "s_ref")
    assert cm.dae.n_states == 0
    res = cm.simulate(t_end=1.0, backend=backend)
    t = res.t
    assert np.max(np.abs(res["mass.s"] - 0.1 * np.sin(W * t))) < 1e-15
    assert np.max(np.abs(res["mass.v"] - 0.1 * W * np.cos(W * t))) < 1e-12
    # the source pushes the mass: f = m a
    assert np.max(np.abs(res["src.flange.f"] - 2.0 * 0.1 * W ** 2 * np.sin(W * t))) < 1e-11
    assert np.all(res["src.v"] == 0.0) and np.all(res["src.a"] == 0.0)   # MSL's dummies


def test_filtered_position_is_msl_s_bessel_filter():
    cm = driven(Position(f_crit=5.0), "s_ref")
    res = cm.simulate(t_end=1.0, rtol=1e-10, atol=1e-12)
    w = 2 * np.pi * 5.0

    def f(t, x):
        s, v = x
        return [v, ((0.1 * np.sin(W * t) - s) * w - 1.3617 * v) * (w / 0.6180)]
    ref = solve_ivp(f, (0, 1), [0.0, 0.0], rtol=1e-12, atol=1e-14, dense_output=True)
    s_ref, v_ref = ref.sol(res.t)
    assert np.max(np.abs(res["mass.s"] - s_ref)) < 1e-9
    assert np.max(np.abs(res["src.v"] - v_ref)) < 1e-8
    # it starts at the input (MSL's initial equation s = s_ref), here with an offset
    m = Model()
    m.src = Position(f_crit=5.0, s_ref=0.3 + 0.1 * sp.sin(1.0 * time))
    m.mass = Mass(m=1.0)
    m.connect(m.src.flange, m.mass.flange)
    res = compile_model(m, cache=False).simulate(t_end=0.1)
    assert res["mass.s"][0] == pytest.approx(0.3, abs=1e-14)


def test_speed_exact_and_filtered():
    # exact: v follows a ramp 0 -> 2 m/s over 0.5 s from 0.2 s; s from 0
    m = Model()
    m.ramp = Ramp(height=2.0, duration=0.5, startTime=0.2)
    m.src = Speed(exact=True)
    m.mass = Mass(m=2.0)
    m.connect(m.ramp.y, m.src.v_ref)
    m.connect(m.src.flange, m.mass.flange)
    res = compile_model(m, cache=False).simulate(t_end=1.0, rtol=1e-10, atol=1e-12)
    assert [t for t, _ in res.events] == [0.2, 0.7]
    assert abs(res["mass.s"][-1] - (0.5 + 0.6)) < 1e-8
    # the flange force is what the mass pushes back with: -m a
    assert res.at("src.flange.f", 0.45) == pytest.approx(-2.0 * 4.0, rel=1e-9)
    # filtered: first order, v starts at v_ref (= 1 here), s at 0
    m = Model()
    m.src = Speed(f_crit=2.0, v_ref=1.0 + 1.0 * time)
    m.mass = Mass(m=1.0)
    m.connect(m.src.flange, m.mass.flange)
    res = compile_model(m, cache=False).simulate(t_end=1.0, rtol=1e-10, atol=1e-12)
    w = 4 * np.pi
    t = res.t   # v' = (1 + t - v) w, v(0) = 1: v = 1 + t - (1 - exp(-w t))/w
    assert np.max(np.abs(res["mass.v"] - (1 + t - (1 - np.exp(-w * t)) / w))) < 1e-8
    assert res["mass.s"][0] == 0.0


@pytest.mark.parametrize("backend", ["sundae", "compiled"])
def test_accelerate_integrates_its_input(backend):
    m = Model()
    m.acc = Constant(k=3.0)
    m.src = Accelerate(v=1.0)
    m.mass = Mass(m=1.0)
    m.spring = Spring(c=100.0)
    m.wall = Fixed()
    m.connect(m.acc.y, m.src.a_ref)
    m.connect(m.src.flange, m.mass.flange, m.spring.flange_b)
    m.connect(m.spring.flange_a, m.wall.flange)
    res = compile_model(m, cache=False).simulate(t_end=1.0, backend=backend, rtol=1e-10,
                                                 atol=1e-12)
    t = res.t
    s = t + 1.5 * t ** 2
    assert np.max(np.abs(res["mass.s"] - s)) < 1e-9
    # the source provides m a plus the spring's pull (its flange takes the opposite)
    assert np.max(np.abs(res["src.flange.f"] + (3.0 + 100.0 * s))) < 1e-6


def test_move_takes_its_velocity_and_acceleration_from_its_inputs():
    m = Model()
    m.src = Move(u1=1.0 * sp.sin(1.0 * time), u2=1.0 * sp.cos(1.0 * time), u3=-1.0 * sp.sin(1.0 * time))
    m.mass = Mass(m=2.0)
    m.connect(m.src.flange, m.mass.flange)
    cm = compile_model(m, cache=False)
    assert cm.dae.n_states == 0
    res = cm.simulate(t_end=1.0)
    assert np.max(np.abs(res["mass.flange.f"] + 2 * np.sin(res.t))) < 1e-14
    # position only, velocity and acceleration zero on purpose (MSL's use): no force
    m = Model()
    m.src = Move(u1=1.0 * sp.sin(1.0 * time), u2=0, u3=0)
    m.mass = Mass(m=2.0)
    m.connect(m.src.flange, m.mass.flange)
    res = compile_model(m, cache=False).simulate(t_end=1.0)
    assert np.all(res["mass.flange.f"] == 0.0) and np.all(res["mass.v"] == 0.0)
    assert len(m.src.u) == 3


def test_rotational_sources_and_a_support():
    m = Model()
    m.src = rot.Position(exact=True, useSupport=True, phi_ref=0.5 * time ** 2)
    m.inertia = rot.Inertia(J=2.0)
    m.housing = rot.Fixed()
    m.connect(m.src.flange, m.inertia.flange)
    m.connect(m.src.support, m.housing.flange)
    res = compile_model(m, cache=False).simulate(t_end=1.0)
    assert np.max(np.abs(res["inertia.w"] - res.t)) < 1e-14
    # the flange takes -J a, the support the reaction +J a
    assert np.max(np.abs(res["src.flange.tau"] + 2.0)) < 1e-14
    assert np.max(np.abs(res["src.support.tau"] - 2.0)) < 1e-14
    m = Model()
    m.src = rot.Speed(exact=True, w_ref=2.0)
    m.acc = rot.Accelerate()
    m.j1, m.j2 = rot.Inertia(J=1.0), rot.Inertia(J=1.0)
    m.a = Constant(k=-1.0)
    m.connect(m.a.y, m.acc.a_ref)
    m.connect(m.src.flange, m.j1.flange)
    m.connect(m.acc.flange, m.j2.flange)
    res = compile_model(m, cache=False).simulate(t_end=1.0, rtol=1e-10, atol=1e-12)
    assert abs(res["j1.phi"][-1] - 2.0) < 1e-9 and abs(res["j2.phi"][-1] + 0.5) < 1e-9
    m = Model()
    m.src = rot.Move(u1=1.0 * time ** 3, u2=3.0 * time ** 2, u3=6.0 * time)
    m.j = rot.Inertia(J=0.5)
    m.connect(m.src.flange, m.j.flange)
    res = compile_model(m, cache=False).simulate(t_end=1.0)
    assert np.max(np.abs(res["j.flange.tau"] - 0.5 * 6 * res.t)) < 1e-13


def test_bound_and_connected_input_is_an_error_naming_both():
    m = Model()
    m.src = Position(exact=True, s_ref=0.1)
    m.c = Constant(k=1.0)
    m.mass = Mass(m=1.0)
    m.connect(m.c.y, m.src.s_ref)
    m.connect(m.src.flange, m.mass.flange)
    with pytest.raises(ConnectionError_, match=r"output c.y and input src.s_ref \(bound to an "
                                               r"expression\) are connected to each other"):
        compile_model(m, cache=False)


class _Gap(Component):
    """A root where the flange passes a position (a test part)."""
    flange = Flange("flange")

    def equations(self):
        return [Eq(self.flange.f, 0)]

    def events(self):
        return [Event("pass", self.flange.s - 0.05, +1, terminal=True)]


@pytest.mark.parametrize("backend", ["sundae", "compiled"])
def test_a_stateless_model_locates_its_events(backend):
    """No states: a root of the prescribed motion (s = 0.1 sin(W t) rising
    through 0.05 at asin(0.5)/W) is located as IDA would, and ends the run."""
    m = Model()
    m.src = Position(exact=True, s_ref=0.1 * sp.sin(W * time))
    m.gap = _Gap()
    m.mass = Mass(m=1.0)
    m.connect(m.src.flange, m.gap.flange, m.mass.flange)
    cm = compile_model(m, cache=False)
    assert cm.dae.n_states == 0
    res = cm.simulate(t_end=1.0, backend=backend)
    t_pass = np.arcsin(0.5) / W
    assert res.events[0][1] == "pass" and abs(res.events[0][0] - t_pass) < 1e-12
    assert res.t[-1] == res.events[0][0]
