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
        worst = max(worst, float(h.column_ulps(rowwise[:, k], col)[1].max()))
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
