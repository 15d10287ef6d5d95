"""Core pipeline against closed forms and published values."""
import numpy as np
import pytest
import sympy as sp

from acausal import (Discrete, Eq, Event, Model, Parameter, Start, StructuralError, compile_model,
                     der)
from acausal.lang.component import Component
from acausal.lang.connectors import Flange
from acausal.mechanics.translational import Fixed, Mass, Spring
from acausal.mechanics.levers import TwoArmLever


def oscillator(**mass):
    m = Model()
    m.mass = Mass(m=1.0, **(mass or dict(s=0.1, v=0.0)))
    m.spring = Spring(c=100.0)
    m.ground = Fixed()
    m.connect(m.ground.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.mass.flange)
    return m


def test_oscillator_closed_form_and_aliases():
    cm = compile_model(oscillator())
    assert cm.dae.n_states == 2 and len(cm.dae.y) == 2   # everything else eliminated
    res = cm.simulate(t_end=1.0, rtol=1e-8, atol=1e-10, output_step=0.01)
    exact = 0.1 * np.cos(10 * res.t)
    assert np.max(np.abs(res["mass.s"] - exact)) < 1e-7
    # aliases and eliminated variables are still reported
    assert np.allclose(res["spring.flange_b.s"], res["mass.s"])
    assert np.allclose(res["spring.f"], 100.0 * res["mass.s"])
    # a stretched spring pulls the support along +s (force into the support)
    assert np.allclose(res["ground.flange.f"], res["spring.f"])


def test_parameter_change_does_not_recompile():
    cm = compile_model(oscillator())
    src = cm.source
    r1 = cm.simulate(t_end=0.5, params={"spring.c": 400.0}, rtol=1e-9, atol=1e-11)
    assert cm.source is src
    assert abs(r1.final()["mass.s"] - 0.1 * np.cos(20 * 0.5)) < 1e-7


def test_lever_masses_index_reduction():
    m = Model()
    m.lever = TwoArmLever(a=0.1, b=0.3)
    m.m1 = Mass(m=2.0, s=0.01, v=0.0)
    m.m2 = Mass(m=1.0)
    m.spring = Spring(c=1000.0)
    m.ground = Fixed()
    m.connect(m.ground.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.m1.flange, m.lever.flange_a)
    m.connect(m.m2.flange, m.lever.flange_b)
    cm = compile_model(m)
    # Pantelides differentiated the two position constraints twice
    assert len(cm.graph.eexpr) > len(cm.reduced.equations)
    assert cm.dae.n_states == 2
    res = cm.simulate(t_end=1.0, rtol=1e-8, atol=1e-10, output_step=0.01)
    w = np.sqrt(1000 * 0.1**2 / (2 * 0.1**2 + 1 * 0.3**2))
    assert np.max(np.abs(res["lever.phi"] - 0.1 * np.cos(w * res.t))) < 1e-7
    assert np.allclose(res["m2.s"], 0.3 * res["lever.phi"], atol=1e-12)


class Robertson(Model):
    """Robertson's chemical kinetics as a DAE (SUNDIALS' idaRoberts_dns)."""

    def __init__(self):
        super().__init__()
        y1 = self.variable("y1", Start(1.0, True))
        y2 = self.variable("y2", Start(0.0, True))
        y3 = self.variable("y3", Start(0.0, False))
        self.equation(Eq(der(y1), -0.04 * y1 + 1e4 * y2 * y3))
        self.equation(Eq(der(y2), 0.04 * y1 - 1e4 * y2 * y3 - 3e7 * y2**2))
        self.equation(Eq(y1 + y2 + y3, 1))


def test_robertson_against_sundials_published_values():
    cm = compile_model(Robertson())
    ts = [0.4, 4.0, 40.0, 400.0, 4e3, 4e4, 4e5]
    res = cm.simulate(t_end=4e5, rtol=1e-6, atol=1e-12, output_times=ts)
    # idaRoberts_dns.out (SUNDIALS examples), 5 significant digits
    published = {0.4: (9.8517e-01, 3.3864e-05, 1.4794e-02),
                 40.0: (7.1582e-01, 9.1851e-06, 2.8417e-01)}
    for t, vals in published.items():
        for name, v in zip(("y1", "y2", "y3"), vals):
            got = res.at(name, t)
            assert abs(got - v) <= 2e-4 * abs(v), (t, name, got, v)
    # and an independent high-accuracy solution (Radau, rtol 1e-12) at 4e5
    from scipy.integrate import solve_ivp

    def f(t, y):
        a, b, c = y
        return [-0.04 * a + 1e4 * b * c, 0.04 * a - 1e4 * b * c - 3e7 * b * b, 3e7 * b * b]
    ref = solve_ivp(f, [0, 4e5], [1, 0, 0], method="Radau", rtol=1e-12, atol=1e-20).y[:, -1]
    for name, v in zip(("y1", "y2", "y3"), ref):
        assert abs(res.final()[name] - v) <= 1e-3 * abs(v), (name, res.final()[name], v)


def test_unconnected_flange_carries_no_force_and_is_listed():
    # Modelica's rule: an unconnected flange's force is zero (no error); the
    # flattened model lists it for the model check
    m = Model()
    m.mass = Mass(m=1.0, s=0.1, v=0.0)
    m.spring = Spring(c=100.0)
    m.connect(m.spring.flange_b, m.mass.flange)
    cm = compile_model(m, cache=False)
    assert cm.flat.unconnected == ["spring.flange_a"]
    res = cm.simulate(t_end=0.1)
    assert max(abs(res["spring.f"])) == 0.0 and max(abs(res["mass.s"] - 0.1)) == 0.0


def test_over_determined_model_is_named():
    m = oscillator()
    m.equation(Eq(m.mass.s, 0.1))         # a second law for the mass position
    with pytest.raises(StructuralError) as err:
        compile_model(m)
    msg = str(err.value)
    assert "too many" in msg or "over-determined" in msg
    assert "mass" in msg


def test_two_supports_on_one_node_are_redundant():
    m = oscillator()
    m.ground2 = Fixed(s0=0.0)
    m.connect(m.ground2.flange, m.ground.flange)
    with pytest.raises(StructuralError) as err:
        compile_model(m)
    assert "ground" in str(err.value)


def test_terminal_event():
    from acausal import Stop
    m = oscillator()
    m.event(Stop("mass.s", "<=", 0.0, name="zero").event(m))
    res = compile_model(m).simulate(t_end=1.0, rtol=1e-10, atol=1e-12)
    assert res.events[-1][1] == "zero"
    assert abs(res.t[-1] - np.pi / 20) < 1e-9


class Switch(Component):
    """Pushes with +F until its flange passes s_switch, then with -F (a mode
    change at an event; the acceleration jumps)."""

    flange = Flange("driven flange")
    F = Parameter(2.0, "N", "force magnitude")
    s_switch = Parameter(1.0, "m", "switching position")
    mode = Discrete(0, "1", "1 after the switch")

    def equations(self):
        return [Eq(self.flange.f, sp.Piecewise((-self.F, Eq(self.mode, 0)), (self.F, True)))]

    def events(self):
        def flip(state):
            state[self.mode] = 1
        return [Event("switch", self.flange.s - self.s_switch, +1, flip)]


def test_mode_switch_reinitialises():
    m = Model()
    m.mass = Mass(m=1.0, s=0.0, v=0.0)
    m.push = Switch()
    m.connect(m.push.flange, m.mass.flange)
    res = compile_model(m).simulate(t_end=2.0, rtol=1e-10, atol=1e-12)
    t1 = np.sqrt(2 * 1.0 / 2.0)
    (te, name), = res.events
    assert name == "switch" and abs(te - t1) < 1e-9
    # after the switch: decelerate from v1 = a t1 with a = -2
    t = 2.0
    v_exact = 2.0 * t1 - 2.0 * (t - t1)
    s_exact = 1.0 + 2.0 * t1 * (t - t1) - (t - t1) ** 2
    f = res.final()
    assert abs(f["mass.v"] - v_exact) < 1e-8 and abs(f["mass.s"] - s_exact) < 1e-8
    # both sides of the event are in the output, and the force jumps there
    k = np.flatnonzero(res.t == te)
    assert len(k) == 2 and res["mass.flange.f"][k[0]] == 2.0 and res["mass.flange.f"][k[1]] == -2.0


class Toggle(Component):
    """A badly written mode machine: whatever the mode, its condition says the
    mode is wrong, so the event iteration can never settle."""

    flange = Flange("flange")
    mode = Discrete(1, "1", "a mode that is never right")
    F0 = Parameter(1.0, "N", "force per unit of mode")

    def equations(self):
        return [Eq(self.flange.f, self.F0 * self.mode)]

    def events(self):
        def flip(state):
            state[self.mode] = -state[self.mode]
        return [Event("flip", -1 - self.flange.s ** 2, -1, flip, recheck=True)]


def test_event_iteration_that_never_settles_names_component():
    from acausal import ChatteringError
    m = Model()
    m.mass = Mass(m=1.0, s=0.0, v=1.0)
    m.toggle = Toggle()
    m.connect(m.toggle.flange, m.mass.flange)
    with pytest.raises(ChatteringError) as err:
        compile_model(m).simulate(t_end=5.0)
    assert "toggle" in str(err.value) and "did not settle" in str(err.value)


def test_inconsistent_fixed_starts_are_an_error():
    from acausal import InitializationError
    m = Model()
    m.lever = TwoArmLever(a=0.1, b=0.3)
    m.m1 = Mass(m=2.0, s=0.01, v=0.0)
    m.m2 = Mass(m=1.0, s=0.05)               # would need 0.03
    m.spring = Spring(c=1000.0)
    m.ground = Fixed()
    m.connect(m.ground.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.m1.flange, m.lever.flange_a)
    m.connect(m.m2.flange, m.lever.flange_b)
    with pytest.raises(InitializationError) as err:
        compile_model(m).simulate(t_end=0.1)
    assert "m1.s" in str(err.value) and "m2.s" in str(err.value)


def test_bound_parameters():
    m = Model()
    k = m.parameter("k", 100.0, "N/m", "shared stiffness", min=0.0)
    m.mass = Mass(m=1.0, s=0.1)
    m.spring = Spring(c=k)
    m.ground = Fixed()
    m.connect(m.ground.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.mass.flange)
    cm = compile_model(m)
    assert "spring.c" in cm.bound
    res = cm.simulate(t_end=0.3, params={"k": 400.0}, rtol=1e-9, atol=1e-11)
    assert abs(res.final()["mass.s"] - 0.1 * np.cos(20 * 0.3)) < 1e-7
    from acausal import ParameterError
    with pytest.raises(ParameterError, match="bound"):
        cm.param_vector({"spring.c": 1.0})
    with pytest.raises(ParameterError, match="k = -1"):
        cm.param_vector({"k": -1.0})


def test_time_window_chattering_guard(monkeypatch):
    """The guard counts events in a window: with the window widened to half
    the run, a mass rattling in a clearance (an event every ~1 ms) must trip
    it and name the component, keeping what was computed."""
    from acausal import ChatteringError
    from acausal.runtime import hybrid as sim
    from acausal.mechanics.contact import Clearance
    monkeypatch.setattr(sim, "CHATTER_SPAN", 0.5)
    m = Model()
    m.housing = Fixed(s0=0.0)
    m.mass = Mass(m=0.1, s=0.0, v=1.0)
    m.slot = Clearance(gap=1e-3, K=1e9, e=1.0)
    m.connect(m.housing.flange, m.slot.flange_a)
    m.connect(m.slot.flange_b, m.mass.flange)
    with pytest.raises(ChatteringError) as err:
        compile_model(m).simulate(t_end=1.0)
    assert "slot" in str(err.value)
    assert err.value.result is not None and len(err.value.result.events) >= 100


class SpringOnMass(Model):
    """A sub-assembly built in its constructor, before it has a path: its
    parameter ``c`` shares its name with the spring's own ``c``."""

    def __init__(self):
        super().__init__()
        c = self.parameter("c", 100.0, "N/m", "stiffness", min=0.0)
        self.mass = Mass(m=1.0, s=0.1)
        self.spring = Spring(c=c)
        self.ground = Fixed()
        self.connect(self.ground.flange, self.spring.flange_a)
        self.connect(self.spring.flange_b, self.mass.flange)


def test_sub_model_bindings_get_full_paths():
    m = Model()
    m.sub = SpringOnMass()
    cm = compile_model(m)
    assert str(cm.bound["sub.spring.c"]) == "sub.c"
    res = cm.simulate(t_end=0.3, params={"sub.c": 400.0}, rtol=1e-9, atol=1e-11)
    assert abs(res.final()["sub.mass.s"] - 0.1 * np.cos(20 * 0.3)) < 1e-7


def test_connecting_different_domains_is_named():
    from acausal import ModelError
    from acausal.mechanics.rotational import Inertia
    m = Model()
    m.mass = Mass(m=1.0)
    m.wheel = Inertia(J=1.0)
    m.connect(m.mass.flange, m.wheel.flange)
    with pytest.raises(ModelError) as err:
        compile_model(m)
    msg = str(err.value)
    assert "mass.flange" in msg and "wheel.flange" in msg and "RotFlange" in msg


def test_equation_with_an_unknown_name_is_named():
    from acausal import ModelError
    m = oscillator()
    m.equation(Eq(m.mass.s, sp.Symbol("mass.typo")))
    with pytest.raises(ModelError, match="mass.typo"):
        compile_model(m)


def test_binding_to_a_non_parameter_is_named():
    from acausal import ModelError
    m = oscillator()
    m.spring.set(c=sp.Symbol("stiffnes"))
    with pytest.raises(ModelError, match="stiffnes"):
        compile_model(m)


def test_unknown_parameter_keyword_lists_the_valid_ones():
    from acausal import ParameterError
    with pytest.raises(ParameterError) as err:
        Mass(mass=1.0)
    assert "'mass'" in str(err.value) and "m" in str(err.value)


def test_an_event_that_cannot_be_evaluated_fails_at_the_compile():
    """The generated callbacks are written when a run needs them, but every
    event condition and variable is resolved at the compile: a model whose
    event asks for a derivative the model never computes fails there, in
    one line naming it, not at its first run."""
    from acausal import Model, compile_model
    from acausal.errors import ModelError
    from acausal.lang import Event
    from acausal.lang.symbols import der
    from acausal.mechanics.translational import Fixed, Mass, Spring

    class Watched(Mass):
        def events(self):
            return list(super().events()) + [Event(f"{self.path}.jerk", der(der(self.a)), -1)]
    m = Model()
    m.ground = Fixed()
    m.b = Watched(m=1.0, s=0.1, v=0.0)
    m.k = Spring(c=10.0)
    m.connect(m.ground.flange, m.k.flange_a)
    m.connect(m.k.flange_b, m.b.flange)
    with pytest.raises(ModelError, match=r"der\(der\(b\.a\)\) cannot be evaluated"):
        compile_model(m, cache=False)
