"""Issue 21, what the last session left failing and the small faults it
noticed (a third battery):

* the observed variables of a large result are evaluated over all rows of
  a mode at once (a 10 M-row interrupted write took 84 s, row by row in
  Python); the values are the per-row callback's, to the last bit but for
  ``x**2`` (libm's ``pow`` against numpy's ``x*x``: one ulp);
"""
import numpy as np
import pytest

from acausal.modelfile import run_file
from acausal.runtime import observe
from acausal.runtime.result import Result, Rows

from . import helpers as h

ROOT = h.ROOT


def _ulps(a, b):
    same = (a == b) | (np.isnan(a) & np.isnan(b))
    gap = np.abs(a - b) / np.spacing(np.maximum(np.abs(a), np.abs(b)))
    return same, np.where(same, 0.0, gap)


@pytest.mark.parametrize("path", ["models/breaker_24kv.py", "models/breaker_24kv_planar.py",
                                  "models/examples/stick_slip.py"])
def test_the_vectorised_observe_gives_the_per_row_values(path, monkeypatch):
    """Every variable at every row of a whole run (all its modes): the
    array code against the per-row callback."""
    res, _ = run_file(str(ROOT / path))
    cm, R = res.model, (res.t, res.y, res.yp, res.d)
    assert len(res.t) >= 300
    rowwise = observe.per_row(cm, res.p, *R)
    monkeypatch.setattr(observe, "VECTOR_ROWS", 1)
    assert observe._function(cm) is not None   # it is vectorised, not the fallback
    arrays = observe.observed_rows(cm, res.p, *R)
    same, ulps = _ulps(rowwise, arrays)
    # the breakers' friction power w**2*bh: pow(w, 2) is one ulp off w*w
    # on some w; that ulp times one more rounding is the whole difference
    assert ulps.max() <= 2.0, ulps.max()
    assert same.mean() > 0.9999
    assert observe._function(cm) is not None   # the guard found nothing to fall back for


def test_a_large_result_is_written_without_a_python_call_per_row(tmp_path, monkeypatch):
    """to_csv of 60 000 rows of the breaker (4 modes): the per-row observe
    is called once per mode and block (the guard's check), not per row."""
    res, _ = run_file(str(ROOT / "models/breaker_24kv.py"))
    cm, n = res.model, 60_000
    reps = -(-n // len(res.t))
    big = Result(cm, res.p, Rows(*(np.tile(a, (reps,) + (1,) * (a.ndim - 1))[:n]
                                   for a in (res.t, res.y, res.yp, res.d))),
                 res.events, res.stats)
    calls = [0]
    real = cm.callbacks

    def counted(p, d):
        cb = real(p, d)
        inner = cb.observe

        def observe_counted(*a):
            calls[0] += 1
            return inner(*a)
        return cb._replace(observe=observe_counted)
    monkeypatch.setattr(cm, "callbacks", counted)
    big.to_csv(tmp_path / "big.csv")
    modes = len({tuple(r) for r in res.d.tolist()})
    assert calls[0] <= modes, calls[0]
    data = np.loadtxt(tmp_path / "big.csv", delimiter=",", skiprows=1, max_rows=len(res.t))
    ref = np.column_stack([res.t] + [res[name] for name in res.names])
    np.testing.assert_array_equal(data[:, 0], ref[:, 0])
    _, ulps = _ulps(data, ref)
    assert ulps.max() <= 2.0
