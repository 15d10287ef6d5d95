"""Signal sources against their closed forms (MSL's laws), with a time
event at every jump or kink: the output is exact on the grid (nothing is
integrated), the event times are the law's instants exactly, and the
rows at an event give the value before and after it."""
import math

import numpy as np
import pytest

from acausal import Model, compile_model
from acausal.blocks import (Constant, Cosine, Exponentials, ExpSine, Pulse, Ramp, SawTooth, Sine,
                            Step, Trapezoid)
from acausal.errors import ParameterError


def run(source, t_end=1.0, backend="sundae", **kw):
    m = Model()
    m.src = source
    return compile_model(m, cache=False).simulate(t_end=t_end, backend=backend,
                                                  output_step=1e-3, **kw)


def right_limits(res):
    """Mask of the rows that are not the first (left) row of an event pair."""
    t = res.t
    return np.r_[t[1:] != t[:-1], True]


def check(res, law, events, t_end=1.0):
    """The output equals ``law`` exactly at every row away from the events
    (1e-9 s), and an event's two rows are the values just before and just
    after it; the events are at ``events`` (one at t_end is not handled:
    the run ends there)."""
    t, y = res.t, res["src.y"]
    times = np.array(sorted({te for te, _ in res.events}))
    assert times == pytest.approx(sorted(e for e in events if e < t_end), abs=1e-15)
    near = np.zeros(t.size, bool)
    for te in list(times) + [e for e in events if e >= t_end]:
        near |= np.abs(t - te) < 1e-9
    assert np.max(np.abs(y[~near] - law(t[~near]))) < 1e-12
    for te in times:
        k = np.flatnonzero(t == te)
        assert len(k) == 2, te
        assert y[k[0]] == pytest.approx(law(np.array([te - 1e-9]))[0], abs=1e-7)
        assert y[k[1]] == pytest.approx(law(np.array([te + 1e-9]))[0], abs=1e-7)


@pytest.mark.parametrize("backend", ["sundae", "compiled"])
def test_step_and_ramp(backend):
    res = run(Step(height=3.0, offset=1.0, startTime=0.25), backend=backend)
    check(res, lambda t: 1.0 + np.where(t < 0.25, 0.0, 3.0), [0.25])
    assert res.events == [(0.25, "src.time_event")]
    res = run(Ramp(height=2.0, duration=0.5, offset=-1.0, startTime=0.1), backend=backend)
    check(res, lambda t: -1 + np.clip((t - 0.1) / 0.5, 0, 1) * 2.0, [0.1, 0.6])


def test_constant_and_zero_duration_ramp():
    res = run(Constant(k=2.5))
    assert np.all(res["src.y"] == 2.5) and res.events == []
    res = run(Ramp(height=2.0, duration=0.0, startTime=0.3))
    check(res, lambda t: np.where(t < 0.3, 0.0, 2.0), [0.3])


def test_sine_cosine_expsine():
    res = run(Sine(amplitude=2.0, f=3.0, phase=0.2, offset=0.5, startTime=0.1))
    check(res, lambda t: 0.5 + np.where(t < 0.1, 0, 2 * np.sin(6 * np.pi * (t - 0.1) + 0.2)),
          [0.1])
    res = run(Cosine(amplitude=2.0, f=3.0, phase=0.2, startTime=0.1))
    check(res, lambda t: np.where(t < 0.1, 0, 2 * np.cos(6 * np.pi * (t - 0.1) + 0.2)), [0.1])
    res = run(ExpSine(amplitude=1.5, f=5.0, damping=2.0, phase=0.1, startTime=0.05))
    check(res, lambda t: np.where(t < 0.05, 0, 1.5 * np.exp(-2 * (t - 0.05))
                                  * np.sin(10 * np.pi * (t - 0.05) + 0.1)), [0.05])


def test_exponentials():
    res = run(Exponentials(outMax=2.0, riseTime=0.3, riseTimeConst=0.1, fallTimeConst=0.2,
                           startTime=0.1))
    y_rise = 2.0 * (1 - math.exp(-3.0))
    check(res, lambda t: np.where(t < 0.1, 0, np.where(
        t < 0.4, 2.0 * (1 - np.exp(-(t - 0.1) / 0.1)),
        y_rise * np.exp(-(t - 0.4) / 0.2))), [0.1, 0.4])


@pytest.mark.parametrize("backend", ["sundae", "compiled"])
def test_pulse_generates_its_edges_one_period_after_the_other(backend):
    res = run(Pulse(amplitude=2.0, width=30.0, period=0.2, offset=0.5, startTime=0.1),
              backend=backend)

    def law(t):
        phase = np.mod(t - 0.1, 0.2)
        return 0.5 + np.where((t >= 0.1) & (phase < 0.06 - 1e-13), 2.0, 0.0)
    edges = [0.1 + 0.2 * k + d for k in range(5) for d in (0.0, 0.06)]
    check(res, law, edges)


def test_pulse_with_a_number_of_periods_and_full_width():
    res = run(Pulse(amplitude=1.0, width=40.0, period=0.25, nperiod=2))
    t, y = res.t, res["src.y"]
    keep = right_limits(res)
    expect = np.where((t < 0.5) & (np.mod(t, 0.25) < 0.1 - 1e-13), 1.0, 0.0)
    assert np.max(np.abs(y[keep] - expect[keep])) == 0.0
    res = run(Pulse(amplitude=1.0, width=100.0, period=0.25))   # always on
    assert np.all(res["src.y"] == 1.0)
    with pytest.raises(ParameterError, match="width"):
        Pulse(width=0.0)
    with pytest.raises(ParameterError, match="nperiod must be an integer"):
        Pulse(nperiod=1.5)


def test_sawtooth_and_trapezoid():
    res = run(SawTooth(amplitude=2.0, period=0.3, startTime=0.1))
    check(res, lambda t: np.where(t < 0.1, 0, 2.0 * np.mod(t - 0.1, 0.3) / 0.3),
          [0.1, 0.4, 0.7, 1.0])
    res = run(Trapezoid(amplitude=1.0, rising=0.1, width=0.2, falling=0.1, period=0.5))

    def trap(t):
        p = np.mod(t, 0.5)
        return np.where(p < 0.1, p / 0.1, np.where(p < 0.3, 1.0, np.where(p < 0.4,
                                                                         (0.4 - p) / 0.1, 0)))
    check(res, trap, [0.1, 0.3, 0.4, 0.5, 0.6, 0.8, 0.9, 1.0])


def test_source_instants_are_run_time_parameters():
    m = Model()
    m.src = Step(height=1.0, startTime=0.5)
    cm = compile_model(m, cache=False)
    for t_step in (0.2, 0.7):
        res = cm.simulate(t_end=1.0, params={"src.startTime": t_step})
        assert res.events == [(t_step, "src.time_event")]
        assert res.at("src.y", t_step + 1e-3) == 1.0 and res.at("src.y", t_step - 1e-3) == 0.0


def test_a_step_at_the_start_is_on_from_the_start_without_an_event():
    res = run(Step(height=2.0, startTime=0.0))
    assert np.all(res["src.y"] == 2.0) and res.events == []
