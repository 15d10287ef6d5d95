"""The chattering guard tells a root that keeps firing without time
advancing (Zeno behaviour: a mode logic that does not settle) from many
different roots firing at one instant (a Newton's cradle of 200 balls: 199
contacts close at t = 0), which is ordinary."""
import numpy as np
import pytest

from acausal import ChatteringError, Discrete, Eq, Event, Model, Parameter, compile_model, time
from acausal.lang.component import Component
from acausal.lang.connectors import Flange
from acausal.mechanics.translational import Fixed, Mass, Spring


class Rearming(Component):
    """A flawed timer that re-arms its own root ``dt`` after each firing,
    for ever (the events of a contact or relay that keeps toggling while
    time hardly advances). No force on its flange."""

    flange = Flange("flange (no force)")
    t_next = Discrete(0.1, "s", "time of the next firing")
    dt = Parameter(1e-13, "s", "re-arming delay")

    def equations(self):
        return [Eq(self.flange.f, 0)]

    def events(self):
        def rearm(state):
            state[self.t_next] = state.t + state[self.dt]
        return [Event("rearm", time - self.t_next, 1, rearm)]


class Tick(Component):
    """Fires once, at ``t_fire``, and counts it (no force on its flange)."""

    flange = Flange("flange (no force)")
    t_fire = Parameter(0.1, "s", "firing time")
    fired = Discrete(0, "1", "times fired")

    def equations(self):
        return [Eq(self.flange.f, 0)]

    def events(self):
        def count(state):
            state[self.fired] = state[self.fired] + 1
        return [Event("tick", time - self.t_fire, 1, count)]


def oscillator(extra):
    """A mass on a spring (x = 0.01 cos(10 t)) with ``extra`` components
    (name -> component) on its flange."""
    m = Model()
    m.ground = Fixed()
    m.mass = Mass(m=1.0, s=0.01, v=0.0)
    m.spring = Spring(c=100.0)
    m.connect(m.ground.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.mass.flange, *[m.add(k, c).flange for k, c in extra.items()])
    return m


def test_a_root_refiring_without_time_advancing_is_chattering():
    cm = compile_model(oscillator({"timer": Rearming()}), cache=False)
    with pytest.raises(ChatteringError) as err:
        cm.simulate(t_end=1.0)
    msg = str(err.value)
    assert "timer" in msg and "rearm" in msg and "\n" not in msg
    assert err.value.t == pytest.approx(0.1, abs=1e-10)
    assert len(err.value.result.events) == 100
    # re-armed 1 ms later it is an ordinary periodic event
    res = cm.simulate(t_end=0.1045, params={"timer.dt": 1e-3}, rtol=1e-10, atol=1e-12)
    assert [round(t, 9) for t, _ in res.events] == [0.1, 0.101, 0.102, 0.103, 0.104]
    assert abs(res.final()["mass.s"] - 0.01 * np.cos(1.045)) < 1e-8


def test_many_roots_firing_at_one_instant_are_not_chattering():
    n = 150      # more than the guard's count, all at t = 0.1
    cm = compile_model(oscillator({f"tick{k}": Tick() for k in range(n)}), cache=False)
    res = cm.simulate(t_end=0.2, rtol=1e-10, atol=1e-12)
    assert len(res.events) == n and all(abs(t - 0.1) < 1e-12 for t, _ in res.events)
    assert all(res.final()[f"tick{k}.fired"] == 1 for k in range(n))
    assert abs(res.final()["mass.s"] - 0.01 * np.cos(2.0)) < 1e-8
