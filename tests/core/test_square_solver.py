"""The re-initialisation's square solves: an LU, least squares where the LU
finds the matrix singular, and a matrix equal to the last singular one sent
to least squares at once, with the same answer."""
import numpy as np
import scipy.linalg
import scipy.sparse as sps
import scipy.sparse.linalg  # noqa: F401  (sps.linalg)

from acausal.runtime import linalg
from acausal.runtime.linalg import SquareSolver


def solve_square(J, b):
    """The reference, written here: an LU (sparse, then dense), least
    squares where it fails."""
    if sps.issparse(J):
        try:
            x = sps.linalg.splu(J).solve(b)
            if np.all(np.isfinite(x)):
                return x
        except RuntimeError:
            pass
        J = J.toarray()
    try:
        return scipy.linalg.solve(J, b)
    except scipy.linalg.LinAlgError:
        return np.linalg.lstsq(J, b, rcond=None)[0]


def _counting_lu(monkeypatch):
    calls = []
    real = scipy.linalg.solve

    def solve(J, b):
        calls.append(J.shape)
        return real(J, b)
    monkeypatch.setattr(linalg.scipy.linalg, "solve", solve)
    return calls


def _singular(n=6, seed=0):
    """A matrix with an exactly zero row (a stuck element's row) and a
    consistent right-hand side."""
    rng = np.random.default_rng(seed)
    J = rng.normal(size=(n, n))
    J[2] = 0.0
    x = rng.normal(size=n)
    return J, J @ x


def test_singular_repeat_skips_the_lu_and_answers_the_same(monkeypatch):
    J, b = _singular()
    reference = [solve_square(J, b), solve_square(J, 2 * b)]
    calls = _counting_lu(monkeypatch)
    solve = SquareSolver()
    first, second = solve(J, b), solve(J.copy(), 2 * b)
    assert len(calls) == 1                       # the second LU was skipped
    assert np.array_equal(first, reference[0]) and np.array_equal(second, reference[1])
    # the minimum-norm solution: the zero row's unknown direction is left out
    assert np.allclose(J @ first, b, atol=1e-12)


def test_a_changed_matrix_gets_its_lu(monkeypatch):
    J, b = _singular()
    K = J.copy()
    K[2, 2] = 1.0                                # the element slides again
    reference = solve_square(K, b)
    calls = _counting_lu(monkeypatch)
    solve = SquareSolver()
    solve(J, b)
    x = solve(K, b)
    assert len(calls) == 2
    assert np.array_equal(x, reference)
    assert np.allclose(K @ x, b, rtol=1e-12, atol=1e-12)


def test_sparse_singular_matrices(monkeypatch):
    J, b = _singular(n=8, seed=3)
    S = sps.csc_matrix(J)
    reference = solve_square(S, b)
    T = S.tolil()
    T[2, 2] = 1.0
    T = T.tocsc()
    changed = solve_square(T, b)
    calls = _counting_lu(monkeypatch)
    solve = SquareSolver()
    x1 = solve(S, b)                             # splu fails, the dense LU too
    x2 = solve(sps.csc_matrix(J.copy()), b)      # equal: least squares at once
    assert len(calls) == 1
    assert np.array_equal(x1, reference) and np.array_equal(x2, reference)
    assert np.array_equal(solve(J, b), reference)     # dense: not the same storage
    assert len(calls) == 2
    assert np.array_equal(solve(T, b), changed)       # splu succeeds
    assert len(calls) == 2
