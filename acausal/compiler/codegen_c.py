"""Stage 5b: generate C for the residual, its iteration matrix and the root
functions, from the same reduced DAE as :mod:`acausal.compiler.codegen` (Python).

The compiled backend (:mod:`acausal.runtime.backends.compiled`) links it with a
small driver around SUNDIALS IDA, so that IDA calls it with no Python in
between. Parameters and discrete values are one input array ``pd``
(parameters first), so that one compiled library serves every mode and
every parameter set. Sub-expressions are shared by hash-consing, as in the
Python code (:func:`acausal.compiler.codegen.repeated_subexpressions`:
every sub-expression met twice gets a name; linear work, where
``sympy.cse`` took most of the time on a model with its sensitivity
equations), and the iteration matrix's entries are the Python code's
(:func:`acausal.compiler.codegen.jacobian_entries`); sympy's C99 printer
writes the expressions (Piecewise as ``?:``).
"""
import functools
from dataclasses import dataclass

import sympy as sp
from sympy.printing.c import C99CodePrinter
from sympy.printing.codeprinter import PrintMethodNotImplementedError

from .codegen import (NamedTemps, Names, PrintMemo, fixed_entries, jacobian_entries,
                      repeated_subexpressions)
from .substitute import replace_shared


class _Printer(NamedTemps, C99CodePrinter):
    """C of sympy expressions, common sub-expressions by name
    (:class:`~acausal.compiler.codegen.NamedTemps`). The printer is strict: a
    function with no C form raises ``PrintMethodNotImplementedError``."""

    def __init__(self, temps=None):
        super().__init__({"order": "none"})
        self._setup_temps(temps)

    def _print_Heaviside(self, expr):   # the Python code's heaviside: 1/2 at 0
        return f"acs_heaviside({self._print(expr.args[0])})"

    # max and min as inline functions of the generated file (HELPERS) with the
    # values of C99's fmax/fmin, NaN rules included, nested as sympy nests
    # them: at -O1 gcc calls libm's fmax (not inlined without -ffast-math),
    # 7 % of a located generic term's run (74 hats max(0, 1 - |x - c|/h))
    def _print_Max(self, expr):
        return self._nested("acs_fmax", expr.args)

    def _print_Min(self, expr):
        return self._nested("acs_fmin", expr.args)

    # a linear spline (lang.splines): evaluated on the interval of x only; its
    # weights, when they are consecutive parameters, read in place from pd
    def _print_HatSum(self, expr):
        return self._spline("acs_hatsum", expr)

    def _print_HatSlope(self, expr):
        return self._spline("acs_hatslope", expr)

    def _spline(self, name, expr):
        x, lo, hi, *w = (self._print(a) for a in expr.args)
        at = [int(c[1:]) if c[:1] == "p" and c[1:].isdigit() else None for c in w]
        if None not in at and at == list(range(at[0], at[0] + len(at))):
            weights = f"pd + {at[0]}"
        else:
            weights = "(const double[]){" + ", ".join(w) + "}"
        return f"{name}({x}, {lo}, {hi}, {len(w)}, {weights})"

    def _nested(self, name, args):
        out = self._print(args[-1])
        for a in reversed(args[:-1]):
            out = f"{name}({self._print(a)}, {out})"
        return out

    # a condition folded into a Piecewise of truth values (|x| of a Piecewise x:
    # x >= 0 becomes a Piecewise whose branches are true, false or relations):
    # sympy prints C99's ``true``/``false``, which need <stdbool.h>; C's own
    # truth values are 1 and 0 (MSL's OneWayClutch and Translational.Friction
    # had fallen back to the sundae backend on "'true' undeclared")
    def _print_BooleanTrue(self, expr):
        return "1"

    def _print_BooleanFalse(self, expr):
        return "0"


# the generated file's helpers, inline: the values of the Python code's
# heaviside (1/2 at 0) and of C99's fmax/fmin as x86-64's libm computes them
# (a NaN argument loses to a number; of 0 and -0 the second, as glibc on
# x86-64 gives it: C99 leaves that sign open)
HELPERS = (
    "static inline double acs_heaviside(double x) "
    "{ return x > 0 ? 1.0 : (x == 0 ? 0.5 : 0.0); }",
    "static inline double acs_fmax(double a, double b) { return (a > b || b != b) ? a : b; }",
    "static inline double acs_fmin(double a, double b) { return (a < b || b != b) ? a : b; }",
    # lang.splines.hat_sum / hat_slope, the same arithmetic in the same order
    """static inline double acs_hatsum(double x, double lo, double hi, int n, const double* w)
{
  const double h = (hi - lo) / (n - 1), u = (x - lo) / h;
  if (!(u > -1.0 && u < n)) return 0.0;
  const double kf = floor(u), t = u - kf;
  const int k = (int)kf;
  const double a = k >= 0 ? w[k] : 0.0, b = k + 1 < n ? w[k + 1] : 0.0;
  return a * (1.0 - t) + b * t;
}""",
    """static inline double acs_hatslope(double x, double lo, double hi, int n, const double* w)
{
  const double h = (hi - lo) / (n - 1), u = (x - lo) / h;
  if (!(u > -1.0 && u < n)) return 0.0;
  const double kf = floor(u), t = u - kf;
  const int k = (int)kf;
  const double b = k + 1 < n ? w[k + 1] : 0.0;
  if (t == 0.0) return (b - (k >= 1 ? w[k - 1] : 0.0)) / (2.0 * h);
  return (b - (k >= 0 ? w[k] : 0.0)) / h;
}""",
)


@dataclass(frozen=True)
class CSource:
    """The generated C and its sizes."""
    text: str
    n: int
    n_roots: int
    n_pd: int


def _decls(n, has_yp):
    lines = [f"  const double y{i} = y[{i}];" for i in range(n)]
    lines += [f"  const double yp{i} = yp[{i}];" for i in range(n) if has_yp[i]]
    return lines


_PRINTED = PrintMemo()   # the C printer's definitions, across models


def _body(exprs, targets):
    if not exprs:
        return []
    repeated = repeated_subexpressions(exprs)
    names = {e: f"c_{k}" for k, e in enumerate(repeated)}
    printer = _Printer(names)

    def code(e):
        return _PRINTED.definition(printer, e)
    lines = [f"  const double {names[e]} = {code(e)};" for e in repeated]
    lines += [f"  {t} = {code(e)};" for t, e in zip(targets, exprs)]
    return lines


def _pd_decls(npar, nd):
    return [f"  const double p{i} = pd[{i}];" for i in range(npar)] + \
        [f"  const double d{j} = pd[{npar + j}];" for j in range(nd)]


# the functions a run calls only at its start and its events (the
# re-initialisation's Jacobians, the fixed-start rows, the observed values),
# compiled without optimisation: a third of the generated C, and gcc's -O1 of it
# was 12-25 % of a model's compile. On x86-64 (SSE2, no FMA contraction) -O0
# and -O1 give the same values (tests/backends/test_c_helpers.py); ACS_COLD is
# empty for other compilers, and -DACS_COLD= compiles them as the rest
COLD = ("acs_jacs", "acs_fixjac", "acs_observe")
COLD_MACRO = ("#ifndef ACS_COLD\n#if defined(__GNUC__) && !defined(__clang__)\n"
              "#define ACS_COLD __attribute__((optimize(\"O0\")))\n"
              "#else\n#define ACS_COLD\n#endif\n#endif")


def _function(name, extra_args, decl, body):
    head = (f"{'ACS_COLD ' if name in COLD else ''}void {name}(double t, const double* y, "
            f"const double* yp, const double* pd{extra_args})")
    return [head, "{", "  (void)t; (void)y; (void)yp; (void)pd;"] + decl + body + ["}", ""]


def _jacs_entries(res, ysyms, ypsyms, n, columns=None):
    """(expressions, targets) of ``dF/dy`` and ``dF/dy'`` as two row-major
    ``n`` x ``n`` arrays (what the Python ``jacs`` callback fills): the
    initialisation and the re-initialisation at events need them apart.
    The entries are the iteration matrix's (:func:`~acausal.compiler.codegen.jacobian_entries`,
    cached: no second differentiation)."""
    exprs, targets = [], []
    for i, j, dy, dyp in jacobian_entries(res, ysyms, ypsyms, columns):
        if dy != 0:
            exprs.append(dy)
            targets.append(f"Jy[{i * n + j}]")
        if dyp != 0:
            exprs.append(dyp)
            targets.append(f"Jyp[{i * n + j}]")
    return exprs, targets


def _observe(cm, names, real, decl, ysyms, ypsyms):
    """``acs_observe`` (``cm.observed_exprs()``, as the Python
    ``observe`` callback) and ``acs_has_observe``: 0 when an observed
    expression has no C form, and the caller keeps the Python one (the
    residual and root functions decide whether the backend can run)."""
    obs = cm.observed_exprs()
    exprs = names.rename(obs, "an observed variable")
    if real:
        exprs = [replace_shared(e, real) for e in exprs]
    try:
        body = _body(exprs, [f"o[{i}]" for i in range(len(exprs))])
        fixjac = _fixjac(cm, exprs, ysyms, ypsyms)
        has = 1
    except PrintMethodNotImplementedError:
        body, fixjac, has = [], [], 0
    return _function("acs_observe", ", double* o", decl, body) + \
        _function("acs_fixjac", ", double* F", decl, fixjac) + \
        [f"int acs_has_observe(void) {{ return {has}; }}",
         f"int acs_n_observed(void) {{ return {len(exprs)}; }}", ""]


def _fixjac(cm, observed, ysyms, ypsyms):
    """Body of ``acs_fixjac``: the rows the initialisation adds for the fixed
    start values (as ``cm.fixed_jacobian()``), row-major over z = (y, y'
    of the states), every entry written."""
    ns, n = cm.dae.n_states, len(ysyms)
    rows = [k for k, nm in enumerate(cm.var_names) if cm.flat.variables[nm].start.fixed]
    entries = fixed_entries(dict((k, observed[k]) for k in rows), rows, ysyms, ypsyms, ns)
    width = n + ns
    return [f"  memset(F, 0, sizeof(double) * {max(len(rows), 1) * width});"] + \
        _body([e for _, _, e in entries], [f"F[{a * width + col}]" for a, col, _ in entries])


@functools.lru_cache(maxsize=20_000)
def _iteration_entry(dy, dyp, cj):
    """``dy + cj*dyp``: one object for the same parts across models (the
    printed-definition memo then finds it by identity, not by comparing
    trees)."""
    return dy + cj * dyp


def generate_c(cm):
    """C source of ``acs_res``, ``acs_jac`` (column-major ``J = dF/dy + cj
    dF/dy'``, every entry written), ``acs_roots`` for compiled model ``cm``
    (events first, then assertions, as in ``cm.callbacks``) and ``acs_jacs``
    (``dF/dy`` and ``dF/dy'`` apart, row-major, as ``cm.callbacks``' jacs)
    and ``acs_observe`` (every variable, as its observe; see :func:`_observe`)."""
    dae = cm.dae
    n = len(dae.y)
    names = Names(dae.y, dae.yp, cm.param_syms, cm.disc_syms)
    roots = [cm.resolve(e.expr) for e in cm.events] + \
        [cm.resolve(a.expr) for a in cm.assertions]
    res = names.rename(dae.residuals, "a residual")
    g = names.rename(roots, "an event")
    # (Names' symbols are real already: then there is nothing to replace)
    real = {s: r for s in names.allowed if (r := sp.Symbol(s.name, real=True)) is not s}
    if real:
        res = [replace_shared(r, real) for r in res]
        g = [replace_shared(e, real) for e in g]
    # the symbols as they stand in the expressions, found by name (whatever
    # assumptions Names gives them)
    by_name = {v.name: v for v in real.values()}
    ysyms = [by_name.get(f"y{i}", sp.Symbol(f"y{i}", real=True)) for i in range(n)]
    has_yp = [s is not None for s in dae.yp]
    ypsyms = [by_name.get(f"yp{i}", sp.Symbol(f"yp{i}", real=True)) if has_yp[i] else None
              for i in range(n)]
    cj = sp.Symbol("cj", real=True)
    jac, targets = [], []
    columns = dae.jacobian_columns
    for i, j, dy, dyp in jacobian_entries(res, ysyms, ypsyms, columns):
        jac.append(_iteration_entry(dy, dyp, cj))
        targets.append(f"J[{j * n + i}]")
    decl = _decls(n, has_yp) + _pd_decls(len(cm.param_syms), len(cm.disc_syms))
    L = ["#include <math.h>", "#include <string.h>", COLD_MACRO,
         *HELPERS,
         ""]
    L += _function("acs_res", ", double* r", decl, _body(res, [f"r[{i}]" for i in range(n)]))
    L += _function("acs_jac", ", double cj, double* J", decl,
                   [f"  memset(J, 0, sizeof(double) * {n * n});"] + _body(jac, targets))
    L += _function("acs_roots", ", double* g", decl,
                   _body(g, [f"g[{i}]" for i in range(len(g))]))
    L += _observe(cm, names, real, decl, ysyms, ypsyms)
    L += _function("acs_jacs", ", double* Jy, double* Jyp", decl,
                   [f"  memset(Jy, 0, sizeof(double) * {n * n});",
                    f"  memset(Jyp, 0, sizeof(double) * {n * n});"]
                   + _body(*_jacs_entries(res, ysyms, ypsyms, n, columns)))
    return CSource("\n".join(L), n, len(g), len(cm.param_syms) + len(cm.disc_syms))
