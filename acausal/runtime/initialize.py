"""Consistent initial conditions.

At the start, the unknowns are every ``y`` and the derivatives ``y'`` of the
states; the equations are the residuals plus one equation per *fixed* start
value. When fixed starts do not pin every degree of freedom, guesses of
states are added (chosen where they raise the rank of the Jacobian). The
system is solved by least squares; fixed starts that contradict each other
or the model raise :class:`InitializationError` naming them — they are never
silently changed. After an event only the algebraic unknowns and ``y'`` are
recomputed, the states are kept.
"""
import math

import numpy as np
import scipy.linalg
import scipy.sparse as sps
import scipy.sparse.linalg
import sympy as sp
from scipy.optimize import least_squares
from scipy.sparse.csgraph import structural_rank

from ..infra.blas import single_threaded
from ..compiler.codegen import Triplets
from ..errors import InitializationError


def _jacobians(cb, t, y, yp, n):
    Jy = np.zeros((n, n))
    Jyp = np.zeros((n, n))
    cb[3](t, y, yp, Jy, Jyp)
    return Jy, Jyp


def initial_point(cm, p, d, cb, t0, starts=None):
    """Return (y0, yp0) consistent with the model and its fixed starts
    (``starts``: name -> value overriding declared fixed start values).
    When there is none because of a parameter changed from its default (a
    1e30 N/m spring), the InitializationError names that parameter."""
    with single_threaded(len(cm.dae.y)):
        try:
            return _solve_initial(cm, p, d, cb, t0, starts)
        except InitializationError as exc:
            _raise_if_parameter_breaks(cm, t0, p, d, exc)
            raise


class _InitialSystem:
    """The initial equations at ``t0``: the residuals, one row per fixed
    start value and one per imposed guess, over z = (y, y' of the states);
    dense, or sparse from :data:`SPARSE_MIN` unknowns."""

    def __init__(self, cm, p, d, cb, t0, starts):
        self.cm, self.p, self.d, self.cb, self.t0 = cm, p, d, cb, t0
        self.n, self.ns = len(cm.dae.y), cm.dae.n_states
        self.fixed = cm.fixed_starts(p, starts)   # list of (var index, value, name)
        y0 = cm.guess_vector(p, starts)
        # start Newton at the fixed start values of the states (a fixed velocity
        # is the value of the slot der(x), which the guess vector leaves at 0): a
        # steep law near 0 (regularised friction) can stall it far from them
        _snap_fixed_states(cm, y0, self.fixed)
        self.z0 = np.concatenate([y0, np.zeros(self.ns)])
        self.sparse = self.n + self.ns >= SPARSE_MIN
        self.fixed_jac = cm.fixed_jacobian(sparse=self.sparse)
        self.r = np.zeros(self.n)

    def split(self, z):
        y = z[:self.n]
        yp = np.zeros(self.n)
        yp[:self.ns] = z[self.n:]
        return y, yp

    def residual(self, z, guess_rows=()):
        y, yp = self.split(z)
        self.cb[0](self.t0, y, yp, self.r)
        o = self.cb[4](self.t0, y, yp)
        f = [o[k] - v for k, v, _ in self.fixed]
        gz = [z[k] - self.z0[k] for k in guess_rows]
        return np.concatenate([self.r, f, gz])

    def jac(self, z, guess_rows=()):
        y, yp = self.split(z)
        F = self.fixed_jac(self.t0, *y, *yp, *self.p, *self.d) if self.fixed else None
        return _initial_jacobian(self.cb, self.t0, y, yp, self.ns, F, guess_rows, self.sparse)

    def check(self, z):
        """:func:`_check` of the point ``z`` (an InitializationError naming
        what it violates)."""
        if self._c_check(z) is not True:
            _check(self.cm, self.residual(z), self.jac(z), z, self.fixed, self.n)

    def consistent(self, z):
        ok = self._c_check(z)
        if ok is NotImplemented:
            return _consistent(self.cm, self.residual(z), self.jac(z), z, self.fixed, self.n)
        return ok

    def _c_check(self, z):
        """The backend's own consistency test (``cb.init_check``, the compiled
        backend's C: the same test), else NotImplemented."""
        fast = getattr(self.cb, "init_check", None)
        return NotImplemented if fast is None else fast(self.t0, z, self.fixed)


def _solve_initial(cm, p, d, cb, t0, starts=None):
    """initial_point without the diagnosis of its failure."""
    sys_ = _InitialSystem(cm, p, d, cb, t0, starts)
    if sys_.n == 0:   # every unknown explicit: only the fixed starts to check
        full = sys_.residual(sys_.z0)
        try:
            _check(cm, full, np.zeros((len(full), 0)), sys_.z0, sys_.fixed, 0)
        except InitializationError as exc:
            raise InitializationError(
                f"{exc}; the model has no states (every motion is prescribed by supports "
                "and sources), so a fixed start must agree with the prescribed motion",
                component=exc.component, variable=exc.variable) from None
        return np.zeros(0), np.zeros(0)
    z0 = sys_.z0
    guess_rows, z, checked = _guesses_and_newton(cm, cb, t0, sys_, starts)
    if not checked:
        z = least_squares(sys_.residual, z0, jac=sys_.jac, args=(guess_rows,), method="trf",
                          xtol=1e-15, ftol=1e-15, gtol=1e-15, max_nfev=200,
                          x_scale="jac").x
    y, yp = sys_.split(z)
    violated = _violated_assertion(cm, cb, t0, y, yp)
    try:
        if not checked:   # (Newton's point has just passed this same check)
            sys_.check(z)
    except InitializationError as exc:
        if violated:
            raise InitializationError(f"{violated}; {exc}") from None
        raise
    if violated:
        raise InitializationError(violated)
    _snap_fixed_states(cm, y, sys_.fixed)
    # least squares meets a fixed start only to ~1e-16 and leaves round-off
    # (1e-30) in unknowns that are exactly zero: impose the fixed states
    # exactly (a body that starts at rest must be exactly at rest) and
    # recompute the algebraic unknowns and y' for them by Newton refined to
    # its floor, so that a stuck friction mode (der(v) = 0) integrates an
    # exact zero and holds v = 0 exactly, not at 1e-78
    y, yp = reinitialize(cm, cb, t0, y, yp)
    sys_.check(np.concatenate([y, yp[:sys_.ns]]))
    return y, yp    # reinitialize has filled the algebraic rates


def _guesses_and_newton(cm, cb, t0, sys_, starts):
    """(guess_rows, z, consistent(z)): the state guesses to impose
    (:func:`_choose_guesses`) and Gauss-Newton from them (:func:`_first_newton`).

    Which guesses make the Jacobian full rank is a matter of the model's
    structure, the same at every parameter set in practice, while the rank
    tests cost more than the Newton solve: the rows that gave a consistent
    point are kept per model and set of fixed starts and tried first. A point
    from them is consistent (the same check as always) or the rows are
    chosen afresh from the Jacobian at the guesses.

    Newton from the guesses comes first: it converges to the solution
    nearest to them (e.g. the assembly mode of a linkage its guesses
    describe). The trust-region least squares is the caller's fallback; its
    long steps (in variables with small Jacobian columns, such as lengths in
    m) can reach another solution."""
    key = (tuple(k for k, _, _ in sys_.fixed), tuple(sorted(starts or ())))
    memo = cm.__dict__.setdefault("_guess_rows", {})
    kept = memo.get(key)
    if kept is not None:
        z, checked = _first_newton(cb, t0, sys_.z0, kept, sys_.fixed, sys_.residual,
                                   sys_.jac, sys_.consistent)
        if checked:
            return kept, z, True
    rows = _choose_guesses(sys_.jac(sys_.z0), sys_.ns, cm.state_guess_order())
    if rows == kept:
        return rows, z, False
    z, checked = _first_newton(cb, t0, sys_.z0, rows, sys_.fixed, sys_.residual, sys_.jac,
                               sys_.consistent)
    if checked:
        memo[key] = rows
    return rows, z, checked


def _first_newton(cb, t0, z0, guess_rows, fixed, residual, jac, consistent):
    """(z, consistent(z)) of Gauss-Newton from the guesses: the backend's
    own (``cb.init_newton``, the compiled backend's C) where it has one,
    else :func:`_newton`; also :func:`_newton` when the C point fails the
    check (its QR declines only below a 1e-10 ratio of R's diagonal, and a
    nearly rank-deficient system, such as a 1e-12 kg*m^2 hook inertia, is
    solved better by the SVD of numpy's least squares)."""
    newton = getattr(cb, "init_newton", None)
    z = newton(t0, z0, guess_rows, fixed) if newton is not None else NotImplemented
    if z is not NotImplemented and z is not None and consistent(z):
        return z, True
    z = _newton(lambda zz: residual(zz, guess_rows), lambda zz: jac(zz, guess_rows), z0)
    return z, z is not None and consistent(z)


# unknowns (y and the states' y') from which the initialisation assembles
# sparse Jacobians and solves them by sparse LU: the dense least squares grew
# as n^3 (0.5 s per Newton step for a 200-mass chain, single-threaded)
SPARSE_MIN = 200


def _initial_jacobian(cb, t, y, yp, ns, F, guess_rows, sparse):
    """The initial system's Jacobian d(residuals, fixed starts ``F`` rows,
    guess rows)/d(y, y'_states), dense or ``scipy.sparse`` CSR."""
    n = len(y)
    if sparse:
        Jy, Jyp = Triplets((n, n)), Triplets((n, n))
        cb[3](t, y, yp, Jy, Jyp)
        blocks = [[Jy.tocsr(), Jyp.tocsr()[:, :ns]]]
        if F is not None:
            blocks.append([F[:, :n], F[:, n:]])
        if guess_rows:
            G = sps.csr_matrix((np.ones(len(guess_rows)), (range(len(guess_rows)), guess_rows)),
                               shape=(len(guess_rows), n + ns))
            blocks.append([G[:, :n], G[:, n:]])
        return sps.bmat(blocks, format="csr")
    Jy, Jyp = _jacobians(cb, t, y, yp, n)
    rows = [np.hstack([Jy, Jyp[:, :ns]])]
    if F is not None:
        rows.append(np.asarray(F, dtype=float).reshape(-1, n + ns))
    if guess_rows:
        G = np.zeros((len(guess_rows), n + ns))
        for a, k in enumerate(guess_rows):
            G[a, k] = 1.0
        rows.append(G)
    return np.vstack(rows)


def _raise_if_parameter_breaks(cm, t0, p, d, exc):
    """Raise an InitializationError naming the parameter whose value makes
    the initial equations unsolvable, instead of ``exc``: each parameter
    set (``--set``, ``simulate(params=...)``) SUSPECT_DECADES or more away
    from its default is put back to its default alone, and the first one
    with which the equations solve is named (a 1e30 N/m spring or a 1e-30
    kg*m^2 inertia makes them numerically singular, which shows as
    "inconsistent fixed start values"). Only the generic failures are
    diagnosed; a named cause (a linkage that cannot close) is kept."""
    text = str(exc)
    if not any(m in text for m in ("inconsistent fixed start values",
                                   "no consistent initial point")):
        return  # a named cause alone (a linkage that cannot close)
    # (an absurd stiffness can also push a linkage past its assertion: then
    # both are reported, and only parameters SUSPECT_DECADES away are tried)
    for name, value, default, unit in suspect_parameters(cm, p):
        k = cm.param_index(name)
        q = np.array(p, dtype=float)
        q[k] = default
        try:
            _solve_initial(cm, q, d, cm.callbacks(q, d), t0)
        except (InitializationError, ArithmeticError, ValueError, np.linalg.LinAlgError):
            continue
        raise InitializationError(
            f"parameter {name} = {value:g} [{unit}] makes the initial equations "
            f"unsolvable (with its default {default:g} they solve): check its value "
            f"and unit; the initialisation said: {exc}",
            variable=name) from None


def suspect_parameters(cm, p):
    """(name, value, default, unit) of each parameter SUSPECT_DECADES or more
    from its default: named when a run fails (a 1e-30 kg*m^2 inertia makes
    the equations too stiff to integrate)."""
    return [(e.name, float(p[k]), e.default, e.unit) for k, e in enumerate(cm.params)
            if _far_from(p[k], e.default)]


# A value this many decades from the parameter's default is suspect when
# the initialisation fails (a 1e30 N/m spring for 2.4e5, a 1e-30 kg*m^2
# inertia for 4.4e-4); values nearer their defaults are design changes.
SUSPECT_DECADES = 6.0


def _far_from(value, default):
    """True if ``value`` lies SUSPECT_DECADES or more (in magnitude) from a
    nonzero default."""
    if default == 0 or value == 0:
        return False
    return abs(math.log10(abs(value / default))) >= SUSPECT_DECADES


def _snap_fixed_states(cm, y, fixed):
    """Set every state slot that a fixed start names (directly or negated)
    exactly to its value; True when a slot changed."""
    changed = False
    for _, value, name in fixed:
        hit = cm.state_slot_of(name)
        if hit is not None and y[hit[0]] != hit[1] * value:
            y[hit[0]] = hit[1] * value
            changed = True
    return changed


def _violated_assertion(cm, cb, t, y, yp):
    """Message of the first assertion that does not hold (``expr < 0``) at
    the initial point, or None. An assertion only fires when its expression
    crosses zero, so one that is already violated at the start must be
    reported here."""
    if not cm.assertions:
        return None
    g = np.zeros(cm.n_roots)
    try:
        cb[2](t, y, yp, g)
    except (ArithmeticError, ValueError):
        return None
    n_ev = len(cm.events)
    for a, v in zip(cm.assertions, g[n_ev:]):
        if v < 0 or not np.isfinite(v):
            return f"{a.owner}: {a.message} (at the initial point, t = {t:g} s)"
    return None


def _newton(fun, jac, z, max_iter=50):
    """Gauss-Newton with step halving from ``z``; the last iterate (the
    caller checks it) or None when the residual is not finite."""
    r = fun(z)
    nr = np.linalg.norm(r)
    for _ in range(max_iter):
        if not np.all(np.isfinite(r)):
            return None
        dz = _lstsq_scaled(jac(z), -r)
        step = 1.0
        for _ in range(30):
            if np.all(np.abs(step * dz) <= 1e-13 * (1 + np.abs(z))):
                # a step this short is below the convergence test's own size
                # (below): z is converged; do not spend up to 30 residuals
                # halving a step that round-off no longer lets reduce |r|
                return z
            z2 = z + step * dz
            r2 = fun(z2)
            n2 = np.linalg.norm(r2)
            if np.isfinite(n2) and n2 <= nr * (1 - 1e-4 * step) or n2 <= 1e-300:
                break
            step *= 0.5
        else:
            return z          # no more progress (converged to round-off, or stuck)
        z, r, nr = z2, r2, n2
        if np.all(np.abs(step * dz) <= 1e-13 * (1 + np.abs(z))) or nr == 0.0:
            return z
    return z


def _lstsq_scaled(J, b):
    """Least-squares solution of ``J x = b`` with the columns of ``J``
    scaled to unit norm first: the unknowns mix positions, velocities,
    accelerations and forces whose columns can differ by many orders of
    magnitude (a stiff spring next to a light body), and an unscaled
    solve would cut the small columns off as rank deficiency."""
    if sps.issparse(J):
        return _sparse_lstsq_scaled(J, b)
    norms = np.linalg.norm(J, axis=0)
    d = np.where(norms > 0, 1.0 / np.where(norms > 0, norms, 1.0), 1.0)
    return d * np.linalg.lstsq(J * d, b, rcond=None)[0]


def _sparse_scaled(J):
    """(J with unit-norm columns as CSC, the column scale factors)."""
    norms = np.sqrt(np.asarray(J.multiply(J).sum(axis=0)).ravel())
    d = np.where(norms > 0, 1.0 / np.where(norms > 0, norms, 1.0), 1.0)
    return (J @ sps.diags(d)).tocsc(), d


def _sparse_lu(Js):
    """A sparse LU (SuperLU) of ``Js`` when square, else of the augmented
    system ``[[I, Js], [Js^T, 0]]``, whose solution is the least-squares
    one (and which is non-singular exactly when Js has full column rank);
    None when SuperLU finds it singular."""
    m, k = Js.shape
    K = Js if m == k else sps.bmat([[sps.identity(m), Js], [Js.T, None]], format="csc")
    try:
        return scipy.sparse.linalg.splu(K.tocsc())
    except RuntimeError:      # "Factor is exactly singular"
        return None


def _sparse_lstsq_scaled(J, b):
    """:func:`_lstsq_scaled` of a sparse ``J`` by sparse LU; the dense least
    squares when the LU finds the system singular or gives no finite
    solution."""
    Js, d = _sparse_scaled(J)
    m, k = Js.shape
    lu = _sparse_lu(Js)
    if lu is not None:
        x = lu.solve(b if m == k else np.concatenate([b, np.zeros(k)]))[-k:]
        if np.all(np.isfinite(x)):
            return d * x
    return d * np.linalg.lstsq(Js.toarray(), b, rcond=None)[0]


def _sparse_full_rank(J, tol=1e-12):
    """True when the sparse ``J`` (more rows than columns, or square) has
    full column rank: structurally, and by its sparse LU, whose smallest
    pivot must not fall below ``tol`` times the largest (columns scaled to
    unit norm first)."""
    if structural_rank(J) < J.shape[1]:
        return False
    lu = _sparse_lu(_sparse_scaled(J)[0])
    if lu is None:
        return False
    piv = np.abs(lu.U.diagonal())
    return bool(piv.min() > tol * piv.max())


def _consistent(cm, full, J, z, fixed, n):
    try:
        _check(cm, full, J, z, fixed, n)
        return True
    except InitializationError:
        return False


def _choose_guesses(J, ns, order):
    """Indices of state slots whose guess must be imposed so that the
    Jacobian has full column rank."""
    if sps.issparse(J):
        if J.shape[0] >= J.shape[1] and _sparse_full_rank(J):
            return []
        J = J.toarray()
    m = J.shape[1]
    rank = np.linalg.matrix_rank(J) if J.size else 0
    chosen = []
    for k in order:
        if rank >= m:
            break
        row = np.zeros((1, m))
        row[0, k] = 1.0
        J2 = np.vstack([J, row])
        r2 = np.linalg.matrix_rank(J2)
        if r2 > rank:
            J, rank = J2, r2
            chosen.append(k)
    return chosen


def _check(cm, full, J, z, fixed, n):
    scale = abs(J) @ (np.abs(z) + 1e-12) + 1e-12
    bad = np.abs(full) > 1e-7 * scale + 1e-10
    if not bad.any():
        return
    names = [name for a, (_, _, name) in enumerate(fixed) if bad[n + a]]
    rows = [k for k in range(n) if bad[k]]
    if names:
        detail = ", ".join(f"{nm} = {v:g}" for (_, v, nm) in fixed if nm in names)
        owners = [cm.flat.owner_of(sp.Symbol(nm)) for nm in names]
        hint = _component_explanation(cm, rows, f" (fixed starts {detail})", owners)
        if hint is not None:
            raise hint
        raise InitializationError(
            "inconsistent fixed start values: " + detail + " cannot all hold together with "
            "the model's equations (largest violation "
            f"{np.max(np.abs(full[n:])):.3g}); make some of them guesses "
            "(Start(value, fixed=False)) or correct them")
    origin = cm.dae.origins[rows[0]]
    what = origin.describe() if hasattr(origin, "describe") else str(origin)
    detail = f"; {what} is violated by {full[rows[0]]:.3g}"
    hint = _component_explanation(cm, rows, detail)
    if hint is not None:
        raise hint
    raise InitializationError(f"no consistent initial point found{detail}")


def _component_explanation(cm, rows, detail, paths=()):
    """The error a component gives for an initialisation failure in its own
    terms (see :func:`ask_components`), from the violated residual ``rows``
    and the component ``paths`` involved; None when none explains it."""
    paths = [p for p in paths if p]
    for k in rows:
        o = getattr(cm.dae.origins[k], "origin", None)
        if o and o not in paths:
            paths.append(o)
    return ask_components(cm.model, "initialization_failure", paths, detail)


def ask_components(model, method, paths, *args):
    """A component class may explain a failure in its own terms (a planar
    loop that cannot close, or that reached a dead centre, names the loop and
    its joints): the first error returned by ``method(model, paths, *args)``
    of a component class of the model (once per class), given the paths of
    the components involved; None when none explains it."""
    seen = set()
    for comp in model.walk():
        fn = getattr(type(comp), method, None)
        if fn is None or fn in seen:
            continue
        seen.add(fn)
        err = fn(comp, model, paths, *args)
        if err is not None:
            return err
    return None


def reinitialize(cm, cb, t, y, yp):
    """After an event: keep the states, recompute algebraic unknowns and y'.
    Callbacks that bring their own implementation of this algorithm
    (``cb.reinit``, the compiled backend's C) run it instead; it returns
    None where this one must run (a singular matrix)."""
    fast = getattr(cb, "reinit", None)
    if fast is not None:
        out = fast(t, y, yp)
        if out is not None:
            return out
    with single_threaded(len(cm.dae.y)):
        return _reinitialize(cm, cb, t, y, yp)


def _reinitialize(cm, cb, t, y, yp):
    """reinitialize without the BLAS thread limit."""
    dae = cm.dae
    n, ns = len(dae.y), dae.n_states
    r = np.zeros(n)
    y = np.array(y, dtype=float)
    yp = np.array(yp, dtype=float)
    z = np.concatenate([y[ns:], yp[:ns]])
    converged, last = False, np.inf
    for _ in range(50):
        cb[0](t, y, yp, r)
        if not r.any():
            break                     # exact: a further solve only adds round-off
        J, _ = _event_matrix(cb, t, y, yp, ns)
        dz = _solve_square(J, -r)
        size = float(np.max(np.abs(dz))) if dz.size else 0.0
        if converged and not size < last:
            break                     # refined to the round-off floor
        z = z + dz
        y[ns:] = z[:n - ns]
        yp[:ns] = z[n - ns:]
        # converged: then refine while the corrections still shrink (they
        # fall by ~1e-16 per step and reach exact zeros where the solution
        # is an exact zero)
        converged = converged or bool(np.all(np.abs(dz) <= 1e-12 * (1 + np.abs(z))))
        last = size
    return y, _algebraic_rates(cm, cb, t, y, yp)


def _algebraic_rates(cm, cb, t, y, yp):
    """Fill y' of the algebraic slots with their true rates.

    IDA keeps every component, algebraic ones too, in its BDF history and
    error test; an algebraic unknown that moves (a holding force under a
    ramped load) with y' = 0 makes the first step's error estimate ~ h*rate,
    which fails the error test down to the minimum step at tight tolerances.
    Differentiating F(t, y, y') = 0 once along the solution gives
    ``[F_y(alg) F_y'(states)] [y'_alg; y''_states] = -(F_t + F_y(states) y'_states)``:
    the same matrix as the re-initialisation. F_t by a central difference.
    """
    dae = cm.dae
    n, ns = len(dae.y), dae.n_states
    if n == ns:
        return yp
    yp = np.array(yp, dtype=float)
    J, Jy_states = _event_matrix(cb, t, y, yp, ns)
    dt = 1e-6 * max(1.0, abs(t))
    rp, rm = np.zeros(n), np.zeros(n)
    count = cb[5] if len(cb) > 5 else None
    saved = list(count) if count is not None else None
    cb[0](t + dt, y, yp, rp)
    cb[0](t - dt, y, yp, rm)
    if count is not None:   # these are not solver step attempts
        count[:] = saved
    rhs = -((rp - rm) / (2 * dt) + Jy_states @ yp[:ns])
    sol = _solve_square(J, rhs)
    if np.all(np.isfinite(sol)):
        yp[ns:] = sol[:n - ns]
    return yp


def _event_matrix(cb, t, y, yp, ns):
    """(J = [dF/dy of the algebraic slots, dF/dy' of the states], dF/dy of
    the states): the matrix of the re-initialisation, dense, or
    ``scipy.sparse`` CSC from SPARSE_MIN unknowns."""
    n = len(y)
    if n + ns >= SPARSE_MIN:
        Jy, Jyp = Triplets((n, n)), Triplets((n, n))
        cb[3](t, y, yp, Jy, Jyp)
        Jy, Jyp = Jy.tocsr().tocsc(), Jyp.tocsr().tocsc()
        return sps.hstack([Jy[:, ns:], Jyp[:, :ns]], format="csc"), Jy[:, :ns]
    Jy, Jyp = _jacobians(cb, t, y, yp, n)
    return np.hstack([Jy[:, ns:], Jyp[:, :ns]]), Jy[:, :ns]


def _solve_square(J, b):
    """``J x = b`` for a square dense or sparse ``J`` (LU); least squares
    when the LU finds it singular."""
    if sps.issparse(J):
        try:
            x = scipy.sparse.linalg.splu(J).solve(b)
            if np.all(np.isfinite(x)):
                return x
        except RuntimeError:      # "Factor is exactly singular"
            pass
        J = J.toarray()
    try:
        return scipy.linalg.solve(J, b)
    except (scipy.linalg.LinAlgError, ValueError):
        return np.linalg.lstsq(J, b, rcond=None)[0]
