"""Symbols shared by every stage: time, and the derivative operator.

A variable is a plain sympy ``Symbol`` named by its dotted path
(``hook.phi``). Its time derivative is the symbol ``der(hook.phi)``; higher
derivatives nest (``der(der(hook.phi))``). Keeping derivatives as symbols
(not sympy ``Derivative`` objects) makes differentiation of equations,
substitution and code generation cheap and explicit.
"""
import sympy as sp

from .fastdiff import diff

time = sp.Symbol("time", real=True)

_PREFIX = "der("


def der(x):
    """Time derivative of a variable symbol (or of an expression)."""
    if isinstance(x, sp.Symbol):
        if x == time:
            return sp.Integer(1)
        return sp.Symbol(f"{_PREFIX}{x.name})")
    expr = sp.sympify(x)
    return total_derivative(expr, lambda s: True)


def Eq(lhs, rhs=0, evaluate=False):
    """An equation ``lhs = rhs`` (a sympy ``Equality``), by default not
    evaluated. Evaluating one (deciding whether ``lhs - rhs`` is identically
    zero) queries sympy's assumptions on every sub-expression; it took 90 %
    of flattening a 100-mass chain, and the compiler never needs it: it
    takes ``lhs - rhs`` as the residual."""
    return sp.Eq(lhs, rhs, evaluate=evaluate)


def ordered(symbols):
    """Symbols sorted by name. Iterating a set of sympy symbols (``free_symbols``)
    follows their string hashes, which change with ``PYTHONHASHSEED``; every
    stage whose result depends on the order it meets symbols in iterates
    them through this, so that the compiled model is the same in every
    process."""
    return sorted(symbols, key=lambda s: s.name)


def is_der(sym):
    return sym.name.startswith(_PREFIX)


def integral(sym):
    """Inverse of :func:`der`: ``der(x)`` -> ``x``."""
    return sp.Symbol(sym.name[len(_PREFIX):-1])


def base_and_order(sym):
    """``der(der(x))`` -> (``x``, 2)."""
    k = 0
    while is_der(sym):
        sym = integral(sym)
        k += 1
    return sym, k


def total_derivative(expr, is_variable):
    """d/dt of ``expr``: the chain rule over every symbol for which
    ``is_variable(symbol)`` is true; other symbols (parameters, discrete
    values) are constant between events."""
    terms = [diff(expr, time)] if expr.has(time) else []
    terms += [diff(expr, s) * der(s) for s in ordered(expr.free_symbols)
              if s != time and is_variable(s)]
    return sp.Add(*terms)
