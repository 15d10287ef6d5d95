"""Stage 5: generate Python source for the residual, its Jacobian, the root
functions and the observed variables, once per model structure.

The generated functions use plain Python arithmetic on float scalars (``y``
is unpacked with ``tolist()``), share sub-expressions through ``sympy.cse``
and fill the solver's arrays in place (``r[i] = ...``). Parameters and
discrete values are closure constants: ``make(p, d)`` builds the
:class:`Callbacks` for one parameter vector and one set of discrete values.
:func:`root_gradients` generates the root functions' derivatives that the
event-time sensitivities need (:mod:`acausal.runtime.sensitivity`).
"""
import functools
import linecache
import math
import os
import threading
import weakref
from dataclasses import dataclass
from typing import Callable, NamedTuple, Optional

import numpy as np
import sympy as sp
from sympy.printing.pycode import PythonCodePrinter

from ..lang.fastdiff import diff
from ..lang.splines import hat_slope, hat_slope_array, hat_sum, hat_sum_array
from .substitute import Substitution, substitute

_counter = [0]


class NamedTemps:
    """Printer mixin (for the Python and the C printer alike): every
    sub-expression that has a name in ``temps`` (common sub-expressions, see
    :func:`_cse_print`) is written as that name, without rebuilding any
    expression; :meth:`definition` writes a named expression itself."""

    def _setup_temps(self, temps):
        self.temps = temps or {}
        self._root = None
        self._trace = None       # (node, its name or None) of every lookup, when traced
        self._not_supported, self._number_symbols = set(), set()

    def _print(self, expr, **kw):
        if expr is not self._root:
            name = self.temps.get(expr) if self.temps else None
            if self._trace is not None:
                self._trace.append((expr, name))
            if name is not None:
                return name
        self._root = None
        return super()._print(expr, **kw)

    def traced_definition(self, expr):
        """(:meth:`definition` of ``expr``, the lookups it made: every node
        the printer asked ``temps`` about and the answer). The text is a
        function of ``expr`` and those answers alone, so it can be reused
        wherever ``temps`` gives the same answers (:class:`PrintMemo`)."""
        self._trace = []
        try:
            text = self.definition(expr)
            return text, tuple(self._trace)
        finally:
            self._trace = None

    def definition(self, expr):
        """Code of ``expr`` itself (not its own name), its parts by name
        (``doprint`` without its walk of the whole tree for
        ``UnevaluatedExpr``, which the compiler never creates)."""
        self._root = expr
        return self._print(expr)


class PrintMemo:
    """Printed definitions remembered across the models of a process: under
    each expression, up to :attr:`VARIANTS` (text, lookups) pairs
    (:meth:`NamedTemps.traced_definition`); a text is reused when the
    printer's ``temps`` give the same answers to the same lookups, which is
    exactly when printing again would write it. The models of one diagnosis
    share most expressions and most of their common sub-expressions' names
    (85 % of the planar breaker's printed C over twelve candidates)."""

    SIZE = 40_000
    VARIANTS = 4

    def __init__(self):
        self._memo = {}          # (insertion order: the oldest first)
        self._lock = threading.Lock()
        # a lock copied by fork while another thread held it would stay locked
        me = weakref.ref(self)
        os.register_at_fork(after_in_child=lambda: me() and me()._new_lock())

    def _new_lock(self):
        self._lock = threading.Lock()

    def definition(self, printer, expr):
        """``printer.definition(expr)``, remembered (``printer`` a
        :class:`NamedTemps` printer of one kind and settings per memo)."""
        temps = printer.temps
        variants = self._memo.get(expr)
        if variants is not None:
            for text, trace in variants:
                if all(temps.get(e) == n for e, n in trace):
                    return text
        text, trace = printer.traced_definition(expr)
        with self._lock:
            if variants is None:
                if len(self._memo) >= self.SIZE:     # the oldest half dropped
                    for k in list(self._memo)[:self.SIZE // 2]:
                        del self._memo[k]
                variants = self._memo.setdefault(expr, [])
            variants.insert(0, (text, trace))
            del variants[self.VARIANTS:]
        return text


class _Printer(NamedTemps, PythonCodePrinter):
    """Python code of sympy expressions, common sub-expressions by name
    (:class:`NamedTemps`)."""

    def __init__(self, temps=None, symbols=None):
        super().__init__({"fully_qualified_modules": False, "standard": "python3",
                          "order": "none"})
        self._setup_temps(temps)
        self.symbols = symbols or {}

    def code(self, expr):
        """Code of ``expr`` (``doprint`` without its walk of the whole tree
        for ``UnevaluatedExpr``, which the compiler never creates)."""
        return self._print(expr)

    def _print_Symbol(self, expr):
        name = self.symbols.get(expr)
        return name if name is not None else super()._print_Symbol(expr)

    def _print_Heaviside(self, expr):
        return f"heaviside({self._print(expr.args[0])})"

    def _print_HatSum(self, expr):    # lang.splines: the namespace's hat_sum(_array)
        return self._spline("_hatsum", expr)

    def _print_HatSlope(self, expr):
        return self._spline("_hatslope", expr)

    def _spline(self, name, expr):
        x, lo, hi, *w = (self._print(a) for a in expr.args)
        return f"{name}({x}, {lo}, {hi}, ({', '.join(w)},))"

    def _print_Pow(self, expr, rational=False):
        """A non-integer power other than a square root as ``pow(b, e)``:
        Python's ``**`` of a negative float makes a complex number without
        a word, ``pow`` (``math.pow``) raises, and the IEEE variant
        (:func:`load`) gives NaN as C does."""
        b, e = expr.args
        if e.is_Integer or e in (sp.S.Half, -sp.S.Half) or not e.is_number:
            return super()._print_Pow(expr, rational=rational)
        return f"pow({self._print(b)}, {self._print(e)})"


def _real(name):
    return sp.Symbol(name, real=True)


def _namespace():
    ns = {k: getattr(math, k) for k in dir(math) if not k.startswith("_")}
    ns.update(np=np, heaviside=lambda x: 1.0 if x > 0 else (0.5 if x == 0 else 0.0),
              Abs=abs, max=max, min=min, _hatsum=hat_sum, _hatslope=hat_slope)
    return ns


# Guarded domains (IEEE semantics). Common sub-expressions are computed before
# the conditions that guard them: ``Piecewise((sqrt(x), x > 0), (0, True))``
# with ``sqrt(x)`` shared evaluates ``sqrt(x)`` for every x. C gives NaN there
# and the branch that is not taken drops it; Python's math raises. So each
# generated callback runs on Python floats and, when that raises one of
# _IEEE_ERRORS, is evaluated again by the same source on numpy float64 (NaN
# and inf as in C, warnings off): the backends agree and the fast path stays.
_IEEE_ERRORS = (ValueError, ZeroDivisionError, OverflowError)
_NUMPY_NAMES = {"asin": "arcsin", "acos": "arccos", "atan": "arctan", "atan2": "arctan2",
                "asinh": "arcsinh", "acosh": "arccosh", "atanh": "arctanh", "pow": "power"}


def _fast_namespace():
    ns = _namespace()
    ns.update(_floats=lambda a: a.tolist(), _consts=lambda a: a, _ieee_errors=_IEEE_ERRORS,
              _quiet=lambda: np.errstate(all="ignore"))
    return ns


def _ieee_namespace():
    ns = _namespace()
    for k in dir(math):
        f = getattr(np, _NUMPY_NAMES.get(k, k), None)
        if isinstance(f, np.ufunc):
            ns[k] = f
    ns.update(_floats=lambda a: np.asarray(a, dtype=float), _ieee_errors=(),
              _consts=lambda a: np.asarray(a, dtype=float), _quiet=None)
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
        from ..lang.symbols import time
        self.map[time] = _real("t")
        self.allowed = set(self.map.values())
        self.code = {s: v.name for s, v in self.map.items()}
        self._sub = Substitution(self.map)

    def check(self, exprs, what):
        """``exprs`` as sympy expressions, checked to use only the DAE's
        symbols (printed with :attr:`code`, not renamed: no rebuilding)."""
        return [_known(sp.sympify(e), self.map, what) for e in exprs]

    def rename(self, exprs, what):
        """``exprs`` with the DAE's symbols replaced by the generated names
        (:func:`~acausal.compiler.substitute.substitute`: remembered across
        the models of a process)."""
        memo = {}
        return [_known(substitute(sp.sympify(e), self._sub, memo), self.allowed, what)
                for e in exprs]


def _known(e, symbols, what):
    """``e``, checked to contain only ``symbols``."""
    bad = [s for s in e.free_symbols if s not in symbols]
    if bad:
        raise ValueError(  # internal: CompiledModel.resolve checked user expressions
            f"internal: {what} refers to {bad[0]} which is not "
            "a state, algebraic unknown, parameter or discrete value")
    return e


def _body(exprs, targets, indent="        ", symbols=None):
    """Lines computing ``targets[i] = exprs[i]`` with common sub-expressions."""
    reps, printed = _cse_print(exprs, indent, symbols=symbols)
    return reps + [f"{indent}{t} = {e}" for t, e in zip(targets, printed)]


def _cse_print(exprs, indent="        ", prefix="c_", symbols=None):
    """(lines of the common sub-expressions, printed expressions).

    Common sub-expression elimination by hash-consing (as sympy's
    ``tree_cse``, without its rebuilding of every expression and its search
    for common sub-sums and sub-products, which dominated compile time on
    large models): every non-atomic sub-expression met twice gets a name,
    defined after the names it uses; work linear in the size of the
    expressions."""
    repeated = repeated_subexpressions(exprs)
    names = {e: f"{prefix}{k}" for k, e in enumerate(repeated)}
    # a definition may only use the names defined before it: the printer
    # rebuilds some parts (x**(-1/2) in a product is printed as 1/sqrt(x)),
    # and such a rebuilt part may be a repeated expression defined later
    printer = _Printer({}, symbols)
    lines = []
    for e in repeated:
        lines.append(f"{indent}{names[e]} = {printer.definition(e)}")
        printer.temps[e] = names[e]
    return lines, [printer.code(e) for e in exprs]


def _shareable(e):
    return isinstance(e, sp.Expr) and not e.is_Atom and bool(e.args)


def repeated_subexpressions(exprs):
    """Sub-expressions met more than once, each after the ones inside it."""
    seen, repeated = set(), set()

    def visit(e):
        if not isinstance(e, sp.Basic) or e.is_Atom:
            return
        if e in seen:
            if _shareable(e):
                repeated.add(e)
            return
        seen.add(e)
        for a in e.args:
            visit(a)
    for e in exprs:
        visit(e)
    order, done = [], set()

    def post(e):
        if not isinstance(e, sp.Basic) or e.is_Atom or e in done:
            return
        done.add(e)
        for a in e.args:
            post(a)
        if e in repeated:
            order.append(e)
    for e in exprs:
        post(e)
    return order


def _unpack(prefix, n, src, indent="        ", array=True, conv=None):
    if n == 0:
        return []
    names = ", ".join(f"{prefix}{i}" for i in range(n))
    if conv:
        return [f"{indent}{names}, = {conv}({src})"]
    return [f"{indent}{names}, = {src}{'.tolist()' if array else ''}"]


_B = " " * 12      # the body of a guarded callback (inside its ``try``)


def _guarded(header, pre, body, fallback, ret=False):
    """A generated callback: ``header``, the lines ``pre``, then ``body``
    (at :data:`_B`) inside ``try``; on one of the guarded-domain errors the
    same callback of the IEEE variant (``fallback``, its call text) runs
    instead (see :data:`_IEEE_ERRORS`)."""
    call = f"{'return ' if ret else ''}{fallback}"
    return ([header] + pre + ["        try:"] + (body or [_B + "pass"])
            + ["        except _ieee_errors:", "            with _quiet():",
               f"                {call}"])


class Triplets:
    """Storage the generated Jacobian code can fill instead of a 2-D array
    (it only assigns ``J[i, j] = v``): collects the entries and gives the
    ``scipy.sparse`` CSR matrix of ``shape``. The initialisation of a large
    model uses it, so that no dense matrix is formed."""

    def __init__(self, shape):
        self.shape = shape
        self.rows, self.cols, self.vals = [], [], []

    def __setitem__(self, ij, value):
        self.rows.append(ij[0])
        self.cols.append(ij[1])
        self.vals.append(value)

    def tocsr(self):
        import scipy.sparse as sps
        return sps.csr_matrix((np.asarray(self.vals, float), (self.rows, self.cols)),
                              shape=self.shape)


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


def jacobian_entries(res, ysyms, ypsyms, columns=None):
    """Non-zero entries (i, j, dF_i/dy_j, dF_i/dy'_j) of the residuals'
    Jacobians, by differentiating each residual only with respect to the
    unknowns it contains (work linear in the number of non-zeros), and,
    with ``columns`` (:attr:`acausal.causalize.DAE.jacobian_columns`), only
    over the slots ``columns[i]`` of row ``i``. The last few are kept: the C
    generator (:mod:`acausal.codegen_c`) asks again for the same residuals
    right after this module."""
    return list(_entries(tuple(res), tuple(ysyms), tuple(ypsyms), columns))


@functools.lru_cache(maxsize=4)
def _entries(res, ysyms, ypsyms, columns):
    index = {s: ("y", j) for j, s in enumerate(ysyms)}
    index.update({s: ("yp", j) for j, s in enumerate(ypsyms) if s is not None})
    out = []
    for i, r in enumerate(res):
        cols = {}
        for s in r.free_symbols:
            hit = index.get(s)
            if hit is not None and (columns is None or hit[1] in columns[i]):
                cols.setdefault(hit[1], {})[hit[0]] = diff(r, s)
        for j in sorted(cols):
            dy = cols[j].get("y", sp.S.Zero)
            dyp = cols[j].get("yp", sp.S.Zero)
            if dy != 0 or dyp != 0:
                out.append((i, j, dy, dyp))
    return tuple(out)


def _sparsity(n, entries):
    csc = sorted(((j, i) for i, j, _, _ in entries))
    rows = [i for _, i in csc]
    cols = [j for j, _ in csc]
    lband = max([i - j for i, j in zip(rows, cols)] + [0])
    uband = max([j - i for i, j in zip(rows, cols)] + [0])
    return Sparsity(n, rows, cols, lband, uband)


def fixed_entries(obs, fixed_rows, ysyms, ypsyms, ns):
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


class Callbacks(NamedTuple):
    """The generated callbacks of one mode (one parameter vector and one set
    of discrete values), by name; a tuple in this order, so that the storage
    a linear solver fills is chosen by position
    (:attr:`acausal.runtime.backends.LinearSolver.jac_index`).

    ``res(t, y, yp, r)`` fills the residual; ``jac(t, y, yp, r, cj, J)`` the
    iteration matrix ``dF/dy + cj dF/dy'`` into a 2-D (dense or band) array;
    ``roots(t, y, yp, g)`` the root functions (events, then assertions);
    ``jacs(t, y, yp, Jy, Jyp)`` ``dF/dy`` and ``dF/dy'`` apart;
    ``observe(t, y, yp)`` returns every variable's value; ``count`` is
    ``[step attempts, last time]`` (the distinct times the residual saw);
    ``jac_csc`` fills the iteration matrix's compressed-sparse-column array.
    A backend may add its own implementations of the runtime's algorithms
    on this mode (``reinit``, ``init_newton``, ``init_check``: the compiled
    backend's C; None where the runtime's Python runs)."""
    res: Callable
    jac: Callable
    roots: Callable
    jacs: Callable
    observe: Callable
    count: list
    jac_csc: Callable
    reinit: Optional[Callable] = None
    init_newton: Optional[Callable] = None
    init_check: Optional[Callable] = None


class Generated:
    """The generated Python callbacks of one model: ``source``, ``make(p,
    d)`` (the :class:`Callbacks` for one parameter vector and set of
    discrete values), ``fixjac(t, y, yp, p, d, F)`` (fills the fixed-start
    rows ``F``) and the iteration matrix's :class:`Sparsity`.

    The source has two parts, the callbacks (``make``) and ``fixjac``. The
    sparsity is known at once; the source is given whole (``source``) or
    each part is written by its writer (``writers``: name -> function of no
    argument giving the part's text) at its first use, and compiled then. A
    model that the compiled backend runs needs only ``fixjac`` (the
    initialisation's choice of guesses; every other callback is C,
    :mod:`acausal.runtime.backends.compiled`): writing the whole Python took
    a fifth of a diagnosis candidate's build. ``on_write(source)`` is told
    of a whole source assembled here (the compile store keeps it)."""

    PARTS = ("make", "fixjac")

    def __init__(self, sparsity, source=None, writers=None, on_write=None):
        if source is None and writers is None:
            raise ValueError("Generated needs a source or its writers")  # internal
        self.sparsity = sparsity
        self._parts = dict(zip(self.PARTS, _split(source))) if source is not None else {}
        self._source, self._writers, self._on_write = source, writers, on_write
        self._functions = {}
        self._lock = threading.RLock()

    def _part(self, name):
        with self._lock:
            if name not in self._parts:
                self._parts[name] = self._writers[name]()
                if len(self._parts) == len(self.PARTS):
                    self._assemble()     # the whole is written: kept
            return self._parts[name]

    def _assemble(self):
        if self._source is None:
            self._source = "".join(self._parts[k] for k in self.PARTS)
            if self._on_write is not None:
                self._on_write(self._source)

    @property
    def source(self):
        """The generated Python source (its parts written now if they were not)."""
        with self._lock:
            for k in self.PARTS:
                self._part(k)
            self._assemble()
            return self._source

    def _function(self, name):
        with self._lock:
            if name not in self._functions:
                self._functions[name] = _exec_part(self._part(name), name)
            return self._functions[name]

    @property
    def make(self):
        """``make(p, d)``: the :class:`Callbacks` of one mode."""
        made = self._function("make")
        return lambda p, d: Callbacks(*made(p, d))

    @property
    def fixjac(self):
        """``fixjac(t, y, yp, p, d, F)``: fills the fixed-start rows ``F``."""
        return self._function("fixjac")


_FIXJAC_HEADER = "def fixjac(t, y, yp, p, d, F):"


def _split(source):
    """(the callbacks' part, fixjac's part) of a whole generated source."""
    k = source.index(_FIXJAC_HEADER)
    return source[:k], source[k:]


def _make_prologue(npar, nd):
    """The first lines of the generated ``make(p, d)``: the parameters and
    discrete values unpacked, the step-attempt counter, and ``other(k)``,
    the IEEE variant's callback k (:data:`_IEEE_ERRORS`), made at its first
    use."""
    return (["def make(p, d):"]
            + _unpack("p", npar, "p", "    ", conv="_consts")
            + _unpack("d", nd, "d", "    ", conv="_consts")
            + ["    count = [0, None]  # step attempts: distinct times the residual sees",
               "    ieee = []",
               "    def other(k):  # the IEEE variant's callback k (made at its first use)",
               "        if not ieee:",
               "            ieee.append(_make_ieee(p, d))",
               "        return ieee[0][k]"])


def _unknown_symbols(dae):
    """(y symbols, y' symbols or None) of the generated code."""
    n = len(dae.y)
    return ([_real(f"y{i}") for i in range(n)],
            [_real(f"yp{i}") if dae.yp[i] is not None else None for i in range(n)])


def iteration_sparsity(dae, params, discretes):
    """The :class:`Sparsity` of ``dae``'s iteration matrix: the entries the
    generated Jacobian fills (:func:`jacobian_entries`, kept for the code
    generators that ask for the same residuals next)."""
    res = Names(dae.y, dae.yp, params, discretes).rename(dae.residuals, "a residual")
    ysyms, ypsyms = _unknown_symbols(dae)
    return _sparsity(len(dae.y), jacobian_entries(res, ysyms, ypsyms, dae.jacobian_columns))


def generate(dae, params, discretes, roots, observed, fixed_rows=()):
    """The callbacks (see :class:`Generated`); the source is written at its
    first use (:func:`write_callbacks`, :func:`write_fixjac`), the sparsity now.

    ``roots``: list of root expressions (resolved); ``observed``: list of
    expressions (resolved) for every reported variable; ``fixed_rows``:
    indices into ``observed`` of the variables with fixed start values.
    """
    return Generated(iteration_sparsity(dae, params, discretes), writers=dict(
        make=functools.partial(write_callbacks, dae, params, discretes, roots, observed),
        fixjac=functools.partial(write_fixjac, dae, params, discretes,
                                 [observed[k] for k in fixed_rows])))


def write_callbacks(dae, params, discretes, roots, observed):
    """The Python source of ``make(p, d)`` (arguments as :func:`generate`)."""
    n = len(dae.y)
    names = Names(dae.y, dae.yp, params, discretes)
    res = names.rename(dae.residuals, "a residual")
    g = names.check(roots, "an event")
    obs = names.check(observed, "an observed variable")
    ysyms, ypsyms = _unknown_symbols(dae)
    cj = sp.Symbol("cj")
    entries = jacobian_entries(res, ysyms, ypsyms, dae.jacobian_columns)
    sparsity = _sparsity(n, entries)
    jy = [(i, j, dy) for i, j, dy, _ in entries if dy != 0]
    jyp = [(i, j, dyp) for i, j, _, dyp in entries if dyp != 0]
    jcomb = [(i, j, dy + cj * dyp) for i, j, dy, dyp in entries]
    csc_pos = {(i, j): k for k, (i, j) in enumerate(zip(sparsity.rows, sparsity.cols))}
    npar, nd = len(params), len(discretes)
    unpack = _unpack("y", n, "y", _B, conv="_floats") + _unpack("yp", n, "yp", _B, conv="_floats")
    L = _make_prologue(npar, nd)
    L += _guarded("    def res(t, y, yp, r):",
                  ["        if t != count[1]:", "            count[0] += 1",
                   "            count[1] = t"],
                  unpack + _body(res, [f"r[{i}]" for i in range(n)], _B),
                  "other(0)(t, y, yp, r)")
    reps, jprinted = _cse_print([e for _, _, e in jcomb], _B)
    L += _guarded("    def jac(t, y, yp, r, cj, J):", [], unpack + reps + [
        f"{_B}J[{i}, {j}] = {e}" for (i, j, _), e in zip(jcomb, jprinted)],
        "other(1)(t, y, yp, r, cj, J)")
    L += _guarded("    def jac_csc(t, y, yp, r, cj, J):", [], unpack + reps + [
        f"{_B}J[{csc_pos[i, j]}] = {e}" for (i, j, _), e in zip(jcomb, jprinted)],
        "other(6)(t, y, yp, r, cj, J)")
    L += _guarded("    def roots(t, y, yp, g):", [], unpack + _body(
        g, [f"g[{i}]" for i in range(len(g))], _B, symbols=names.code),
        "other(2)(t, y, yp, g)")
    L += _guarded("    def jacs(t, y, yp, Jy, Jyp):", [], unpack + _body(
        [e for _, _, e in jy] + [e for _, _, e in jyp],
        [f"Jy[{i}, {j}]" for i, j, _ in jy] + [f"Jyp[{i}, {j}]" for i, j, _ in jyp], _B),
        "other(3)(t, y, yp, Jy, Jyp)")
    L += _guarded("    def observe(t, y, yp):", [], unpack + [
        f"{_B}o = [0.0] * {len(obs)}"] + _body(
        obs, [f"o[{i}]" for i in range(len(obs))], _B, symbols=names.code) + [
        f"{_B}return o"], "other(4)(t, y, yp)", ret=True)
    L += ["    return res, jac, roots, jacs, observe, count, jac_csc"]
    return "\n".join(L) + "\n"


def write_fixjac(dae, params, discretes, fixed_observed):
    """The Python source of ``fixjac(t, y, yp, p, d, F)``: the derivatives of
    ``fixed_observed`` (the resolved expressions of the variables with fixed
    start values, in order) over z = (y, y' of the states)."""
    n = len(dae.y)
    names = Names(dae.y, dae.yp, params, discretes)
    ysyms, ypsyms = _unknown_symbols(dae)
    renamed = names.rename(names.check(fixed_observed, "an observed variable"),
                           "a fixed start")
    rows = list(range(len(renamed)))
    fixed = fixed_entries(dict(zip(rows, renamed)), rows, ysyms, ypsyms, dae.n_states)
    npar, nd = len(params), len(discretes)
    L = _guarded(_FIXJAC_HEADER, [], [
        line for v, m in (("p", npar), ("d", nd), ("y", n), ("yp", n))
        for line in _unpack(v, m, v, _B, conv="_consts")]
        + _body([e for _, _, e in fixed], [f"F[{a}, {k}]" for a, k, _ in fixed], _B),
        "_fixjac_ieee(t, y, yp, p, d, F)")
    return "\n".join(L) + "\n"


def load(src):
    """Compile a whole generated source; returns its (make, fixjac),
    ``make(p, d)`` giving :class:`Callbacks`."""
    g = Generated(None, source=src)
    return g.make, g.fixjac


def _exec_part(src, name):
    """The function ``name`` of generated source ``src``, compiled, with the
    IEEE variant it falls back on (:data:`_IEEE_ERRORS`)."""
    _counter[0] += 1
    fname = f"<acausal-generated-{_counter[0]}>"
    linecache.cache[fname] = (len(src), None, src.splitlines(True), fname)
    ns, ieee = exec_twins(compile(src, fname, "exec"))
    ns[f"_{name}_ieee"] = ieee[name]
    return ns[name]


def exec_twins(code):
    """(fast namespace, IEEE namespace) after running compiled generated
    ``code`` in each (:data:`_IEEE_ERRORS`): the same functions on Python
    floats and on numpy float64."""
    ns, ieee = _fast_namespace(), _ieee_namespace()
    exec(code, ns)
    exec(code, ieee)
    return ns, ieee


def root_gradients(dae, params, discretes, roots, wrt, dyn):
    """A function ``(t, y, yp, p, d)`` -> (G_y, G_y', G_t, G_p, G_d), the
    derivatives of the (resolved) root functions ``roots`` as dense arrays
    (rows = roots) with respect to the DAE's unknowns and derivatives, time,
    the parameters ``wrt`` (symbols among ``params``) and the discrete values
    of indices ``dyn``; generated as the other callbacks, with the same
    guarded-domain fallback (:data:`_IEEE_ERRORS`)."""
    n, nr, m = len(dae.y), len(roots), len(wrt)
    names = Names(dae.y, dae.yp, params, discretes)
    from ..lang.symbols import time
    cols = [("Gy", k, s) for k, s in enumerate(dae.y)]
    cols += [("Gyp", k, s) for k, s in enumerate(dae.yp) if s is not None]
    exprs, targets = [], []
    for i, g in enumerate(roots):
        fs = g.free_symbols
        for arr, k, s in cols + [("Gp", j, x) for j, x in enumerate(wrt)] + \
                [("Gd", q, discretes[x]) for q, x in enumerate(dyn)]:
            if s in fs:
                exprs.append(diff(g, s))
                targets.append(f"{arr}[{i}, {k}]")
        if time in fs:
            exprs.append(diff(g, time))
            targets.append(f"Gt[{i}]")
    L = ["def rootgrad(t, y, yp, p, d, Gy, Gyp, Gt, Gp, Gd):"]
    L += _unpack("y", n, "y", "    ", False) + _unpack("yp", n, "yp", "    ", False)
    L += _unpack("p", len(params), "p", "    ", False)
    L += _unpack("d", len(discretes), "d", "    ", False)
    L += _body(exprs, targets, "    ", symbols=names.code) + ["    pass"]
    ns, ieee = exec_twins(compile("\n".join(L) + "\n", "<acausal-root-gradients>", "exec"))
    fill, fill_ieee = ns["rootgrad"], ieee["rootgrad"]

    def rootgrad(t, y, yp, p, d):
        G = (np.zeros((nr, n)), np.zeros((nr, n)), np.zeros(nr), np.zeros((nr, m)),
             np.zeros((nr, len(dyn))))
        try:
            fill(t, list(map(float, y)), list(map(float, yp)), list(map(float, p)),
                 list(map(float, d)), *G)
        except _IEEE_ERRORS:      # a guarded domain: as the callbacks
            with np.errstate(all="ignore"):
                fill_ieee(t, *(np.asarray(a, dtype=float) for a in (y, yp, p, d)), *G)
        return G
    return rootgrad


# The observed variables over many rows at once (numpy arrays, one per
# unknown): what a large result's CSV or scan needs, where the per-row
# ``observe`` callback costs a Python call per row (10 M rows: 84 s). The
# same expressions and the same common sub-expressions, printed for arrays:
# conditionals become selections that keep Python's semantics (``min``,
# ``max``, ``if``/``else`` on NaN), the math functions numpy's ufuncs (as the
# IEEE variant of the callbacks: equal to the per-row values up to the last
# bit of a transcendental function).
class _ArrayPrinter(_Printer):
    """Python code of sympy expressions over numpy arrays of rows. A
    function of the model's own prints itself by its ``_numpycode``; one
    with only ``_pythoncode`` (scalar code) runs element by element."""

    printmethod = "_numpycode"

    def _print_Function(self, expr):
        if not hasattr(expr, "_pythoncode"):
            return super()._print_Function(expr)
        args = [sp.Symbol(f"_a{k}") for k in range(len(expr.args))]
        scalar = _Printer().code(expr.func(*args, evaluate=False))
        return (f"_elementwise(lambda {', '.join(a.name for a in args)}: {scalar}, "
                f"{', '.join(self._print(a) for a in expr.args)})")

    def _print_Piecewise(self, expr):
        code = "_nan"
        for e, c in reversed(expr.args):
            code = self._print(e) if c == sp.true else \
                f"_where({self._print(c)}, {self._print(e)}, {code})"
        return code

    def _print_ITE(self, expr):
        return self._print(expr.rewrite(sp.Piecewise))

    def _logic(self, fn, expr):
        return f"{fn}({', '.join(self._print(a) for a in expr.args)})"

    def _print_And(self, expr):
        return self._logic("_and", expr)

    def _print_Or(self, expr):
        return self._logic("_or", expr)

    def _print_Not(self, expr):
        return self._logic("_not", expr)

    def _print_Min(self, expr):
        return self._logic("_min", expr)

    def _print_Max(self, expr):
        return self._logic("_max", expr)

    def _print_sign(self, expr):
        return self._logic("_sign", expr)

    def _print_Heaviside(self, expr):
        return f"_heaviside({self._print(expr.args[0])})"


def _reduce(step):
    return lambda *a: functools.reduce(step, a)


def _array_namespace():
    ns = _ieee_namespace()
    ns.update(
        _nan=np.nan, _where=np.where,
        _elementwise=lambda f, *a: np.vectorize(f, otypes=[float])(*a),
        _and=_reduce(np.logical_and), _or=_reduce(np.logical_or), _not=np.logical_not,
        # Python's min/max keep the first of equal values and skip a NaN
        # that comes after a number: ``b if b < a else a``
        _min=_reduce(lambda a, b: np.where(b < a, b, a)),
        _max=_reduce(lambda a, b: np.where(b > a, b, a)),
        _sign=lambda x: np.where(x == 0, 0.0, np.copysign(1.0, x)),
        _heaviside=lambda x: np.where(x > 0, 1.0, np.where(x == 0, 0.5, 0.0)),
        _hatsum=hat_sum_array, _hatslope=hat_slope_array)
    return ns


def generate_observe_rows(observed, y, yp, params, discretes):
    """``observe_rows(t, Y, YP, p, d, O)``: the expressions ``observed``
    (resolved, in the DAE's unknowns ``y``, ``yp``, the parameters and the
    discrete values) over many rows of one mode at once: ``t`` the rows'
    times, ``Y`` and ``YP`` (unknowns x rows), ``p`` and ``d`` the mode's
    values; fills ``O`` (observed x rows). The vectorised twin of the
    ``observe`` callback (same values; the math functions are numpy's)."""
    names = Names(y, yp, params, discretes)
    obs = names.check(observed, "an observed variable")
    repeated = repeated_subexpressions(obs)
    printer = _ArrayPrinter({}, names.code)
    L = ["def observe_rows(t, y, yp, p, d, o):"]
    for v, m in (("y", len(y)), ("yp", len(yp)), ("p", len(params)), ("d", len(discretes))):
        L += _unpack(v, m, v, "    ", array=False)
    for k, e in enumerate(repeated):
        L.append(f"    c_{k} = {printer.definition(e)}")
        printer.temps[e] = f"c_{k}"
    L += [f"    o[{k}] = {printer.code(e)}" for k, e in enumerate(obs)] + ["    pass"]
    _counter[0] += 1
    fname = f"<acausal-observe-rows-{_counter[0]}>"
    src = "\n".join(L) + "\n"
    linecache.cache[fname] = (len(src), None, src.splitlines(True), fname)
    ns = _array_namespace()
    exec(compile(src, fname, "exec"), ns)
    return ns["observe_rows"]
