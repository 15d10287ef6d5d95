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


def _as_written(base):
    """The ``__new__`` of a subclass of sympy's ``base`` (``Max``, ``Min``)
    built as written: ``base`` itself (its number) when every argument is a
    number, otherwise the subclass's node without ``base``'s evaluation."""
    def __new__(cls, *args, **assumptions):
        args = [sp.sympify(a) for a in args]
        if all(a.is_number for a in args):
            return base(*args)
        assumptions["evaluate"] = False
        return base.__new__(cls, *args, **assumptions)
    return __new__


class FastMax(sp.Max):
    """``max(a, b, ...)`` as sympy's ``Max``, built without its symbolic
    reduction of the arguments (``Max(0, u)`` tries to prove ``u >= 0`` and
    to drop redundant arguments through sympy's assumptions: about 40 ms a
    node for a hat ``max(0, 1 - |x - c|/h)`` over a body's position, paid
    again each time an expression containing it is rebuilt: by
    ``xreplace``, by the code generator's renaming, by unpickling a cached
    compile). A 65 x 33-knot generic term at the cam follower took 11 s to
    build, nearly all of it in ``Max``. With numbers for every argument it
    is sympy's ``Max`` (a number); otherwise it stays as written. Printed,
    differentiated and evaluated as ``Max`` (a subclass: the printers and
    :func:`.fastdiff.diff` dispatch on it)."""

    __new__ = _as_written(sp.Max)


class FastAbs(sp.Abs):
    """``|u|`` as sympy's ``Abs``, built without its evaluation (which asks
    sympy's assumptions whether ``u`` is real, zero, of one sign: half of
    the remaining build of that generic term, :class:`FastMax`). With a
    number it is sympy's ``Abs``; otherwise it stays as written."""

    def __new__(cls, arg, **assumptions):
        arg = sp.sympify(arg)
        if arg.is_number:
            return sp.Abs(arg)
        assumptions["evaluate"] = False
        return sp.Abs.__new__(cls, arg, **assumptions)


class FastMin(sp.Min):
    """``min(a, b, ...)`` as sympy's ``Min``, built as written (see
    :class:`FastMax`): a clip ``Min(Max(u, -1), 1)`` of a loop's closing
    cosine cost a planar breaker's hypothesis model 1 s of its 2.3 s build,
    in sympy's ``Max``/``Min`` reduction at every ``xreplace``. With numbers
    for every argument it is sympy's ``Min`` (a number)."""

    __new__ = _as_written(sp.Min)


# sympy's code printers look ``Max``, ``Min`` and ``Abs`` up by the class's ``__name__``
# (Python's ``known_functions``, numpy's, C's ``fmax``, ``fabs``); pickling
# finds the classes by their ``__qualname__``, which stays FastMax, FastAbs, FastMin
FastMax.__name__ = "Max"
FastAbs.__name__ = "Abs"
FastMin.__name__ = "Min"


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


class KnownDerivatives(sp.Function):
    """``KnownDerivatives(x, dx, ddx, ...)`` is ``x`` whose time derivatives
    are given: d/dt of it is ``KnownDerivatives(dx, ddx, ...)`` (the index
    reduction does not differentiate ``x``), and with one argument left it
    is that argument. Modelica's ``derivative`` annotation, as MSL's Move
    uses it (position, velocity and acceleration as three inputs). Its
    value, and its partial derivatives (those of ``x``), are ``x``'s."""

    nargs = None

    @classmethod
    def eval(cls, *args):
        if len(args) == 1:
            return args[0]
        return None

    def fdiff(self, argindex=1):
        return sp.S.One if argindex == 1 else sp.S.Zero

    def shifted(self):
        """The time derivative: the same with the first argument dropped."""
        return KnownDerivatives(*self.args[1:])

    def _eval_derivative(self, s):
        return sp.diff(self.args[0], s)

    def _print_value(self, printer, *args, **kw):
        return printer._print(self.args[0])

    _ccode = _pythoncode = _lambdacode = _numpycode = _mpmathcode = _print_value


def total_derivative(expr, is_variable):
    """d/dt of ``expr``: the chain rule over every symbol for which
    ``is_variable(symbol)`` is true; other symbols (parameters, discrete
    values) are constant between events. A :class:`KnownDerivatives`
    contributes its given derivative."""
    known = {}
    if expr.has(KnownDerivatives):
        for k, node in enumerate(ordered_atoms(expr, KnownDerivatives)):
            known[sp.Dummy(f"known{k}")] = node
        expr = expr.xreplace({node: z for z, node in known.items()})
    terms = [diff(expr, time)] if expr.has(time) else []
    terms += [diff(expr, s) * der(s) for s in ordered(expr.free_symbols)
              if s != time and s not in known and is_variable(s)]
    terms += [diff(expr, z) * node.shifted() for z, node in known.items()]
    out = sp.Add(*terms)
    return out.xreplace(known) if known else out


def ordered_atoms(expr, kind):
    """The sub-expressions of type ``kind`` of ``expr``, in a fixed order."""
    return sorted(expr.atoms(kind), key=sp.srepr)
