"""Stage 5: generate Python source for the residual, its Jacobian, the root
functions and the observed variables, once per model structure.

The generated functions use plain Python arithmetic on float scalars (``y``
is unpacked with ``tolist()``), share sub-expressions through ``sympy.cse``
and fill the solver's arrays in place (``r[i] = ...``). Parameters and
discrete values are closure constants: ``make(p, d)`` builds the callbacks
for one parameter vector and one set of discrete values.
"""
import linecache
import math

import numpy as np
import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

_counter = [0]


class _Printer(PythonCodePrinter):
    def __init__(self):
        super().__init__({"fully_qualified_modules": False, "standard": "python3"})

    def _print_Heaviside(self, expr):
        return f"heaviside({self._print(expr.args[0])})"


def _namespace():
    ns = {k: getattr(math, k) for k in dir(math) if not k.startswith("_")}
    ns.update(np=np, heaviside=lambda x: 1.0 if x > 0 else (0.5 if x == 0 else 0.0),
              Abs=abs, max=max, min=min)
    return ns


class Names:
    """Maps symbols to the names used in generated code."""

    def __init__(self, y, yp, params, discretes):
        self.map = {}
        for i, s in enumerate(y):
            self.map[s] = sp.Symbol(f"y{i}")
        for i, s in enumerate(yp):
            if s is not None:
                self.map[s] = sp.Symbol(f"yp{i}")
        for i, s in enumerate(params):
            self.map[s] = sp.Symbol(f"p{i}")
        for i, s in enumerate(discretes):
            self.map[s] = sp.Symbol(f"d{i}")
        from .symbols import time
        self.map[time] = sp.Symbol("t")
        self.allowed = set(self.map.values())

    def rename(self, exprs, what):
        out = []
        for e in exprs:
            e = sp.sympify(e).xreplace(self.map)
            bad = [s for s in e.free_symbols if s not in self.allowed]
            if bad:
                raise ValueError(  # internal: CompiledModel.resolve checked user expressions
                    f"internal: {what} refers to {bad[0]} which is not "
                    "a state, algebraic unknown, parameter or discrete value")
            out.append(e)
        return out


def _body(exprs, targets, indent="        "):
    """Lines computing ``targets[i] = exprs[i]`` with common sub-expressions."""
    printer = _Printer()
    reps, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("c_"), order="none")
    lines = [f"{indent}{printer.doprint(v)} = {printer.doprint(e)}" for v, e in reps]
    lines += [f"{indent}{t} = {printer.doprint(e)}" for t, e in zip(targets, reduced)]
    return lines


def _unpack(prefix, n, src, indent="        ", array=True):
    if n == 0:
        return []
    names = ", ".join(f"{prefix}{i}" for i in range(n))
    return [f"{indent}{names}, = {src}{'.tolist()' if array else ''}"]


def generate(dae, params, discretes, roots, observed):
    """Return (source, namespace-populated functions).

    ``roots``: list of root expressions (resolved); ``observed``: list of
    expressions (resolved) for every reported variable.
    """
    n = len(dae.y)
    names = Names(dae.y, dae.yp, params, discretes)
    res = names.rename(dae.residuals, "a residual")
    g = names.rename(roots, "an event")
    obs = names.rename(observed, "an observed variable")
    # differentiate over real symbols (every quantity is real): d|x|/dx is
    # then sign(x), not an expression of re(x), im(x) the printer cannot write
    real = {s: sp.Symbol(s.name, real=True) for s in names.allowed}
    res = [r.xreplace(real) for r in res]
    ysyms = [real.get(sp.Symbol(f"y{i}"), sp.Symbol(f"y{i}")) for i in range(n)]
    ypsyms = [real.get(sp.Symbol(f"yp{i}"), sp.Symbol(f"yp{i}")) if dae.yp[i] is not None
              else None for i in range(n)]
    cj = sp.Symbol("cj")
    jy, jyp, jcomb = [], [], []
    for i, r in enumerate(res):
        fs = r.free_symbols
        for j in range(n):
            dy = sp.diff(r, ysyms[j]) if ysyms[j] in fs else sp.Integer(0)
            dyp = sp.diff(r, ypsyms[j]) if ypsyms[j] is not None and ypsyms[j] in fs \
                else sp.Integer(0)
            if dy != 0:
                jy.append((i, j, dy))
            if dyp != 0:
                jyp.append((i, j, dyp))
            if dy != 0 or dyp != 0:
                jcomb.append((i, j, dy + cj * dyp))
    npar, nd = len(params), len(discretes)
    L = ["def make(p, d):"]
    L += _unpack("p", npar, "p", "    ", False) + _unpack("d", nd, "d", "    ", False)
    L += ["    count = [0, None]  # step attempts: distinct times the residual sees"]
    L += ["    def res(t, y, yp, r):"]
    L += ["        if t != count[1]:", "            count[0] += 1", "            count[1] = t"]
    L += _unpack("y", n, "y") + _unpack("yp", n, "yp")
    L += _body(res, [f"r[{i}]" for i in range(n)])
    L += ["    def jac(t, y, yp, r, cj, J):"]
    L += _unpack("y", n, "y") + _unpack("yp", n, "yp")
    L += _body([e for _, _, e in jcomb], [f"J[{i}, {j}]" for i, j, _ in jcomb]) or ["        pass"]
    L += ["    def roots(t, y, yp, g):"]
    L += _unpack("y", n, "y") + _unpack("yp", n, "yp")
    L += _body(g, [f"g[{i}]" for i in range(len(g))]) or ["        pass"]
    L += ["    def jacs(t, y, yp, Jy, Jyp):"]
    L += _unpack("y", n, "y") + _unpack("yp", n, "yp")
    L += _body([e for _, _, e in jy] + [e for _, _, e in jyp],
               [f"Jy[{i}, {j}]" for i, j, _ in jy] + [f"Jyp[{i}, {j}]" for i, j, _ in jyp]) \
        or ["        pass"]
    L += ["    def observe(t, y, yp):"]
    L += _unpack("y", n, "y") + _unpack("yp", n, "yp")
    L += ["        o = [0.0] * %d" % len(obs)]
    L += _body(obs, [f"o[{i}]" for i in range(len(obs))])
    L += ["        return o"]
    L += ["    return res, jac, roots, jacs, observe, count"]
    src = "\n".join(L) + "\n"
    _counter[0] += 1
    fname = f"<acausal-generated-{_counter[0]}>"
    linecache.cache[fname] = (len(src), None, src.splitlines(True), fname)
    ns = _namespace()
    exec(compile(src, fname, "exec"), ns)
    return src, ns["make"]
