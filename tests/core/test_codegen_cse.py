"""The generated code's common sub-expressions: each name is defined before
any line uses it, even where the printer rebuilds a part (a product with
x**(-1/2) is printed as .../sqrt(x), and sqrt(x) may be a repeated
expression of its own, named later)."""
import math

import sympy as sp

from acausal.compiler.codegen import _cse_print


def test_a_rebuilt_part_never_refers_to_a_later_name():
    x, y = sp.symbols("x y", positive=True)
    e1 = y * x ** sp.Rational(-1, 2)               # printed as y/sqrt(x)
    exprs = [e1 + 1, e1 + 2, sp.sqrt(x) + 3, sp.sqrt(x) + 4]
    lines, printed = _cse_print(exprs, indent="")
    env = {"sqrt": math.sqrt, "x": 2.0, "y": 3.0}
    for line in lines:
        exec(line, env)                            # NameError if a name comes later
    got = [eval(p, env) for p in printed]
    want = [float(e.subs({x: 2.0, y: 3.0})) for e in exprs]
    assert max(abs(g - w) for g, w in zip(got, want)) < 1e-15
