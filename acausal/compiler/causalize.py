"""Stage 4: from the index-reduced graph to the DAE that IDA solves.

States are the variable nodes whose derivative is not a dummy. The other
nodes are algebraic. Equations are sorted into blocks (matching + Tarjan's
strongly connected components, via scipy); a scalar block that is linear in
its unknown with a constant coefficient is solved explicitly and substituted
(trivial tearing), so the residual handed to IDA is as small as a hand-written
one. What remains: residuals ``F(t, y, y', p, d) = 0`` over ``y`` = states +
algebraic unknowns of implicit blocks.

Last, :func:`semi_explicit` confines each state derivative that its state
row equates to an algebraic unknown (``y'_k = z_j``) to that row: the other
rows use ``z_j``. This is the semi-explicit index-1 form ``y' = f(y, z),
0 = g(y, z)`` of Brenan, Campbell and Petzold (1996, section 3.2), whose
algebraic rows do not depend on IDA's ``cj``.
"""
import dataclasses
import functools
from dataclasses import dataclass

import numpy as np
import scipy.linalg
import scipy.sparse as sps
from scipy.sparse.csgraph import connected_components, maximum_bipartite_matching
import sympy as sp

from ..errors import StructuralError
from ..lang.fastdiff import diff
from ..lang.symbols import ordered
from .substitute import Substitution, substitute


@dataclass
class DAE:
    y: list            # symbols held in y (states first, then algebraic)
    yp: list           # symbol standing for yp[i] (None for algebraic slots)
    n_states: int
    residuals: list    # sympy expressions, one per y slot
    origins: list      # Equation object (or description) per residual
    explicit: dict     # eliminated algebraic symbol -> expression of y/yp symbols
    # per residual, the y slots its Jacobian row is taken over (None: all):
    # a sensitivity model's iteration matrix keeps only its diagonal blocks
    jacobian_columns: tuple = None


def build_dae(g, dummies, params, values=None):
    """``params``: the set of parameter symbols (constant coefficients)."""
    states, yp_sym, eqs, unknowns = _index1_system(g, dummies)
    yp_set = set(yp_sym.values())
    explicit, residuals, origins, implicit_alg = {}, {}, {}, []
    for block in _blt(eqs, unknowns):
        _causalize_block(block, eqs, unknowns, yp_set, params, values,
                         (explicit, residuals, origins, implicit_alg))
    # order residuals to y slots: state i <-> unknown i (its derivative),
    # algebraic slots follow
    y = [g.vsym[j] for j in states] + implicit_alg
    yp = [yp_sym[j] for j in states] + [None] * len(implicit_alg)
    idx = {u: k for k, u in enumerate(unknowns)}
    res = [residuals.get(k) for k in range(len(states))] + [residuals[idx[u]]
                                                            for u in implicit_alg]
    org = [origins.get(k) for k in range(len(states))] + [origins[idx[u]]
                                                          for u in implicit_alg]
    # states whose derivative was solved explicitly are not possible (yp are
    # never made explicit), so every state row has a residual
    return semi_explicit(DAE(y, yp, len(states), res, org, explicit))


def semi_explicit(dae):
    """``dae`` with every state derivative that its state row equates to an
    algebraic unknown (``c*y'_k - c*z_j``, ``c`` a number) replaced by that
    unknown in the other rows (a new DAE, with the same solutions).

    The dummy derivative method leaves the derivative of a state in
    algebraic rows: a four-bar's acceleration constraints hold
    ``der(der(hook.phi))``, the derivative of the state ``der(hook.phi)``,
    which the state row equates to the algebraic ``der(hook.w)``. IDA's
    iteration matrix ``dF/dy + cj dF/dy'`` then has ``cj`` in those
    algebraic rows. IDA reuses the matrix while ``cj`` changes by up to
    25 %, and it rescales each Newton correction by ``2/(1 + cj/cj_old)``,
    a correction meant for differential rows. Measured on the frictionless
    generic four-bar (docs/planar.md): the Newton iteration left errors of
    a median 6-13 % of the error weights in the accelerations, which enter
    IDA's local error estimates. In 4-5 % of neighbouring runs (decided by
    the last bits of the arithmetic) IDA's step and order control then
    locked into a cycle at order 2: 7000 steps, and an energy drift of 4e-8
    instead of 1e-9. In this form: none of 81 runs, in 35 % fewer steps.
    A derivative that its state row gives as an expression is left where it
    is (substituting expressions was not needed, nor measured)."""
    n, alg = dae.n_states, set(dae.y[dae.n_states:])
    sub = {}
    for k in range(n):
        u, r = dae.yp[k], dae.residuals[k]
        c = diff(r, u)
        if c.is_number and c != 0:
            v = -r.xreplace({u: 0}) / c
            if v in alg:
                sub[u] = v
    if not sub:
        return dae
    rows = [r if k < n else r.xreplace({u: v for u, v in sub.items() if u in r.free_symbols})
            for k, r in enumerate(dae.residuals)]
    return dataclasses.replace(dae, residuals=rows)


def _index1_system(g, dummies):
    """The index-1 system after state selection: (state nodes, state node ->
    its derivative's symbol in yp, equations as (expr, origin), unknowns).
    It keeps every equation and every derivative of it (the dummy
    derivatives are its extra algebraic unknowns)."""
    nv = len(g.vsym)
    states = [j for j in range(nv) if g.vder[j] != -1 and g.vder[j] not in dummies]
    deriv_of_state = {g.vder[j]: j for j in states}
    # y slots: states first, then every other node that is not the plain
    # derivative of a state (those live in yp).
    aux_eqs, yp_sym = [], {}
    for j in states:
        d = g.vder[j]
        if d in states:  # a state whose derivative is also a state: link by an equation
            sym = sp.Symbol(f"__yp__{g.vsym[j].name}")
            yp_sym[j] = sym
            aux_eqs.append((sym - g.vsym[d], f"derivative link der({g.vsym[j].name})"))
        else:
            yp_sym[j] = g.vsym[d]
    alg_nodes = [j for j in range(nv) if j not in set(states) and j not in deriv_of_state]
    eqs = [(g.eexpr[i], g.eorig[i]) for i in range(len(g.eexpr))] + aux_eqs
    unknowns = [yp_sym[j] for j in states] + [g.vsym[j] for j in alg_nodes]
    if len(eqs) != len(unknowns):
        raise StructuralError(f"internal: index-1 system has {len(eqs)} equations for "
                              f"{len(unknowns)} unknowns after state selection")
    return states, yp_sym, eqs, unknowns


def _causalize_block(block, eqs, unknowns, yp_set, params, values, out):
    """One BLT block: unknowns solved explicitly where the block is linear
    in them (never a state derivative), else residuals. ``out`` =
    (explicit, residuals, origins, implicit_alg), filled in place."""
    explicit, residuals, origins, implicit_alg = out
    if len(block) == 1:
        (ei, ui), = block
        expr = _subs(eqs[ei][0], explicit)
        u = unknowns[ui]
        sol = _solve_linear(expr, u, params, values)
        if sol is not None and u not in yp_set:
            explicit[u] = sol
            return
        residuals[ui], origins[ui] = expr, eqs[ei][1]
        if u not in yp_set:
            implicit_alg.append(u)
        return
    exprs = [_subs(eqs[ei][0], explicit) for ei, _ in block]
    us = [unknowns[ui] for _, ui in block]
    sol = _solved_block(exprs, us, params, values)
    if sol is not None:
        for (ei, ui), u, v in zip(block, us, sol):
            if u in yp_set:
                residuals[ui], origins[ui] = u - v, eqs[ei][1]
            else:
                explicit[u] = v
        return
    for ei, ui in block:
        residuals[ui], origins[ui] = _subs(eqs[ei][0], explicit), eqs[ei][1]
        if unknowns[ui] not in yp_set:
            implicit_alg.append(unknowns[ui])


def _subs(expr, explicit):
    """``expr`` with the explicit solutions found so far substituted (their
    keys are unknowns: symbols), remembered across models
    (:func:`~acausal.compiler.substitute.substitute`)."""
    if not explicit:
        return expr
    return substitute(expr, Substitution(explicit, by_symbol=True))


def _numeric(expr, values):
    try:
        v = complex(expr.xreplace(values or {}))
    except (TypeError, ValueError, ZeroDivisionError):
        return float("nan")
    return v.real if abs(v.imag) <= 1e-12 * max(1.0, abs(v.real)) else float("nan")


def _solve_linear(expr, u, params, values=None):
    """u = -rest/coeff when expr is linear in u with a coefficient made of
    numbers and parameters only (never zero in a valid model)."""
    coeff = diff(expr, u)
    if coeff == 0 or coeff.has(u) or not _safe_coefficient(coeff, params):
        return None
    if not coeff.free_symbols <= params:
        # a coefficient of variables: only divide if it is clearly non-zero
        # at the start values (else the matching chose a bad pivot there)
        c = _numeric(coeff, values)
        if not np.isfinite(c) or abs(c) < 1e-9:
            return None
    rest = expr.xreplace({u: 0})
    return -rest / coeff


def _safe_coefficient(c, params):
    """A coefficient we may divide by: numbers and parameters, or smooth
    functions of variables already known (states, earlier blocks) — but never
    a mode-dependent (Piecewise) one, which is zero in some mode (a stuck
    friction element has no force law). A coefficient of known variables can
    still vanish at a singular configuration (a linkage at dead centre);
    components guard those with assertions."""
    if c.free_symbols <= params:
        return True
    return not c.has(sp.Piecewise, sp.Heaviside, sp.sign, sp.Abs, sp.Max, sp.Min)


_BLOCKS = {}          # solved blocks, across the models of a process (insertion order)
_BLOCKS_SIZE = 2_000


def _solved_block(exprs, us, params, values):
    """:func:`_solve_linear_block`, remembered across the models one process
    compiles (the breaker's candidates share its three linear blocks, whose
    solution, ``cancel`` included, was a fifth of each build) under what the
    solution depends on: the equations, the unknowns, which of their
    symbols are parameters and the start values of their symbols (the
    numeric pivots)."""
    syms = set().union(*(e.atoms(sp.Symbol) for e in exprs))
    key = (tuple(exprs), tuple(us), frozenset(syms & params),
           frozenset((s, values[s]) for s in syms if values and s in values))
    try:
        return _BLOCKS[key]
    except KeyError:
        pass
    sol = _solve_linear_block(exprs, us, params, values)
    if len(_BLOCKS) >= _BLOCKS_SIZE:
        _BLOCKS.clear()
    _BLOCKS[key] = sol
    return sol


def _solve_linear_block(exprs, us, params, values=None, max_size=12, max_varying=2):
    """Solve a block of equations linear in its unknowns, with constant
    (parameter) coefficients, symbolically; None when it is not such a block.
    A block whose coefficients depend on variables is solved by
    :func:`_constant_pivot_solve` if it can be, else on pivots chosen at the
    start values; the solution of a block of at most ``max_varying``
    unknowns is simplified (``cancel``)."""
    if len(us) > max_size:
        return None
    try:
        A, b = sp.linear_eq_to_matrix(exprs, us)
    except (sp.PolynomialError, ValueError, TypeError):
        return None
    if any(a.has(*us) for a in A) or not all(_safe_coefficient(a, params) for a in A):
        return None
    if any(set(us) & bi.free_symbols for bi in b):
        return None
    simplify = len(us) <= max_varying   # cancel on trigonometric entries costs seconds
    if not all(a.free_symbols <= params for a in A):
        # coefficients that move with the variables (a planar body's r x f):
        # pivots fixed at the start values could vanish later in the motion,
        # so first eliminate on constant pivots, the rest by the determinant
        x = _constant_pivot_solve(A, b, params, values)
        if x is not None:
            return _cancelled(x, simplify)
        # pivots chosen numerically at the start values (partial pivoting),
        # then imposed on the symbolic LU by reordering the rows: sympy would
        # otherwise take the first structurally non-zero pivot, which can be
        # zero there (e*sin(theta1) at theta1 = 0)
        An = np.array([[_numeric(a, values) for a in A.row(i)] for i in range(A.rows)])
        if not np.all(np.isfinite(An)) or np.linalg.matrix_rank(An) < A.rows:
            return None
        perm = scipy.linalg.lu(An)[0].T @ np.arange(A.rows)
        order = [int(round(k)) for k in perm]
        A = A.extract(order, list(range(A.cols)))
        b = b.extract(order, [0])
    try:
        x = A.LUsolve(b)
    except (ValueError, ZeroDivisionError):
        return None
    return _cancelled(x, simplify)


def _cancelled(x, simplify):
    """The solution ``x`` with each small entry simplified (``cancel``) when
    ``simplify``."""
    return [sp.cancel(xi) if simplify and xi.count_ops() < 200 else xi for xi in x]


def _constant_pivot_solve(A, b, params, values, max_adjugate=3):
    """``A x = b`` solved so that it divides only by what cannot vanish as
    the variables move, or by the determinant: Gaussian elimination on
    pivots made of numbers and parameters only (full pivoting, largest at
    the start values, among such entries), then, for the at most
    ``max_adjugate`` unknowns left when such pivots run out, after pivots
    that are numbers, Cramer's rule (:func:`_adjugate_solve`). None
    otherwise. No ``cancel`` (it costs seconds on trigonometric entries and
    gains nothing at run time).

    The rest of a four-bar's velocity block is 2 x 2 in the rocker's and the
    coupler's rates; its LU pivot chosen at the start values was
    ``r1*cos(shaft.phi)``, zero whenever the rocker passes the vertical
    although the block is regular there (its determinant is the transmission
    angle's sine): the generated code then divided by nearly zero and IDA's
    corrector failed (docs/planar.md). The determinant vanishes only where
    the block is singular."""
    n = A.rows
    M, rhs, cols, k0 = _eliminate_on_constant_pivots(A, b, params, values)
    x = [None] * n
    if k0 < n:
        # after a pivot that is a parameter (a 1e-30 kg m^2 hook's inertia
        # in a breaker's dynamics block) the rest would be scaled by it:
        # then the start values' pivots, as before, instead
        if n - k0 > max_adjugate or not all(M[k, k].is_number for k in range(k0)):
            return None
        tail = _adjugate_solve(M[k0:, k0:], rhs[k0:, :], values)
        if tail is None:
            return None
        for i, v in enumerate(tail):
            x[cols[k0 + i]] = v
    for k in reversed(range(k0)):
        acc = rhs[k] - sp.Add(*[M[k, j] * x[cols[j]] for j in range(k + 1, n)])
        x[cols[k]] = acc / M[k, k]
    return x


def _eliminate_on_constant_pivots(A, b, params, values):
    """(M, rhs, cols, k): ``A x = b`` after ``k`` steps of Gaussian
    elimination on constant pivots (rows and columns swapped, ``cols[j]``
    the unknown of column ``j``); ``k < n`` when such pivots ran out."""
    n = A.rows
    M, rhs, cols = A.as_mutable(), b.as_mutable(), list(range(n))
    for k in range(n):
        best = None
        for i in range(k, n):
            for j in range(k, n):
                a = M[i, j]
                if a == 0 or not a.free_symbols <= params:
                    continue
                v = abs(_numeric(a, values))
                if np.isfinite(v) and v > 1e-12 and (best is None or v > best[0]):
                    best = (v, i, j)
        if best is None:
            best = _simplified_pivot(M, k, params, values)
        if best is None:
            return M, rhs, cols, k
        _, i, j = best
        M.row_swap(k, i)
        rhs.row_swap(k, i)
        M.col_swap(k, j)
        cols[k], cols[j] = cols[j], cols[k]
        for i in range(k + 1, n):
            if M[i, k] != 0:
                fct = M[i, k] / M[k, k]
                for j in range(k + 1, n):
                    M[i, j] = M[i, j] - fct * M[k, j]
                rhs[i] = rhs[i] - fct * rhs[k]
                M[i, k] = 0
    return M, rhs, cols, n


def _adjugate_solve(S, r, values):
    """``S x = r`` by Cramer's rule, ``x = adj(S) r / det(S)`` (both
    division-free, Berkowitz), so that the only division is by the
    determinant; None when the determinant is zero or not a finite non-zero
    number at the start values."""
    det = S.det(method="berkowitz")
    v = _numeric(det, values)
    if det == 0 or not np.isfinite(v) or v == 0:
        return None
    adj = S.adjugate(method="berkowitz")
    return [sp.Add(*[adj[i, j] * r[j, 0] for j in range(S.rows)]) / det
            for i in range(S.rows)]


def _simplified_pivot(M, k, params, values, max_ops=30, max_tries=6):
    """A pivot from the remaining diagonal entries that ``trigsimp`` shows to
    be made of parameters only (a body's ``I + m r^2 (sin^2 + cos^2)``); the
    entry is replaced by its simplified form. None when there is none (at
    most ``max_tries`` small entries are simplified: trigsimp is slow)."""
    best, tries = None, 0
    for i in range(k, M.rows):
        for j in (i,):
            a = M[i, j]
            if a == 0 or a.count_ops() > max_ops or not a.has(sp.sin, sp.cos):
                continue
            if _moves(a, params, values):
                continue
            tries += 1
            if tries > max_tries:
                return best
            s = _trigsimp(a)
            if s == 0 or not s.free_symbols <= params:
                continue
            M[i, j] = s
            v = abs(_numeric(s, values))
            if np.isfinite(v) and v > 1e-12 and (best is None or v > best[0]):
                best = (v, i, j)
    return best


_PROBES = (0.37, -1.13, 2.71)   # offsets [SI] added to every variable in _moves


def _moves(a, params, values, rtol=1e-8):
    """Whether ``a`` visibly changes when its variables (the symbols that are
    not parameters) move from their start values by each of ``_PROBES``,
    parameters held: then no identity can make it parameters-only, and
    ``trigsimp`` (about a second on a four-bar's entry) need not try. An
    entry that evaluates to no finite number is not judged (False)."""
    moving = ordered(a.free_symbols - params)
    base = dict(values or {})
    v0 = _numeric(a, base)
    if not moving or not np.isfinite(v0):
        return False
    for d in _PROBES:
        v = _numeric(a, {**base, **{s: float(base.get(s, 0.0)) + d for s in moving}})
        if np.isfinite(v) and abs(v - v0) > rtol * max(1.0, abs(v0)):
            return True
    return False


@functools.lru_cache(maxsize=256)
def _trigsimp(a):
    """``sp.trigsimp(a)``, remembered in this process: the models of a
    diagnosis (one per hypothesis, site and pair) share the mechanism's
    blocks, so the same entries come back with every model (a four-bar's
    inertia entries: 0.2-0.5 s a call, most of the Python of compiling the
    breaker)."""
    return sp.trigsimp(a)


def _blt(eqs, unknowns):
    """Blocks [(eq index, unknown index), ...] in an order where each block
    only needs unknowns of earlier blocks."""
    index = {u: k for k, u in enumerate(unknowns)}
    rows, cols = [], []
    for i, (expr, _) in enumerate(eqs):
        for s in ordered(expr.free_symbols):
            k = index.get(s)
            if k is not None:
                rows.append(i)
                cols.append(k)
    n = len(eqs)
    m = sps.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(n, n))
    match = maximum_bipartite_matching(m, perm_type="column")
    if (match == -1).any():
        bad = [eqs[i][1] for i in np.flatnonzero(match == -1)]
        raise StructuralError("the index-reduced system is singular (no unknown left for): "
                              + "; ".join(getattr(b, "describe", lambda: str(b))() for b in bad),
                              excess=bad)
    # dependency graph on equations: i depends on the equation matched to each unknown in it
    eq_of_unknown = {int(match[i]): i for i in range(n)}
    drows, dcols = [], []
    for i, k in zip(rows, cols):
        j = eq_of_unknown[k]
        if j != i:
            drows.append(i)
            dcols.append(j)
    dep = sps.csr_matrix((np.ones(len(drows)), (drows, dcols)), shape=(n, n))
    ncomp, labels = connected_components(dep, directed=True, connection="strong")
    comps = [[] for _ in range(ncomp)]
    for i in range(n):
        comps[labels[i]].append(i)
    # topological order of the condensation (Kahn)
    cdeps = [set() for _ in range(ncomp)]
    for i, j in zip(drows, dcols):
        if labels[i] != labels[j]:
            cdeps[labels[i]].add(labels[j])
    order, done = [], set()
    pending = list(range(ncomp))
    while pending:
        nxt = [c for c in pending if cdeps[c] <= done]
        for c in nxt:
            order.append(c)
            done.add(c)
        pending = [c for c in pending if c not in done]
    return [[(i, int(match[i])) for i in comps[c]] for c in order]
