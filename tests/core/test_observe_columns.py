"""``Result[name]`` of an observed variable reads that variable's
expression alone, vectorised over each mode (runtime/observe.observed_column):
the same values as every variable computed row by row by the per-row
callback, in every mode of a hybrid run, and the per-row values when the
vectorised expression disagrees with them (the guard)."""
import weakref

import numpy as np
import pytest

from acausal.modelfile import run_file
from acausal.runtime import observe
from tests.faults import helpers as h

ROOT = h.ROOT


def _ulps(a, b):
    """(same, gap): where ``a`` and ``b`` agree to the bit, and their gap in
    ulps of each column's largest magnitude over the run. An absolute
    measure: numpy's array math (SIMD pow, tanh, exp) is one ulp off libm's
    on some values (numpy 2.4.6 on AVX-512: pow(x, 1.5) on 5 %, tanh on 27 %),
    and a force summed from terms the size of the column's peak carries that
    ulp into a small result (the breaker hook's acceleration: 71 of its own
    ulps, 2 of the column's). A printer that writes a function wrong is off
    by far more."""
    same = (a == b) | (np.isnan(a) & np.isnan(b))
    scale = np.max(np.abs(np.nan_to_num(np.where(same, a, np.fmax(np.abs(a), np.abs(b))))),
                   axis=0)
    gap = np.abs(a - b) / np.spacing(np.maximum(scale, np.finfo(float).tiny))
    return same, np.where(same, 0.0, gap)


@pytest.mark.parametrize("path", ["models/breaker_24kv.py", "models/examples/stick_slip.py"])
def test_each_observed_variable_alone_is_its_per_row_value(path):
    res, _ = run_file(str(ROOT / path))
    cm = res.model
    modes = {tuple(r) for r in np.nan_to_num(res.d, nan=-7.0).tolist()}
    assert len(modes) >= 2     # a hybrid run: the columns cross mode switches
    rowwise = observe.per_row(cm, res.p, res.t, res.y, res.yp, res.d)
    observed = [(k, n) for k, n in enumerate(cm.var_names)
                if cm.y_column(n) is None]
    assert len(observed) > 10
    worst = 0.0
    for k, name in observed:
        res._columns.clear()     # each read alone (past ALONE names: the whole matrix)
        col = res[name]
        assert col.shape == res.t.shape
        worst = max(worst, float(_ulps(rowwise[:, k], col)[1].max()))
    # a primitive one ulp off (numpy's array pow or tanh against libm's, pow(w, 2)
    # against w*w), carried through a sum of a few terms: 2 measured (numpy 2.4.6)
    assert worst <= 4.0, worst
    assert all(observe._COLUMNS[cm][k] is not None for k, _ in observed)


def test_a_column_that_disagrees_falls_back_to_the_per_row_values(monkeypatch):
    res, _ = run_file(str(ROOT / "models/examples/stick_slip.py"))
    cm = res.model
    k, name = next((k, n) for k, n in enumerate(cm.var_names) if cm.y_column(n) is None
                   and np.ptp(observe.per_row(cm, res.p, res.t, res.y, res.yp,
                                              res.d)[:, k]) > 0)
    real = observe.generate_observe_rows

    def wrong(*a, **kw):
        fn = real(*a, **kw)

        def off(t, y, yp, p, d, o):
            fn(t, y, yp, p, d, o)
            o += 1.0          # what a wrong array printer would give
        return off
    # this test's own tables: the wrong function must not stay with the
    # (cached, shared) compiled model for the tests after it
    monkeypatch.setattr(observe, "_COLUMNS", weakref.WeakKeyDictionary())
    monkeypatch.setattr(observe, "_ROWS", weakref.WeakKeyDictionary())
    monkeypatch.setattr(observe, "generate_observe_rows", wrong)
    expect = observe.per_row(cm, res.p, res.t, res.y, res.yp, res.d)[:, k]
    got = res[name]
    assert np.array_equal(got, expect)
    assert observe._COLUMNS[cm][k] is None     # never tried again on this model
