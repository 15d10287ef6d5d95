"""Stage 1b: every equation is dimensionally consistent.

After :mod:`.flatten`, each equation's terms are given the dimension that the
declared units of its parameters, variables and connector variables imply
(``der(x)``: the unit of ``x`` per second; ``time``: seconds), and the terms
of every sum, both sides of every relation, the branches of every
``Piecewise`` and the arguments of ``Max``/``Min``/``atan2`` must agree;
``sin``, ``exp``, ``tanh``... take dimensionless arguments (an angle in rad is
dimensionless, as in SI). A mismatch raises :class:`~acausal.errors.ModelError`
naming the component, the equation and both units.

As in Modelica tools' unit checking, a literal number carries no unit of
its own: it may stand beside any term (``x + 1``), and a literal factor may
stand for a constant with an implied unit (``Force(f=lambda s: 1000.0*s**3)``,
a spring of 1000 N/m^3; ``sin(3*time)``, 3 rad/s), so a product with one
carries no unit. A sign (-1, from a subtraction) is a pure number. A symbol whose unit cannot be
read (``"N/m^gamma"`` with a structural exponent that does not resolve), or
that was declared without a unit (Modelica's ``unit = ""``), carries none
either, so the check never rejects what it cannot read.
Dimensions are pint's (``acausal.data.units``), held as exponent maps over
the SI base dimensions. The stage runs on a compile-cache miss only: a
cached model was checked when it was compiled, and nothing is left at run
time.
"""
from __future__ import annotations

import functools
import re
from fractions import Fraction

import sympy as sp

from ..data.units import parse_unit
from ..errors import ModelError
from ..lang.symbols import base_and_order, time

_ANY = None   # a term without a unit (a literal number, an unreadable unit)
_NONE = ()    # dimensionless

_DIMENSIONLESS_ARG = (sp.sin, sp.cos, sp.tan, sp.exp, sp.log, sp.tanh, sp.sinh, sp.cosh,
                      sp.asin, sp.acos, sp.atan, sp.asinh, sp.acosh, sp.atanh, sp.cot, sp.sec,
                      sp.csc, sp.erf)
_DIMENSIONLESS_RESULT = (sp.sign, sp.Heaviside, sp.floor, sp.ceiling)


@functools.lru_cache(maxsize=4096)
def dimension(unit: str):
    """The exponent map (sorted tuple of (base dimension, Fraction)) of a
    unit text, or None when pint cannot read it."""
    try:
        dims = parse_unit(unit).dimensionality
    except Exception:  # noqa: BLE001 - pint raises several kinds on what it cannot read
        return _ANY
    return tuple(sorted((str(k), Fraction(v).limit_denominator(1000)) for k, v in dims.items()
                        if v != 0))


_NAMED = ("N", "N*m", "m", "s", "kg", "m/s", "m/s^2", "rad/s", "rad/s^2", "N/m", "N*s/m",
          "N*m*s/rad", "kg*m^2", "N/m^2", "W", "N*s", "A", "V", "K")


def show(dim) -> str:
    """A dimension as a unit text: the first of the usual mechanical units
    with that dimension (``N``, ``N*m``, ``m/s``...), else SI base units;
    dimensionless: ``1``."""
    if dim is _ANY:
        return "?"
    if not dim:
        return "1"
    for name in _NAMED:
        if dimension(name) == dim:
            return name
    base = {"[length]": "m", "[mass]": "kg", "[time]": "s", "[current]": "A",
            "[temperature]": "K", "[substance]": "mol", "[luminosity]": "cd"}
    num = [base.get(k, k) + (f"^{v}" if v != 1 else "") for k, v in dim if v > 0]
    den = [base.get(k, k) + (f"^{-v}" if v != -1 else "") for k, v in dim if v < 0]
    return ("*".join(num) or "1") + ("/" + "/".join(den) if den else "")


def _mul(a, b, power=Fraction(1)):
    if a is _ANY or b is _ANY:
        return _ANY
    out = dict(a)
    for k, v in b:
        out[k] = out.get(k, Fraction(0)) + v * power
    return tuple(sorted((k, v) for k, v in out.items() if v != 0))


def _pow(a, p):
    if a is _ANY:
        return _ANY
    return tuple(sorted((k, v * p) for k, v in a if v * p != 0))


class Mismatch(Exception):
    """Two terms of one expression with different dimensions."""

    def __init__(self, first, second, where):
        super().__init__(where)
        self.first, self.second, self.where = first, second, where


class _Dimensions:
    """The dimension of sympy expressions of one flat model's symbols."""

    def __init__(self, flat):
        self.units = {}
        self.values = {}
        self.declared = {}    # path -> the unit text as declared
        for path, info in flat.params.items():
            if not getattr(info.decl, "unit_declared", True):
                continue
            self.declared[path] = info.decl.unit
            self.units[info.symbol] = self._unit_text(info.decl.unit, path, flat)
            if isinstance(info.value, (int, float)) and not isinstance(info.value, bool):
                self.values[info.symbol] = sp.Float(info.value)
        for table in (flat.variables, flat.discretes):
            for path, info in table.items():
                if info.unit_declared:
                    self.declared[path] = info.unit
                    self.units[info.symbol] = self._unit_text(info.unit, path, flat)

    @staticmethod
    def _unit_text(unit, path, flat):
        """A unit text with the owner's parameter names (``m^gamma``) replaced
        by their values where they are numbers."""
        unit = unit or "1"
        if dimension(unit) is not _ANY:
            return unit
        owner = path.rsplit(".", 1)[0] if "." in path else ""

        def value(m):
            p = flat.params.get(f"{owner}.{m.group(0)}" if owner else m.group(0))
            if p is not None and isinstance(p.value, (int, float)):
                return repr(float(p.value))
            return m.group(0)
        return re.sub(r"[A-Za-z_]\w*", value, unit)

    def of_symbol(self, sym):
        if sym == time:
            return dimension("s")
        base, order = base_and_order(sym)
        unit = self.units.get(base)
        if unit is None:
            return _ANY
        d = dimension(unit)
        return _mul(d, dimension("s"), Fraction(-order)) if order and d is not _ANY else d

    def of(self, e):
        """The dimension of ``e``; raises :class:`Mismatch`."""
        if e.is_Number or e.is_NumberSymbol or isinstance(e, (sp.logic.boolalg.BooleanAtom,)):
            return _ANY
        if e.is_Symbol:
            return self.of_symbol(e)
        if e.is_Add:
            return self.same(e.args, e)
        if e.is_Mul:
            if any((a.is_Number and abs(a) != 1) or a.is_NumberSymbol for a in e.args):
                for a in e.args:   # still check inside
                    self.of(a)
                return _ANY        # a literal may carry a unit: 1000.0*s**3 [N], sin(3*time)
            out = _NONE
            for a in e.args:       # a sign keeps the term's unit
                if not a.is_Number:
                    out = _mul(out, self.of(a))
            return out
        if e.is_Pow:
            return self._power(e)
        if isinstance(e, sp.Piecewise):
            for _, cond in e.args:
                self.relation(cond)
            return self.same([v for v, _ in e.args], e)
        if isinstance(e, (sp.Max, sp.Min)):
            return self.same(e.args, e)
        if isinstance(e, sp.Abs):
            return self.of(e.args[0])
        if isinstance(e, sp.atan2):
            self.same(e.args, e)
            return _NONE
        if isinstance(e, _DIMENSIONLESS_ARG):
            for a in e.args:
                self.dimensionless(a, e)
            return _NONE
        if isinstance(e, _DIMENSIONLESS_RESULT):
            for a in e.args:
                self.of(a)
            return _NONE
        if isinstance(e, sp.Function) and type(e).__name__ == "PosPow":
            base, p = e.args
            return self._raise(self.of(base), p, e)
        if isinstance(e, (sp.core.relational.Relational, sp.logic.boolalg.BooleanFunction)):
            self.relation(e)
            return _NONE
        for a in e.args:      # an unknown function: check inside, no unit outside
            if isinstance(a, sp.Expr):
                self.of(a)
        return _ANY

    def _power(self, e):
        base, p = e.args
        return self._raise(self.of(base), p, e)

    def _raise(self, d, p, e):
        if d is _ANY or d == _NONE:
            if not p.is_number:
                self.dimensionless(p, e)
            return d
        if not p.is_number:
            p = p.xreplace(self.values)
            if not p.is_number:
                return _ANY
        try:
            return _pow(d, Fraction(float(p)).limit_denominator(1000))
        except (TypeError, ValueError):
            return _ANY

    def same(self, args, e):
        known = None
        first = None
        for a in args:
            d = self.of(a)
            if d is _ANY:
                continue
            if known is None:
                known, first = d, a
            elif d != known:
                raise Mismatch((first, known), (a, d), e)
        return known if known is not None else _ANY

    def relation(self, cond):
        if isinstance(cond, sp.core.relational.Relational):
            self.same([cond.lhs, cond.rhs], cond)
        elif isinstance(cond, sp.logic.boolalg.BooleanFunction):
            for a in cond.args:
                self.relation(a)

    def dimensionless(self, a, e):
        d = self.of(a)
        if d is not _ANY and d != _NONE:
            raise Mismatch((a, d), (sp.Integer(1), _NONE), e)


def check_units(flat, owners=None):
    """Raise ModelError at the first equation whose terms disagree in
    dimension (see the module docstring); ``owners``: component path ->
    class name, for the message."""
    dims = _Dimensions(flat)
    owners = owners or getattr(flat, "owners", {}) or {}
    for path, unit in dims.declared.items():
        why = _not_si(unit, path, flat)
        if why:
            raise ModelError(f"units: {path}: unit {unit!r} {why}")
    for eq in flat.equations:
        residuals, conditions = _residuals(eq.expr)
        try:
            for residual in residuals:
                dims.of(residual)
            for cond in conditions:
                dims.relation(cond)
        except Mismatch as m:
            where = eq.origin or "the model"
            cls = owners.get(eq.origin)
            label = f"{where} ({cls})" if cls else where
            (a, da), (b, db) = m.first, m.second
            raise ModelError(
                f"units: {eq.label or 'an equation'} of {label} is not consistent: "
                f"{_short(a)} is [{show(da)}] but {_short(b)} is [{show(db)}] "
                f"(in {_short(eq.expr, 160)} = 0)") from None


def _not_si(unit, path, flat):
    """Why a declared unit is refused, or None: one pint cannot read (after
    Modelica's ``s2`` for ``s^2``), unless it holds a name of its owner's
    parameters (``N/m^gamma``: an exponent read when it resolves), or one
    with a dimension that is not a coherent SI unit (``furlongs``, ``mm``,
    ``kN``: values are SI, so the declared unit must be too; it passed and
    labelled SI values with it). A scaled pure number (``%`` of a pulse's
    period) is the equations' business and passes."""
    text = (unit or "1").strip()
    if text in ("", "-", "1"):
        return None
    owner = path.rsplit(".", 1)[0] if "." in path else ""
    names = re.findall(r"[A-Za-z_]\w*", text)
    if any((f"{owner}.{n}" if owner else n) in flat.params for n in names):
        return None
    modelica = re.sub(r"(?<=[A-Za-z])(\d+)", r"^\1", text)
    try:
        from ..data.units import ureg
        q = ureg().Quantity(1.0, parse_unit(modelica)).to_base_units()
    except Exception:  # noqa: BLE001 - pint raises several kinds on what it cannot read
        return "is not a unit (write SI units: m, kg, s, N, N/m, rad/s...)"
    if abs(q.magnitude - 1.0) > 1e-12 and dimension(modelica):
        return (f"is not an SI unit (1 {text} = {q.magnitude:.6g} {show(dimension(modelica))}): "
                f"values are in SI units, declare {show(dimension(modelica))!r}")
    return None


def _residuals(expr):
    """(residuals, conditions) an equation stands for: a ``Piecewise``
    residual (times a number) is one equation per mode (stuck: ``a = 0``;
    sliding: a force balance), each with its own dimension, and its
    conditions are relations to check."""
    _, rest = expr.as_coeff_Mul()
    if not isinstance(rest, sp.Piecewise):
        return [expr], []
    residuals, conditions = [], []
    for value, cond in rest.args:
        r, c = _residuals(value)
        residuals += r
        conditions += c + [cond]
    return residuals, conditions


def _short(e, n=80):
    text = str(e)
    return text if len(text) <= n else text[:n - 3] + "..."
