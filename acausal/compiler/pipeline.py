"""The pipeline from a model to generated callbacks, run once per model
structure: flatten -> units -> aliases -> structure check -> Pantelides (1988) ->
dummy derivatives (Mattsson and Soederlind 1993) -> causalize -> codegen.
The result, a frozen :class:`~acausal.compiler.artefact.Artefact`, serves
any number of simulations (parameter sets, start values) without
re-generating anything; the runtime simulates it
(:func:`acausal.runtime.model.compile_model` wraps this module's
:func:`compile_artefact`). The stages' outputs are kept in the store's
``compile`` namespace (:mod:`acausal.compiler.cache`).
"""
import dataclasses
import time as _time

import numpy as np
import sympy as sp

from . import cache as compile_cache
from .aliases import eliminate_aliases
from .artefact import Artefact, BuildInfo, ParameterSpace, Resolver, StartPlan
from .causalize import build_dae
from .codegen import Generated, iteration_sparsity, write_callbacks, write_fixjac
from ..infra import store
from ..lang.declare import Start
from ..lang.fastdiff import diff
from .flatten import flatten
from .units import check_units
from .structure import Graph, check_structure, dummy_derivatives, pantelides
from ..lang.symbols import base_and_order, time


def compile_artefact(model, cache=True):
    """Compile ``model`` (flatten, reduce, generate) into an
    :class:`~acausal.compiler.artefact.Artefact`. With ``cache`` (and the
    store not disabled by ``ACAUSAL_CACHE=off``) the compiled stages are read
    from / written to the store's ``compile`` namespace."""
    t0 = _time.perf_counter()
    flat = flatten(model)
    stage_s = {"flatten": _time.perf_counter() - t0}
    key = compile_cache.model_key(flat) if cache and store.enabled() else None
    entry = compile_cache.load(key) if key is not None else None
    hit = entry is not None
    if entry is None:
        entry = _compile(model, flat, stage_s, key)
        if key is not None:
            compile_cache.save(entry)
    parameters = ParameterSpace.of(flat, entry.reduced.param_subs)
    disc_syms = [d.symbol for d in flat.discretes.values()]
    resolve = Resolver.of(entry.reduced, entry.dae, parameters.symbols, disc_syms)
    if not hit:
        # every variable, event and assertion in the DAE's terms now, so that a
        # model that cannot be evaluated fails at its compile (the resolver
        # keeps them for the code generators)
        _resolve_all(flat, resolve)
    code = _python_code(flat, entry, parameters.symbols, disc_syms, resolve)
    return Artefact(model, flat, entry.reduced, entry.graph, entry.dae, parameters,
                    StartPlan.of(flat, entry, parameters), resolve,
                    code, BuildInfo(stage_s, _time.perf_counter() - t0, hit, key))


def _resolve_all(flat, resolve):
    """(observed, roots): every variable, then every event's and assertion's
    root, resolved (:class:`~acausal.compiler.artefact.Resolver`)."""
    observed = [resolve(info.symbol) for info in flat.variables.values()]
    roots = [resolve(e.expr) for e in flat.events] + [resolve(a.expr) for a in flat.assertions]
    return observed, roots


def _python_code(flat, entry, param_syms, disc_syms, resolve):
    """The model's generated Python callbacks
    (:class:`~acausal.compiler.codegen.Generated`): the store entry's source,
    else each part written at its first use from the resolved roots and
    observed variables (a model the compiled backend runs needs only the
    fixed-start rows), the whole then kept in the store's entry (when it
    has a key)."""
    if entry.source is not None:
        return Generated(entry.sparsity, source=entry.source)
    variables = list(flat.variables.values())

    def write_make():
        observed, roots = _resolve_all(flat, resolve)
        return write_callbacks(entry.dae, list(param_syms), disc_syms, roots, observed)

    def write_fixed():
        fixed = [resolve(info.symbol) for info in variables if info.start.fixed]
        return write_fixjac(entry.dae, list(param_syms), disc_syms, fixed)

    def keep(source):
        if entry.key is not None:
            compile_cache.save(dataclasses.replace(entry, source=source))
    return Generated(entry.sparsity, writers=dict(make=write_make, fixjac=write_fixed),
                     on_write=keep)


def _compile(model, flat, stage_s, key):
    """The compile stages after flattening: a
    :class:`acausal.compiler.cache.Entry` (without the Python source:
    :func:`_python_code`)."""
    param_syms = ParameterSpace.of(flat, {}).symbols
    disc_syms = [d.symbol for d in flat.discretes.values()]
    clock = _Stages(stage_s)
    check_units(flat)
    clock.lap("units")
    red = eliminate_aliases(flat)
    clock.lap("aliases")
    check_structure(red.equations, red.unknowns, flat)
    g = Graph(red.equations, red.unknowns)
    pantelides(g)
    root_starts, root_via = _alias_starts(flat, red)
    open_across = _open_across(model, flat, red)
    values = _propagate_starts(red.equations, _start_values(flat, root_starts, g),
                               open_across)
    # guesses of the frames' positions and angles (at the default parameters)
    propagated = {s: values[s] for s in open_across if s in values}
    fixed = {v.symbol for v in flat.variables.values() if v.start.fixed}
    fixed |= {r for r, st in root_starts.items() if st.fixed}
    dummies = dummy_derivatives(g, values, lambda s: base_and_order(s)[0] in fixed)
    clock.lap("structure")
    dae = build_dae(g, dummies, set(param_syms), values)
    clock.lap("causalize")
    sparsity = iteration_sparsity(dae, list(param_syms), disc_syms)
    clock.lap("codegen")
    # the Python source is written at its first use (_python_code)
    return compile_cache.Entry(key, red, g, root_starts, dae, None, sparsity,
                               root_via, propagated)


def _start_values(flat, root_starts, graph):
    """Every symbol's start value at the default parameters (0 where there
    is none): what the structural stages evaluate their Jacobians at."""
    vals = {}
    for info in flat.params.values():
        if not info.decl.structural:
            vals[info.symbol] = info.value
    for info in flat.variables.values():
        v = info.start.value
        vals[info.symbol] = v
    for r, st in root_starts.items():
        vals[r] = st.value
    for d in flat.discretes.values():
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
    for s in list(graph.vsym):
        out.setdefault(s, 0.0)
    out[time] = 0.0
    return out


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
