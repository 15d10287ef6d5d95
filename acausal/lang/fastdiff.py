"""Symbolic partial derivatives for the compiler's Jacobians.

``sympy.diff`` builds and evaluates a ``Derivative`` object for every node of
an expression, and each new node queries sympy's assumption system; on the
polynomial-like residuals of mechanisms that is most of the cost of a
Jacobian. :func:`diff` applies the sum, product and power rules directly to
``Add``, ``Mul``, ``Pow``, ``Piecewise`` (piece by piece) and functions
(chain rule with the function's own ``fdiff``, ``Max`` and ``Min``
included), skips sub-trees free of the variable, and hands every other node
to ``sympy.diff``, so the result is the same derivative.

Every variable of a model is real. ``Abs`` is therefore differentiated as
``sign(u) * du/dx``: sympy's own rule, for a symbol it does not know to be
real, writes ``re()`` and ``im()`` terms that no printer can generate (a
quadratic drag ``-c*v*Abs(v)`` at a planar loop's joint, whose velocity is an
expression of the loop's states, failed to compile that way). For the same
reason ``sign(u)`` differentiates to 0, its value everywhere but at u = 0
(sympy's ``2 DiracDelta(u) du/dx`` for a real ``u``, an unprintable
``Derivative`` otherwise): the sensitivity equations of that drag, whose
second derivatives hold it, could not be generated.
"""
import functools

import sympy as sp

MEMO_SIZE = 50_000   # derivatives remembered per process (least recently used dropped)


def diff(expr, x):
    """d expr / d x for a symbol ``x``; same value as ``sympy.diff``.
    Remembered per process: a diagnosis compiles dozens of models that
    share most of their equations, and so most of their Jacobians' entries
    (the same expression object for the same arguments)."""
    try:
        hash(expr)
    except TypeError:       # (a mutable matrix: not remembered)
        return _diff(expr, x)
    return _remembered(expr, x)


@functools.lru_cache(maxsize=MEMO_SIZE)
def _remembered(expr, x):
    return _diff(expr, x)


def _diff(expr, x):
    if expr == x:
        return sp.S.One
    if not expr.has(x):
        return sp.S.Zero
    if expr.is_Add:
        return sp.Add(*[_diff(a, x) for a in expr.args if a.has(x)])
    if expr.is_Mul:
        args = expr.args
        terms = []
        for k, a in enumerate(args):
            if a.has(x):
                terms.append(sp.Mul(*(args[:k] + args[k + 1:] + (_diff(a, x),))))
        return sp.Add(*terms)
    if expr.is_Pow and not expr.exp.has(x):
        base, p = expr.args
        return p * base ** (p - 1) * _diff(base, x)
    if isinstance(expr, sp.Piecewise) and not any(c.has(x) for _, c in expr.args):
        # the conditions are those of an evaluated Piecewise already: keep them
        pieces = [(_diff(e, x), c) for e, c in expr.args]
        if all(d == 0 for d, _ in pieces):
            return sp.S.Zero
        return sp.Piecewise(*pieces, evaluate=False)
    if isinstance(expr, sp.Abs):
        u = expr.args[0]
        return sp.sign(u) * _diff(u, x)
    if isinstance(expr, sp.sign):
        # zero wherever it has a value: its jump at u = 0 is an event's business
        return sp.S.Zero
    if (isinstance(expr, (sp.Max, sp.Min))
            or (isinstance(expr, sp.Function)
                and type(expr)._eval_derivative is sp.Function._eval_derivative)):
        # chain rule, as Function._eval_derivative (not for Abs & co., which
        # define their own derivative)
        try:
            return sp.Add(*[expr.fdiff(k + 1) * _diff(a, x)
                            for k, a in enumerate(expr.args) if a.has(x)])
        except sp.ArgumentIndexError:
            pass
    return sp.diff(expr, x)
