"""Forward parameter sensitivities through events (the hybrid loop's stage 6b).

For parameters ``p_j`` the sensitivities ``s_j = dy/dp_j`` of the reduced
DAE ``F(t, y, y', p, d) = 0`` satisfy the sensitivity DAE (Maly & Petzold
1996; Li & Petzold 2000; the IDAS guide)::

    F_y s_j + F_y' s_j' + F_p_j + F_d sd_j = 0

(``sd_j``: sensitivities of the discrete values the equations use, constant
between events). :func:`sensitivity_model` appends these rows, built
symbolically from the same residuals with :func:`acausal.fastdiff.diff`, to
the DAE and generates the augmented system with the ordinary code
generators (Python, :mod:`acausal.codegen`; C, :mod:`acausal.codegen_c`), so
each backend integrates it as any model, with no math of its own (CasADi's
principle: one graph, several backends, sensitivities from the same graph).
The augmented unknowns are ordered states first (the states, then their
sensitivities per parameter, then the algebraic unknowns and theirs), so
everything that splits a DAE into states and algebraic unknowns works
unchanged. The augmented system's Jacobian is block lower triangular; its
iteration matrix keeps the diagonal blocks, each the base model's
(:meth:`SensitivityModel._generate`: IDAS's simultaneous corrector).

At the start the sensitivities follow from the consistent-initialisation
equations by the implicit function theorem (:meth:`SensRun.start`). At an
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
moved to first order along the sensitivities (:meth:`Sensitivities.measure`).

Limits: rates of observed variables read by actions are central
differences in time; an action must be a function of what it reads.
The generated augmented model is cached on disk (``sensitivities/`` in the
model cache, :func:`_cache_key`).
"""
import weakref

import numpy as np
import sympy as sp

from .backends import choose_linear_solver
from ..compiler.causalize import DAE
from ..compiler.codegen import (_IEEE_ERRORS, Names, Sparsity, _body, _unpack, exec_twins, generate,
                      load)
from ..errors import ModelError, UsageError
from .events import EventState
from ..lang.fastdiff import diff

_models = weakref.WeakKeyDictionary()   # CompiledModel -> {names: SensitivityModel}


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
    :class:`~acausal.compile.CompiledModel` (``dae``, ``callbacks``,
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
        self._sd_syms = [s for row in SD for s in row]
        lin = self._lin = _Linearize(dae, P, [cm.disc_syms[q] for q in self.dyn], S, Sp, SD)
        rows = [lin.total(r) for r in dae.residuals]      # rows[i][j]
        self.order = self._order()
        y_all = list(dae.y) + [s for j in range(m) for s in S[j]]
        yp_all = list(dae.yp) + [s for j in range(m) for s in Sp[j]]
        res_all = list(dae.residuals) + [rows[i][j] for j in range(m) for i in range(n)]
        org_all = list(dae.origins) + [dae.origins[i] for j in range(m) for i in range(n)]
        block = self.order // n                   # block of each augmented position
        same = [tuple(np.flatnonzero(block == b).tolist()) for b in range(m + 1)]
        self.dae = DAE([y_all[k] for k in self.order], [yp_all[k] for k in self.order],
                       ns * (1 + m), [res_all[k] for k in self.order],
                       [org_all[k] for k in self.order], dae.explicit,
                       tuple(frozenset(same[b]) for b in block))
        self.disc_syms = list(cm.disc_syms) + self._sd_syms
        roots = [cm.resolve(e.expr) for e in cm.events] + \
            [cm.resolve(a.expr) for a in cm.assertions]
        key = _cache_key(cm, names, self.dae.residuals)
        hit = _cache_load(key)
        if hit is None:
            gen = self._generate(lin, roots)
            self.source, self.sparsity = gen.source, gen.sparsity
            _cache_store(key, self.source, self.sparsity)
        else:
            self.source, self.sparsity = hit
        self._make = load(self.source)[0]
        self.rootgrad = _root_gradients(cm, roots, P, self.dyn)
        self.inverse = np.argsort(self.order)

    def _generate(self, lin, roots):
        """The augmented system's generated callbacks (:func:`acausal.codegen.generate`):
        its residuals, the diagonal blocks of its Jacobian (see below), the
        base roots and the observed variables followed by their
        sensitivities.

        The iteration matrix keeps only the diagonal blocks: each is the base
        model's (``F_y + cj F_y'``), and the blocks coupling a parameter's
        rows to the base unknowns (second derivatives of the residuals,
        most of the generation's work) are left out, as IDAS's simultaneous
        corrector does: Newton's error in the sensitivities then vanishes
        one iteration after the base unknowns' (the neglected part is
        nilpotent), and the sensitivities are those of the exact equations.
        Where the coupling is needed (the algebraic rates after an event),
        it is a directional difference (:meth:`SensRun.rates`)."""
        return generate(self.dae, self.base.param_syms, self.disc_syms, roots,
                        self.observed_exprs())

    def observed_exprs(self):
        """The base model's observed variables, then their sensitivities per
        parameter (the observe callback's output, :attr:`n_observed`)."""
        cm = self.base
        observed = cm.observed_exprs()
        obs_sens = [self._lin.total(o) for o in observed]
        return observed + [obs_sens[k][j] for j in range(self.m)
                           for k in range(len(cm.var_names))]

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

    def block_solve(self, J, b, coupling):
        """``A x = b`` for the augmented system's re-initialisation matrix
        ``A``, block lower triangular: each parameter's block depends only
        on its own sensitivities and the base unknowns, with the base
        matrix on the diagonal. ``J``: its diagonal blocks (the generated
        Jacobian, :func:`acausal.initialize._event_matrix`);
        ``coupling(x0)``: the off-diagonal blocks times the base block's
        solution ``x0`` (rows of the whole vector). Forward substitution
        with the base block (every diagonal block is the base model's
        matrix): one solve for the base block, one with a right-hand side
        per parameter for the rest; a dense solve of the whole would also
        mix blocks of very different scales (d/dp of a 1e-4 kg m^2
        inertia; rcond 1e-16 on the breaker)."""
        from .initialize import _solve_square
        rows, cols = self._event_blocks()
        if not isinstance(J, np.ndarray):
            J = J.toarray()
        J0 = J[np.ix_(rows[0], cols[0])]
        x = np.empty_like(b)
        x0 = _solve_square(J0, b[rows[0]])
        x[cols[0]] = x0
        c0 = coupling(x0)
        X = _solve_square(J0, np.column_stack([b[r] - c0[r] for r in rows[1:]]))
        for j, c in enumerate(cols[1:]):
            x[c] = X[:, j]
        return x

    def _event_blocks(self):
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


def _cache_key(cm, names, residuals):
    """Key of a sensitivity model in the on-disk cache: the base model's
    generated source (which fixes its DAE), the parameter names, the
    augmented residuals (which the derivative rules of the model's own
    functions shape) and the generators' sources."""
    import hashlib
    import os
    h = hashlib.sha256(cm.source.encode())
    h.update("\0".join(names).encode())
    from ..infra.store import digest
    h.update(digest(residuals).encode())
    here = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))   # the acausal package
    for mod in ("runtime/sensitivity.py", "compiler/codegen.py", "lang/fastdiff.py"):
        with open(os.path.join(here, mod), "rb") as fh:
            h.update(fh.read())
    return h.hexdigest()[:24]


def _cache_path(key):
    from ..infra.store import cache_dir
    d = cache_dir()
    return None if d is None else d / "sensitivities" / f"sens_{key}.json"


def _cache_load(key):
    """(source, Sparsity) of a cached sensitivity model, or None."""
    import json
    path = _cache_path(key)
    if path is None or not path.exists():
        return None
    try:
        data = json.loads(path.read_text())
        return data["source"], Sparsity(**data["sparsity"])
    except (OSError, ValueError, KeyError, TypeError):
        return None   # an unreadable entry is generated again


def _cache_store(key, source, sparsity):
    import dataclasses
    import json
    import os
    import tempfile
    path = _cache_path(key)
    if path is None:
        return
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".tmp")
        with os.fdopen(fd, "w") as fh:
            json.dump({"source": source, "sparsity": dataclasses.asdict(sparsity)}, fh)
        os.replace(tmp, path)   # atomic: a reader never sees a partial file
    except OSError:
        pass   # no cache then; the model is generated again next time


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


def _root_gradients(cm, roots, P, dyn):
    """A function ``(t, y, yp, p, d)`` -> (G_y, G_y', G_t, G_p, G_d) of the root
    functions (dense arrays, rows = roots), generated as the other callbacks."""
    dae = cm.dae
    n, nr, m = len(dae.y), len(roots), len(P)
    names = Names(dae.y, dae.yp, cm.param_syms, cm.disc_syms)
    from ..lang.symbols import time
    cols = [("Gy", k, s) for k, s in enumerate(dae.y)]
    cols += [("Gyp", k, s) for k, s in enumerate(dae.yp) if s is not None]
    exprs, targets = [], []
    for i, g in enumerate(roots):
        fs = g.free_symbols
        for arr, k, s in cols + [("Gp", j, x) for j, x in enumerate(P)] + \
                [("Gd", q, cm.disc_syms[x]) for q, x in enumerate(dyn)]:
            if s in fs:
                exprs.append(diff(g, s))
                targets.append(f"{arr}[{i}, {k}]")
        if time in fs:
            exprs.append(diff(g, time))
            targets.append(f"Gt[{i}]")
    L = ["def rootgrad(t, y, yp, p, d, Gy, Gyp, Gt, Gp, Gd):"]
    L += _unpack("y", n, "y", "    ", False) + _unpack("yp", n, "yp", "    ", False)
    L += _unpack("p", len(cm.param_syms), "p", "    ", False)
    L += _unpack("d", len(cm.disc_syms), "d", "    ", False)
    L += _body(exprs, targets, "    ", symbols=names.code) + ["    pass"]
    ns, ieee = exec_twins(compile("\n".join(L) + "\n", "<acausal-root-gradients>", "exec"))
    fill, fill_ieee = ns["rootgrad"], ieee["rootgrad"]

    def rootgrad(t, y, yp, p, d):
        G = (np.zeros((nr, n)), np.zeros((nr, n)), np.zeros(nr), np.zeros((nr, m)),
             np.zeros((nr, len(dyn))))
        try:
            fill(t, list(map(float, y)), list(map(float, yp)), list(map(float, p)),
                 list(map(float, d)), *G)
        except _IEEE_ERRORS:      # a guarded domain: as the callbacks (acausal.codegen)
            with np.errstate(all="ignore"):
                fill_ieee(t, *(np.asarray(a, dtype=float) for a in (y, yp, p, d)), *G)
        return G
    return rootgrad


class SensRun:
    """The sensitivity bookkeeping of one run: initial sensitivities, the
    event-time sensitivities and the jumps at mode changes."""

    def __init__(self, sm, p, span, serve=None):
        self.sm, self.p = sm, np.asarray(p, float)
        # (model, d) -> that model's callbacks in mode d, as the run's backend
        # serves them (compiled C on the compiled backend)
        self.serve = serve or (lambda model, d: model.callbacks(self.p, d))
        self.span = max(float(span), 1e-300)
        self.dtau = np.zeros(sm.m)       # of the instant being handled
        self.sd_all = np.zeros((sm.m, len(sm.base.disc_syms)))   # of every discrete value
        self.noted = {}                  # index in run.events -> dtau/dp (m)
        self._polished = None            # the last polished point (see polish)

    # -- start -----------------------------------------------------------------
    def start(self, p, d, t0, y, yp, starts):
        """(Y, Y', d, callbacks) of the augmented system at the consistent
        initial point ``(y, yp)`` of the base model: the states'
        sensitivities from the initial equations (implicit function
        theorem), the rest re-solved."""
        sm, cm = self.sm, self.sm.base
        d_aug = list(d) + [0.0] * len(sm._sd_syms)
        cb = self.serve(sm, d_aug)
        ds = _initial_state_sensitivities(sm, cm, cb, self.serve(cm, d), p, d, t0, y, yp,
                                          starts)
        S = np.zeros((sm.m, sm.n))
        S[:, :sm.ns] = ds
        Y, YP = sm.pack(y, S), sm.pack(yp, np.zeros((sm.m, sm.n)))
        Y, YP = self.reinit(t0, Y, YP, d_aug)
        return Y, YP, d_aug, cb

    def reinit(self, t, Y, YP, d_aug, rates=True):
        """The re-initialisation of the augmented system at ``t`` (states and
        their sensitivities kept): the base model's
        (:func:`acausal.initialize.reinitialize`), then the sensitivity rows,
        linear in ``(s_alg, s'_states)`` with the base iteration matrix, in
        one solve; with ``rates``, y' of every algebraic slot as
        :func:`acausal.initialize._algebraic_rates` gives it."""
        from .initialize import _jacobians, reinitialize
        sm, cm = self.sm, self.sm.base
        n, ns = sm.n, sm.ns
        cb = self.serve(cm, d_aug[:len(cm.disc_syms)])
        (y, S), (yp, Sp) = sm.unpack(Y), sm.unpack(YP)
        y, yp = reinitialize(cm, cb, t, y, yp)
        S, Sp = S.copy(), Sp.copy()
        S[:, ns:] = 0.0
        Sp[:, :ns] = 0.0
        cba = self.serve(sm, d_aug)
        r = np.zeros(len(sm.dae.y))
        cba[0](t, sm.pack(y, S), sm.pack(yp, Sp), r)
        Jy, Jyp = _jacobians(cb, t, y, yp, n)
        J = np.hstack([Jy[:, ns:], Jyp[:, :ns]])
        rhs = -sm.unpack(r)[1].T                          # n x m
        try:
            X = np.linalg.solve(J, rhs)
        except np.linalg.LinAlgError:
            X = np.linalg.lstsq(J, rhs, rcond=None)[0]
        S[:, ns:] = X[:n - ns].T
        Sp[:, :ns] = X[n - ns:].T
        Y, YP = sm.pack(y, S), sm.pack(yp, Sp)
        if rates:
            YP = self.rates(cba, t, Y, YP)
        return Y, YP

    def rates(self, cb, t, Y, YP):
        """``YP`` with y' of every algebraic slot of the augmented system
        (callbacks ``cb``), as :func:`acausal.initialize._algebraic_rates`
        gives it: ``J x = -(F_t + F_y(states) y'_states)`` for x = (y' of the
        algebraic slots, y'' of the states), solved by blocks with the base
        model's matrix ``J0`` (:meth:`SensitivityModel.block_solve`). The
        right side, and the coupling of each parameter's rows to the base
        block's solution, are directional central differences of the
        augmented residual (the generated Jacobian has only the diagonal
        blocks)."""
        from .initialize import _event_matrix
        sm = self.sm
        N, nsa = len(sm.dae.y), sm.ns * (1 + sm.m)
        if N == nsa:
            return YP
        Y, YP = np.asarray(Y, float), np.array(YP, dtype=float)
        J, _ = _event_matrix(cb, t, Y, YP, nsa)
        move = np.zeros(N)
        move[:nsa] = YP[:nsa]
        dt = 1e-6 * max(1.0, abs(t))
        count = cb[5] if len(cb) > 5 else None
        saved = list(count) if count is not None else None
        rhs = -_central(lambda h: _residual(cb, t + h, Y + h * move, YP), dt)
        x = sm.block_solve(J, rhs, lambda x0: self._coupling(cb, t, Y, YP, x0))
        if count is not None:   # these are not solver step attempts
            count[:] = saved
        if np.all(np.isfinite(x)):
            YP[nsa:] = x[:N - nsa]
        return YP

    def _coupling(self, cb, t, Y, YP, x0):
        """(rows of the parameters' blocks) the augmented residual's
        derivative along the base block's unknowns moved by ``x0`` (its
        re-initialisation columns: the algebraic slots' y, the states' y')."""
        sm = self.sm
        N, nsa = len(sm.dae.y), sm.ns * (1 + sm.m)
        rows, cols = sm._event_blocks()
        v = np.zeros(N)                              # event-matrix column space
        v[cols[0]] = x0
        dY, dYP = np.zeros(N), np.zeros(N)
        dY[nsa:] = v[:N - nsa]
        dYP[:nsa] = v[N - nsa:]
        base = np.concatenate([Y[nsa:], YP[:nsa]])
        h = 1e-7 * (1.0 + np.max(np.abs(base))) / max(np.max(np.abs(x0)), 1e-300)
        return _central(lambda e: _residual(cb, t, Y + e * dY, YP + e * dYP), h)

    # -- events ------------------------------------------------------------------
    def polish(self, t, Y, YP, d_aug):
        """The point IDA located a root at, with its algebraic unknowns and
        derivatives re-solved from the (augmented) equations: IDA's
        interpolated values there meet them only to the tolerance. The last
        one is kept: a mode change polishes the point its event time did."""
        last = self._polished
        if (last is not None and last[0] == t and np.array_equal(last[1], Y)
                and np.array_equal(last[2], YP) and last[3] == list(d_aug)):
            return last[4], last[5]
        out = self.reinit(t, Y, YP, d_aug, rates=False)
        self._polished = (t, np.array(Y), np.array(YP), list(d_aug)) + out
        return out

    def event_time(self, t, Y, YP, d_aug, i, rates):
        """dtau/dp (m) of root ``i`` at the (polished) point ``(t, Y, Y')``;
        ``rates`` = (y', y'') of the base model there."""
        sm = self.sm
        nd = len(sm.base.disc_syms)
        (y, S), (yp, Sp) = sm.unpack(Y), sm.unpack(YP)
        Gy, Gyp, Gt, Gp, Gd = sm.rootgrad(t, y, yp, self.p, d_aug[:nd])
        sd = sm.sd_of(d_aug)
        num = S @ Gy[i] + Sp @ Gyp[i] + Gp[i] + sd @ Gd[i]
        rate = Gy[i] @ rates[0] + Gyp[i] @ rates[1] + Gt[i]
        if rate == 0 or not np.isfinite(rate):
            return np.full(sm.m, np.nan)   # a grazing root: tau is not differentiable
        return -num / rate

    def event_times(self, t, Y, YP, d_aug, fired, current=False):
        """index -> dtau/dp of each fired event; with ``current`` the first
        one is the instant's (the one its mode changes jump by)."""
        n_ev = len(self.sm.base.events)
        fired = [i for i in fired if i < n_ev]
        if not fired:
            return {}
        Y, YP = self.polish(t, Y, YP, d_aug)
        rates = _rates(self.sm, self.serve(self.sm.base, d_aug[:len(self.sm.base.disc_syms)]),
                       t, Y, YP)
        taus = {i: self.event_time(t, Y, YP, d_aug, i, rates) for i in fired}
        if current and taus:
            first = taus[min(taus)]
            self.dtau[:] = np.where(np.isfinite(first), first, 0.0)
        return taus

    def note(self, k, dtau):
        self.noted[k] = np.asarray(dtau, float)

    def mode_change(self, events, t, Y, YP, d_before, d_after, obs):
        """After ``events``' actions changed the discrete values from
        ``d_before`` to ``d_after`` (augmented, the sensitivities still those
        before) at the point ``(t, Y, Y')`` with base observed values
        ``obs``: the new discrete sensitivities, the re-initialised point and
        the jump of the states' sensitivities. Returns (d, callbacks, Y, Y')."""
        sm = self.sm
        nd = len(sm.base.disc_syms)
        Y, YP = self.polish(t, Y, YP, d_before)
        self.sd_all = self._action_sensitivities(events, t, Y, YP, d_before, obs, self.dtau)
        d_new = list(d_after[:nd]) + self.sd_all[:, sm.dyn].ravel().tolist()
        cb = self.serve(sm, d_new)
        Y1, YP1 = self.reinit(t, Y, YP, d_new, rates=False)
        ns = sm.ns
        jump = (np.asarray(YP)[:ns] - YP1[:ns])[None, :] * self.dtau[:, None]   # m x ns
        if np.any(jump != 0):
            y, S = sm.unpack(Y1)
            S[:, :ns] += jump
            Y1, YP1 = self.reinit(t, sm.pack(y, S), YP1, d_new, rates=False)
        YP1 = self.rates(cb, t, Y1, YP1)
        return d_new, cb, Y1, YP1

    def _action_sensitivities(self, events, t, Y, YP, d_before, obs, dtau):
        """The sensitivities of every discrete value after ``events``' actions
        (m x nd; ``self.sd_all`` before them): the actions' directional
        derivative along the total derivative of what they read (the
        observed values at the event time ``t + dtau dp``, the parameters,
        the discrete values), by central differences."""
        sm, cm = self.sm, self.sm.base
        nd, nobs = len(cm.disc_syms), len(cm.var_names)
        sd = self.sd_all.copy()
        if not any(ev.action is not None for ev in events):
            return sd
        out = np.asarray(self.serve(sm, d_before)[4](t, Y, YP), float)
        dobs = out[nobs:].reshape(sm.m, nobs)
        odot = self._observed_rate(t, Y, YP, d_before)
        obs = np.asarray(obs, float)[:nobs]
        for j, k in enumerate(sm.pidx):
            h = 1e-6 * (abs(self.p[k]) if self.p[k] != 0 else 1.0)
            vals, written = [], np.zeros(nd, bool)
            for sgn in (1.0, -1.0):
                q = self.p.copy()
                q[k] += sgn * h
                given = np.asarray(d_before[:nd], float) + sgn * h * sd[j]
                st = EventState(cm, q, list(given), t + sgn * h * dtau[j],
                                list(obs + sgn * h * (dobs[j] + odot * dtau[j])))
                for ev in events:
                    if ev.action is not None:
                        ev.action(st)
                vals.append(np.array(st.d[:nd], float))
                written |= vals[-1] != given
            # a value no action wrote keeps its sensitivity exactly
            sd[j] = np.where(written, (vals[0] - vals[1]) / (2 * h), sd[j])
        return sd

    def observer_actions(self, events, t, Y, YP, d_before, obs, taus):
        """Observer events' actions ran at ``t``: the sensitivities of the
        discrete values they record (``taus``: index -> dtau/dp)."""
        cm = self.sm.base
        for ev in events:
            i = cm.events.index(ev)
            dtau = np.nan_to_num(taus.get(i, np.zeros(self.sm.m)))
            self.sd_all = self._action_sensitivities([ev], t, Y, YP, d_before, obs, dtau)

    def _observed_rate(self, t, Y, YP, d_aug):
        """d(observed)/dt along the solution, by a central difference."""
        sm = self.sm
        nobs = len(sm.base.var_names)
        obs = self.serve(sm, d_aug)[4]
        dt = 1e-7 * self.span
        Y, YP = np.asarray(Y, float), np.asarray(YP, float)
        a = np.asarray(obs(t + dt, Y + dt * YP, YP), float)[:nobs]
        b = np.asarray(obs(t - dt, Y - dt * YP, YP), float)[:nobs]
        return (a - b) / (2 * dt)

    # -- result ------------------------------------------------------------------
    def result_data(self, T, Y, YP, D, SD, n_events):
        """A :class:`Sensitivities` of the stored rows."""
        E = np.full((n_events, self.sm.m), np.nan)
        for k, v in self.noted.items():
            if k < n_events:
                E[k] = v
        SD = SD.reshape(len(T), self.sm.m, len(self.sm.base.disc_syms))
        return Sensitivities(self.sm, self.p, T, Y, YP, D, SD, E)


def _residual(cb, t, Y, YP):
    r = np.zeros(len(Y))
    cb[0](t, Y, YP, r)
    return r


def _central(f, h):
    """(f(h) - f(-h)) / 2h."""
    return (f(h) - f(-h)) / (2 * h)


def _rates(sm, cb, t, Y, YP):
    """(y', y'') of the base model (its callbacks ``cb``) at a consistent point: y' of the states
    from ``YP``, y' of the algebraic unknowns and y'' of the states from the
    equations differentiated once along the solution,
    ``[F_y(alg) F_y'(states)] [y'_alg; y''_states] = -(F_t + F_y(states) y'_states)``
    (as :func:`acausal.initialize._algebraic_rates`; F_t by a central
    difference)."""
    from .initialize import _jacobians
    cm, n, ns = sm.base, sm.n, sm.ns
    y, yp = sm.unpack(Y)[0], sm.unpack(YP)[0]
    ydot, ydd = np.array(yp, float), np.zeros(n)
    if n == ns and not any(s is not None for s in cm.dae.yp):
        return ydot, ydd
    Jy, Jyp = _jacobians(cb, t, y, yp, n)
    dt = 1e-7 * max(1.0, abs(t))
    rp, rm = np.zeros(n), np.zeros(n)
    cb[0](t + dt, y, yp, rp)
    cb[0](t - dt, y, yp, rm)
    rhs = -((rp - rm) / (2 * dt) + Jy[:, :ns] @ yp[:ns])
    J = np.hstack([Jy[:, ns:], Jyp[:, :ns]])
    try:
        sol = np.linalg.solve(J, rhs)
    except np.linalg.LinAlgError:
        sol = np.linalg.lstsq(J, rhs, rcond=None)[0]
    ydot[ns:] = sol[:n - ns]
    ydd[:ns] = sol[n - ns:]
    return ydot, ydd


def _initial_state_sensitivities(sm, cm, cb, cb_base, p, d, t0, y, yp, starts):
    """d(states)/dp (m x ns) at the consistent initial point (``cb``, ``cb_base``:
    the augmented and the base model's callbacks): the initial
    system (residuals, fixed starts, imposed guesses; see
    :mod:`acausal.initialize`) differentiated with respect to each parameter
    and solved for ``dz = (dy, dy'_states)`` (implicit function theorem)."""
    from .initialize import _choose_guesses, _jacobians, _lstsq_scaled
    n, ns, m = sm.n, sm.ns, sm.m
    Jy, Jyp = _jacobians(cb_base, t0, y, yp, n)
    rows = [np.hstack([Jy, Jyp[:, :ns]])]
    fixed = cm.fixed_starts(p, starts)
    if fixed:
        F = np.asarray(cm.fixed_jacobian()(t0, *y, *yp, *p, *d), float)
        rows.append(F.reshape(len(fixed), n + ns))
    A = np.vstack(rows)
    guesses = _choose_guesses(A, ns, cm.state_guess_order())
    # F_p and the observed variables' o_p: the sensitivity rows at s = 0
    zero = sm.pack(y, np.zeros((m, n))), sm.pack(yp, np.zeros((m, n)))
    r = np.zeros(len(sm.dae.y))
    cb[0](t0, zero[0], zero[1], r)
    Fp = sm.unpack(r)[1]                              # m x n (rows ordered as y)
    nobs = len(cm.var_names)
    op = np.asarray(cb[4](t0, *zero), float)[nobs:].reshape(m, nobs)
    G = np.zeros((len(guesses), n + ns))
    for a, k in enumerate(guesses):
        G[a, k] = 1.0
    A = np.vstack([A, G])
    out = np.zeros((m, ns))
    for j, k in enumerate(sm.pidx):
        h = 1e-6 * (abs(p[k]) if p[k] != 0 else 1.0)
        qp, qm = np.array(p, float), np.array(p, float)
        qp[k] += h
        qm[k] -= h
        dv = np.array([_start_derivative(cm, name, k, p, starts) for _, _, name in fixed])
        dg = (cm.guess_vector(qp, starts) - cm.guess_vector(qm, starts)) / (2 * h)
        rhs = [-Fp[j]]
        if fixed:
            rhs.append(-(op[j][[kk for kk, _, _ in fixed]] - dv))
        rhs.append(np.array([dg[kk] for kk in guesses]))
        dz = _lstsq_scaled(A, np.concatenate(rhs))
        out[j] = dz[:ns]
    return out


def _start_derivative(cm, name, k, p, starts):
    """d(fixed start value of variable ``name``)/d(parameter ``k``): the start
    value is a number (0), an override for this run (0) or an expression of
    parameters (differentiated symbolically)."""
    value = cm.flat.variables[name].start.value
    if (starts and name in starts) or not isinstance(value, sp.Basic) or value.is_number:
        return 0.0
    e = value.xreplace(cm._subs)
    de = diff(e, cm.param_syms[k])
    return float(de.xreplace(dict(zip(cm.param_syms, map(float, p)))))


class Sensitivities:
    """The sensitivities a run stored (``Result.sensitivity`` reads them)."""

    def __init__(self, sm, p, T, Y, YP, D, SD, E):
        self.sm, self.p, self.t = sm, p, T
        self.Y, self.YP, self.D, self.SD, self.events = Y, YP, D, SD, E
        self._obs = None

    def names(self):
        return list(self.sm.names)

    def _j(self, param):
        if param not in self.sm.names:
            raise UsageError(f"no sensitivity with respect to {param!r}: the run computed "
                             f"them for {', '.join(self.sm.names)} (simulate(sensitivities=...))")
        return self.sm.names.index(param)

    def observed(self):
        """rows x m x len(var_names): d(variable)/d(parameter) at every row."""
        if self._obs is None:
            sm = self.sm
            nobs = len(sm.base.var_names)
            out = np.empty((len(self.t), sm.m, nobs))
            cache = {}
            for k in range(len(self.t)):
                key = tuple(self.D[k])
                cb = cache.get(key)
                if cb is None:
                    cb = cache[key] = sm.callbacks(self.p, list(key))
                o = np.asarray(cb[4](self.t[k], self.Y[k], self.YP[k]), float)
                out[k] = o[nobs:].reshape(sm.m, nobs)
            self._obs = out
        return self._obs

    def of(self, var, param):
        j = self._j(param)
        names = self.sm.base.var_names
        discretes = [s.name for s in self.sm.base.disc_syms]
        if var in discretes:
            return self.SD[:, j, discretes.index(var)]
        if var not in names:
            if var in self.sm.names or var in [e.name for e in self.sm.base.params]:
                return np.full(len(self.t), 1.0 if var == param else 0.0)
            from ..errors import UnknownNameError
            raise UnknownNameError(f"no variable {var!r} in the result", variable=var)
        return self.observed()[:, j, names.index(var)]

    def event(self, param):
        return self.events[:, self._j(param)]

    def measure(self, result, fn, param, rel_step=1e-6):
        """d fn(result) / d param for a measure ``fn`` (any function of a
        result): a central difference of ``fn`` over the result moved to
        first order along the sensitivities (unknowns, discrete values, event
        times and the rows at events with them, the parameter itself), so no
        simulation is repeated and the difference is exact for measures that
        are linear in what they read (event times, values at events,
        discrete values) and second-order accurate for others."""
        j = self._j(param)
        k = self.sm.pidx[j]
        h = rel_step * (abs(self.p[k]) if self.p[k] != 0 else 1.0)
        return (fn(self._moved(result, j, h)) - fn(self._moved(result, j, -h))) / (2 * h)

    def _moved(self, result, j, h):
        """``result`` with parameter j moved by ``h``, to first order."""
        from .result import Result
        sm = self.sm
        y, S = sm.unpack(self.Y)
        yp, Sp = sm.unpack(self.YP)
        dtau = np.nan_to_num(self.events[:, j])
        shift = np.zeros(len(self.t))
        for (te, _), dt in zip(result.events, dtau):
            shift[self.t == te] = dt      # rows at an event move with it
        p = np.array(self.p, float)
        p[sm.pidx[j]] += h
        T = self.t + h * shift
        Ym = y + h * (S[:, j] + yp * shift[:, None])
        D = self.D[:, :self.SD.shape[2]] + h * self.SD[:, j]
        events = [(te + h * dt, name) for (te, name), dt in zip(result.events, dtau)]
        return Result(sm.base, p, T, Ym, yp + h * Sp[:, j], D, events, result.stats,
                      result.status, result.message)
