"""Consistent initial conditions.

At the start, the unknowns are every ``y`` and the derivatives ``y'`` of the
states; the equations are the residuals plus one equation per *fixed* start
value. When fixed starts do not pin every degree of freedom, guesses of
states are added (chosen where they raise the rank of the Jacobian). The
system is solved by least squares; fixed starts that contradict each other
or the model raise :class:`InitializationError` naming them — they are never
silently changed. After an event only the algebraic unknowns and ``y'`` are
recomputed, the states are kept (Newton on the DAE with the states fixed,
the index-1 re-initialisation of Brown, Hindmarsh and Petzold 1998,
"Consistent initial condition calculation for differential-algebraic
systems"). The linear algebra is :mod:`.linalg`'s.
"""
import math
import weakref

import numpy as np
import scipy.sparse as sps
import sympy as sp
from scipy.optimize import least_squares

from . import linalg
from .linalg import SquareSolver, choose_guesses, event_matrix, jacobians, newton
from ..infra.blas import single_threaded
from ..compiler.codegen import Triplets
from ..errors import InitializationError

# generated code of a compiled model (shared by its copies with other
# parameter defaults) -> {(fixed starts, overridden starts): guess rows that
# gave a consistent point}: the runtime's memo across the model's runs (see
# _guesses_and_newton)
_GUESS_ROWS = weakref.WeakKeyDictionary()




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
        except np.linalg.LinAlgError as exc:
            # a NaN or inf in the Jacobian at the start values (a 1e300 m crank
            # radius: "SVD did not converge", a traceback)
            err = InitializationError(f"no consistent initial point found: the initial "
                                      f"equations are not finite at the start values ({exc})")
            _raise_if_parameter_breaks(cm, t0, p, d, err)
            raise err from None


class _InitialSystem:
    """The initial equations at ``t0``: the residuals, one row per fixed
    start value and one per imposed guess, over z = (y, y' of the states);
    dense, or sparse from :data:`acausal.runtime.linalg.SPARSE_MIN` unknowns."""

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
        self.sparse = self.n + self.ns >= linalg.SPARSE_MIN
        self.fixed_jac = cm.fixed_jacobian(sparse=self.sparse)
        self.r = np.zeros(self.n)

    def split(self, z):
        y = z[:self.n]
        yp = np.zeros(self.n)
        yp[:self.ns] = z[self.n:]
        return y, yp

    def residual(self, z, guess_rows=()):
        y, yp = self.split(z)
        self.cb.res(self.t0, y, yp, self.r)
        o = self.cb.observe(self.t0, y, yp)
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
        fast = self.cb.init_check
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
    (:func:`~acausal.runtime.linalg.choose_guesses`) and Gauss-Newton from
    them (:func:`_first_newton`).

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
    memo = _GUESS_ROWS.setdefault(cm.artefact.code, {})
    kept = memo.get(key)
    if kept is not None:
        z, checked = _first_newton(cb, t0, sys_, kept)
        if checked:
            return kept, z, True
    rows = choose_guesses(sys_.jac(sys_.z0), sys_.ns, cm.state_guess_order())
    if rows == kept:
        return rows, z, False
    z, checked = _first_newton(cb, t0, sys_, rows)
    if checked:
        memo[key] = rows
    return rows, z, checked


def _first_newton(cb, t0, sys_, guess_rows):
    """(z, consistent(z)) of Gauss-Newton from the guesses (the initial
    system ``sys_`` with ``guess_rows`` imposed): the backend's
    own (``cb.init_newton``, the compiled backend's C) where it has one,
    else :func:`~acausal.runtime.linalg.newton`; also that one when the C
    point fails the check (its QR declines only below a 1e-10 ratio of R's
    diagonal, and a nearly rank-deficient system, such as a 1e-12 kg*m^2
    hook inertia, is solved better by the SVD of numpy's least squares)."""
    fast = cb.init_newton
    z = fast(t0, sys_.z0, guess_rows, sys_.fixed) if fast is not None else NotImplemented
    if z is not NotImplemented and z is not None and sys_.consistent(z):
        return z, True
    z = newton(lambda zz: sys_.residual(zz, guess_rows), lambda zz: sys_.jac(zz, guess_rows),
               sys_.z0)
    return z, z is not None and sys_.consistent(z)



def _initial_jacobian(cb, t, y, yp, ns, F, guess_rows, sparse):
    """The initial system's Jacobian d(residuals, fixed starts ``F`` rows,
    guess rows)/d(y, y'_states), dense or ``scipy.sparse`` CSR."""
    n = len(y)
    if sparse:
        Jy, Jyp = Triplets((n, n)), Triplets((n, n))
        cb.jacs(t, y, yp, Jy, Jyp)
        blocks = [[Jy.tocsr(), Jyp.tocsr()[:, :ns]]]
        if F is not None:
            blocks.append([F[:, :n], F[:, n:]])
        if guess_rows:
            G = sps.csr_matrix((np.ones(len(guess_rows)), (range(len(guess_rows)), guess_rows)),
                               shape=(len(guess_rows), n + ns))
            blocks.append([G[:, :n], G[:, n:]])
        return sps.bmat(blocks, format="csr")
    Jy, Jyp = jacobians(cb, t, y, yp, n)
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
    if default == 0 or value == 0 or not (math.isfinite(value) and math.isfinite(default)):
        return False
    # a difference of logs: value / default underflows to 0 for a subnormal value
    return abs(math.log10(abs(value)) - math.log10(abs(default))) >= SUSPECT_DECADES


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
        cb.roots(t, y, yp, g)
    except (ArithmeticError, ValueError):
        return None
    n_ev = len(cm.events)
    for a, v in zip(cm.assertions, g[n_ev:]):
        if v < 0 or not np.isfinite(v):
            return f"{a.owner}: {a.message} (at the initial point, t = {t:g} s)"
    return None














def _consistent(cm, full, J, z, fixed, n):
    try:
        _check(cm, full, J, z, fixed, n)
        return True
    except InitializationError:
        return False




def _check(cm, full, J, z, fixed, n):
    scale = abs(J) @ (np.abs(z) + 1e-12) + 1e-12
    bad = np.abs(full) > 1e-7 * scale + 1e-10
    if not bad.any():
        return
    names = [name for a, (_, _, name) in enumerate(fixed) if bad[n + a]]
    rows = [k for k in range(n) if bad[k]]
    stuck = _no_real_solution(cm, full, J, z, rows)
    if stuck is not None:   # a component's own explanation first (a loop that cannot close)
        raise _component_explanation(cm, rows, f"; {stuck}") or stuck
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


NO_SOLUTION_REACH = 1e-3   # see _no_real_solution


def _no_real_solution(cm, full, J, z, rows):
    """An InitializationError for a violated equation at a minimum of its
    residual that is not a zero (``x**2 + 1 = 0``: the iteration ends at
    x = 0 with 1 left, its derivative 0), or None. Such a row changes by
    less than ``NO_SOLUTION_REACH`` of its residual when every unknown moves
    by its own size: no real solution near the starts, whatever the fixed
    starts are (it was reported as inconsistent fixed starts, or as another
    equation violated by rounding)."""
    if not rows or J.shape[1] == 0:
        return None
    reach = np.asarray(abs(J) @ (np.abs(z) + 1.0)).ravel()
    k = max(rows, key=lambda r: abs(full[r]) / (reach[r] + 1e-300))
    if not abs(full[k]) > 1e-8 or reach[k] >= NO_SOLUTION_REACH * abs(full[k]):
        return None
    origin = cm.dae.origins[k]
    what = origin.describe() if hasattr(origin, "describe") else str(origin)
    slots = cm.slot_names()
    cols = np.flatnonzero(np.asarray(abs(J[k]).todense() if hasattr(J, "todense")
                                     else np.abs(J[k])).ravel()[:len(slots)] > 0)
    unknowns = ", ".join(f"{slots[j][0]} = {z[j]:.6g}" for j in cols[:4] if slots[j]) or \
        "its unknowns"
    return InitializationError(
        f"the initial equations have no real solution near the start values: {what} stays "
        f"at {full[k]:.3g} where its residual has a minimum, not a zero ({unknowns}); "
        "check the equation's signs and terms")


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
    fast = cb.reinit
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
    solve = SquareSolver()
    for _ in range(50):
        cb.res(t, y, yp, r)
        if not r.any():
            break                     # exact: a further solve only adds round-off
        J, _ = event_matrix(cb, t, y, yp, ns)
        dz = solve(J, -r)
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
    return y, _algebraic_rates(cm, cb, t, y, yp, solve)


def _algebraic_rates(cm, cb, t, y, yp, solve):
    """Fill y' of the algebraic slots with their true rates.

    IDA keeps every component, algebraic ones too, in its BDF history and
    error test; an algebraic unknown that moves (a holding force under a
    ramped load) with y' = 0 makes the first step's error estimate ~ h*rate,
    which fails the error test down to the minimum step at tight tolerances.
    Differentiating F(t, y, y') = 0 once along the solution gives
    ``[F_y(alg) F_y'(states)] [y'_alg; y''_states] = -(F_t + F_y(states) y'_states)``:
    the same matrix as the re-initialisation (``solve``, the
    re-initialisation's :class:`~acausal.runtime.linalg.SquareSolver`).
    F_t by a central difference.
    """
    dae = cm.dae
    n, ns = len(dae.y), dae.n_states
    if n == ns:
        return yp
    yp = np.array(yp, dtype=float)
    J, Jy_states = event_matrix(cb, t, y, yp, ns)
    dt = 1e-6 * max(1.0, abs(t))
    rp, rm = np.zeros(n), np.zeros(n)
    saved = list(cb.count)
    cb.res(t + dt, y, yp, rp)
    cb.res(t - dt, y, yp, rm)
    cb.count[:] = saved     # these are not solver step attempts
    rhs = -((rp - rm) / (2 * dt) + Jy_states @ yp[:ns])
    sol = solve(J, rhs)
    if np.all(np.isfinite(sol)):
        yp[ns:] = sol[:n - ns]
    return yp



