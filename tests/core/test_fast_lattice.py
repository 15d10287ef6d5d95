"""FastMax, FastMin and FastAbs (acausal.lang.symbols): sympy's Max and Abs built
without the symbolic reduction of their arguments. They must print,
differentiate, pickle and evaluate exactly as Max and Abs do, and a
number-only call must give the number. Compared against sympy's own
classes on the hat max(0, 1 - |x - c|/h) of the generic located term."""
import pickle

import numpy as np
import pytest
import sympy as sp
from sympy.printing.c import C99CodePrinter
from sympy.printing.pycode import PythonCodePrinter

from acausal.lang.fastdiff import diff
from acausal.lang.symbols import FastAbs, FastMax, FastMin

x, c, h = sp.symbols("body.s x_lo h")


def hat(mx, ab):
    return mx(0, 1 - ab(x - c) / h)


def test_numbers_evaluate_and_symbols_stay_as_written():
    assert FastMax(1, 3, 2) == 3 and FastAbs(-2.5) == 2.5
    assert isinstance(FastMax(1, 3), sp.Integer)
    e = hat(FastMax, FastAbs)
    assert isinstance(e, sp.Max) and type(e) is FastMax
    vals = {x: 0.31, c: 0.3, h: 0.05}
    for at in (0.31, 0.36, 0.2, 0.3, 0.35):
        vals[x] = at
        assert float(e.xreplace(vals)) == float(hat(sp.Max, sp.Abs).xreplace(vals))


def test_printers_and_lambdify_see_max_and_abs():
    e = hat(FastMax, FastAbs)
    ref = hat(sp.Max, sp.Abs)
    assert "max(" in PythonCodePrinter().doprint(e) and "abs(" in PythonCodePrinter().doprint(e)
    assert "fmax(" in C99CodePrinter().doprint(e) and "fabs(" in C99CodePrinter().doprint(e)
    f, g = sp.lambdify((x, c, h), e, "numpy"), sp.lambdify((x, c, h), ref, "numpy")
    xs = np.linspace(0.1, 0.5, 401)
    np.testing.assert_array_equal(f(xs, 0.3, 0.05), g(xs, 0.3, 0.05))


def test_derivative_equals_sympys():
    e, ref = hat(FastMax, FastAbs), hat(sp.Max, sp.Abs)
    d, dref = diff(e, x), diff(ref, x)
    for at in (0.26, 0.29, 0.31, 0.34, 0.4):
        vals = {x: at, c: 0.3, h: 0.05}
        assert float(d.xreplace(vals)) == pytest.approx(float(dref.xreplace(vals)), abs=1e-15)
    assert float(diff(e, x).xreplace({x: 0.29, c: 0.3, h: 0.05})) == pytest.approx(20.0)


def test_a_pickled_term_comes_back_equal_and_of_its_class():
    """Unpickling rebuilds every node by calling its class (a cached
    compile is such a pickle): the term comes back equal, still FastMax and
    FastAbs (not re-reduced by sympy's Max)."""
    terms = [sp.Symbol(f"w{i}") * FastMax(0, 1 - FastAbs(x - (c + i * h)) / h)
             for i in range(65)]
    back = pickle.loads(pickle.dumps(terms))
    assert back == terms
    assert {type(a) for b in back for a in sp.preorder_traversal(b)
            if isinstance(a, (sp.Max, sp.Abs))} == {FastMax, FastAbs}


def clip(mx, mn, u):
    return mn(mx(u, -1), 1)


def test_fast_min_is_min():
    """FastMin, as the loop's clipped cosine uses it: numbers evaluate, a
    symbolic clip stays as written, and values, C and Python printing and
    the derivative are sympy's Min's."""
    assert FastMin(1, 3, 2) == 1 and isinstance(FastMin(1, 3), sp.Integer)
    u = (x - c) / h
    e, ref = clip(FastMax, FastMin, u), clip(sp.Max, sp.Min, u)
    assert type(e) is FastMin and "fmin(" in C99CodePrinter().doprint(e)
    assert "min(" in PythonCodePrinter().doprint(e)
    f, g = sp.lambdify((x, c, h), e, "numpy"), sp.lambdify((x, c, h), ref, "numpy")
    xs = np.linspace(-0.2, 0.8, 401)
    np.testing.assert_array_equal(f(xs, 0.3, 0.05), g(xs, 0.3, 0.05))
    for at in (0.2, 0.29, 0.31, 0.4):
        vals = {x: at, c: 0.3, h: 0.05}
        assert float(diff(e, x).xreplace(vals)) == pytest.approx(
            float(diff(ref, x).xreplace(vals)), abs=1e-12)
    back = pickle.loads(pickle.dumps(e))
    assert back == e and type(back) is FastMin
