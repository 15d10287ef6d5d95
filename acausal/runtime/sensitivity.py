"""Forward parameter sensitivities through events: the augmented model.

For parameters ``p_j`` the sensitivities ``s_j = dy/dp_j`` of the reduced
DAE ``F(t, y, y', p, d) = 0`` satisfy the sensitivity DAE (Maly & Petzold
1996; Li & Petzold 2000; the IDAS guide)::

    F_y s_j + F_y' s_j' + F_p_j + F_d sd_j = 0

(``sd_j``: sensitivities of the discrete values the equations use, constant
between events). :func:`sensitivity_model` appends these rows, built
symbolically from the same residuals with :func:`acausal.lang.fastdiff.diff`, to
the DAE and generates the augmented system with the ordinary code
generators (Python, :mod:`acausal.compiler.codegen`; C,
:mod:`acausal.compiler.codegen_c`), so
each backend integrates it as any model, with no math of its own (CasADi's
principle: one graph, several backends, sensitivities from the same graph).
The augmented unknowns are ordered states first (the states, then their
sensitivities per parameter, then the algebraic unknowns and theirs), so
everything that splits a DAE into states and algebraic unknowns works
unchanged. The augmented system's Jacobian is block lower triangular
(each diagonal block the base model's); its iteration matrix has the
diagonal blocks and the small entries of the blocks that couple a
parameter's rows to the base unknowns (:meth:`SensitivityModel._generate`).

The run integrates it as one observer of the hybrid loop
(:class:`acausal.runtime.sensitivity_run.SensitivityObserver`): at the
start the sensitivities follow from the consistent-initialisation
equations by the implicit function theorem. At an
event of root ``g`` at time ``tau`` (Galan, Feehery & Barton 1999,
"Parametric sensitivity functions for hybrid discrete/continuous systems",
Appl. Numer. Math. 31)::

    dtau/dp = -(g_y s + g_y' s' + g_p + g_d sd) / (g_y y' + g_t)

and, since event actions change only discrete values (the states are
continuous, ``h = identity``), the states' sensitivities jump by
``(y'- - y'+) dtau/dp`` at a mode change, the algebraic ones are re-solved
from the differentiated re-initialisation (the re-initialisation of the
augmented system). The sensitivities of discrete values an action sets from
continuous ones (an impact velocity) are the action's directional
derivative, by a central difference of the action along the total
derivative of its inputs (exact for the piecewise-linear actions of the
library; an action must be a function of what it reads).

The event time's derivative is taken at the located point polished
(algebraic unknowns and derivatives re-solved from the equations, y' of the
algebraic unknowns and y'' of the states from the equations differentiated
once), so roots of forces and rates are as exact as roots of positions.
A measure (any function of a result) is differentiated over the result
moved to first order along the sensitivities
(:meth:`acausal.runtime.sensitivity_run.Sensitivities.measure`).

Limits: rates of observed variables read by actions are central
differences in time; an action must be a function of what it reads.
The generated augmented model is kept in the on-disk store (namespace
``sensitivity``, :func:`_cache_key`).
"""
import dataclasses
import hashlib
import json
import os
import weakref

import numpy as np
import sympy as sp

from .backends import choose_linear_solver
from ..compiler.cache import digest
from ..compiler.causalize import DAE
from ..compiler.codegen import Sparsity, generate, load, root_gradients
from ..errors import ModelError, UsageError
from ..infra import store
from ..lang.fastdiff import diff
from .linalg import SquareSolver

# compiled model -> {names: SensitivityModel}: the runtime's cache of them
_models = weakref.WeakKeyDictionary()


def sensitivity_model(cm, names):
    """The :class:`SensitivityModel` of ``cm`` for parameters ``names``
    (generated once per model and tuple of names)."""
    names = tuple(names)
    if not names:
        raise UsageError("sensitivities: give at least one parameter name")
    if len(set(names)) != len(names):
        raise UsageError(f"sensitivities: a parameter is named twice in {list(names)}")
    per = _models.setdefault(cm, {})
    if names not in per:
        for n in names:
            cm.param_index(n)   # a ParameterError naming a parameter that is not one
        try:
            per[names] = SensitivityModel(cm, names)
        except (TypeError, ValueError, NotImplementedError, AttributeError) as exc:
            # e.g. a function of the model whose derivative sympy cannot print
            raise ModelError(f"sensitivities with respect to {', '.join(names)}: the "
                             f"sensitivity equations cannot be generated "
                             f"({type(exc).__name__}: {str(exc).splitlines()[0]})") from None
    return per[names]


class SensitivityModel:
    """A compiled model with its sensitivity DAE appended, for parameters
    ``names``. It has what the hybrid loop and the backends use of a
    :class:`~acausal.runtime.model.CompiledModel` (``dae``, ``callbacks``,
    ``disc_syms``, ``source``, ``sparsity``, ``linear_solver``); everything
    else (events, parameters, names, ``resolve``) is the base model's, read
    through :meth:`__getattr__`. Its discrete values are the base model's,
    then ``sd`` (per parameter, one per discrete value the equations use)."""

    def __init__(self, cm, names):
        self.base = cm
        self.names = names
        self.pidx = [cm.param_index(n) for n in names]
        dae = cm.dae
        n, ns, m = len(dae.y), dae.n_states, len(names)
        self.n, self.ns, self.m = n, ns, m
        self.dyn = sorted(cm.dynamic_discretes())
        P = [cm.param_syms[k] for k in self.pidx]
        S = [[sp.Symbol(f"__sens{j}__{s.name}") for s in dae.y] for j in range(m)]
        Sp = [[sp.Symbol(f"__sensp{j}__{s.name}") if dae.yp[k] is not None else None
               for k, s in enumerate(dae.y)] for j in range(m)]
        SD = [[sp.Symbol(f"__sensd{j}__{cm.disc_syms[q].name}") for q in self.dyn]
              for j in range(m)]
        self.sd_syms = [s for row in SD for s in row]   # the discrete sensitivities
        lin = self._lin = _Linearize(dae, P, [cm.disc_syms[q] for q in self.dyn], S, Sp, SD)
        rows = [lin.total(r) for r in dae.residuals]      # rows[i][j]
        self.order = self._order()
        y_all = list(dae.y) + [s for j in range(m) for s in S[j]]
        yp_all = list(dae.yp) + [s for j in range(m) for s in Sp[j]]
        res_all = list(dae.residuals) + [rows[i][j] for j in range(m) for i in range(n)]
        org_all = list(dae.origins) + [dae.origins[i] for j in range(m) for i in range(n)]
        # the Jacobian's columns are chosen at generation (_generate)
        self.dae = DAE([y_all[k] for k in self.order], [yp_all[k] for k in self.order],
                       ns * (1 + m), [res_all[k] for k in self.order],
                       [org_all[k] for k in self.order], dae.explicit, None)
        self.disc_syms = list(cm.disc_syms) + self.sd_syms
        roots = [cm.resolve(e.expr) for e in cm.events] + \
            [cm.resolve(a.expr) for a in cm.assertions]
        key = self.key = _cache_key(cm, names, self.dae.residuals)
        hit = _cache_load(key)
        if hit is None:
            columns = self._jacobian_columns()
            self.dae = dataclasses.replace(self.dae, jacobian_columns=columns)
            gen = self._generate(lin, roots)
            self.source, self.sparsity = gen.source, gen.sparsity
            _cache_store(key, self.source, self.sparsity, columns)
        else:
            self.source, self.sparsity, columns = hit
            # (the C generator reads them too: codegen_c)
            self.dae = dataclasses.replace(self.dae, jacobian_columns=columns)
        self._make = load(self.source)[0]
        self.rootgrad = root_gradients(dae, cm.param_syms, cm.disc_syms, roots, P, self.dyn)
        self.inverse = np.argsort(self.order)

    def _generate(self, lin, roots):
        """The augmented system's generated callbacks (:func:`acausal.compiler.codegen.generate`):
        its residuals, its whole Jacobian (see below), the base roots and
        the observed variables followed by their sensitivities.

        The iteration matrix has the diagonal blocks (each the base model's
        ``F_y + cj F_y'``) and the small entries of the blocks that couple a
        parameter's rows to the base unknowns (``d/dy`` of ``F_y s + F_y' s'
        + F_p``: second derivatives of the residuals; :meth:`_jacobian_columns`).
        Keeping only the diagonal blocks (IDAS's simultaneous corrector)
        leaves the sensitivities one Newton iteration behind the base
        unknowns: the second iteration then corrects them by the coupling
        times the base unknowns' first correction, and IDA's convergence
        test reads that as a diverging iteration (rate > 0.9) whenever the
        coupling, weighted by the tolerances, exceeds the base block's:
        ``m a + ... = 0`` with respect to ``m`` where ``|a| > |da/dm|`` (a
        mass after a friction element's stop and break-away: 1.5 million
        steps of 1e-7 s instead of 287). With the coupling in the matrix
        there is no such ratio."""
        return generate(self.dae, self.base.param_syms, self.disc_syms, roots,
                        self.observed_exprs())

    def _jacobian_columns(self):
        """Per augmented residual, the slots its Jacobian row is taken over:
        a base row its own block; a parameter's row its own block and each
        base slot whose coupling entries (d/dy and d/dy' of the row) are
        small expressions (at most :data:`COUPLING_NODES` tree nodes: a
        parameter times an unknown, ``m a``, ``c x``, gives a constant).
        Larger ones (the breaker's contact law differentiated twice: up to
        1e5 operations an entry, which doubled the C build of a cold cache)
        are left out, as all of them were before: the matrix is then a
        modified Newton's there (the solution is that of the exact
        equations either way)."""
        dae, n = self.dae, self.n
        block = self.order // n
        base = [k for k in range(len(dae.y)) if block[k] == 0]
        out = []
        for i, r in enumerate(dae.residuals):
            own = [k for k in range(len(dae.y)) if block[k] == block[i]]
            if block[i] == 0:
                out.append(frozenset(own))
                continue
            keep = [k for k in base
                    if all(_size(diff(r, x), COUPLING_NODES + 1) <= COUPLING_NODES
                           for x in (dae.y[k], dae.yp[k]) if x is not None and r.has(x))]
            out.append(frozenset(own + keep))
        return tuple(out)

    def observed_exprs(self):
        """The base model's observed variables, then their sensitivities per
        parameter (the observe callback's output, :attr:`n_observed`)."""
        cm = self.base
        observed = cm.observed_exprs()
        obs_sens = [self._lin.total(o) for o in observed]
        return observed + [obs_sens[k][j] for j in range(self.m)
                           for k in range(len(cm.var_names))]

    def observed_sensitivity(self, k, j):
        """d(the base model's observed variable ``k``)/d(parameter ``j``), an
        expression of the augmented unknowns and discrete values (the observe
        callback's entry ``n_obs (1 + j) + k``, n_obs the base's variables)."""
        cm = self.base
        return self._lin.total(cm.artefact.observed_expr(cm.var_names[k]))[j]

    def identity(self):
        """A digest that fixes the augmented equations: their store key (the
        base model's :meth:`~acausal.runtime.model.CompiledModel.identity`,
        the parameters, the augmented residuals, the generators)."""
        return self.key

    def __getattr__(self, name):
        if name == "base":   # not set yet (copying, pickling)
            raise AttributeError(name)
        return getattr(self.base, name)

    def _order(self):
        """Positions in (y, s_0, ..., s_m-1) of the augmented unknowns: states
        (base, then each parameter's), then algebraic unknowns likewise."""
        n, ns, m = self.n, self.ns, self.m
        states = [j * n + k for j in range(m + 1) for k in range(ns)]
        alg = [j * n + k for j in range(m + 1) for k in range(ns, n)]
        return np.array(states + alg, dtype=int)

    # -- the CompiledModel interface the loop and the backends use ------------
    def callbacks(self, p, d):
        return self._make(list(map(float, p)), list(map(float, d)))

    def linear_solver(self, kind="auto"):
        return choose_linear_solver(self.sparsity, kind)

    @property
    def n_observed(self):
        """Length of the observe callback's output: the base model's observed
        variables, then their sensitivities per parameter."""
        return len(self.base.var_names) * (1 + self.m)

    def block_solve(self, J, b):
        """``J x = b`` for the augmented system's re-initialisation matrix
        ``J`` (:func:`acausal.runtime.linalg.event_matrix` of the generated
        Jacobian), block lower triangular: each parameter's block depends
        only on its own sensitivities and the base unknowns, with the base
        matrix on the diagonal. Forward substitution with the base block
        (every diagonal block is the base model's matrix): one solve for
        the base block, one with a right-hand side per parameter for the
        rest, less the coupling blocks times the base block's solution; a
        dense solve of the whole would also mix blocks of very different
        scales (d/dp of a 1e-4 kg m^2 inertia; rcond 1e-16 on the
        breaker)."""
        rows, cols = self.event_blocks()
        if not isinstance(J, np.ndarray):
            J = J.toarray()
        J0 = J[np.ix_(rows[0], cols[0])]
        x = np.empty_like(b)
        solve = SquareSolver()
        x0 = solve(J0, b[rows[0]])
        x[cols[0]] = x0
        c0 = J[:, cols[0]] @ x0
        X = solve(J0, np.column_stack([b[r] - c0[r] for r in rows[1:]]))
        for j, c in enumerate(cols[1:]):
            x[c] = X[:, j]
        return x

    def event_blocks(self):
        """(rows, columns) of the re-initialisation matrix per block (base,
        then each parameter's), each in the base model's order."""
        if getattr(self, "_blocks", None) is None:
            N, ns_aug = len(self.dae.y), self.ns * (1 + self.m)
            block = self.order // self.n                    # block of each augmented position
            col_pos = np.concatenate([np.arange(ns_aug, N), np.arange(ns_aug)])
            self._blocks = ([np.flatnonzero(block == j) for j in range(self.m + 1)],
                            [np.flatnonzero(block[col_pos] == j) for j in range(self.m + 1)])
        return self._blocks

    # -- packing ---------------------------------------------------------------
    def pack(self, y, S):
        """Augmented vector from ``y`` (n) and ``S`` (m x n)."""
        return np.concatenate([np.asarray(y, float)] + [np.asarray(s, float) for s in S])[
            self.order]

    def unpack(self, Y):
        """(y, S) from augmented rows ``Y`` (... x N): y (... x n), S (... x m x n)."""
        Y = np.asarray(Y, float)
        flat = Y[..., self.inverse]
        y = flat[..., :self.n]
        S = flat[..., self.n:].reshape(Y.shape[:-1] + (self.m, self.n))
        return y, S

    def sd_of(self, d_aug):
        """The discrete-value sensitivities (m x len(dyn)) in augmented ``d``."""
        nd = len(self.base.disc_syms)
        return np.asarray(d_aug[nd:], float).reshape(self.m, len(self.dyn))

    def atol(self, atol, p):
        """Absolute tolerances of the augmented unknowns: ``atol`` for y,
        ``atol / |p_j|`` for ``s_j`` (IDAS's default scaling by the
        parameter's magnitude)."""
        a = np.broadcast_to(np.asarray(atol, float), (self.n,))
        scales = [abs(p[k]) if p[k] != 0 else 1.0 for k in self.pidx]
        return self.pack(a, [a / s for s in scales])


COUPLING_NODES = 64   # a coupling entry of at most this many tree nodes is generated


def _size(expr, limit):
    """Nodes of ``expr``'s tree, counting stops past ``limit``."""
    count = 0
    for _ in sp.preorder_traversal(expr):
        count += 1
        if count > limit:
            break
    return count


def _cache_key(cm, names, residuals):
    """Key of a sensitivity model in the store: the base model's identity
    (which fixes its DAE), the parameter names, the augmented
    residuals (which the derivative rules of the model's own functions
    shape) and the generators' sources."""
    h = hashlib.sha256(cm.identity().encode())
    h.update("\0".join(names).encode())
    h.update(digest(residuals).encode())
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))   # the acausal package
    for mod in ("runtime/sensitivity.py", "compiler/codegen.py", "lang/fastdiff.py"):
        with open(os.path.join(here, mod), "rb") as fh:
            h.update(fh.read())
    return h.hexdigest()[:24]


def _cache_load(key):
    """(source, Sparsity, Jacobian columns) of a stored sensitivity model, or None."""
    data = store.read_bytes("sensitivity", f"sens_{key}.json")
    if data is None:
        return None
    try:
        data = json.loads(data)
        columns = tuple(frozenset(c) for c in data["columns"])
        return data["source"], Sparsity(**data["sparsity"]), columns
    except (ValueError, KeyError, TypeError):
        return None   # an unreadable entry is generated again


def _cache_store(key, source, sparsity, columns):
    """Keep a sensitivity model in the store (atomically; nothing when the
    store is off or cannot be written: it is generated again next time)."""
    text = json.dumps({"source": source, "sparsity": dataclasses.asdict(sparsity),
                       "columns": [sorted(c) for c in columns]})
    store.write_bytes("sensitivity", f"sens_{key}.json", text.encode())


class _Linearize:
    """Total parameter derivatives ``e_y s_j + e_y' s_j' + e_p_j + e_d sd_j``
    of expressions of the DAE's symbols, each partial taken once."""

    def __init__(self, dae, P, D, S, Sp, SD):
        self.wrt = {}
        m = len(P)
        for k, s in enumerate(dae.y):
            self.wrt[s] = [S[j][k] for j in range(m)]
        for k, s in enumerate(dae.yp):
            if s is not None:
                self.wrt[s] = [Sp[j][k] for j in range(m)]
        for q, s in enumerate(D):
            self.wrt[s] = [SD[j][q] for j in range(m)]
        self.P, self.m = P, m

    def total(self, e):
        """[d e / d p_j for each j] (expressions linear in the sensitivities)."""
        e = sp.sympify(e)
        out = [[] for _ in range(self.m)]
        for x in e.free_symbols:
            coeffs = self.wrt.get(x)
            if coeffs is not None:
                dx = diff(e, x)
                if dx != 0:
                    for j in range(self.m):
                        out[j].append(dx * coeffs[j])
        for j, pj in enumerate(self.P):
            if e.has(pj):
                out[j].append(diff(e, pj))
        return [sp.Add(*terms) for terms in out]
