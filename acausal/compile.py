"""The pipeline from a model to generated callbacks, run once per model
structure: flatten -> aliases -> structure check -> Pantelides -> dummy
derivatives -> causalize -> codegen. The result, :class:`CompiledModel`,
simulates any number of parameter sets without re-generating anything.
"""
import time as _time
from dataclasses import dataclass

import numpy as np
import sympy as sp

from .aliases import eliminate_aliases
from .causalize import build_dae
from .codegen import generate
from .declare import Start
from .errors import ModelError, ParameterError
from .flatten import flatten
from .structure import Graph, check_structure, dummy_derivatives, pantelides
from .symbols import base_and_order, der, time


@dataclass
class ParamEntry:
    name: str
    default: float
    unit: str
    desc: str
    decl: object
    owner: str


class CompiledModel:
    """A model turned into solver callbacks. Use :meth:`simulate`."""

    def __init__(self, model):
        t0 = _time.perf_counter()
        self.model = model
        flat = self.flat = flatten(model)
        red = self.reduced = eliminate_aliases(flat)
        check_structure(red.equations, red.unknowns, flat)
        self.params = [ParamEntry(i.symbol.name, float(i.value), i.decl.unit, i.decl.desc,
                                  i.decl, i.owner)
                       for i in flat.params.values()
                       if not i.decl.structural and not i.bound]
        self.structural = {i.symbol.name: i.value for i in flat.params.values()
                           if i.decl.structural}
        self.bound = {i.symbol.name: i.value for i in flat.params.values()
                      if not i.decl.structural and i.bound}
        self.param_syms = [sp.Symbol(p.name) for p in self.params]
        self.discretes = list(flat.discretes.values())
        self.disc_syms = [d.symbol for d in self.discretes]
        g = self.graph = Graph(red.equations, red.unknowns)
        pantelides(g)
        self._root_starts = _alias_starts(flat, red)
        open_across = _open_across(model, flat, red)
        values = _propagate_starts(red.equations, self._start_values(), open_across)
        # guesses of the frames' positions and angles (at the default parameters)
        self._propagated = {s: values[s] for s in open_across if s in values}
        fixed = {v.symbol for v in flat.variables.values() if v.start.fixed}
        fixed |= {r for r, st in self._root_starts.items() if st.fixed}
        dummies = dummy_derivatives(g, values, lambda s: base_and_order(s)[0] in fixed)
        self.dae = build_dae(g, dummies, set(self.param_syms), values)
        if not self.dae.y:
            raise ModelError("the model leaves nothing to integrate: every variable is "
                             "given explicitly (prescribed motion, constants), so there is no "
                             "state or implicit unknown for the solver; add a dynamic element "
                             "(a mass, an inertia, a damper between moving parts)")
        self._subs = dict(red.param_subs)
        self._start_fns = {}
        self._alias = red.subs
        self.var_names = list(flat.variables)
        observed = [self.resolve(flat.variables[n].symbol) for n in self.var_names]
        self.events = list(flat.events)
        self.assertions = list(flat.assertions)
        self.stop_events = []
        roots = [self.resolve(e.expr) for e in self.events] + \
                [self.resolve(a.expr) for a in self.assertions]
        self.source, self._make = generate(self.dae, self.param_syms, self.disc_syms,
                                           roots, observed)
        self.n_roots = len(roots)
        self.compile_s = _time.perf_counter() - t0

    # -- symbol resolution -------------------------------------------------
    def resolve(self, expr):
        """Rewrite an expression of model symbols in terms of the DAE's y and
        y' symbols, free parameters, discrete values and time."""
        e = sp.sympify(expr)
        if self._subs:
            e = e.xreplace(self._subs)
        e = e.xreplace(self._alias)
        if self.dae.explicit:
            e = e.xreplace(self.dae.explicit)
        known = set(self.dae.y) | {s for s in self.dae.yp if s is not None} | \
            set(self.param_syms) | set(self.disc_syms) | {time}
        bad = [s for s in e.free_symbols if s not in known]
        if bad:
            raise ModelError(f"{expr} cannot be evaluated: {bad[0].name} is not available "
                             "(a derivative the model never needs, or an unknown name)")
        return e

    def _start_values(self):
        vals = {}
        for info in self.flat.params.values():
            if not info.decl.structural:
                vals[info.symbol] = info.value
        for info in self.flat.variables.values():
            v = info.start.value
            vals[info.symbol] = v
        for r, st in self._root_starts.items():
            vals[r] = st.value
        for d in self.flat.discretes.values():
            vals[d.symbol] = d.start.value
        for k, v in list(vals.items()):
            if isinstance(v, sp.Basic) and not v.is_number:
                vals[k] = v.xreplace(vals)
        out = {}
        for k, v in vals.items():
            try:
                out[k] = float(sp.sympify(v).xreplace(vals))
            except TypeError:
                out[k] = 0.0
        for s in list(self.graph.vsym):
            out.setdefault(s, 0.0)
        out[time] = 0.0
        return out

    # -- runtime helpers -------------------------------------------------------
    def param_index(self, name):
        for i, p in enumerate(self.params):
            if p.name == name:
                return i
        if name in self.bound:
            raise ParameterError(f"parameter {name} is bound to {self.bound[name]}; "
                                 "set the parameters it depends on instead")
        if name in self.structural:
            raise ParameterError(f"parameter {name} is structural (it changes the equations); "
                                 "set it in the model file")
        raise ParameterError(f"the model has no parameter {name!r}")

    def param_vector(self, overrides=None):
        """Free parameter values with ``overrides`` (name -> value) applied and
        checked against each parameter's bounds."""
        p = np.array([e.default for e in self.params], dtype=float)
        for name, value in (overrides or {}).items():
            i = self.param_index(name)
            e = self.params[i]
            value = float(value)
            e.decl.check_bounds(value, name)
            p[i] = value
        return p

    def _eval_start(self, value, p):
        """A start value, which may be an expression of parameters."""
        if isinstance(value, sp.Basic) and not value.is_number:
            fn = self._start_fns.get(value)
            if fn is None:  # compiled once per expression (it runs every simulation)
                e = value.xreplace(self._subs)
                fn = self._start_fns[value] = sp.lambdify([self.param_syms], e, "math")
            return float(fn(p))
        return float(value)

    def fixed_jacobian(self):
        """A function (y, yp) -> d(fixed-start variables)/d(y, y'_states),
        generated once: the rows the initialisation adds for fixed starts."""
        fn = getattr(self, "_fixed_jac", None)
        if fn is None:
            ns = self.dae.n_states
            zs = list(self.dae.y) + [s for s in self.dae.yp[:ns]]
            rows = []
            for name in self.var_names:
                if self.flat.variables[name].start.fixed:
                    e = self.resolve(sp.Symbol(name))
                    rows.append([sp.diff(e, z) for z in zs])
            ysyms = list(self.dae.y)
            ypsyms = [s if s is not None else sp.Dummy() for s in self.dae.yp]
            args = [time] + ysyms + ypsyms + self.param_syms + self.disc_syms
            fn = sp.lambdify(args, sp.Matrix(rows) if rows else sp.zeros(0, len(zs)),
                             "numpy")
            self._fixed_jac = fn
        return fn

    def state_slot_of(self, name):
        """(slot, sign) when variable ``name`` is ±(one state slot), else None."""
        cache = self.__dict__.setdefault("_slot_cache", {})
        if name not in cache:
            e = self.resolve(sp.Symbol(name))
            sign = 1.0
            if isinstance(e, sp.Mul) and len(e.args) == 2 and e.args[0] == -1:
                sign, e = -1.0, e.args[1]
            slots = {s: i for i, s in enumerate(self.dae.y[:self.dae.n_states])}
            cache[name] = (slots[e], sign) if e in slots else None
        return cache[name]

    def dynamic_discretes(self):
        """Indices of the discrete values the residual equations use."""
        dyn = getattr(self, "_dynamic", None)
        if dyn is None:
            used = set()
            for r in self.dae.residuals:
                used |= r.free_symbols
            dyn = self._dynamic = {j for j, s in enumerate(self.disc_syms) if s in used}
        return dyn

    def slot_names(self):
        """For each solver unknown, the names that denote it up to sign: its
        own symbol and every variable that resolves to ±it."""
        names = getattr(self, "_slot_names", None)
        if names is None:
            names = [[s.name] for s in self.dae.y]
            index = {s: i for i, s in enumerate(self.dae.y)}
            for name in self.var_names:
                e = self.resolve(sp.Symbol(name))
                if isinstance(e, sp.Mul) and len(e.args) == 2 and e.args[0] == -1:
                    e = e.args[1]
                if e in index:
                    names[index[e]].append(name)
            self._slot_names = names
        return names

    def fixed_starts(self, p):
        """(index in var_names, value, name) of every fixed start value."""
        out = []
        for k, name in enumerate(self.var_names):
            st = self.flat.variables[name].start
            if st.fixed:
                out.append((k, self._eval_start(st.value, p), name))
        return out

    def guess_vector(self, p):
        """Initial guess of y from the start values of the variables."""
        y = np.zeros(len(self.dae.y))
        for i, s in enumerate(self.dae.y):
            base, k = base_and_order(s)
            info = self.flat.variables.get(base.name)
            if k == 0 and info is not None:
                st = self._root_starts.get(base, info.start)
                y[i] = self._eval_start(st.value, p)
                if base in self._propagated:
                    y[i] = self._propagated[base]
        return y

    def state_guess_order(self):
        """State slots in the order their guesses are imposed when the fixed
        starts leave degrees of freedom (declared non-zero starts first)."""
        ns = self.dae.n_states
        guess = self.guess_vector(self.param_vector())
        return sorted(range(ns), key=lambda i: (guess[i] == 0.0, i))

    def discrete_start(self):
        return [float(d.start.value) for d in self.discretes]

    def callbacks(self, p, d):
        return self._make(list(map(float, p)), list(map(float, d)))

    def simulate(self, **kw):
        from .simulate import simulate
        return simulate(self, **kw)


def _open_across(model, flat, red):
    """Connector across variables left as unknowns with no start of their own
    (a zero guess): the positions and angles of the frames between planar
    links, which only the equations can place."""
    out = set()
    unknowns = set(red.unknowns)
    for comp in model.walk():
        for name in comp.connectors():
            for a, _ in comp.port(name).pairs():
                st = flat.variables[a.name].start
                if a in unknowns and not st.fixed and st.value == 0:
                    out.add(a)
    return out


def _propagate_starts(equations, values, open_vars, max_rounds=50):
    """Start values of ``open_vars`` propagated through the equations (each
    equation with one of them left, linear in it, gives its value from the
    others), so that the Jacobians of the state selection are evaluated at
    a configuration the equations describe (a planar loop whose link angles
    all start at 0 would look like a dead centre). The Modelica tools'
    start-value propagation; only the values for the structural stages
    change, not the initialisation's guesses."""
    vals = dict(values)
    todo = set(open_vars)
    for _ in range(max_rounds):
        progress = False
        for eq in equations:
            left = [s for s in eq.expr.free_symbols if s in todo]
            if len(left) != 1:
                continue
            u = left[0]
            coeff = sp.diff(eq.expr, u)
            if coeff.has(u):
                continue
            try:
                c = float(coeff.xreplace(vals))
                rest = float(eq.expr.xreplace({u: 0}).xreplace(vals))
            except (TypeError, ValueError):
                continue
            if abs(c) > 1e-12 and np.isfinite(rest):
                vals[u] = -rest / c
                todo.discard(u)
                progress = True
        if not progress or not todo:
            break
    return vals


def _alias_starts(flat, red):
    """Start values given on variables eliminated as aliases, carried to the
    variable that stays (``root``): root symbol -> :class:`Start`.

    A root without a fixed start takes the fixed start of an alias (first by
    name), else, if its own start is a zero guess, the first non-zero guess
    of an alias; ``x = s*root + o`` gives ``root = (x0 - o)/s``. Fixed starts
    of aliases are still imposed by name at initialisation; this only makes
    them (and guesses) reach the state selection and the initial guess.
    """
    groups = {}
    for x, expr in red.aliases.items():
        roots = [s for s in expr.free_symbols if s.name in flat.variables]
        if len(roots) != 1:
            continue
        r = roots[0]
        sign = sp.diff(expr, r)
        if sign not in (1, -1):
            continue
        groups.setdefault(r, []).append((x, sign, expr - sign * r))
    out = {}
    for r, members in groups.items():
        own = flat.variables[r.name].start
        if own.fixed:
            continue
        members.sort(key=lambda m: m[0].name)
        starts = [(flat.variables[x.name].start, sign, off) for x, sign, off in members]
        pick = next((m for m in starts if m[0].fixed), None)
        if pick is None and _is_zero(own.value):
            pick = next((m for m in starts if not _is_zero(m[0].value)), None)
        if pick is not None:
            st, sign, off = pick
            out[r] = Start((sp.sympify(st.value) - off) / sign, st.fixed)
    return out


def _is_zero(v):
    try:
        return float(v) == 0.0
    except (TypeError, ValueError):
        return False


def compile_model(model):
    """Compile ``model`` (flatten, reduce, generate)."""
    return CompiledModel(model)
