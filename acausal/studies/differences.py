"""Forward differences with an absolute step for ``scipy.optimize.least_squares``
(used by :mod:`acausal.calibrate`, :mod:`acausal.profile` and the diagnosis;
why the step is absolute: see ``acausal.calibrate.FD_STEP``)."""
from dataclasses import dataclass

import numpy as np


class ForwardDifferences:
    """``fun`` with a ``jac`` for ``scipy.optimize.least_squares``: forward
    differences with the absolute step ``step`` (backward where a forward step
    would cross the upper bound ``hi``). The residual at the point the
    optimiser just evaluated is reused, so a Jacobian costs one evaluation per
    variable, as scipy's own."""

    def __init__(self, fun, step, hi):
        self.fun, self.step, self.hi = fun, float(step), np.asarray(hi, float)
        self._z = self._r = None

    def __call__(self, z):
        r = np.asarray(self.fun(z), float)
        self._z, self._r = np.array(z, float), r
        return r

    def jac(self, z):
        z = np.asarray(z, float)
        r0 = self._r if self._z is not None and np.array_equal(z, self._z) else self(z)
        J = np.empty((r0.size, z.size))
        for i in range(z.size):
            h = self.step if z[i] + self.step <= self.hi[i] else -self.step
            zz = z.copy()
            zz[i] += h
            J[:, i] = (np.asarray(self.fun(zz), float) - r0) / h
        return J


@dataclass(frozen=True)
class LinearSeed:
    """A linear model of a least-squares problem's residuals, the first
    Jacobian a :class:`SecantDifferences` may use instead of differences:
    ``r(x) ~ offset + J x`` over every row the objective returns (``x`` in
    the variables' own units), made at a point whose residuals were
    ``r_ref`` (the first ``r_ref.size`` rows: the data rows, on which the
    model is judged; rows after them, such as a penalty's, are exact in it).
    Example: the columns of a finer spline at a fitted point, seen through
    a coarser spline's weights (``acausal.diagnose.stages.locate``)."""

    offset: np.ndarray
    J: np.ndarray
    r_ref: np.ndarray


class SecantDifferences:
    """``jac`` for ``scipy.optimize.least_squares``: the forward differences
    of ``fd`` (a :class:`ForwardDifferences`) at the first point, then
    Broyden's rank-one (secant) update between two points the optimiser
    asks a Jacobian at, as long as the last Jacobian predicted the step
    between them well (``|dr - J dz| <= trust |dr|``); a fresh difference
    Jacobian otherwise. ``fresh`` says whether the last one returned was a
    difference Jacobian (the one a caller reports at the optimum should
    be).

    ``seed``: a :class:`LinearSeed` and the variables' scales ``sc`` (the
    optimiser's variables are ``x / sc``). At the first point its Jacobian
    is used in place of differences when it predicts the residuals there
    within the same trust, the step measured from ``seed.r_ref`` (on the
    data rows); otherwise the differences are taken as without it."""

    def __init__(self, fd, trust=0.3, seed=None, sc=None):
        self.fd, self.trust = fd, float(trust)
        self.z = self.r = self.J = None
        self.fresh = False
        self.updates = 0
        self.seed, self.sc = seed, None if sc is None else np.asarray(sc, float)
        self.seeded = False           # the seed's Jacobian was used at the first point

    def jac(self, z):
        z = np.asarray(z, float)
        fd = self.fd
        r = fd._r if fd._z is not None and np.array_equal(z, fd._z) else fd(z)
        if self.J is not None:
            dz, dr = z - self.z, r - self.r
            miss = dr - self.J @ dz
            if dz @ dz > 0 and np.linalg.norm(miss) <= self.trust * np.linalg.norm(dr):
                self.J = self.J + np.outer(miss, dz) / (dz @ dz)
                self.z, self.r, self.fresh = z, r, False
                self.updates += 1
                return self.J
        elif self.seed is not None:
            J = self._from_seed(z, r)
            self.seed = None
            if J is not None:
                self.J, self.z, self.r, self.fresh, self.seeded = J, z, r, False, True
                return J
        self.J = fd.jac(z)
        self.z, self.r, self.fresh = z, r, True
        return self.J

    def _from_seed(self, z, r):
        """The seed's Jacobian in the optimiser's variables, or None when
        it does not predict ``r`` at ``z`` within the trust."""
        s, sc = self.seed, self.sc if self.sc is not None else np.ones(z.size)
        if s.J.shape != (r.size, z.size) or s.offset.shape != (r.size,):
            raise ValueError(f"a LinearSeed of shape {s.J.shape} for {r.size} residuals "
                             f"of {z.size} variables")
        m = s.r_ref.size
        miss = r[:m] - (s.offset + s.J @ (z * sc))[:m]
        if np.linalg.norm(miss) > self.trust * np.linalg.norm(r[:m] - s.r_ref):
            return None
        return s.J * sc[None, :]
