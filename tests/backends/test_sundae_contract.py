"""What acausal.backends.sundae relies on in scikit-sundae. If a new
scikit-sundae changes any of it, this fails and names what moved (widen the
pin in pyproject.toml only after this passes).

The DAE: y0' = 1, 0 = y1 - 2 y0 (y1 algebraic), from y0 = 0; roots
g0 = y0 - 0.3 (rising, observer), g1 = 0.5 - y0 (falling, terminal),
g2 = y0 - 0.2 (falling only: never fires, y0 rises)."""
import numpy as np
import pytest
from sksundae.ida import IDA

from acausal.runtime.backends.sundae import _EVENT_LOG, _clear_event_log


def _res(t, y, yp, r):
    r[0] = yp[0] - 1.0
    r[1] = y[1] - 2.0 * y[0]


def _jac(t, y, yp, r, cj, J):
    J[:, :] = 0.0
    J[0, 0] = cj
    J[1, 0] = -2.0
    J[1, 1] = 1.0


def _roots(t, y, yp, g):
    g[0] = y[0] - 0.3
    g[1] = 0.5 - y[0]
    g[2] = y[0] - 0.2


def _solver():
    _roots.terminal = [False, True, False]
    _roots.direction = [1, -1, -1]
    return IDA(_res, jacfn=_jac, eventsfn=_roots, num_events=3, algebraic_idx=[1],
               rtol=1e-10, atol=1e-12, max_step=0.0, max_num_steps=10000)


def _solve(ida):
    return ida.solve(np.array([0.0, 0.25, 0.75, 1.0]), np.zeros(2), np.array([1.0, 2.0]))


def test_result_fields_terminal_direction_and_event_log():
    sol = _solve(_solver())
    for field in ("t", "y", "yp", "status", "message", "i_events", "t_events", "y_events",
                  "yp_events", "nfev", "njev"):
        assert hasattr(sol, field), f"IDAResult has no field {field!r}"
    assert sol.status == 2, "a terminal root no longer stops solve() with status 2"
    np.testing.assert_allclose(sol.t, [0.0, 0.25, 0.5], atol=1e-9)
    # the observer root (non-terminal) is reported, the falling-only one is not
    np.testing.assert_allclose(sol.t_events, [0.3, 0.5], atol=1e-9)
    assert [list(np.nonzero(f)[0]) for f in sol.i_events] == [[0], [1]]
    assert list(sol.i_events[0][[0]]) == [1] and list(sol.i_events[1][[1]]) == [-1], \
        "i_events no longer gives the crossing direction (+1 rising, -1 falling)"
    np.testing.assert_allclose(sol.y_events[:, 1], [0.6, 1.0], atol=1e-8)  # algebraic
    np.testing.assert_allclose(sol.yp_events[:, 0], [1.0, 1.0], atol=1e-8)
    assert sol.nfev > 0 and sol.njev > 0


def test_two_point_tspan_reports_every_internal_step():
    _roots.terminal = [False, False, False]
    _roots.direction = [1, -1, -1]
    ida = IDA(_res, jacfn=_jac, eventsfn=_roots, num_events=3, algebraic_idx=[1],
              rtol=1e-10, atol=1e-12)
    sol = ida.solve(np.array([0.0, 0.4]), np.zeros(2), np.array([1.0, 2.0]))
    assert len(sol.t) > 3 and sol.t[-1] == pytest.approx(0.4)


def test_event_log_persists_across_solves_and_clearing_it_restores_a_fresh_start():
    ida = _solver()
    _solve(ida)
    for name in _EVENT_LOG + ("_i_cnt",):
        assert hasattr(_roots, name), f"scikit-sundae no longer keeps {name} on eventsfn"
    stale = _solve(ida)
    # the private log is kept for the life of the IDA object: the terminal
    # count left from the first solve stops the second at the observer root.
    # If this fails, scikit-sundae resets it itself and the adapter's private
    # access (_clear_event_log) can go.
    assert stale.t[-1] == pytest.approx(0.3, abs=1e-9)
    assert len(stale.t_events) == 3
    _clear_event_log(_roots, True)
    fresh = _solve(ida)
    np.testing.assert_allclose(fresh.t_events, [0.3, 0.5], atol=1e-9)
    assert fresh.t[-1] == pytest.approx(0.5, abs=1e-9) and fresh.status == 2
