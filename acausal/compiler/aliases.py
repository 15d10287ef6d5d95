"""Stage 2: bind parameters and eliminate aliases.

* A parameter whose value is an expression of other parameters is replaced
  by that expression (so only free parameters reach the runtime vector).
* Equations ``x = ±y + c`` and ``x = c`` (``c`` built from numbers and
  parameters) are removed; every eliminated variable is kept as an
  expression of the one that stays, so results can still report it.
"""
from dataclasses import dataclass

import sympy as sp

from ..errors import ModelError, StructuralError
from ..lang.fastdiff import diff
from ..lang.symbols import base_and_order, der, is_der, ordered, time


@dataclass
class Reduced:
    equations: list      # Equation objects, aliases substituted
    unknowns: list       # remaining variable symbols (no derivatives)
    aliases: dict        # eliminated symbol -> expression of kept symbols
    param_subs: dict     # bound parameter symbol -> expression of free ones
    subs: dict           # aliases and their derivatives (der(x) -> ±der(root))


def bind_parameters(flat):
    """Bound parameter symbol -> expression of free parameters."""
    names = set(flat.params)
    bound = {}
    for info in flat.params.values():
        if info.decl.structural:
            continue
        if info.bound:
            for s in info.value.free_symbols:
                if s.name not in names:
                    raise ModelError(
                        f"parameter {info.symbol.name} is bound to {info.value}, but "
                        f"{s.name!r} is not a parameter of the model", variable=info.symbol.name)
            bound[info.symbol] = info.value
    resolved = {}

    def resolve(sym, stack=()):
        if sym in resolved:
            return resolved[sym]
        if sym in stack:
            raise ModelError("parameter bindings form a cycle: "
                             + " -> ".join(s.name for s in stack + (sym,)))
        expr = bound[sym]
        subs = {s: resolve(s, stack + (sym,)) for s in expr.free_symbols if s in bound}
        resolved[sym] = expr.xreplace(subs) if subs else expr
        return resolved[sym]

    for sym in bound:
        resolve(sym)
    return resolved


class _UnionFind:
    """value(x) = sign * value(root) + offset; a constant root has value 0
    and carries everything in the offset."""

    CONST = sp.Symbol("__const__")

    def __init__(self, priority):
        self.parent = {}
        self.priority = priority

    def find(self, x):
        if x not in self.parent:
            return x, sp.Integer(1), sp.Integer(0)
        p, s, o = self.parent[x]
        r, s2, o2 = self.find(p)
        res = (r, s * s2, s * o2 + o)
        self.parent[x] = res
        return res

    def _outranks(self, a, b):
        """True when root ``a`` should stay rather than ``b``: higher
        priority, and on a tie the smaller name (a total order, so that the
        root of each alias class is the same whatever order the equations
        come in)."""
        pa, pb = self.priority(a), self.priority(b)
        return pa > pb if pa != pb else a.name < b.name

    def union(self, x, a, y, b):
        """Record x = a*y + b (y may be CONST). Returns None, or 'redundant' /
        'inconsistent' when the equation adds nothing / contradicts."""
        rx, sx, ox = self.find(x)
        ry, sy, oy = self.find(y)
        # x = sx*rx + ox ; y = sy*ry + oy ; x = a*y + b
        if rx == ry:
            if sp.simplify(sx - a * sy) != 0:
                return "not-alias"
            return "redundant" if sp.simplify(ox - a * oy - b) == 0 else "inconsistent"
        # rx = (a*sy*ry + a*oy + b - ox)/sx, with sx = ±1
        if self._outranks(ry, rx):
            self.parent[rx] = (ry, a * sy / sx, (a * oy + b - ox) / sx)
        else:
            # ry = (sx*rx + ox - a*oy - b)/(a*sy)
            self.parent[ry] = (rx, sx / (a * sy), (ox - a * oy - b) / (a * sy))
        return None


def _alias_form(expr, unknowns):
    """(x, a, y, b) for expr = 0 <=> x = a*y + b with a = ±1, or
    (x, 0, CONST, b) for x = b; None otherwise."""
    syms = [s for s in ordered(expr.free_symbols) if s in unknowns or is_der(s)]
    if any(is_der(s) for s in syms) or expr.has(time) or len(syms) not in (1, 2):
        return None
    if not expr.is_Add and len(syms) == 2:
        return None
    coeffs = []
    rest = expr
    for s in syms:
        c = diff(expr, s)
        if c not in (1, -1):
            return None
        coeffs.append(c)
        rest = rest - c * s
    rest = sp.expand(rest)
    if any(s in unknowns for s in rest.free_symbols):
        return None
    x = syms[0]
    if len(syms) == 1:
        return x, sp.Integer(0), _UnionFind.CONST, -rest / coeffs[0]
    y = syms[1]
    # cx*x + cy*y + rest = 0  ->  x = -(cy/cx) y - rest/cx
    return x, -coeffs[1] / coeffs[0], y, -rest / coeffs[0]


def eliminate_aliases(flat):
    """Apply parameter bindings and remove alias equations."""
    psubs = bind_parameters(flat)
    unknowns = [info.symbol for info in flat.variables.values()]
    eqs = [(eq, eq.expr.xreplace(psubs) if psubs else eq.expr) for eq in flat.equations]
    uf = _UnionFind(_priority(flat, eqs))
    kept = _union_aliases(uf, eqs, set(unknowns))
    aliases, subs = {}, {}
    for x in unknowns:
        r, s, o = uf.find(x)
        if r == x:
            continue
        const = r == _UnionFind.CONST
        aliases[x] = subs[x] = o if const else s * r + o
        for k in (1, 2, 3):  # offsets are constant: der(x) = s*der(r)
            subs[_der_n(x, k)] = sp.Integer(0) if const else s * _der_n(r, k)
    out = []
    for eq, expr in kept:
        e = expr.xreplace(subs) if subs else expr
        if e == 0:
            raise StructuralError(
                f"the model is over-determined: {eq.describe()} holds identically "
                f"once aliases are removed", excess=[eq], component=eq.origin)
        out.append(type(eq)(e, eq.origin, eq.label))
    remaining = [x for x in unknowns if x not in aliases]
    return Reduced(out, remaining, aliases, psubs, subs)


def _priority(flat, eqs):
    """Which member of an alias set stays (the highest score): one that is
    differentiated, then one with a fixed start, then one that is not a
    connector variable, then the shortest path."""
    differentiated = {base_and_order(s)[0] for _, expr in eqs for s in expr.free_symbols
                      if is_der(s)}

    def priority(sym):
        if sym == _UnionFind.CONST:
            return 100
        info = flat.variables[sym.name]
        score = 8 * (sym in differentiated) + 4 * bool(info.start.fixed) \
            + 2 * (not _is_port_var(flat, sym))
        return score - 1e-3 * sym.name.count(".")

    return priority


def _union_aliases(uf, eqs, uset):
    """Merge every alias equation's two sides in ``uf``; returns the other
    equations. An alias that contradicts or repeats others raises."""
    kept = []
    for eq, expr in eqs:
        form = _alias_form(expr, uset)
        if form is None:
            kept.append((eq, expr))
            continue
        x, a, y, b = form
        status = uf.union(x, sp.Integer(1), y, b) if y == _UnionFind.CONST \
            else uf.union(x, a, y, b)
        if status == "not-alias":
            kept.append((eq, expr))
        elif status is not None:
            what = "contradicts" if status == "inconsistent" else "repeats"
            raise StructuralError(
                f"the model is over-determined: {eq.describe()} {what} other equations "
                f"(the same relation is imposed twice; e.g. two fixed supports connected "
                f"to each other, or a connection made twice)", excess=[eq], component=eq.origin)
    return kept


def _der_n(x, k):
    for _ in range(k):
        x = der(x)
    return x


def _is_port_var(flat, sym):
    return flat.variables[sym.name].port
