"""Linear algebra of the initialisation and the re-initialisation at events
(:mod:`.initialize`, :mod:`.sensitivity_run`): the Jacobians of the
generated callbacks, dense or sparse; square solves (LU, least squares when
singular); least squares with unit-norm columns; rank tests that choose
which state guesses to impose; Gauss-Newton with step halving.

From :data:`SPARSE_MIN` unknowns the matrices are ``scipy.sparse`` and are
solved by SuperLU; a rectangular least-squares problem by the LU of the
augmented system ``[[I, J], [J^T, 0]]`` (its solution is the least-squares
one; Bjorck, "Numerical Methods for Least Squares Problems", 1996, sec. 2.5).
"""
import re
import warnings

import numpy as np
import scipy.linalg
import scipy.sparse as sps
import scipy.sparse.linalg
from scipy.sparse.csgraph import structural_rank

from ..compiler.codegen import Triplets

# unknowns (y and the states' y') from which the initialisation assembles
# sparse Jacobians and solves them by sparse LU: the dense least squares grew
# as n^3 (0.5 s per Newton step for a 200-mass chain, single-threaded)
SPARSE_MIN = 200

# scipy.linalg.solve warns (LinAlgWarning) when a matrix is ill-conditioned.
# The iterations that call it here judge their own convergence (and a
# singular matrix goes to least squares), so the warning tells a caller of
# the library nothing it can act on: it is ignored for this module's calls
# only (scipy attributes it to the module that called ``solve``). The command
# line keeps every library warning from the terminal anyway (``cli._quiet_warnings``).
warnings.filterwarnings("ignore", category=scipy.linalg.LinAlgWarning,
                        module=re.escape(__name__) + "$")


def jacobians(cb, t, y, yp, n):
    """(dF/dy, dF/dy') of callbacks ``cb`` at ``(t, y, y')``, dense ``n`` x ``n``."""
    Jy = np.zeros((n, n))
    Jyp = np.zeros((n, n))
    cb.jacs(t, y, yp, Jy, Jyp)
    return Jy, Jyp


def newton(fun, jac, z, max_iter=50):
    """Gauss-Newton with step halving from ``z``; the last iterate (the
    caller checks it) or None when the residual is not finite."""
    r = fun(z)
    nr = np.linalg.norm(r)
    for _ in range(max_iter):
        if not np.all(np.isfinite(r)):
            return None
        dz = lstsq_scaled(jac(z), -r)
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


def lstsq_scaled(J, b):
    """Least-squares solution of ``J x = b`` with the columns of ``J``
    scaled to unit norm first: the unknowns mix positions, velocities,
    accelerations and forces whose columns can differ by many orders of
    magnitude (a stiff spring next to a light body), and an unscaled
    solve would cut the small columns off as rank deficiency. ``b``: a
    vector, or a matrix of right-hand sides (columns)."""
    if sps.issparse(J):
        if np.ndim(b) == 2:
            return np.column_stack([_sparse_lstsq_scaled(J, c) for c in np.asarray(b).T])
        return _sparse_lstsq_scaled(J, b)
    norms = np.linalg.norm(J, axis=0)
    d = np.where(norms > 0, 1.0 / np.where(norms > 0, norms, 1.0), 1.0)
    x = np.linalg.lstsq(J * d, b, rcond=None)[0]
    return d * x if x.ndim == 1 else d[:, None] * x


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
    """:func:`lstsq_scaled` of a sparse ``J`` by sparse LU; the dense least
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


def choose_guesses(J, ns, order):
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


def event_matrix(cb, t, y, yp, ns):
    """(J = [dF/dy of the algebraic slots, dF/dy' of the states], dF/dy of
    the states): the matrix of the re-initialisation, dense, or
    ``scipy.sparse`` CSC from SPARSE_MIN unknowns."""
    n = len(y)
    if n + ns >= SPARSE_MIN:
        Jy, Jyp = Triplets((n, n)), Triplets((n, n))
        cb.jacs(t, y, yp, Jy, Jyp)
        Jy, Jyp = Jy.tocsr().tocsc(), Jyp.tocsr().tocsc()
        return sps.hstack([Jy[:, ns:], Jyp[:, :ns]], format="csc"), Jy[:, :ns]
    Jy, Jyp = jacobians(cb, t, y, yp, n)
    return np.hstack([Jy[:, ns:], Jyp[:, :ns]]), Jy[:, :ns]


class SquareSolver:
    """``J x = b`` for square dense or sparse matrices ``J`` (an LU; least
    squares when the LU finds ``J`` singular), for a run of matrices that
    often repeat: the Newton iterations of one event's re-initialisation
    and the algebraic rates after it. At a stuck friction element that
    matrix is singular by structure, and the LU fails at every iteration
    before least squares answers. A matrix equal to the last one whose LU
    failed goes to least squares at once: its LU would fail again, so the
    answer is the same, bit for bit, without the failed factorisation."""

    def __init__(self):
        self._singular = None

    def __call__(self, J, b):
        if self._singular is not None and _same_matrix(J, self._singular):
            return _least_squares(_dense(J), b)
        if sps.issparse(J):
            try:
                x = scipy.sparse.linalg.splu(J).solve(b)
                if np.all(np.isfinite(x)):
                    return x
            except RuntimeError:      # "Factor is exactly singular"
                pass
        A = _dense(J)
        try:
            return scipy.linalg.solve(A, b)
        except (scipy.linalg.LinAlgError, ValueError):
            self._singular = J.copy()
            return _least_squares(A, b)


def _dense(J):
    """``J`` as a dense array (a sparse one converted once)."""
    return J.toarray() if sps.issparse(J) else J


def _least_squares(A, b):
    """The minimum-norm least-squares solution of ``A x = b`` (``A`` dense)."""
    return np.linalg.lstsq(A, b, rcond=None)[0]


def _same_matrix(J, K):
    """Whether ``J`` and ``K`` hold the same numbers in the same storage
    kind (dense or sparse)."""
    if J.shape != K.shape:
        return False
    if sps.issparse(J) or sps.issparse(K):
        return sps.issparse(J) and sps.issparse(K) and (J != K).nnz == 0
    return np.array_equal(J, K)
