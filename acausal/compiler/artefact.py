"""The compiler's product: a frozen record of one compiled model.

:func:`acausal.compiler.pipeline.compile_artefact` makes one
:class:`Artefact` per model structure; nothing is written into it after
(its fields cannot be rebound; the runtime keeps its own per-model and
per-run caches, :mod:`acausal.runtime`). Its parts:

* the stages' outputs: the flattened model, the reduced equations, the
  matching graph, the DAE (:mod:`.flatten` ... :mod:`.causalize`), and the
  generated code (:class:`~acausal.compiler.codegen.Generated`, whose
  ``make(p, d)`` gives a mode's :class:`~acausal.compiler.codegen.Callbacks`);
* :class:`ParameterSpace` -- the free parameters in vector order (defaults,
  units, bounds), the structural and the bound ones, and how a run's
  overrides (``params={...}``) split into parameters and start values;
* :class:`StartPlan` -- the start values: fixed starts imposed by name, the
  initial guess of each solver slot (carried through aliases and propagated
  through the equations: the Modelica tools' start-value propagation), and
  the order in which state guesses are imposed;
* :class:`Resolver` -- model symbols rewritten in the DAE's unknowns;
* the solver-slot lookups (which unknown each variable is, up to sign;
  which discrete values the equations use; what an event action may read).

Lookups derived from these (a variable's slot, the slot table, the state
guesses' order) are computed on first use and memoised by the record's own
methods, which give the same answer every time.
"""
import hashlib
from dataclasses import dataclass, field, replace
from functools import cached_property

import numpy as np
import sympy as sp

from ..errors import ModelError, ParameterError
from ..lang.symbols import base_and_order, time
from .codegen import Triplets
from .substitute import Substitution, substitute


@dataclass(frozen=True)
class ParamEntry:
    """One free parameter: dotted ``name``, ``default`` value, ``unit``,
    description ``desc``, its declaration ``decl`` (bounds) and ``owner``
    component path."""
    name: str
    default: float
    unit: str
    desc: str
    decl: object
    owner: str


@dataclass(frozen=True)
class ParameterSpace:
    """The model's parameters: ``entries`` (:class:`ParamEntry`) and
    ``symbols`` of the free ones, in the order of the parameter vector;
    ``structural`` (name -> value: they change the equations) and ``bound``
    (name -> value expression) ones, which a run cannot set; ``bindings``
    (bound parameter symbol -> expression of free ones)."""
    entries: tuple
    symbols: tuple
    structural: dict
    bound: dict
    bindings: dict

    @classmethod
    def of(cls, flat, bindings):
        """The parameter space of flattened model ``flat``."""
        entries = tuple(ParamEntry(i.symbol.name, float(i.value), i.decl.unit, i.decl.desc,
                                   i.decl, i.owner)
                        for i in flat.params.values()
                        if not i.decl.structural and not i.bound)
        return cls(entries, tuple(sp.Symbol(e.name) for e in entries),
                   {i.symbol.name: i.value for i in flat.params.values()
                    if i.decl.structural},
                   {i.symbol.name: i.value for i in flat.params.values()
                    if not i.decl.structural and i.bound},
                   dict(bindings))

    @cached_property
    def _defaults(self):
        return np.array([e.default for e in self.entries], dtype=float)

    @cached_property
    def _positions(self):
        out = {}
        for i, e in enumerate(self.entries):
            out.setdefault(e.name, i)
        return out

    def index(self, name):
        """Position of free parameter ``name`` in the vector; a
        ParameterError saying why another name cannot be set."""
        i = self._positions.get(name)
        if i is not None:
            return i
        if name in self.bound:
            raise ParameterError(f"parameter {name} is bound to {self.bound[name]}; "
                                 "set the parameters it depends on instead")
        if name in self.structural:
            raise ParameterError(f"parameter {name} is structural (it changes the equations); "
                                 "set it in the model file")
        raise ParameterError(f"the model has no parameter {name!r}")

    def vector(self, overrides=None):
        """Free parameter values with ``overrides`` (name -> value) applied and
        checked against each parameter's bounds."""
        p = self._defaults.copy()
        for name, value in (overrides or {}).items():
            i = self.index(name)
            e = self.entries[i]
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

    def with_defaults(self, values):
        """This space with the free parameters ``values`` (name -> value,
        checked against their bounds) as their defaults."""
        new = {}
        for name, v in values.items():
            e = self.entries[self.index(name)]
            e.decl.check_bounds(float(v), name)
            new[name] = float(v)
        return replace(self, entries=tuple(replace(e, default=new[e.name]) if e.name in new
                                           else e for e in self.entries))

    def split(self, overrides, variables):
        """(parameter overrides, start overrides) from one dict of dotted path
        -> value. A name of a variable with a fixed start value (``m2.v``,
        ``armature.mass.v``; ``variables``: the flattened model's) sets that
        start value for this run: start values are runtime values, like
        parameters (the initialisation imposes them by name; nothing is
        regenerated). Other names are left to :meth:`vector`, which checks
        them as parameters."""
        params, starts = {}, {}
        for name, value in (overrides or {}).items():
            info = variables.get(name)
            if name in self._positions or info is None:
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


def start_function(e, param_syms):
    """``fn(p)`` evaluating the start-value expression ``e`` of parameters at
    the parameter vector ``p``. Only the parameters ``e`` uses are passed,
    under plain names given in one unevaluated replacement: lambdify itself
    would rename every dotted parameter name (about 40 on the breaker) by a
    replacement each, and re-evaluate the Min/Max of a linkage's closure
    angle at each (0.6 s per expression)."""
    index = {s: i for i, s in enumerate(param_syms)}
    used = sorted((s for s in e.free_symbols if s in index), key=lambda s: s.name)
    if set(used) != e.free_symbols:      # not a function of the parameters alone:
        return sp.lambdify([list(param_syms)], e, "math")   # (fails as it always did)
    plain = [sp.Symbol(f"_start_p{k}") for k in range(len(used))]
    with sp.evaluate(False):
        e = e.xreplace(dict(zip(used, plain)))
    f = sp.lambdify(plain, e, "math")
    at = [index[s] for s in used]
    return lambda p: f(*[p[i] for i in at])


def _start_form(value):
    """A start value as the plan keeps it: a float, or the expression when
    it depends on parameters."""
    if isinstance(value, sp.Basic) and not value.is_number:
        return value
    return float(value)


@dataclass(frozen=True)
class StartPlan:
    """The start values, planned once per model (they are evaluated at every
    simulation's start). ``fixed``: (index in var_names, name, start value)
    of each fixed start; ``slots``: (slot, variable name, alias (name, sign,
    offset) or None, start value, propagated value or None) of each solver
    slot that is a variable itself (not a derivative). Start values are
    floats, or expressions of parameters (evaluated at the run's
    parameters, through ``bindings``: bound parameter -> its expression)."""
    fixed: tuple
    slots: tuple
    param_syms: tuple
    bindings: dict
    defaults: tuple          # the parameters' default values (the guesses' order)
    n: int                   # solver unknowns
    n_states: int
    _functions: dict = field(default_factory=dict, repr=False, compare=False)
    _order: list = field(default_factory=list, repr=False, compare=False)

    @classmethod
    def of(cls, flat, entry, parameters):
        """The plan of flattened model ``flat`` compiled as ``entry``
        (:class:`acausal.compiler.cache.Entry`)."""
        fixed = tuple((k, name, _start_form(info.start.value))
                      for k, (name, info) in enumerate(flat.variables.items())
                      if info.start.fixed)
        slots = []
        for i, s in enumerate(entry.dae.y):
            base, k = base_and_order(s)
            info = flat.variables.get(base.name)
            if k != 0 or info is None:
                continue
            via = (entry.root_via or {}).get(base)
            if via is not None:
                via = (via[0], via[1], _start_form(via[2]))
            st = entry.root_starts.get(base, info.start)
            slots.append((i, base.name, via, _start_form(st.value),
                          (entry.propagated or {}).get(base)))
        return cls(fixed, tuple(slots), parameters.symbols, parameters.bindings,
                   tuple(e.default for e in parameters.entries), len(entry.dae.y),
                   entry.dae.n_states)

    def value(self, form, p):
        """A start value of the plan at parameters ``p``."""
        if type(form) is float:
            return form
        fn = self._functions.get(form)
        if fn is None:  # made once per expression (it runs every simulation)
            fn = self._functions[form] = start_function(form.xreplace(self.bindings),
                                                        self.param_syms)
        return float(fn(p))

    def fixed_values(self, p, starts=None):
        """(index in var_names, value, name) of every fixed start value;
        ``starts`` (name -> value, see :meth:`ParameterSpace.split`) replaces
        the declared ones."""
        starts = starts or {}
        return [(k, float(starts[name]) if name in starts else self.value(form, p), name)
                for k, name, form in self.fixed]

    def guess_vector(self, p, starts=None):
        """Initial guess of the solver's unknowns y from the start values of
        the variables (with the overridden ``starts``, also where they reach
        a slot through an alias ``x = sign*root + off``)."""
        starts = starts or {}
        y = np.zeros(self.n)
        for i, name, via, form, propagated in self.slots:
            if name in starts:
                y[i] = starts[name]
            elif via is not None and via[0] in starts:
                y[i] = (starts[via[0]] - self.value(via[2], p)) / via[1]
            elif propagated is not None:
                y[i] = propagated
            else:
                y[i] = self.value(form, p)
        return y

    def guess_order(self):
        """State slots in the order their guesses are imposed when the fixed
        starts leave degrees of freedom (declared non-zero starts first, at
        the default parameters; made once per model)."""
        if not self._order:
            guess = self.guess_vector(np.array(self.defaults, dtype=float))
            self._order.append(sorted(range(self.n_states), key=lambda i: (guess[i] == 0.0, i)))
        return list(self._order[0])


@dataclass(frozen=True)
class Resolver:
    """Rewrites expressions of model symbols in the DAE's y and y' symbols,
    free parameters, discrete values and time: parameter ``bindings``, then
    ``aliases`` (and their derivatives), then the DAE's ``explicit``
    solutions (each a :class:`~acausal.compiler.substitute.Substitution`);
    ``known`` the symbols a result may contain. Each expression is rewritten
    once per resolver (the events' conditions are resolved for the Python
    code, again for the C code and for the sensitivities' roots), and each
    substitution is remembered across the models a process compiles
    (:func:`~acausal.compiler.substitute.substitute`: on the planar breaker
    the event conditions' rewriting had been 0.1-0.2 s of every model build)."""
    bindings: Substitution
    aliases: Substitution
    explicit: Substitution
    known: frozenset
    _done: dict = field(default_factory=dict, compare=False, repr=False)

    @classmethod
    def of(cls, reduced, dae, param_syms, disc_syms):
        known = frozenset(set(dae.y) | {s for s in dae.yp if s is not None}
                          | set(param_syms) | set(disc_syms) | {time})
        return cls(Substitution(reduced.param_subs), Substitution(reduced.subs),
                   Substitution(dae.explicit or {}), known)

    def __call__(self, expr):
        e = sp.sympify(expr)
        done = self._done.get(e)
        if done is not None:
            return done
        out = self._rewrite(e, expr)
        self._done[e] = out
        return out

    def _rewrite(self, e, expr):
        for sub in (self.bindings, self.aliases, self.explicit):
            e = substitute(e, sub)
        bad = [s for s in e.free_symbols if s not in self.known]
        if bad:
            raise ModelError(f"{expr} cannot be evaluated: {bad[0].name} is not available "
                             "(a derivative the model never needs, or an unknown name)")
        return e


@dataclass(frozen=True)
class BuildInfo:
    """How the artefact was made: wall time of each compile stage [s]
    (``stage_s``; benchmarks/scaling.py prints them), the whole compile
    ``compile_s`` [s], whether it was read from the store (``cache_hit``)
    and the store's key of the model (``key``: a digest of the flattened
    model and the compiler; None when the store was not used)."""
    stage_s: dict
    compile_s: float
    cache_hit: bool
    key: str | None = None


@dataclass(frozen=True, eq=False)
class Artefact:
    """One compiled model (see the module doc). ``model``: the
    :class:`~acausal.Model` it was compiled from (its components explain
    failures in their own terms); ``flat``, ``reduced``, ``graph``, ``dae``:
    the stages' outputs; ``code``: the generated callbacks
    (:class:`~acausal.compiler.codegen.Generated`)."""
    model: object
    flat: object
    reduced: object
    graph: object
    dae: object
    parameters: ParameterSpace
    starts: StartPlan
    resolve: Resolver
    code: object
    build: BuildInfo
    var_names: tuple = field(init=False)
    discretes: tuple = field(init=False)
    disc_syms: tuple = field(init=False)
    events: tuple = field(init=False)
    assertions: tuple = field(init=False)
    n_roots: int = field(init=False)
    _memo: dict = field(default_factory=dict, init=False, repr=False)

    def __post_init__(self):
        put = object.__setattr__   # (a frozen dataclass's own derived fields)
        put(self, "var_names", tuple(self.flat.variables))
        put(self, "discretes", tuple(self.flat.discretes.values()))
        put(self, "disc_syms", tuple(d.symbol for d in self.discretes))
        put(self, "events", tuple(self.flat.events))
        put(self, "assertions", tuple(self.flat.assertions))
        put(self, "n_roots", len(self.events) + len(self.assertions))

    def with_defaults(self, values):
        """This artefact with the free parameters ``values`` (name -> value,
        checked against their bounds) as their defaults; it shares
        everything else, the generated code too."""
        parameters = self.parameters.with_defaults(values)
        starts = replace(self.starts, defaults=tuple(e.default for e in parameters.entries))
        return replace(self, parameters=parameters, starts=starts)

    # -- the generated code ----------------------------------------------------
    def identity(self):
        """A digest that fixes the compiled equations, for the stores of what
        is derived from them (the compiled backend's libraries, the
        sensitivity models): the compile store's key, else (no store) the
        digest of the generated Python source."""
        if self.build.key is not None:
            return self.build.key
        return hashlib.sha256(self.code.source.encode()).hexdigest()

    def callbacks(self, p, d):
        """The :class:`~acausal.compiler.codegen.Callbacks` of parameter vector
        ``p`` and discrete values ``d``."""
        return self.code.make(list(map(float, p)), list(map(float, d)))

    def fixed_jacobian(self, sparse=False):
        """A function ``(t, *y, *yp, *p, *d)`` -> d(fixed-start variables)/d(y,
        y'_states) as a dense array (a ``scipy.sparse`` CSR matrix with
        ``sparse``): the rows the initialisation adds for fixed starts
        (generated with the other callbacks, non-zeros only)."""
        n, ns = len(self.dae.y), self.dae.n_states
        n_fixed = len(self.starts.fixed)
        npar = len(self.parameters.symbols)
        code = self.code     # (its Python is written when a run first needs it)

        def fixed_jac(t, *args):
            F = Triplets((n_fixed, n + ns)) if sparse else np.zeros((n_fixed, n + ns))
            code.fixjac(t, args[:n], args[n:2 * n], args[2 * n:2 * n + npar],
                        args[2 * n + npar:], F)
            return F.tocsr() if sparse else F
        return fixed_jac

    def discrete_start(self):
        """The discrete values' start values."""
        return [float(d.start.value) for d in self.discretes]

    def observed_exprs(self):
        """The expressions the observe callback computes: every variable of
        :attr:`var_names`, resolved to the DAE's unknowns."""
        return [self.observed_expr(n) for n in self.var_names]

    def observed_expr(self, name):
        """Variable ``name`` resolved to the DAE's unknowns (one entry of
        :meth:`observed_exprs`)."""
        return self.resolve(self.flat.variables[name].symbol)

    # -- solver slots ------------------------------------------------------------
    def _memoised(self, kind, key, make):
        table = self._memo.setdefault(kind, {})
        if key not in table:
            table[key] = make()
        return table[key]

    def state_slot_of(self, name):
        """(slot, sign) when variable ``name`` is ±(one state slot), else None."""
        def make():
            e, sign = _unsigned(self.resolve(sp.Symbol(name)))
            slots = self._memoised("state slots", None, lambda: {
                s: i for i, s in enumerate(self.dae.y[:self.dae.n_states])})
            return (slots[e], sign) if e in slots else None
        return self._memoised("state slot", name, make)

    def y_column(self, name):
        """The column of the DAE's unknowns y that variable ``name`` is
        (directly, as itself or an alias), else None: a result then reads it
        without evaluating every observed variable at every output."""
        def make():
            e = self.resolve(self.flat.variables[name].symbol)
            return self.dae.y.index(e) if e in self.dae.y else None
        return self._memoised("y column", name, make)

    def slot_names(self):
        """For each solver unknown, the names that denote it up to sign: its
        own symbol and every variable that resolves to ±it."""
        def make():
            names = [[s.name] for s in self.dae.y]
            index = {s: i for i, s in enumerate(self.dae.y)}
            for name in self.var_names:
                e = _unsigned(self.resolve(sp.Symbol(name)))[0]
                if e in index:
                    names[index[e]].append(name)
            return names
        return self._memoised("slot names", None, make)

    def scaled_slot_of(self, name):
        """(slot, gain) when variable ``name`` is ``gain*y[slot] + offset``
        (``gain`` a non-zero number, ``offset`` free of unknowns: an alias
        with a sign, a scale or an offset), else None. A variable that is
        (a multiple of) a state's derivative ``y'_k`` is followed through
        the state's row to the unknown that row equates ``y'_k`` with
        (``w = der(phi)``: the unknown ``w``), when it is one."""
        def make():
            e = self.resolve(sp.Symbol(name))
            hit = _linear_in_one(e, self._memoised("unknown index", None, self._unknown_index))
            if hit is None:
                return None
            (kind, k), gain = hit
            if kind == "y":
                return k, gain
            row = self.dae.residuals[k]
            c = sp.diff(row, self.dae.yp[k])
            if not (c.is_number and c != 0):
                return None
            rest = _linear_in_one(-row.xreplace({self.dae.yp[k]: 0}) / c,
                                  self._memoised("unknown index", None, self._unknown_index))
            if rest is None or rest[0][0] != "y":
                return None
            return rest[0][1], gain * rest[1]
        return self._memoised("scaled slot", name, make)

    def _unknown_index(self):
        index = {s: ("y", i) for i, s in enumerate(self.dae.y)}
        index.update({s: ("yp", i) for i, s in enumerate(self.dae.yp) if s is not None})
        return index

    def dynamic_discretes(self):
        """Indices of the discrete values the residual equations use."""
        def make():
            used = set()
            for r in self.dae.residuals:
                used |= r.free_symbols
            return frozenset(j for j, s in enumerate(self.disc_syms) if s in used)
        return self._memoised("dynamic discretes", None, make)

    def readable(self, name):
        """What an event action reads or sets under ``name``: ("d", discrete
        index) | ("v", index in var_names) | ("p", parameter index) | ("b",
        expression of a parameter bound to others), or None; a name in
        several kinds resolves in that order."""
        def make():
            index = {}
            for s, expr in self.parameters.bindings.items():
                index[s.name] = ("b", expr)
            for j, prm in enumerate(self.parameters.entries):
                index[prm.name] = ("p", j)
            for k, n in enumerate(self.var_names):
                index[n] = ("v", k)
            for j, dsc in enumerate(self.discretes):
                index[dsc.symbol.name] = ("d", j)
            return index
        return self._memoised("readable", None, make).get(name)


def _unsigned(e):
    """(expression, sign) with a leading factor -1 taken out."""
    if isinstance(e, sp.Mul) and len(e.args) == 2 and e.args[0] == -1:
        return e.args[1], -1.0
    return e, 1.0


def _linear_in_one(e, index):
    """((kind, slot), gain) when ``e`` is ``gain*u + rest`` with ``u`` the only
    unknown of ``index`` in it and ``gain`` a non-zero number, else None."""
    e = sp.sympify(e)
    hits = [s for s in e.free_symbols if s in index]
    if len(hits) != 1:
        return None
    gain = sp.diff(e, hits[0])
    if not gain.is_number or gain == 0:
        return None
    return index[hits[0]], float(gain)
