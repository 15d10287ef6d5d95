"""A linear spline on equally spaced knots as one expression node.

``HatSum(x, lo, hi, w_0, ..., w_{n-1})`` is

    sum_i w_i max(0, 1 - |x - c_i| / h),   c_i = lo + i h,  h = (hi - lo) / (n - 1)

(n >= 2): the piecewise-linear function through the values w_i at the knots,
falling to zero one spacing outside [lo, hi]. Written out as that sum (as the
diagnosis's generic located term was), an n-knot spline costs the generated
code n absolute values, maxima and divisions at every evaluation of the
residuals, and as many again in the Jacobian: on the geared drive's
65 + 9-knot term, half of every simulation's time. As one node it is
evaluated where it is not zero only: the interval ``k = floor((x - lo)/h)``
and the two hats on it, ``w_k (1 - t) + w_{k+1} t`` with ``t = (x - lo)/h - k``
(de Boor, *A Practical Guide to Splines*, 1978, ch. II: the broken line in
its B-spline form of order 2). The C code (``codegen_c``), the Python
callbacks and the vectorised observed columns (``codegen``) evaluate it with
:func:`hat_sum` / :func:`hat_slope`'s arithmetic, in the same order, so
they give the same values.

Derivatives (:meth:`HatSum.fdiff`): in ``x`` the spline's slope
:class:`HatSlope` (at a knot the mean of the two sides, as the sum's
``Heaviside(0) = 1/2`` and ``sign(0) = 0`` make it); in a weight ``w_i`` the
hat ``max(0, 1 - |x - c_i|/h)`` itself; in ``lo`` and ``hi`` those of the
written-out sum (:meth:`HatSum.expanded`). The slope's derivative in ``x``
is 0 (its value everywhere but at the knots, as ``sign``'s in
:mod:`.fastdiff`).
"""
from __future__ import annotations

import math

import numpy as np
import sympy as sp

from ..errors import ModelError

__all__ = ["HatSum", "HatSlope", "hat_sum", "hat_slope", "hat_sum_array", "hat_slope_array"]


def _cell(x, lo, hi, n):
    """(spacing h, knot k at or below ``x``, t = (x - x_k)/h in [0, 1)) for a
    number ``x``; None one spacing or more outside [lo, hi] and at a NaN
    (the scalar twin of :func:`_interval`: the same arithmetic)."""
    h = (hi - lo) / (n - 1)
    u = (x - lo) / h
    if not (-1.0 < u < n):
        return None
    k = math.floor(u)
    return h, k, u - k


def hat_sum(x, lo, hi, w):
    """The spline's value at a number ``x`` (``w`` the n weights); 0 one
    spacing or more outside [lo, hi], and at a NaN ``x`` (as
    ``max(0, NaN) = 0`` makes the written-out sum)."""
    n = len(w)
    cell = _cell(x, lo, hi, n)
    if cell is None:
        return 0.0
    _, k, t = cell
    a = w[k] if k >= 0 else 0.0
    b = w[k + 1] if k + 1 < n else 0.0
    return a * (1.0 - t) + b * t


def hat_slope(x, lo, hi, w):
    """d/dx of :func:`hat_sum` at a number ``x``; at a knot the mean of the
    slopes on its two sides."""
    n = len(w)
    cell = _cell(x, lo, hi, n)
    if cell is None:
        return 0.0
    h, k, t = cell
    b = w[k + 1] if k + 1 < n else 0.0
    if t == 0.0:
        c = w[k - 1] if k >= 1 else 0.0
        return (b - c) / (2.0 * h)
    a = w[k] if k >= 0 else 0.0
    return (b - a) / h


def _padded(w):
    """The weights with a zero on each side (index k + 1 for weight k)."""
    return np.concatenate([[0.0], np.asarray(w, dtype=float), [0.0]])


def _interval(x, lo, hi, n):
    """:func:`_cell` over an array: (h, inside, k, t), k and t 0 outside."""
    x = np.asarray(x, dtype=float)
    h = (hi - lo) / (n - 1)
    u = (x - lo) / h
    inside = (u > -1.0) & (u < n)
    k = np.where(inside, np.floor(np.where(inside, u, 0.0)), 0.0)
    return h, inside, k.astype(int), u - k


def _per_element(fn, x, lo, hi, w):
    """``fn`` element by element, for knots or weights that vary by row."""
    with np.errstate(invalid="ignore"):
        return np.vectorize(lambda *a: fn(a[0], a[1], a[2], a[3:]),
                            otypes=[float])(x, lo, hi, *w)


def _scalar(lo, hi, w):
    return not (np.ndim(lo) or np.ndim(hi) or any(np.ndim(v) for v in w))


def hat_sum_array(x, lo, hi, w):
    """:func:`hat_sum` over an array of ``x`` (same arithmetic: same values)."""
    if not _scalar(lo, hi, w):
        return _per_element(hat_sum, x, lo, hi, w)
    wp = _padded(w)
    with np.errstate(invalid="ignore"):     # rows outside (inf, NaN) are set to 0
        h, inside, k, t = _interval(x, lo, hi, len(w))
        val = wp[k + 1] * (1.0 - t) + wp[k + 2] * t
    return np.where(inside, val, 0.0)


def hat_slope_array(x, lo, hi, w):
    """:func:`hat_slope` over an array of ``x``."""
    if not _scalar(lo, hi, w):
        return _per_element(hat_slope, x, lo, hi, w)
    wp = _padded(w)
    with np.errstate(invalid="ignore"):
        h, inside, k, t = _interval(x, lo, hi, len(w))
        off = (wp[k + 2] - wp[k + 1]) / h
        at = (wp[k + 2] - wp[np.maximum(k, 0)]) / (2.0 * h)   # w_{k-1}: the pad's 0 for k < 1
    return np.where(inside, np.where(t == 0.0, at, off), 0.0)


def _parts(expr):
    x, lo, hi, *w = expr.args
    return x, lo, hi, w


def _hat(x, lo, hi, n, i):
    """The i-th hat, written out (the derivative in weight i)."""
    from .symbols import FastAbs, FastMax
    h = (hi - lo) / (n - 1)
    return FastMax(0, 1 - FastAbs(x - (lo + i * h)) / h)


class _SplineNode(sp.Function):
    """What :class:`HatSum` and :class:`HatSlope` share: the arguments
    (x, lo, hi, then at least 2 weights), real, and a number when every
    argument is one (``_value``: the numeric form)."""

    nargs = None
    is_real = True
    _value = None

    @classmethod
    def eval(cls, *args):
        if len(args) < 5:
            raise ModelError(f"{cls.__name__} needs x, lo, hi and at least 2 weights, got "
                             f"{len(args)} arguments")
        if all(a.is_number for a in args):
            x, lo, hi, *w = (float(a) for a in args)
            return sp.Float(cls._value(x, lo, hi, w))
        return None


class HatSum(_SplineNode):
    """``HatSum(x, lo, hi, w_0, ..., w_{n-1})``: the linear spline of the
    module doc (n >= 2 weights). A number when every argument is one."""

    _value = staticmethod(hat_sum)

    def expanded(self):
        """The written-out sum of hats (the same function)."""
        x, lo, hi, w = _parts(self)
        return sp.Add(*[wi * _hat(x, lo, hi, len(w), i) for i, wi in enumerate(w)])

    def fdiff(self, argindex=1):
        x, lo, hi, w = _parts(self)
        if argindex == 1:
            return HatSlope(*self.args)
        if argindex in (2, 3):
            from .fastdiff import diff
            return diff(self.expanded(), self.args[argindex - 1])
        return _hat(x, lo, hi, len(w), argindex - 4)


class HatSlope(_SplineNode):
    """``HatSlope(x, lo, hi, w_0, ...)``: d/dx of :class:`HatSum` with the
    same arguments (piecewise constant)."""

    _value = staticmethod(hat_slope)

    def fdiff(self, argindex=1):
        x, lo, hi, w = _parts(self)
        if argindex == 1:
            return sp.S.Zero
        from .fastdiff import diff
        if argindex in (2, 3):
            return diff(diff(HatSum(*self.args).expanded(), x), self.args[argindex - 1])
        return diff(_hat(x, lo, hi, len(w), argindex - 4), x)
