"""acausal.data.tube against cases whose answer is known in closed form.

Every case uses tol = 1e-3 over a reference on [0, 1] unless it says
otherwise, so the tube's half-width in time is dt = 1e-3 s and its
half-height dy = 1e-3 * max(range, |min|, nominal).
"""
import numpy as np
import pytest

from acausal.data.tube import TubeResult, tube_bounds, tube_compare, tube_size
from acausal.errors import UsageError

TOL = 1e-3
GRID = np.linspace(0.0, 1.0, 100001)          # a fine test grid (1e-5 s)


def piecewise(switches, values, t_end=1.0, n=1001):
    """A piecewise-constant signal as a result file writes it: a regular grid
    plus both sides of every event. ``values[0]`` holds until
    ``switches[0]``, ``values[k]`` from ``switches[k-1]`` on."""
    t = np.sort(np.concatenate([np.linspace(0.0, t_end, n), switches, switches]))
    y = np.empty(t.size)
    for k in range(t.size):
        # at an event time the first point is the value before, the second after
        before = np.searchsorted(switches, t[k], side="left")
        first = k == 0 or t[k - 1] != t[k]
        y[k] = values[before if first else before + 1]
    return t, y


def step(t0, lo=0.0, hi=1.0):
    """A step from lo to hi at t0, with both sides of the event."""
    return piecewise(np.array([t0]), [lo, hi])


def trapezoid(t):
    """0 until 0.2, up to 1 at 0.4 (slope 5), 1 until 0.6, down to 0 at 0.8."""
    return np.interp(t, [0, 0.2, 0.4, 0.6, 0.8, 1.0], [0, 0, 1, 1, 0, 0])


# -- the tube's size ---------------------------------------------------------------

def test_size_is_relative_to_the_span_and_the_range():
    t = np.linspace(0.0, 2.0, 11)
    assert tube_size(t, 3.0 * t - 6.0, TOL) == pytest.approx((2e-3, 6e-3))
    # a base of max(range, |min|): 5 + sin has range 2 but |min| 4
    t = np.linspace(0.0, 1.0, 4001)
    assert tube_size(t, 5.0 + np.sin(2 * np.pi * t), TOL)[1] == pytest.approx(4e-3)


def test_a_constant_signal_has_a_tube_of_its_magnitude_or_of_the_nominal_value():
    t = np.linspace(0.0, 1.0, 11)
    assert tube_size(t, np.full(11, 2.0), TOL)[1] == pytest.approx(2e-3)
    assert tube_size(t, np.full(11, -2.0), TOL)[1] == pytest.approx(2e-3)
    # zero: csv-compare 2.1's default nominal value 1e-3 ...
    assert tube_size(t, np.zeros(11), TOL)[1] == pytest.approx(1e-6)
    # ... and 2.0.3's guard 1e-12 (the MSL 4.0.0 reference runs)
    assert tube_size(t, np.zeros(11), TOL, nominal=1e-12)[1] == pytest.approx(1e-15)


def test_a_time_axis_not_starting_at_zero_uses_the_larger_of_span_and_start():
    t = np.linspace(10.0, 11.0, 11)
    assert tube_size(t, t, TOL)[0] == pytest.approx(10e-3)    # max(1, |10|) = 10


def test_absolute_sizes_override_the_relative_ones():
    t = np.linspace(0.0, 1.0, 11)
    assert tube_size(t, t, TOL, dt_abs=0.1, dy_abs=0.5) == (0.1, 0.5)


# -- a constant signal -------------------------------------------------------------

@pytest.mark.parametrize("c", [2.0, -2.0])
def test_constant_reference_passes_within_its_magnitude(c):
    t = np.linspace(0.0, 1.0, 101)
    ref = np.full(t.size, c)
    assert tube_compare(t, ref, GRID, np.full(GRID.size, c + 0.99 * 2e-3), TOL).passed
    res = tube_compare(t, ref, GRID, np.full(GRID.size, c - 1.01 * 2e-3), TOL)
    assert not res.passed
    assert res.worst == pytest.approx(0.01 * 2e-3)
    assert res.n_violations == GRID.size


def test_zero_reference_passes_within_tol_times_nominal():
    t = np.linspace(0.0, 1.0, 101)
    zero = np.zeros(t.size)
    assert tube_compare(t, zero, GRID, np.full(GRID.size, 0.99e-6), TOL).passed
    assert not tube_compare(t, zero, GRID, np.full(GRID.size, 1.01e-6), TOL).passed
    # csv-compare 2.0.3: a zero reference must be met to 1e-15
    assert tube_compare(t, zero, GRID, np.zeros(GRID.size), TOL, nominal=1e-12).passed
    assert not tube_compare(t, zero, GRID, np.full(GRID.size, 1e-14), TOL,
                            nominal=1e-12).passed


# -- a signal scaled in value ------------------------------------------------------

def test_scaled_sine_passes_just_inside_and_fails_just_outside_the_value_tolerance():
    # sin(2 pi t): range 2, so dy = 2e-3. A scaled copy (1 + eps) sin is off by
    # eps at the peaks, where the tube is exactly 1 + dy high whatever dt is.
    t = np.linspace(0.0, 1.0, 1001)            # has the peaks 0.25 and 0.75
    ref = np.sin(2 * np.pi * t)
    assert tube_compare(t, ref, t, 1.00199 * ref, TOL).passed
    res = tube_compare(t, ref, t, 1.00201 * ref, TOL)
    assert not res.passed
    assert res.worst == pytest.approx(0.00201 - 0.002, rel=1e-6)
    assert res.t_worst in (pytest.approx(0.25), pytest.approx(0.75))
    assert abs(res.y_worst) == pytest.approx(1.00201)
    assert res.worst_rel == pytest.approx(0.005, rel=1e-6)


def test_offset_signal_uses_its_minimum_as_the_base():
    t = np.linspace(0.0, 1.0, 1001)
    ref = 5.0 + np.sin(2 * np.pi * t)          # dy = 1e-3 * |min| = 4e-3
    assert tube_compare(t, ref, t, ref + 3.99e-3, TOL).passed
    assert not tube_compare(t, ref, t, ref + 4.01e-3, TOL).passed


# -- a signal shifted in time ------------------------------------------------------

@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_step_passes_when_its_event_is_within_dt_of_the_reference_event(sign):
    # the step's range is 1: dt = 1e-3 s; the test's values between the two
    # event times differ by the whole step, so only the time tolerance counts
    t_ref, y_ref = step(0.5)
    t_in, y_in = step(0.5 + sign * 0.999e-3)
    assert tube_compare(t_ref, y_ref, t_in, y_in, TOL).passed
    t_out, y_out = step(0.5 + sign * 1.001e-3)
    res = tube_compare(t_ref, y_ref, t_out, y_out, TOL)
    assert not res.passed
    assert res.t_worst == pytest.approx(0.5 + sign * 1.001e-3)
    assert res.worst == pytest.approx(1.0 - 1e-3)     # a whole step less dy
    # the tube is open across the event: both values are inside at t_ref +- dt
    lo, hi = tube_bounds(t_ref, y_ref, [0.5 - 0.999e-3, 0.5 + 0.999e-3], 1e-3, 1e-3)
    np.testing.assert_allclose(lo, [-1e-3, -1e-3])
    np.testing.assert_allclose(hi, [1 + 1e-3, 1 + 1e-3])


def test_step_sampled_without_its_event_points():
    # a test written on its grid only, the jump between two grid points: the
    # last point before the jump and the first after are what is checked
    t_ref, y_ref = step(0.5)
    t = np.linspace(0.0, 1.0, 100001)
    assert tube_compare(t_ref, y_ref, t, np.where(t >= 0.5009, 1.0, 0.0), TOL).passed
    assert not tube_compare(t_ref, y_ref, t, np.where(t >= 0.5011, 1.0, 0.0), TOL).passed


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_trapezoid_shift_limit_is_dt_plus_dy_over_the_slope(sign):
    # on a ramp of slope 5 a time shift d puts the test 5 (d - dt) below the
    # tube's window bound, which dy = 1e-3 widens: the limit is dt + dy/5
    t_ref = np.linspace(0.0, 1.0, 1001)
    y_ref = trapezoid(t_ref)
    limit = 1e-3 + 1e-3 / 5
    assert tube_compare(t_ref, y_ref, GRID, trapezoid(GRID - sign * 0.99 * limit), TOL).passed
    res = tube_compare(t_ref, y_ref, GRID, trapezoid(GRID - sign * 1.01 * limit), TOL)
    assert not res.passed
    assert res.worst == pytest.approx(5 * 0.01 * limit, rel=1e-3)


def test_a_ramp_shifted_in_time_fails_at_the_end_where_the_tube_is_cut():
    # the window is cut at the reference's last time: there a time shift can
    # only be absorbed by dy (documented csv-compare behaviour)
    t = np.linspace(0.0, 1.0, 1001)
    late = tube_compare(t, t, t, t + 1.5e-3, TOL)      # 1.5e-3 < dt + dy = 2e-3
    assert not late.passed
    assert late.t_worst == pytest.approx(1.0)
    assert late.worst == pytest.approx(0.5e-3)
    assert tube_compare(t, t, t[:-5], t[:-5] + 1.5e-3, TOL, require_coverage=False).passed


# -- events in the reference -------------------------------------------------------

def test_short_pulse_in_the_reference_may_be_missed_but_not_misplaced():
    # a Boolean true for 3e-7 s (MSL's startForward): a test that never shows it
    # passes; a test that shows it 10 dt away does not
    t = np.union1d(np.linspace(0.0, 1.0, 2001), [0.3, 0.3 + 3e-7])
    t = np.sort(np.concatenate([t, [0.3, 0.3 + 3e-7]]))
    k0, k1 = np.searchsorted(t, 0.3), np.searchsorted(t, 0.3 + 3e-7)
    y = np.zeros(t.size)
    y[k0 + 1:k1 + 1] = 1.0
    assert tube_compare(t, y, GRID, np.zeros(GRID.size), TOL).passed
    moved = np.where((GRID >= 0.31) & (GRID <= 0.31 + 1e-5), 1.0, 0.0)
    assert not tube_compare(t, y, GRID, moved, TOL).passed


def test_mode_signal_switching_late():
    # an integer mode 2 -> 1 -> 0 (range 2: dy = 2e-3): each switch within dt
    t, y = piecewise(np.array([0.1, 0.6]), [2.0, 1.0, 0.0])
    tt, yt = piecewise(np.array([0.1005, 0.6008]), [2.0, 1.0, 0.0])
    assert tube_compare(t, y, tt, yt, TOL).passed
    tt, yt = piecewise(np.array([0.1005, 0.6012]), [2.0, 1.0, 0.0])
    res = tube_compare(t, y, tt, yt, TOL)
    assert not res.passed
    assert res.t_worst == pytest.approx(0.6012)
    assert res.y_worst == 1.0 and res.upper_worst == pytest.approx(0.002)


# -- what the test must be -----------------------------------------------------------

def test_nan_in_the_test_fails():
    t = np.linspace(0.0, 1.0, 11)
    y = t.copy()
    y[4] = np.nan
    res = tube_compare(t, t, t, y, TOL)
    assert not res.passed and res.n_violations == 1 and res.t_worst == pytest.approx(0.4)


def test_a_test_that_stops_early_fails_unless_coverage_is_waived():
    t = np.linspace(0.0, 1.0, 1001)
    res = tube_compare(t, np.sin(t), t[:500], np.sin(t[:500]), TOL)
    assert not res.passed and not res.covered and res.n_violations == 0
    assert "cover" in res.describe("x")
    assert tube_compare(t, np.sin(t), t[:500], np.sin(t[:500]), TOL,
                        require_coverage=False).passed


def test_points_outside_the_reference_span_are_counted_not_checked():
    t = np.linspace(0.0, 1.0, 101)
    tt = np.concatenate([[-0.1, -0.05], t, [1.05, 1.1]])
    res = tube_compare(t, t, tt, np.where((tt < 0) | (tt > 1), 99.0, tt), TOL)
    assert res.passed and res.n_outside == 4 and res.n_checked == 101


def test_reference_time_must_not_decrease():
    with pytest.raises(UsageError, match="decreases at point 2"):
        tube_compare([0.0, 0.5, 0.4, 1.0], [0, 1, 2, 3], [0.0, 1.0], [0.0, 3.0])
    with pytest.raises(UsageError, match="values 2"):
        tube_compare([0.0, 0.5, 1.0], [0, 1], [0.0, 1.0], [0.0, 3.0])


def test_result_reads_as_a_boolean_and_says_where():
    t = np.linspace(0.0, 1.0, 11)
    ok = tube_compare(t, t, t, t, TOL)
    assert isinstance(ok, TubeResult) and ok and "inside" in ok.describe("m.s")
    bad = tube_compare(t, t, t, t + 0.1, TOL)
    assert not bad
    text = bad.describe("m.s")
    assert text.startswith("m.s: 11 of 11 points outside the tube; worst at t = ")
    assert "tube [" in text


# -- the bounds against a brute-force envelope --------------------------------------

def test_bounds_equal_the_window_extremes_of_the_polyline():
    rng = np.random.default_rng(7)
    t_ref = np.sort(np.concatenate([rng.uniform(0, 1, 300), [0.0, 1.0]]))
    t_ref = np.sort(np.concatenate([t_ref, t_ref[50:53]]))      # three jumps
    y_ref = rng.normal(size=t_ref.size)
    dt, dy = 0.013, 0.1
    t = rng.uniform(0, 1, 400)
    lo, hi = tube_bounds(t_ref, y_ref, t, dt, dy)
    for k in range(t.size):
        a, b = max(t[k] - dt, 0.0), min(t[k] + dt, 1.0)
        inner = (t_ref >= a) & (t_ref <= b)
        vals = np.concatenate([y_ref[inner], np.interp([a, b], t_ref, y_ref)])
        assert hi[k] == pytest.approx(vals.max() + dy, abs=1e-12)
        assert lo[k] == pytest.approx(vals.min() - dy, abs=1e-12)
