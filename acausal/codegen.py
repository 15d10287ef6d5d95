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
from dataclasses import dataclass

import numpy as np
import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

from .fastdiff import diff

_counter = [0]


class _Printer(PythonCodePrinter):
    def __init__(self):
        super().__init__({"fully_qualified_modules": False, "standard": "python3",
                          "order": "none"})

    def _print_Heaviside(self, expr):
        return f"heaviside({self._print(expr.args[0])})"


def _real(name):
    return sp.Symbol(name, real=True)


def _namespace():
    ns = {k: getattr(math, k) for k in dir(math) if not k.startswith("_")}
    ns.update(np=np, heaviside=lambda x: 1.0 if x > 0 else (0.5 if x == 0 else 0.0),
              Abs=abs, max=max, min=min)
    return ns


class Names:
    """Maps symbols to the names used in generated code. The new symbols are
    real (every quantity is): derivatives are then taken over real
    symbols, so that d|x|/dx is sign(x), not an expression of re(x), im(x)
    the printer cannot write."""

    def __init__(self, y, yp, params, discretes):
        self.map = {}
        for i, s in enumerate(y):
            self.map[s] = _real(f"y{i}")
        for i, s in enumerate(yp):
            if s is not None:
                self.map[s] = _real(f"yp{i}")
        for i, s in enumerate(params):
            self.map[s] = _real(f"p{i}")
        for i, s in enumerate(discretes):
            self.map[s] = _real(f"d{i}")
        from .symbols import time
        self.map[time] = _real("t")
        self.allowed = set(self.map.values())

    def rename(self, exprs, what):
        out = []
        for e in exprs:
            e = sp.sympify(e).xreplace(self.map)
            bad = [s for s in e.free_symbols if s not in self.allowed]
            if bad:
                raise ValueError(f"internal: {what} refers to {bad[0]} which is not "
                                 "a state, algebraic unknown, parameter or discrete value")
            out.append(e)
        return out


def _body(exprs, targets, indent="        "):
    """Lines computing ``targets[i] = exprs[i]`` with common sub-expressions."""
    reps, printed = _cse_print(exprs, indent)
    return reps + [f"{indent}{t} = {e}" for t, e in zip(targets, printed)]


def _cse_print(exprs, indent="        ", prefix="c_"):
    """(lines of the common sub-expressions, printed reduced expressions)."""
    printer = _Printer()
    reps, reduced = sp.cse(exprs, symbols=sp.numbered_symbols(prefix), order="none")
    lines = [f"{indent}{printer.doprint(v)} = {printer.doprint(e)}" for v, e in reps]
    return lines, [printer.doprint(e) for e in reduced]


def _unpack(prefix, n, src, indent="        ", array=True):
    if n == 0:
        return []
    names = ", ".join(f"{prefix}{i}" for i in range(n))
    return [f"{indent}{names}, = {src}{'.tolist()' if array else ''}"]


@dataclass
class Sparsity:
    """Structure of the iteration matrix ``J = dF/dy + cj dF/dy'``: its
    non-zero entries (``rows``, ``cols``, in compressed-sparse-column order,
    the order of the flat array a sparse solver fills) and its lower and
    upper bandwidths."""
    n: int
    rows: list
    cols: list
    lband: int
    uband: int

    @property
    def nnz(self):
        return len(self.rows)

    def matrix(self):
        """The pattern as a ``scipy.sparse.csc_matrix`` of ones."""
        import scipy.sparse as sps
        return sps.csc_matrix((np.ones(self.nnz), (self.rows, self.cols)),
                              shape=(self.n, self.n))


def _jacobian_entries(res, ysyms, ypsyms):
    """Non-zero entries (i, j, dF_i/dy_j, dF_i/dy'_j) of the residuals'
    Jacobians, by differentiating each residual only with respect to the
    unknowns it contains (work linear in the number of non-zeros)."""
    index = {s: ("y", j) for j, s in enumerate(ysyms)}
    index.update({s: ("yp", j) for j, s in enumerate(ypsyms) if s is not None})
    out = []
    for i, r in enumerate(res):
        cols = {}
        for s in r.free_symbols:
            hit = index.get(s)
            if hit is not None:
                cols.setdefault(hit[1], {})[hit[0]] = diff(r, s)
        for j in sorted(cols):
            dy = cols[j].get("y", sp.S.Zero)
            dyp = cols[j].get("yp", sp.S.Zero)
            if dy != 0 or dyp != 0:
                out.append((i, j, dy, dyp))
    return out


def _sparsity(n, entries):
    csc = sorted(((j, i) for i, j, _, _ in entries))
    rows = [i for _, i in csc]
    cols = [j for j, _ in csc]
    lband = max([i - j for i, j in zip(rows, cols)] + [0])
    uband = max([j - i for i, j in zip(rows, cols)] + [0])
    return Sparsity(n, rows, cols, lband, uband)


def _fixed_entries(obs, fixed_rows, ysyms, ypsyms, ns):
    """Non-zero entries (a, k, expr) of d(observed[fixed_rows[a]])/dz with
    z = (y, y' of the states): the rows initialisation adds for fixed starts."""
    zs = list(ysyms) + list(ypsyms[:ns])
    index = {s: k for k, s in enumerate(zs) if s is not None}
    out = []
    for a, k in enumerate(fixed_rows):
        e = obs[k]
        hits = sorted((index[s], s) for s in e.free_symbols if s in index)
        for col, s in hits:
            d = diff(e, s)
            if d != 0:
                out.append((a, col, d))
    return out


@dataclass
class Generated:
    """What :func:`generate` returns: the source, ``make(p, d)`` (the
    callbacks for one parameter vector and set of discrete values),
    ``fixjac(t, y, yp, p, d, F)`` (fills the fixed-start rows ``F``) and the
    iteration matrix's :class:`Sparsity`."""
    source: str
    make: object
    fixjac: object
    sparsity: Sparsity


def generate(dae, params, discretes, roots, observed, fixed_rows=()):
    """Generate and compile the callbacks (see :class:`Generated`).

    ``roots``: list of root expressions (resolved); ``observed``: list of
    expressions (resolved) for every reported variable; ``fixed_rows``:
    indices into ``observed`` of the variables with fixed start values.
    """
    n = len(dae.y)
    names = Names(dae.y, dae.yp, params, discretes)
    res = names.rename(dae.residuals, "a residual")
    g = names.rename(roots, "an event")
    obs = names.rename(observed, "an observed variable")
    ysyms = [_real(f"y{i}") for i in range(n)]
    ypsyms = [_real(f"yp{i}") if dae.yp[i] is not None else None for i in range(n)]
    cj = sp.Symbol("cj")
    entries = _jacobian_entries(res, ysyms, ypsyms)
    sparsity = _sparsity(n, entries)
    jy = [(i, j, dy) for i, j, dy, _ in entries if dy != 0]
    jyp = [(i, j, dyp) for i, j, _, dyp in entries if dyp != 0]
    jcomb = [(i, j, dy + cj * dyp) for i, j, dy, dyp in entries]
    csc_pos = {(i, j): k for k, (i, j) in enumerate(zip(sparsity.rows, sparsity.cols))}
    fixed = _fixed_entries(obs, fixed_rows, ysyms, ypsyms,
                           dae.n_states)
    npar, nd = len(params), len(discretes)
    unpack = _unpack("y", n, "y") + _unpack("yp", n, "yp")
    L = ["def make(p, d):"]
    L += _unpack("p", npar, "p", "    ", False) + _unpack("d", nd, "d", "    ", False)
    L += ["    count = [0, None]  # step attempts: distinct times the residual sees"]
    L += ["    def res(t, y, yp, r):"]
    L += ["        if t != count[1]:", "            count[0] += 1", "            count[1] = t"]
    L += unpack
    L += _body(res, [f"r[{i}]" for i in range(n)])
    reps, jprinted = _cse_print([e for _, _, e in jcomb])
    L += ["    def jac(t, y, yp, r, cj, J):"] + unpack + reps
    L += [f"        J[{i}, {j}] = {e}" for (i, j, _), e in zip(jcomb, jprinted)]
    L += ["        pass"]
    L += ["    def jac_csc(t, y, yp, r, cj, J):"] + unpack + reps
    L += [f"        J[{csc_pos[i, j]}] = {e}" for (i, j, _), e in zip(jcomb, jprinted)]
    L += ["        pass"]
    L += ["    def roots(t, y, yp, g):"] + unpack
    L += _body(g, [f"g[{i}]" for i in range(len(g))]) or ["        pass"]
    L += ["    def jacs(t, y, yp, Jy, Jyp):"] + unpack
    L += _body([e for _, _, e in jy] + [e for _, _, e in jyp],
               [f"Jy[{i}, {j}]" for i, j, _ in jy] + [f"Jyp[{i}, {j}]" for i, j, _ in jyp]) \
        or ["        pass"]
    L += ["    def observe(t, y, yp):"] + unpack
    L += ["        o = [0.0] * %d" % len(obs)]
    L += _body(obs, [f"o[{i}]" for i in range(len(obs))])
    L += ["        return o"]
    L += ["    return res, jac, roots, jacs, observe, count, jac_csc"]
    L += ["def fixjac(t, y, yp, p, d, F):"]
    L += _unpack("p", npar, "p", "    ", False) + _unpack("d", nd, "d", "    ", False)
    L += _unpack("y", n, "y", "    ", False) + _unpack("yp", n, "yp", "    ", False)
    L += _body([e for _, _, e in fixed], [f"F[{a}, {k}]" for a, k, _ in fixed], "    ")
    L += ["    pass"]
    src = "\n".join(L) + "\n"
    make, fixjac = load(src)
    return Generated(src, make, fixjac, sparsity)


def load(src):
    """Compile generated source; returns its (make, fixjac). Used again when
    a compiled model is read back from the cache."""
    _counter[0] += 1
    fname = f"<acausal-generated-{_counter[0]}>"
    linecache.cache[fname] = (len(src), None, src.splitlines(True), fname)
    ns = _namespace()
    exec(compile(src, fname, "exec"), ns)
    return ns["make"], ns["fixjac"]
