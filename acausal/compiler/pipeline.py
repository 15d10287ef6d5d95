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
from ..runtime.backends import choose_linear_solver
from .causalize import build_dae
from ..infra import store as _cache
from .codegen import Triplets, generate, load as load_generated
from ..lang.declare import Start
from ..errors import ModelError, ParameterError, UsageError
from ..lang.fastdiff import diff
from .flatten import flatten
from .units import check_units
from .structure import Graph, check_structure, dummy_derivatives, pantelides
from ..lang.symbols import base_and_order, der, time


@dataclass
class ParamEntry:
    name: str
    default: float
    unit: str
    desc: str
    decl: object
    owner: str


def _start_function(e, param_syms):
    """``fn(p)`` evaluating the start-value expression ``e`` of parameters at
    the parameter vector ``p``. Only the parameters ``e`` uses are passed,
    under plain names given in one unevaluated replacement: lambdify itself
    would rename every dotted parameter name (about 40 on the breaker) by a
    replacement each, and re-evaluate the Min/Max of a linkage's closure
    angle at each (0.6 s per expression)."""
    index = {s: i for i, s in enumerate(param_syms)}
    used = sorted((s for s in e.free_symbols if s in index), key=lambda s: s.name)
    if set(used) != e.free_symbols:      # not a function of the parameters alone:
        return sp.lambdify([param_syms], e, "math")   # (fails as it always did)
    plain = [sp.Symbol(f"_start_p{k}") for k in range(len(used))]
    with sp.evaluate(False):
        e = e.xreplace(dict(zip(used, plain)))
    f = sp.lambdify(plain, e, "math")
    at = [index[s] for s in used]
    return lambda p: f(*[p[i] for i in at])


class CompiledModel:
    """A model turned into solver callbacks. Use :meth:`simulate`."""

    def __init__(self, model, cache=True):
        t0 = _time.perf_counter()
        self.model = model
        flat = self.flat = flatten(model)
        # wall time of each compile stage [s] (benchmarks/scaling.py prints them)
        self.stage_s = {"flatten": _time.perf_counter() - t0}
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
        self.var_names = list(flat.variables)
        self.events = list(flat.events)
        self.assertions = list(flat.assertions)
        self.stop_events = []
        self.n_roots = len(self.events) + len(self.assertions)
        self._start_fns = {}
        key = _cache.model_key(flat) if cache and _cache.cache_dir() is not None else None
        entry = _cache.load(key) if key is not None else None
        self.cache_hit = entry is not None
        if entry is None:
            entry, make, fixjac = self._compile(flat, key)
            if key is not None:
                _cache.store(entry)
        else:
            make, fixjac = load_generated(entry.source)
        self.reduced, self.graph, self.dae = entry.reduced, entry.graph, entry.dae
        self._root_starts, self._root_via = entry.root_starts, entry.root_via or {}
        self._propagated = entry.propagated or {}
        self._subs = dict(self.reduced.param_subs)
        self._alias = self.reduced.subs
        self.source, self._make, self._fixjac = entry.source, make, fixjac
        self.sparsity = entry.sparsity
        self.compile_s = _time.perf_counter() - t0

    def _compile(self, flat, key):
        """The compile stages after flattening: an :class:`acausal.cache.Entry`
        and the compiled ``make`` and ``fixjac``."""
        clock = _Stages(self.stage_s)
        check_units(flat)
        clock.lap("units")
        red = self.reduced = eliminate_aliases(flat)
        clock.lap("aliases")
        check_structure(red.equations, red.unknowns, flat)
        g = self.graph = Graph(red.equations, red.unknowns)
        pantelides(g)
        self._root_starts, self._root_via = _alias_starts(flat, red)
        open_across = _open_across(self.model, flat, red)
        values = _propagate_starts(red.equations, self._start_values(), open_across)
        # guesses of the frames' positions and angles (at the default parameters)
        self._propagated = {s: values[s] for s in open_across if s in values}
        fixed = {v.symbol for v in flat.variables.values() if v.start.fixed}
        fixed |= {r for r, st in self._root_starts.items() if st.fixed}
        dummies = dummy_derivatives(g, values, lambda s: base_and_order(s)[0] in fixed)
        clock.lap("structure")
        self.dae = build_dae(g, dummies, set(self.param_syms), values)
        clock.lap("causalize")
        self._subs = dict(red.param_subs)
        self._alias = red.subs
        observed = self.observed_exprs()
        roots = [self.resolve(e.expr) for e in self.events] + \
                [self.resolve(a.expr) for a in self.assertions]
        fixed_rows = [k for k, n in enumerate(self.var_names)
                      if flat.variables[n].start.fixed]
        gen = generate(self.dae, self.param_syms, self.disc_syms, roots, observed, fixed_rows)
        clock.lap("codegen")
        entry = _cache.Entry(key, red, g, self._root_starts, self.dae, gen.source,
                             gen.sparsity, self._root_via, self._propagated)
        return entry, gen.make, gen.fixjac

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
        known = self.__dict__.get("_known")
        if known is None:
            known = self._known = set(self.dae.y) | {s for s in self.dae.yp if s is not None} \
                | set(self.param_syms) | set(self.disc_syms) | {time}
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
            try:
                value = float(value)
            except (TypeError, ValueError):
                raise ParameterError(f"parameter {name} must be a number [{e.unit}], got "
                                     f"{value!r}", variable=name) from None
            if not np.isfinite(value):
                raise ParameterError(f"parameter {name} = {value} [{e.unit}] is not a finite "
                                     "number", variable=name)
            e.decl.check_bounds(value, name)
            p[i] = value
        return p

    def split_overrides(self, overrides):
        """(parameter overrides, start overrides) from one dict of dotted path
        -> value. A name of a variable with a fixed start value (``m2.v``,
        ``armature.mass.v``) sets that start value for this run: start values
        are runtime values, like parameters (the initialisation imposes them
        by name; nothing is regenerated). Other names are left to
        :meth:`param_vector`, which checks them as parameters."""
        params, starts = {}, {}
        free = {e.name for e in self.params}
        for name, value in (overrides or {}).items():
            info = self.flat.variables.get(name)
            if name in free or info is None:
                params[name] = value
                continue
            if not info.start.fixed:
                raise ParameterError(
                    f"{name} is a variable whose start value is only a guess (not fixed), "
                    "so it cannot be set; fixed start values and parameters can")
            value = float(value)
            if not np.isfinite(value):
                raise ParameterError(f"start value {name} = {value} is not finite [{info.unit}]")
            starts[name] = value
        return params, starts

    def _eval_start(self, value, p):
        """A start value, which may be an expression of parameters."""
        if isinstance(value, sp.Basic) and not value.is_number:
            fn = self._start_fns.get(value)
            if fn is None:  # compiled once per expression (it runs every simulation)
                fn = self._start_fns[value] = _start_function(value.xreplace(self._subs),
                                                              self.param_syms)
            return float(fn(p))
        return float(value)

    def fixed_jacobian(self, sparse=False):
        """A function ``(t, *y, *yp, *p, *d)`` -> d(fixed-start variables)/d(y,
        y'_states) as a dense array (a ``scipy.sparse`` CSR matrix with
        ``sparse``): the rows the initialisation adds for fixed starts
        (generated with the other callbacks, non-zeros only)."""
        n, ns = len(self.dae.y), self.dae.n_states
        n_fixed = len(self._start_plan()[0])
        npar = len(self.param_syms)
        fill = self._fixjac

        def fixed_jac(t, *args):
            F = Triplets((n_fixed, n + ns)) if sparse else np.zeros((n_fixed, n + ns))
            fill(t, args[:n], args[n:2 * n], args[2 * n:2 * n + npar], args[2 * n + npar:], F)
            return F.tocsr() if sparse else F
        return fixed_jac

    def state_slot_of(self, name):
        """(slot, sign) when variable ``name`` is ±(one state slot), else None."""
        cache = self.__dict__.setdefault("_slot_cache", {})
        if name not in cache:
            e = self.resolve(sp.Symbol(name))
            sign = 1.0
            if isinstance(e, sp.Mul) and len(e.args) == 2 and e.args[0] == -1:
                sign, e = -1.0, e.args[1]
            slots = self.__dict__.get("_state_slots")
            if slots is None:
                slots = self._state_slots = {s: i for i, s in
                                             enumerate(self.dae.y[:self.dae.n_states])}
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

    def fixed_starts(self, p, starts=None):
        """(index in var_names, value, name) of every fixed start value;
        ``starts`` (name -> value, see :meth:`split_overrides`) replaces the
        declared ones."""
        starts = starts or {}
        return [(k, float(starts[name]) if name in starts else self._start_value(value, p),
                 name) for k, name, value in self._start_plan()[0]]

    def guess_vector(self, p, starts=None):
        """Initial guess of y from the start values of the variables (with
        the overridden ``starts``, also where they reach a slot through an
        alias ``x = sign*root + off``)."""
        starts = starts or {}
        y = np.zeros(len(self.dae.y))
        for i, name, via, value, propagated in self._start_plan()[1]:
            if name in starts:
                y[i] = starts[name]
            elif via is not None and via[0] in starts:
                y[i] = (starts[via[0]] - self._start_value(via[2], p)) / via[1]
            elif propagated is not None:
                y[i] = propagated
            else:
                y[i] = self._start_value(value, p)
        return y

    def _start_plan(self):
        """(fixed, slots), made once per model: ``fixed`` the (index in
        var_names, name, start value) of each fixed start, ``slots`` the
        (slot, variable name, alias (name, sign, offset) or None, start
        value, propagated value or None) of each slot that is a variable
        itself (not a derivative), for :meth:`fixed_starts` and
        :meth:`guess_vector` (which run at every simulation's start). Start
        values are floats, or expressions of parameters (evaluated then)."""
        plan = self.__dict__.get("_start_plans")
        if plan is None:
            fixed = [(k, name, self._start_form(self.flat.variables[name].start.value))
                     for k, name in enumerate(self.var_names)
                     if self.flat.variables[name].start.fixed]
            slots = []
            for i, s in enumerate(self.dae.y):
                base, k = base_and_order(s)
                info = self.flat.variables.get(base.name)
                if k != 0 or info is None:
                    continue
                via = self._root_via.get(base)
                if via is not None:
                    via = (via[0], via[1], self._start_form(via[2]))
                st = self._root_starts.get(base, info.start)
                slots.append((i, base.name, via, self._start_form(st.value),
                              self._propagated.get(base)))
            plan = self._start_plans = (fixed, slots)
        return plan

    @staticmethod
    def _start_form(value):
        """A start value as :meth:`_start_plan` keeps it: a float, or the
        expression when it depends on parameters."""
        if isinstance(value, sp.Basic) and not value.is_number:
            return value
        return float(value)

    def _start_value(self, value, p):
        """A start value as :meth:`_start_form` keeps it, at parameters ``p``."""
        if type(value) is float:
            return value
        fn = self._start_fns.get(value)
        return self._eval_start(value, p) if fn is None else float(fn(p))

    def state_guess_order(self):
        """State slots in the order their guesses are imposed when the fixed
        starts leave degrees of freedom (declared non-zero starts first)."""
        order = getattr(self, "_guess_order", None)
        if order is None:   # (of the default values: made once per model)
            ns = self.dae.n_states
            guess = self.guess_vector(self.param_vector())
            order = self._guess_order = sorted(range(ns), key=lambda i: (guess[i] == 0.0, i))
        return list(order)

    def discrete_start(self):
        return [float(d.start.value) for d in self.discretes]

    def y_column(self, name):
        """The column of the DAE's unknowns y that variable ``name`` is
        (directly, as itself or an alias), else None: a result then reads it
        without evaluating every observed variable at every output."""
        cols = self.__dict__.setdefault("_y_columns", {})
        if name not in cols:
            e = self.resolve(self.flat.variables[name].symbol)
            cols[name] = self.dae.y.index(e) if e in self.dae.y else None
        return cols[name]

    def observed_exprs(self):
        """The expressions the observe callback computes: every variable of
        :attr:`var_names`, resolved to the DAE's unknowns."""
        return [self.resolve(self.flat.variables[n].symbol) for n in self.var_names]

    def callbacks(self, p, d):
        """(res, jac, roots, jacs, observe, count, jac_csc) for parameter vector
        ``p`` and discrete values ``d``: ``jac`` fills a 2-D (dense or band)
        matrix, ``jac_csc`` the flat compressed-sparse-column array of
        :attr:`sparsity`."""
        return self._make(list(map(float, p)), list(map(float, d)))

    def linear_solver(self, kind="auto"):
        """The IDA linear solver for this model's iteration matrix, chosen from
        its structure (:attr:`sparsity`): a :class:`acausal.backends.LinearSolver`.

        ``kind``: ``"dense"``, ``"band"`` (bandwidths from the pattern),
        ``"sparse"`` (SuperLU_MT on the CSC pattern; the Jacobian callback is
        then ``callbacks(...)[6]``) or ``"auto"``: dense below
        :data:`acausal.backends.BAND_MIN_SIZE` unknowns or when the band is not narrow, else
        band."""
        return choose_linear_solver(self.sparsity, kind)

    def simulate(self, **kw):
        from ..runtime.hybrid import simulate
        return simulate(self, **kw)

    def simulate_batch(self, param_sets, **kw):
        """One simulation per parameter set, in parallel worker processes that
        hold this compiled model: see :func:`acausal.batch.simulate_batch`."""
        from ..runtime.batch import simulate_batch
        return simulate_batch(self, param_sets, **kw)


class _Stages:
    """Records the wall time since the previous lap under each stage name."""

    def __init__(self, out):
        self.out, self.t = out, _time.perf_counter()

    def lap(self, name):
        now = _time.perf_counter()
        self.out[name] = now - self.t
        self.t = now


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
            coeff = diff(eq.expr, u)
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
    variable that stays (``root``): (root symbol -> :class:`Start`, root
    symbol -> (alias name, sign, offset) of the alias it was taken from).

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
        sign = diff(expr, r)
        if sign not in (1, -1):
            continue
        groups.setdefault(r, []).append((x, sign, expr - sign * r))
    out, via = {}, {}
    for r, members in groups.items():
        own = flat.variables[r.name].start
        if own.fixed:
            continue
        members.sort(key=lambda m: m[0].name)
        starts = [(flat.variables[x.name].start, sign, off, x.name)
                  for x, sign, off in members]
        pick = next((m for m in starts if m[0].fixed), None)
        if pick is None and _is_zero(own.value):
            pick = next((m for m in starts if not _is_zero(m[0].value)), None)
        if pick is not None:
            st, sign, off, name = pick
            out[r] = Start((sp.sympify(st.value) - off) / sign, st.fixed)
            via[r] = (name, float(sign), off)
    return out, via


def _is_zero(v):
    try:
        return float(v) == 0.0
    except (TypeError, ValueError):
        return False


def compile_model(model, cache=True):
    """Compile ``model`` (flatten, reduce, generate). With ``cache`` (and the
    cache not disabled by ``ACAUSAL_CACHE=off``) the compiled stages are read
    from / written to the on-disk cache (:mod:`acausal.cache`)."""
    return CompiledModel(model, cache=cache)
