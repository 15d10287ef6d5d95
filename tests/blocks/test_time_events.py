"""Discontinuities in time are time events: the integrator stops exactly at
them (IDA's stop time), restarts after them, and records them. Closed
forms on a mass driven by time-dependent forces, on both backends."""
import numpy as np
import pytest
import sympy as sp

from acausal import Model, compile_model, time
from acausal.blocks import Step
from acausal.lang import Component, Eq, Flange, Parameter
from acausal.mechanics.translational import Force, Mass


class _TimeForce(Component):
    """A force on the flange given by an expression of time (a test part)."""
    flange = Flange("flange")
    F = Parameter(2.0, "N", "force level")
    K = Parameter(2.0, "N/s", "force rate")
    T = Parameter(0.5, "s", "switching time")

    def __init__(self, law, **kw):
        super().__init__(**kw)
        object.__setattr__(self, "_law", law)

    def equations(self):
        return [Eq(self.flange.f, -self._law(self))]


def pushed_mass(law, **kw):
    m = Model()
    m.push = _TimeForce(law, **kw)
    m.mass = Mass(m=1.0, s=0.0, v=0.0)
    m.connect(m.push.flange, m.mass.flange)
    return compile_model(m, cache=False)


@pytest.mark.parametrize("backend", ["sundae", "compiled"])
def test_step_at_half_a_second_kinks_the_motion_exactly_there(backend):
    """Step (0 -> 2 N at t = 0.5) on a 1 kg mass: s = (t - 0.5)^2 for t > 0.5;
    the event is at 0.5 exactly, with the force 0 before and 2 after it."""
    m = Model()
    m.step = Step(height=2.0, startTime=0.5)
    m.force = Force()
    m.mass = Mass(m=1.0, s=0.0, v=0.0)
    m.connect(m.step.y, m.force.f)
    m.connect(m.force.flange, m.mass.flange)
    res = compile_model(m, cache=False).simulate(t_end=1.0, rtol=1e-10, atol=1e-12,
                                                 backend=backend)
    assert res.events == [(0.5, "step.time_event")]
    k = np.flatnonzero(res.t == 0.5)
    assert len(k) == 2 and list(res["mass.flange.f"][k]) == [0.0, 2.0]
    exact = np.where(res.t <= 0.5, 0.0, (res.t - 0.5) ** 2)
    assert np.max(np.abs(res["mass.s"] - exact)) < 1e-9
    assert np.max(np.abs(res["mass.s"][res.t <= 0.5])) == 0.0   # nothing leaks before it


@pytest.mark.parametrize("backend", ["sundae", "compiled"])
def test_piecewise_in_time_with_a_parameter_instant(backend):
    cm = pushed_mass(lambda c: sp.Piecewise((0, time < c.T), (c.F, True)))
    for T in (0.3, 0.65):
        res = cm.simulate(t_end=1.0, rtol=1e-10, atol=1e-12, params={"push.T": T},
                          backend=backend)
        assert res.events == [(T, "push.time_event")]
        assert abs(res["mass.s"][-1] - (1 - T) ** 2) < 1e-9


def test_a_window_in_time_and_kinks_of_max_and_abs():
    # force 2 N between 0.2 and 0.6 s: two events, v = 0.8 m/s after
    cm = pushed_mass(lambda c: sp.Piecewise((c.F, (time >= 0.2) & (time < 0.6)), (0, True)))
    res = cm.simulate(t_end=1.0, rtol=1e-10, atol=1e-12)
    assert [t for t, _ in res.events] == [0.2, 0.6]
    assert abs(res["mass.v"][-1] - 0.8) < 1e-9
    # Max(0, t - T): a ramp that starts at T (a kink, not a jump)
    cm = pushed_mass(lambda c: c.K * sp.Max(0, time - c.T))
    res = cm.simulate(t_end=1.0, rtol=1e-10, atol=1e-12)
    assert [t for t, _ in res.events] == [0.5]
    assert abs(res["mass.s"][-1] - 2 * 0.5 ** 3 / 6) < 1e-10
    # |t - T|: v = F*(sign(t-T)(t-T)^2/2 + T^2/2)
    cm = pushed_mass(lambda c: c.K * sp.Abs(time - c.T))
    res = cm.simulate(t_end=1.0, rtol=1e-10, atol=1e-12)
    assert [t for t, _ in res.events] == [0.5]
    assert abs(res["mass.v"][-1] - 2 * (0.125 + 0.125)) < 1e-9


def test_periodic_floor_and_a_relation_not_affine_in_time():
    # a square wave from floor(): +F on even half periods, -F on odd ones
    cm = pushed_mass(lambda c: c.F * (1 - 2 * sp.Mod(sp.floor(time / 0.1), 2)))
    res = cm.simulate(t_end=1.0, rtol=1e-10, atol=1e-12)
    assert np.allclose([t for t, _ in res.events], np.arange(1, 10) * 0.1, atol=1e-15, rtol=0)
    assert abs(res["mass.v"][-1]) < 1e-9                       # as much + as -
    assert abs(res["mass.s"][-1] - 5 * 2 * 0.1 ** 2) < 1e-9    # 5 triangles of area F*0.1^2
    # sin(w t) > 0 is not affine in time: its instants are roots IDA locates
    cm = pushed_mass(lambda c: sp.Piecewise((c.F, sp.sin(2 * sp.pi * time / 0.4) > 0), (0, True)))
    res = cm.simulate(t_end=1.0, rtol=1e-10, atol=1e-12)
    assert np.allclose([t for t, _ in res.events], [0.2, 0.4, 0.6, 0.8], atol=1e-9, rtol=0)
    assert abs(res["mass.v"][-1] - 2 * 0.4 - 2 * 0.2) < 1e-7


def test_the_instant_of_a_time_event_has_a_sensitivity():
    """d s(1)/d T of the step: the state sensitivities jump by
    (y'- - y'+) dT at the event (s = F/2 (1 - T)^2 -> -F (1 - T))."""
    m = Model()
    m.step = Step(height=2.0, startTime=0.4)
    m.force = Force()
    m.mass = Mass(m=1.0, s=0.0, v=0.0)
    m.connect(m.step.y, m.force.f)
    m.connect(m.force.flange, m.mass.flange)
    res = compile_model(m, cache=False).simulate(
        t_end=1.0, rtol=1e-10, atol=1e-12, sensitivities=["step.startTime", "step.height"])
    assert abs(res.sensitivity("mass.s", "step.startTime")[-1] + 1.2) < 1e-8
    assert abs(res.sensitivity("mass.v", "step.startTime")[-1] + 2.0) < 1e-8
    assert abs(res.sensitivity("mass.s", "step.height")[-1] - 0.18) < 1e-8
    assert res.event_sensitivity("step.startTime") == pytest.approx([1.0])


def test_output_just_after_an_event_is_merged_with_it():
    """An output time one ulp after a time event (0.7 vs 0.7000000000000001)
    is the same instant: IDA would refuse it ('tout too close')."""
    cm = pushed_mass(lambda c: sp.Piecewise((0, time < 0.2 + 0.5), (c.F, True)))
    res = cm.simulate(t_end=1.0, output_step=0.1)
    assert res.status == "ok" and [t for t, _ in res.events] == [0.7]
