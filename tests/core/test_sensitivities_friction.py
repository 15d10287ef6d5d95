"""Forward sensitivities through the friction mode machine
(:mod:`acausal.mechanics.frictionmodes`): stops, break-aways found by the
event iteration at the same instant ("recheck"), an engagement at a time
event, the final stick, and an observer event fired by the event iteration,
each against five-point central differences of separate runs (as
``test_sensitivities.py::test_bouncing_contact_against_central_differences``).

The differences share no sensitivity code with the runs they check: each is
four ordinary simulations with the parameter moved by -2h, -h, h, 2h.
Output times are kept away from the events (a grid time within 2h dtau/dp of
an event would put the event inside the difference stencil).
"""
import numpy as np
import pytest
import sympy as sp
from sympy import Eq as Rel

from acausal import Model, compile_model
from acausal.blocks.sources import Step
from acausal.lang import Discrete, Event
from acausal.mechanics import rotational as rot
from acausal.mechanics.frictionmodes import STUCK
from acausal.mechanics.translational import Fixed, Mass, Spring
from acausal.mechanics.translational.friction import SupportFriction

TIGHT = dict(rtol=1e-10, atol=1e-12)


def _five_point(runs, get, h):
    v = {k: np.asarray(get(r), float) for k, r in runs.items()}
    return (v[-2] - 8 * v[-1] + 8 * v[1] - v[2]) / (12 * h)


def _differences(cm, name, kw, rel=1e-3):
    """(step h, runs at p0 + k h for k = -2, -1, 1, 2)."""
    p0 = float(cm.param_vector()[cm.param_index(name)])
    h = rel * p0
    return h, {k: cm.simulate(params={name: p0 + k * h}, **kw) for k in (-2, -1, 1, 2)}


def _grid(events, t_end, count, margin):
    """``count`` output times in (0, t_end) at least ``margin`` from every event."""
    grid = np.linspace(0.0, t_end, count + 2)[1:-1]
    times = np.array([t for t, _ in events])
    return grid[np.min(np.abs(grid[:, None] - times[None, :]), axis=1) > margin]


def _rel(a, b):
    return np.max(np.abs(np.asarray(a) - np.asarray(b))) / max(np.max(np.abs(b)), 1e-300)


def _check(cm, names, variables, kw, t_end, tols, rel=1e-3, margin=2e-3):
    """The run with sensitivities against differences: event times (every
    logged event, those of the event iteration included) and ``variables``
    at output times away from the events. Returns the measured worst
    relative deviations {(name, what): value}. ``tols``: (events,
    trajectories); ``rel``: the differences' relative step; ``margin``
    [s]: the output times' distance from the events (more than 2h dtau/dp)."""
    event_tol, traj_tol = tols
    plain = cm.simulate(t_end=t_end, **kw)
    grid = _grid(plain.events, t_end, 40, margin)
    kw = dict(kw, t_end=t_end, output_times=grid)
    res = cm.simulate(sensitivities=names, **kw)
    events = [n for _, n in res.events]
    out = {}
    for name in names:
        h, runs = _differences(cm, name, kw, rel)
        assert all([n for _, n in r.events] == events for r in runs.values()), name
        fd = _five_point(runs, lambda r: r.event_times(), h)
        got = res.event_sensitivity(name)
        out[name, "events"] = err = _rel(got, fd)
        assert err < event_tol, (name, err, got, fd)
        for var in variables:
            fdx = _five_point(runs, lambda r: np.interp(grid, r.t, r[var]), h)
            sx = np.interp(grid, res.t, res.sensitivity(var, name))
            out[name, var] = err = _rel(sx, fdx)
            assert err < traj_tol, (name, var, err)
    return res, out


# -- (a) a mass on a spring with SupportFriction: stop, break-away, final stick ------

def _support_friction(table, cls=SupportFriction):
    """1 kg on a 100 N/m spring with SupportFriction (sliding ``table``, peak
    1.3), started at 0.05 m, 1 m/s: it slides, stops where the spring
    exceeds the break-away (slide_stop and break_* at one instant), slides
    back, ..., and sticks for good at its third stop."""
    m = Model()
    m.ground = Fixed()
    m.spring = Spring(c=100.0, s_rel0=0.0)
    m.mass = Mass(m=1.0, s=0.05, v=1.0)
    m.fric = cls(f_pos=table, peak=1.3)
    m.connect(m.ground.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.mass.flange)
    m.connect(m.mass.flange, m.fric.flange_a)
    return compile_model(m)


CONSTANT, RISING = ((0.0, 2.0),), ((0.0, 2.0), (1.0, 3.0))
EXPECTED = ["fric.initial_mode", "fric.slide_stop", "fric.break_backward", "fric.slide_stop",
            "fric.break_forward", "fric.slide_stop"]


def test_support_friction_after_a_stop_and_break_takes_few_steps():
    """The run that crawled: with respect to mass.m, after the stop and
    break-away at t = 0.0928 s, IDA took 1,483,111 steps to t = 0.2 (252 s;
    the second table failed at t = 0.1317), its Newton iteration read as
    diverging (see :meth:`acausal.runtime.sensitivity.SensitivityModel._generate`).
    Measured now: 287 steps to 0.2 s (the run without sensitivities: 265)."""
    cm = _support_friction(CONSTANT)
    res = cm.simulate(sensitivities=["mass.m"], t_end=1.0, **TIGHT)
    plain = cm.simulate(t_end=1.0, **TIGHT)
    assert [n for _, n in res.events] == EXPECTED
    assert res.stats["steps"] < 2 * plain.stats["steps"], res.stats["steps"]
    assert res["fric.mode"][-1] == STUCK and res["fric.locked"][-1] == 1
    # the logged break-away (a recheck event) moves with its instant's stop
    dtau = res.event_sensitivity("mass.m")
    assert dtau[2] == dtau[1] != 0 and dtau[4] == dtau[3] != 0
    # the row stored right after each instant (re-initialised, the
    # sensitivities jumped) meets the augmented equations (measured: 7e-18)
    sens = res.sensitivities
    for te, _ in res.events[1:]:
        k = np.flatnonzero(sens.t == te)[-1]
        r = np.zeros(sens.Y.shape[1])
        sens.sm.callbacks(sens.p, list(sens.D[k])).res(te, sens.Y[k], sens.YP[k], r)
        assert np.max(np.abs(r)) < 1e-12, (te, r)


@pytest.mark.parametrize("table", [CONSTANT, pytest.param(RISING, marks=pytest.mark.slow)],
                         ids=["constant", "rising"])
def test_support_friction_against_central_differences(table):
    """Event times and s, v, the friction force and sa over three stops (two
    with a break-away at the same instant, the last one the final stick)
    against five-point differences (step 1e-3 of each parameter). Measured,
    as fractions of the largest difference: event times within 6e-8
    (constant table) and 7e-8 (rising), s, v and sa within 7.4e-7 and
    2.2e-7, the friction force within 2.1e-6 and 6.7e-7."""
    cm = _support_friction(table)
    res, _ = _check(cm, ["mass.m", "spring.c"], ["mass.s", "mass.v", "fric.f", "fric.sa"],
                    TIGHT, 1.0, (3e-7, 1e-5))
    assert [n for _, n in res.events] == EXPECTED


# -- (b) a rotational brake engaged at a time event -------------------------------

def _brake():
    """An inertia on a torsion spring, spinning at 5 rad/s; a Brake (friction
    coefficient falling with speed, peak 1.2) whose normal force steps from
    0 to fn_max at t = 0.05 s: the time event's iteration engages it, it
    slides, stops and breaks away again twice, and sticks."""
    m = Model()
    m.fixed = rot.Fixed()
    m.spring = rot.Spring(c=50.0)
    m.J = rot.Inertia(J=0.5, phi=0.1, w=5.0)
    m.brake = rot.Brake(fn_max=60.0, cgeo=0.1, mu_pos=((0.0, 0.5), (10.0, 0.3)), peak=1.2)
    m.step = Step(height=1.0, startTime=0.05)
    m.connect(m.fixed.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.J.flange_a)
    m.connect(m.J.flange_b, m.brake.flange_a)
    m.connect(m.step.y, m.brake.f_normalized)
    return compile_model(m)


@pytest.mark.slow
def test_brake_engaged_at_a_time_event_against_central_differences():
    """The time event (the step), the engagement its event iteration
    fires, the stops, break-aways and the final stick: event times and the
    trajectory against five-point differences, with respect to the inertia,
    the normal force and the step's time (step 1e-2: the event times move
    by 1e-4 s per N of fn_max, so smaller steps leave the differences to the
    solver's noise). Measured, as fractions of the largest difference:
    event times within 1.9e-7, angle, speed and torque within 3.2e-6.
    Before the fix of the iteration matrix IDA failed at t = 0.325 s."""
    cm = _brake()
    res, _ = _check(cm, ["J.J", "brake.fn_max", "step.startTime"],
                    ["J.phi", "J.w", "brake.tau"], TIGHT, 1.5, (1e-6, 1e-5), rel=1e-2,
                    margin=0.02)
    names = [n for _, n in res.events]
    assert names[1:3] == ["step.time_event", "brake.engage"]
    assert names[-1] == "brake.slide_stop" and names.count("brake.slide_stop") >= 3
    assert res["brake.locked"][-1] == 1
    # the engagement happens at the step: its time moves one for one with
    # startTime (the schedule's central difference of the instant, step
    # 5e-8 s: round-off 1e-16 / 5e-8; measured 1 + 2.9e-11)
    assert res.event_sensitivity("step.startTime")[2] == pytest.approx(1.0, abs=1e-8)


# -- (c) an observer event fired by the event iteration ----------------------------

class _NotedFriction(SupportFriction):
    """SupportFriction that notes, once the acceleration has fallen below
    -10 m/s2 (``arm``), the instant it jumps back above it (``note``, an
    observer event: at a stop that happens at the stop's instant, found by
    the event iteration): the time ``t_note`` [s] and the position
    ``s_note`` [m] and ``sa_note`` [1] there (discrete values no equation
    uses; at a stop the event iteration fires it with the element stuck,
    so ``sa`` is the holding force)."""

    armed = Discrete(0, "1", "1 after the acceleration fell below -10 m/s2")
    t_note = Discrete(0.0, "s", "time of the note")
    s_note = Discrete(0.0, "m", "position at the note")
    sa_note = Discrete(0.0, "1", "sa (the holding force while stuck) at the note")

    def events(self):
        _, a = self.friction_motion()

        def arm(state):
            state[self.armed] = 1

        def note(state):
            state[self.armed] = 0
            state[self.t_note] = state.t
            state[self.s_note] = state[self.s]
            state[self.sa_note] = state[self.sa]
        armed = Rel(self.armed, 1)
        # (a component's events are collected class by class: these are added
        # to the machine's)
        return [
            Event(self.path + ".arm", sp.Piecewise((-(a + 10), ~armed), (-1, True)), 1, arm,
                  observer=True),
            Event(self.path + ".note", sp.Piecewise((a + 10, armed), (-1, True)), 1, note,
                  observer=True, recheck=True)]


def test_observer_event_at_a_recheck_against_central_differences():
    """The note fires in the event iteration of the first stop; its time's
    sensitivity is the stop's (the instant's, kept as a copy), and the
    values it records (time, position and the element's
    holding force) move as differences of separate runs say. Measured:
    event times within 4e-9, the recorded values within 1.3e-8 (relative)."""
    cm = _support_friction(CONSTANT, _NotedFriction)
    kw = dict(TIGHT, t_end=0.3)
    res = cm.simulate(sensitivities=["mass.m", "spring.c"], **kw)
    names = [n for _, n in res.events]
    stop = names.index("fric.slide_stop")
    assert "fric.arm" in names[:stop] and "fric.note" in names[stop:stop + 3]
    k = names.index("fric.note")
    assert res.events[k][0] == res.events[stop][0]
    for name in ("mass.m", "spring.c"):
        h, runs = _differences(cm, name, kw)
        assert all([n for _, n in r.events] == names for r in runs.values())
        fd = _five_point(runs, lambda r: r.event_times(), h)
        got = res.event_sensitivity(name)
        assert got[k] == got[stop] != 0
        assert _rel(got, fd) < 1e-7, (name, got, fd)
        for var in ("fric.t_note", "fric.s_note", "fric.sa_note"):
            d = _five_point(runs, lambda r: r[var][-1], h)
            s = res.sensitivity(var, name)[-1]
            assert abs(s - d) <= 1e-6 * abs(d) + 1e-12, (name, var, s, d)
