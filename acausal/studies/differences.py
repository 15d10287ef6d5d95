"""Forward differences with an absolute step for ``scipy.optimize.least_squares``
(used by :mod:`acausal.calibrate`, :mod:`acausal.profile` and the diagnosis;
why the step is absolute: see ``acausal.calibrate.FD_STEP``)."""
import numpy as np


class ForwardDifferences:
    """``fun`` with a ``jac`` for ``scipy.optimize.least_squares``: forward
    differences with the absolute step ``step`` (backward where a forward step
    would cross the upper bound ``hi``). The residual at the point the
    optimiser just evaluated is reused, so a Jacobian costs one evaluation per
    variable, as scipy's own. ``many``: ``fun`` of a list of points, in
    order (``[fun(z) for z in zs]`` when not given), so that a caller can
    run a Jacobian's evaluations side by side (a lone fit of the diagnosis:
    :meth:`acausal.diagnose.stages.fitting.Objective.many`)."""

    def __init__(self, fun, step, hi, many=None):
        self.fun, self.step, self.hi = fun, float(step), np.asarray(hi, float)
        self.many = many if many is not None else (lambda zs: [self.fun(z) for z in zs])
        self._z = self._r = None

    def __call__(self, z):
        r = np.asarray(self.fun(z), float)
        self._z, self._r = np.array(z, float), r
        return r

    def jac(self, z):
        z = np.asarray(z, float)
        r0 = self._r if self._z is not None and np.array_equal(z, self._z) else self(z)
        steps, points = [], []
        for i in range(z.size):
            h = self.step if z[i] + self.step <= self.hi[i] else -self.step
            zz = z.copy()
            zz[i] += h
            steps.append(h)
            points.append(zz)
        J = np.empty((r0.size, z.size))
        for i, (r, h) in enumerate(zip(self.many(points), steps)):
            J[:, i] = (np.asarray(r, float) - r0) / h
        return J


class SecantDifferences:
    """``jac`` for ``scipy.optimize.least_squares``: the forward differences
    of ``fd`` (a :class:`ForwardDifferences`) at the first point, then
    Broyden's rank-one (secant) update between two points the optimiser
    asks a Jacobian at, as long as the last Jacobian predicted the step
    between them well (``|dr - J dz| <= trust |dr|``); a fresh difference
    Jacobian otherwise. ``fresh`` says whether the last one returned was a
    difference Jacobian (the one a caller reports at the optimum should
    be)."""

    def __init__(self, fd, trust=0.3):
        self.fd, self.trust = fd, float(trust)
        self.z = self.r = self.J = None
        self.fresh = False
        self.updates = 0

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
        self.J = fd.jac(z)
        self.z, self.r, self.fresh = z, r, True
        return self.J
