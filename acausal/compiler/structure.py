"""Stage 3: structural analysis and index reduction.

* :func:`check_structure` — bipartite matching of equations and unknowns;
  a structurally singular system raises :class:`StructuralError` naming the
  equations in excess or the unknowns left without an equation.
* :func:`pantelides` — Pantelides (1988): differentiate the equations whose
  highest derivatives cannot be matched, until every highest derivative is.
* :func:`dummy_derivatives` — Mattsson and Söderlind (1993): at each level of
  the differentiated equations choose derivatives to become algebraic
  ("dummy"), so that what is left is an index-1 DAE with a consistent set of
  states. Columns are chosen by QR with column pivoting on the Jacobian at the
  start values, preferring to keep variables with fixed starts as states.
"""
import numpy as np
import scipy.linalg
import scipy.sparse as sps
from scipy.sparse.csgraph import maximum_bipartite_matching

from ..infra.blas import single_threaded
from ..errors import StructuralError
from ..lang.fastdiff import diff
from ..lang.symbols import base_and_order, der, ordered, total_derivative


class Graph:
    """Variable nodes (a variable and each of its derivatives) and equation
    nodes (each equation and each of its derivatives)."""

    def __init__(self, equations, unknowns):
        self.vsym, self.vder, self.vint = [], [], {}
        self.vindex = {}
        self.eexpr, self.eder, self.eint, self.eorig = [], [], {}, []
        self.inc = []
        self.unknown_bases = set(unknowns)
        for x in unknowns:
            self._var(x)
        for eq in equations:
            self._eq(eq.expr, eq)

    def is_var(self, s):
        return base_and_order(s)[0] in self.unknown_bases

    def _var(self, sym):
        j = self.vindex.get(sym)
        if j is not None:
            return j
        base, k = base_and_order(sym)
        lower = self._var(_integral_n(base, k - 1)) if k > 0 else None
        j = len(self.vsym)
        self.vsym.append(sym)
        self.vder.append(-1)
        self.vindex[sym] = j
        if lower is not None:
            self.vder[lower] = j
            self.vint[j] = lower
        return j

    def _eq(self, expr, origin):
        i = len(self.eexpr)
        self.eexpr.append(expr)
        self.eder.append(-1)
        self.eorig.append(origin)
        self.inc.append({self._var(s) for s in ordered(expr.free_symbols) if self.is_var(s)})
        return i

    def differentiate_eq(self, i):
        if self.eder[i] != -1:
            return self.eder[i]
        expr = total_derivative(self.eexpr[i], self.is_var)
        j = self._eq(expr, self.eorig[i])
        self.eder[i] = j
        self.eint[j] = i
        return j

    def differentiate_var(self, j):
        if self.vder[j] == -1:
            self._var(der(self.vsym[j]))
        return self.vder[j]


def _integral_n(base, k):
    s = base
    for _ in range(k):
        s = der(s)
    return s


def check_structure(equations, unknowns, flat):
    """Raise StructuralError unless equations and unknowns can be matched
    one to one (counting a variable and its derivatives as one unknown)."""
    index = {x: j for j, x in enumerate(unknowns)}
    rows, cols = [], []
    for i, eq in enumerate(equations):
        for s in ordered(eq.expr.free_symbols):
            b = base_and_order(s)[0]
            if b in index:
                rows.append(i)
                cols.append(index[b])
    ne, nv = len(equations), len(unknowns)
    m = sps.csr_matrix((np.ones(len(rows)), (rows, cols)), shape=(ne, nv))
    match = maximum_bipartite_matching(m, perm_type="column")  # eq -> var
    unmatched_eqs = [i for i in range(ne) if match[i] == -1]
    matched_vars = set(int(v) for v in match if v != -1)
    unmatched_vars = [j for j in range(nv) if j not in matched_vars]
    if not unmatched_eqs and not unmatched_vars:
        return
    lines = [f"the model is structurally singular: {ne} equations for {nv} unknowns "
             f"(after alias elimination)."]
    excess, missing = [], []
    if unmatched_eqs:
        excess = _alternating_eqs(m, match, unmatched_eqs)
        lines.append(f"{len(unmatched_eqs)} equation(s) too many; the over-determined part:")
        lines += [f"  - {equations[i].describe()}" for i in excess]
    if unmatched_vars:
        missing = _alternating_vars(m, match, unmatched_vars)
        lines.append(f"{len(unmatched_vars)} unknown(s) without an equation; the "
                     f"under-determined part involves:")
        owners = sorted({flat.owner_of(unknowns[j]) for j in missing})
        lines += [f"  - {unknowns[j].name} (of {flat.owner_of(unknowns[j]) or 'the model'})"
                  for j in missing]
        involved = [p for p in flat.unconnected
                    if any(p.startswith(o + ".") or p == o for o in owners if o)]
        if flat.unconnected:
            lines.append("unconnected connectors (their force/torque is zero; connect them "
                         "if something should act there): "
                         + ", ".join(involved or flat.unconnected))
    raise StructuralError("\n".join(lines), excess=[equations[i] for i in excess],
                          missing=[unknowns[j] for j in missing])


def _alternating_eqs(m, match, start):
    """Equations reachable from unmatched ones by alternating paths."""
    var_to_eq = {int(v): i for i, v in enumerate(match) if v != -1}
    seen, stack = set(start), list(start)
    while stack:
        i = stack.pop()
        for v in m.indices[m.indptr[i]:m.indptr[i + 1]]:
            k = var_to_eq.get(int(v))
            if k is not None and k not in seen:
                seen.add(k)
                stack.append(k)
    return sorted(seen)


def _alternating_vars(m, match, start):
    mt = m.T.tocsr()
    seen, stack = set(start), list(start)
    while stack:
        j = stack.pop()
        for i in mt.indices[mt.indptr[j]:mt.indptr[j + 1]]:
            k = int(match[i])
            if k != -1 and k not in seen:
                seen.add(k)
                stack.append(k)
    return sorted(seen)


def pantelides(g, max_rounds=None):
    """Run Pantelides' algorithm on graph ``g`` in place; returns the matching
    (variable node -> equation node) of highest derivatives."""
    nv0 = len(g.vsym)
    max_rounds = max_rounds or 4 * (nv0 + 2)
    assign = {}

    def augment(i, vcol, ecol):
        ecol.add(i)
        cands = sorted(j for j in g.inc[i] if g.vder[j] == -1)
        for j in cands:
            if j not in assign:
                assign[j] = i
                return True
        for j in cands:
            if j not in vcol:
                vcol.add(j)
                if augment(assign[j], vcol, ecol):
                    assign[j] = i
                    return True
        return False

    n_orig = len(g.eexpr)
    rounds = 0
    for k in range(n_orig):
        i = k
        while True:
            vcol, ecol = set(), set()
            if augment(i, vcol, ecol):
                break
            rounds += 1
            if rounds > max_rounds:
                raise StructuralError(
                    "index reduction did not converge: the model is structurally singular "
                    f"(around {g.eorig[k].describe()})", excess=[g.eorig[k]])
            for j in sorted(vcol):
                g.differentiate_var(j)
            for l in sorted(ecol):
                g.differentiate_eq(l)
            for j in sorted(vcol):
                assign[g.vder[j]] = g.eder[assign[j]]
            i = g.eder[i]
    return assign


def dummy_derivatives(g, values, prefer_state):
    """Mattsson–Söderlind dummy derivative selection.

    ``values`` maps symbols (variables, parameters, discrete values) to
    numbers used to evaluate Jacobians; ``prefer_state(sym)`` is true for
    variables that should stay states when there is a choice. Returns the
    set of dummy variable nodes.

    The preference for fixed starts is a heuristic: with first-order chains
    (``der(phi) = w``) a fixed ``w`` but free ``phi`` can make it keep
    ``der(w)`` and drop ``der(phi)``, which leaves ``phi`` with neither a
    state nor an equation. Such a selection is detected by counting and the
    selection is redone without the preference.
    """
    dummies = _integrable(g, _select_dummies(g, values, prefer_state))
    if not _consistent(g, dummies):
        dummies = _integrable(g, _select_dummies(g, values, lambda s: False))
    return dummies


def _integrable(g, dummies):
    """``dummies`` without the derivatives of variables that no equation
    holds undifferentiated. Such a variable (a position whose velocity
    alone is prescribed, ``der(s) = v_ref(t)``) is only known by
    integrating its derivative: it must stay a state, whereas the
    selection, when the equation that gives the derivative was itself
    differentiated, makes that derivative a dummy and leaves the variable
    with no equation at all."""
    used = set()
    for inc in g.inc:
        used |= inc
    out = set(dummies)
    for j in sorted(dummies):
        low = g.vint.get(j)
        if low is not None and low not in used and low not in out:
            out.discard(j)
    return out


def _consistent(g, dummies):
    """True when the index-1 system left by ``dummies`` is square: as many
    equations as unknowns (derivatives of states + algebraic nodes), the
    count :func:`acausal.causalize.build_dae` needs."""
    nv = len(g.vsym)
    states = {j for j in range(nv) if g.vder[j] != -1 and g.vder[j] not in dummies}
    state_ders = {g.vder[j] for j in states}
    n_unknowns = len(states) + sum(1 for j in range(nv)
                                   if j not in states and j not in state_ders)
    n_links = sum(1 for j in states if g.vder[j] in states)
    return n_unknowns == len(g.eexpr) + n_links


def _select_dummies(g, values, prefer_state):
    dummies = set()
    geqs = [i for i in range(len(g.eexpr)) if g.eder[i] == -1 and i in g.eint]
    hvars = [j for j in range(len(g.vsym)) if g.vder[j] == -1 and j in g.vint]
    while geqs:
        cand = sorted({j for i in geqs for j in g.inc[i]} & set(hvars))
        if len(cand) < len(geqs):
            raise StructuralError("dummy derivative selection failed: fewer candidate "
                                  "derivatives than differentiated equations",
                                  excess=[g.eorig[i] for i in geqs])
        chosen = _select_columns(g, geqs, cand, values, prefer_state)
        dummies.update(chosen)
        geqs = [g.eint[i] for i in geqs if i in g.eint]
        hvars = [g.vint[j] for j in chosen if j in g.vint]
    return dummies


def _select_columns(g, rows, cols, values, prefer_state):
    jac = np.zeros((len(rows), len(cols)))
    for a, i in enumerate(rows):
        for b, j in enumerate(cols):
            if j in g.inc[i]:
                d = diff(g.eexpr[i], g.vsym[j])
                try:
                    jac[a, b] = float(d.xreplace(values))
                except (TypeError, ValueError):
                    jac[a, b] = np.nan
    # Prefer keeping as states (so: not choosing as dummies) derivatives of
    # higher order (position-like chains: with first-order forms such as
    # der(s) = v, leaving der(v) instead of der(der(s)) would leave no
    # position state) and variables with fixed start values.
    weights = np.array([(0.1 if prefer_state(g.vsym[j]) else 1.0)
                        / (1.0 + base_and_order(g.vsym[j])[1]) ** 2 for j in cols])
    scaled = np.nan_to_num(jac * weights, nan=1e-3)
    with single_threaded(len(cols)):    # spinning BLAS threads: 50x slower under load
        _, piv = scipy.linalg.qr(scaled, mode="r", pivoting=True)
        chosen = [cols[k] for k in piv[:len(rows)]]
        sub = np.nan_to_num(jac[:, [cols.index(c) for c in chosen]], nan=1.0)
        full = np.linalg.matrix_rank(sub) == len(rows)
    if not full:
        raise StructuralError(
            "cannot select states: the constraint Jacobian is singular at the start "
            "values (a kinematic loop at a dead centre, or redundant constraints): "
            + "; ".join(g.eorig[i].describe() for i in rows), excess=[g.eorig[i] for i in rows])
    return chosen
