"""Symbolic partial derivatives for the compiler's Jacobians.

``sympy.diff`` builds and evaluates a ``Derivative`` object for every node of
an expression, and each new node queries sympy's assumption system; on the
polynomial-like residuals of mechanisms that is most of the cost of a
Jacobian. :func:`diff` applies the sum, product and power rules directly to
``Add``, ``Mul`` and ``Pow`` nodes (and skips sub-trees free of the
variable), and hands every other node (functions, ``Piecewise``, ``Abs``...)
to ``sympy.diff``, so the result is the same derivative.
"""
import sympy as sp


def diff(expr, x):
    """d expr / d x for a symbol ``x``; same value as ``sympy.diff``."""
    if expr == x:
        return sp.S.One
    if not expr.has(x):
        return sp.S.Zero
    if expr.is_Add:
        return sp.Add(*[diff(a, x) for a in expr.args if a.has(x)])
    if expr.is_Mul:
        args = expr.args
        terms = []
        for k, a in enumerate(args):
            if a.has(x):
                terms.append(sp.Mul(*(args[:k] + args[k + 1:] + (diff(a, x),))))
        return sp.Add(*terms)
    if expr.is_Pow and not expr.exp.has(x):
        base, p = expr.args
        return p * base ** (p - 1) * diff(base, x)
    return sp.diff(expr, x)
