"""The observed variables of many stored rows at once.

The per-row ``observe`` callback (:class:`~acausal.compiler.codegen.Callbacks`)
costs a Python call per row: 54 k rows/s on the breaker's 107 variables, so
a 10 M-row interrupted run took 84 s to write. Here the same expressions run
over all rows of one mode at once with numpy
(:func:`acausal.compiler.codegen.generate_observe_rows`), generated once per
compiled model on first use. The values equal the per-row ones bit for bit
in arithmetic; a transcendental function may differ in its last bit
(numpy's implementation against the C library's).
"""
import weakref

import numpy as np

from ..compiler.codegen import generate_observe_rows

VECTOR_ROWS = 1000   # fewer rows than this: the per-row callback (no generation)
_ROWS = weakref.WeakKeyDictionary()   # compiled model -> observe_rows (None: not vectorisable)
# owner (a compiled model) -> {key: _Column}: one expression vectorised (a variable
# by its index, a sensitivity by its own key: expression_column)
_COLUMNS = weakref.WeakKeyDictionary()


def _function(cm):
    fn = _ROWS.get(cm, False)
    if fn is False:
        try:
            a = cm.artefact
            fn = generate_observe_rows(a.observed_exprs(), a.dae.y, a.dae.yp,
                                       list(a.parameters.symbols), list(cm.disc_syms))
        except AttributeError:   # not a compiled model's artefact
            fn = None
        _ROWS[cm] = fn
    return fn


class _Column:
    """One observed variable's vectorised expression (``fn``: as
    :func:`generate_observe_rows`' function, filling one output row), and
    the modes (discrete values) where it was checked against the per-row
    callback."""

    __slots__ = ("fn", "checked")

    def __init__(self, fn):
        self.fn, self.checked = fn, set()


def _column_function(owner, key, build):
    table = _COLUMNS.setdefault(owner, {})
    col = table.get(key, False)
    if col is False:
        try:
            expr, y, yp, params, discretes = build()
            col = _Column(generate_observe_rows([expr], y, yp, list(params), list(discretes)))
        except AttributeError:   # not a compiled model's artefact
            col = None
        table[key] = col
    return col


def expression_column(owner, key, build, rows_of, per_row_value):
    """One expression's value at each row, over all rows of each mode at
    once (numpy); None when it cannot be vectorised. ``owner`` keeps the
    generated function (a weak key: a compiled model), ``key`` names the
    expression for it; ``build()`` gives (expression, y, yp, parameter
    symbols, discrete symbols) of the callbacks the rows came from, the
    first time only. ``rows_of`` = (p, t, y, yp, d); ``per_row_value(i)``
    is the per-row callback's value at row ``i``: the first row of each
    mode is checked against it once per owner and key (a guard against a
    function the array printer writes wrong: then None, always)."""
    col = _column_function(owner, key, build)
    if col is None:
        return None

    def agrees(mode, i, first):
        if mode in col.checked:
            return True
        ok = _agrees(first, np.array([per_row_value(i)], float))
        if ok:
            col.checked.add(mode)
        return ok
    out = _by_mode(col.fn, 1, rows_of, agrees)
    if out is None:
        _COLUMNS[owner][key] = None
        return None
    return out[0]


def observed_column(cm, k, p, t, y, yp, d):
    """Variable ``k`` (index in ``var_names``) at each row, its expression
    alone over all rows of each mode at once; None when it cannot be
    vectorised (then read it from :func:`observed_rows`). What a fit's
    residuals read: one or two measured variables of a short result, where
    every variable row by row cost a fifth of a diagnosis (an independent
    cam follower case, 2026-11-27: ``per_row`` 17 % of its samples). The
    first row of each mode is checked against the per-row callback once
    per model (:func:`expression_column`)."""
    def build():
        a = cm.artefact
        return (a.observed_expr(cm.var_names[k]), a.dae.y, a.dae.yp, a.parameters.symbols,
                cm.disc_syms)
    return expression_column(cm, k, build, (p, t, y, yp, d), lambda i: per_row(
        cm, p, t[i:i + 1], y[i:i + 1], yp[i:i + 1], d[i:i + 1])[0, k])


def per_row(cm, p, t, y, yp, d):
    """Every variable (``var_names``' order) at each row, by the per-row
    ``observe`` callback (one mode's callbacks per distinct row of ``d``)."""
    cache = {}
    out = np.empty((len(t), len(cm.var_names)))
    for k in range(len(t)):
        key = tuple(d[k]) if d.size else ()
        cb = cache.get(key)
        if cb is None:
            cb = cache[key] = cm.callbacks(p, list(key))
        out[k] = cb.observe(t[k], y[k], yp[k])
    return out


def _modes(d):
    """(mode's discrete values, its rows: a slice or an index array) of each
    distinct row of ``d``; rows keep their order (a mode holds runs of
    consecutive rows between events)."""
    if not d.size:
        return [((), slice(None))]
    same = (d[1:] == d[:-1]) | (np.isnan(d[1:]) & np.isnan(d[:-1]))
    starts = np.concatenate(([0], np.flatnonzero(~same.all(axis=1)) + 1))
    ends = np.append(starts[1:], len(d))
    runs = {}
    for k0, k1 in zip(starts.tolist(), ends.tolist()):
        runs.setdefault(tuple(d[k0].tolist()), []).append((k0, k1))
    out = []
    for key, spans in runs.items():
        rows = slice(*spans[0]) if len(spans) == 1 else \
            np.concatenate([np.arange(k0, k1) for k0, k1 in spans])
        out.append((key, rows))
    return out


def observed_rows(cm, p, t, y, yp, d):
    """As :func:`per_row`, over all rows of each mode at once when there are
    :data:`VECTOR_ROWS` rows or more and the model's observe is vectorised."""
    fn = _function(cm) if len(t) >= VECTOR_ROWS else None
    if fn is None:
        return per_row(cm, p, t, y, yp, d)
    out = _by_mode(fn, len(cm.var_names), (p, t, y, yp, d), lambda key, i, first: _agrees(
        first, per_row(cm, p, t[i:i + 1], y[i:i + 1], yp[i:i + 1], d[i:i + 1])[0]))
    if out is None:
        _ROWS[cm] = None   # a function the array code got wrong: never again
        return per_row(cm, p, t, y, yp, d)
    return out.T


def _by_mode(fn, n, rows_of, agrees):
    """(n x rows) of the vectorised ``fn`` (:func:`generate_observe_rows`)
    over all rows of each mode at once; ``rows_of`` = (p, t, y, yp, d);
    None as soon as ``agrees(mode, its first row's index, that row's
    values)`` is False (the guard against a wrong array function)."""
    p, t, y, yp, d = rows_of
    out = np.empty((n, len(t)))
    pv = [float(v) for v in p]
    with np.errstate(all="ignore"):
        for key, rows in _modes(d):
            o = out[:, rows] if isinstance(rows, slice) else np.empty((n, len(rows)))
            fn(t[rows], np.ascontiguousarray(y[rows].T), np.ascontiguousarray(yp[rows].T),
               pv, list(key), o)
            i = (rows.start or 0) if isinstance(rows, slice) else rows[0]
            if not agrees(key, i, o[:, 0]):
                return None
            if not isinstance(rows, slice):
                out[:, rows] = o
    return out


def _agrees(a, b):
    """Whether the vectorised row ``a`` is the per-row ``b`` (up to the last
    bits a transcendental function or a cancellation after it may change):
    a guard against a function the array printer writes wrong."""
    return bool(np.allclose(a, b, rtol=1e-9, atol=1e-300, equal_nan=True))
