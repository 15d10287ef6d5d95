"""Profile-likelihood confidence intervals (Raue et al., "Structural and
practical identifiability analysis of partially observed dynamical models by
exploiting the profile likelihood", Bioinformatics 25 (2009) 1923-1929).

For a least-squares objective chi^2(x) = sum r(x)^2, r the residuals already
divided by the instrument's noise (so that chi^2 is -2 ln L + const), the
profile of parameter i is

    PL(x_i) = min over the other parameters of chi^2,

and its pointwise 95 % interval is {x_i : PL(x_i) - chi^2_min <= Delta}, with
Delta = chi2.ppf(0.95, 1) = 3.84 for a known noise level, or
``dispersion`` * t.ppf(0.975, dof)^2 when the noise is scaled by the fit's own
S/(n-k) (the same as the Student-t Wald interval of a linear model).

The profile is traced from the optimum in both directions, re-optimising the
other parameters at each step (``scipy.optimize.least_squares``, warm-started
by linear extrapolation of the previous points), with Raue's adaptive step
(the step grows while chi^2 rises slowly and is halved when it jumps), until
chi^2 crosses the threshold (the crossing is then refined with
``scipy.optimize.brentq``) or a bound is reached with chi^2 still below it:
the interval is then *open* on that side (a practically non-identifiable
parameter; a flat profile on both sides is a structurally non-identifiable
one).

The linearised (Wald) interval from the Jacobian at the optimum is computed
beside it; it is *trustworthy* when the profile is closed on both sides and
each side agrees with the Wald half-width to within ``rel_tol`` (10 %) in
the variable the fit uses (the logarithm for a log-scaled parameter).
Everything here is pure: the objective is only evaluated, never changed.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Sequence

import numpy as np
from scipy import optimize, stats

from .differences import ForwardDifferences
from .residuals import principal_directions

Residuals = Callable[[np.ndarray], np.ndarray]


@dataclass(frozen=True)
class Coordinates:
    """How the parameters are seen by a profile: ``bounds`` (low, high)
    arrays in natural units (may hold +-inf; None: unbounded), ``log`` per
    parameter (or one bool for all: fit and profile on log(x)), ``scale``
    the typical magnitudes of the others (default |x_opt|)."""

    bounds: tuple | None = None
    log: bool | Sequence[bool] = False
    scale: Sequence[float] | None = None


@dataclass(frozen=True)
class Confidence:
    """The interval's level and how the noise is known: ``dispersion`` and
    ``dof`` as in :func:`threshold` (known noise: 1.0 and None)."""

    level: float = 0.95
    dispersion: float = 1.0
    dof: int | None = None

    def threshold(self) -> float:
        return threshold(self.level, self.dispersion, self.dof)


@dataclass(frozen=True)
class Tracing:
    """How hard a profile is traced. ``fd_step``: absolute finite-difference
    step in the profile's variables (1e-3 for simulated objectives, see
    ``acausal.studies.calibrate.FD_STEP``); ``rel_tol``: the Wald interval is
    trusted within this fraction; ``max_points`` per side;
    ``inner_max_nfev``, ``inner_tol``: limits of each re-optimisation of the
    others; ``crossing_tol``: the threshold crossing is located to this
    fraction of the last step (looser values for costly objectives)."""

    fd_step: float = 1e-6
    rel_tol: float = 0.1
    max_points: int = 40
    inner_max_nfev: int | None = None
    inner_tol: float = 1e-10
    crossing_tol: float = 1e-5


@dataclass(frozen=True)
class LikelihoodProfile:
    """The profile likelihood of one parameter and its interval (natural
    units throughout). (Not :class:`acausal.mechanics.planar.polyline.Profile`,
    a cam's polyline.)

    ``lower``/``upper``: the interval's ends; on an open side the bound when
    it is finite, else None (``open_lower``/``open_upper`` say which).
    ``values``/``delta_chi2``: the traced points (ascending in the parameter)
    and chi^2 - chi^2_min there; ``points``: the full parameter vectors.
    ``wald``: the linearised interval ((-inf, inf) when the Jacobian cannot
    determine the parameter). ``trustworthy``: the Wald interval agrees with
    the profile (closed, and each side within ``rel_tol`` of it)."""

    name: str
    index: int
    estimate: float
    lower: float | None
    upper: float | None
    open_lower: bool
    open_upper: bool
    wald: tuple
    trustworthy: bool
    threshold: float
    level: float
    values: np.ndarray
    delta_chi2: np.ndarray
    points: np.ndarray
    n_evaluations: int
    message: str = ""

    @property
    def ci95(self) -> tuple:
        return (self.lower, self.upper)

    def to_dict(self) -> dict:
        """JSON-ready: floats and lists; infinities as None."""
        def num(v):
            return None if v is None or not np.isfinite(v) else float(v)
        return dict(name=self.name, estimate=float(self.estimate), level=self.level,
                    lower=num(self.lower), upper=num(self.upper),
                    open_lower=self.open_lower, open_upper=self.open_upper,
                    wald=[num(w) for w in self.wald], trustworthy=self.trustworthy,
                    threshold=float(self.threshold),
                    values=[float(v) for v in self.values],
                    delta_chi2=[float(v) for v in self.delta_chi2],
                    n_evaluations=self.n_evaluations, message=self.message)


def threshold(level: float = 0.95, dispersion: float = 1.0, dof: int | None = None) -> float:
    """Delta chi^2 of a pointwise interval at ``level``: chi2.ppf(level, 1)
    (3.84 at 95 %) for a known noise level; with ``dof`` given,
    ``dispersion`` * t.ppf((1 + level)/2, dof)^2, the exact counterpart of a
    Student-t Wald interval whose covariance is scaled by ``dispersion``."""
    if dof:
        return float(dispersion * stats.t.ppf(0.5 + level / 2, dof) ** 2)
    return float(dispersion * stats.chi2.ppf(level, 1))


class _Coords:
    """The variables the profile works in: u = log(x / x*) for a log-scaled
    parameter, (x - x*) / scale otherwise, so the optimum is at u = 0 and an
    absolute finite-difference step is a relative change of the parameter."""

    def __init__(self, x_opt, log, scale, bounds):
        self.x0 = np.asarray(x_opt, float)
        k = self.x0.size
        self.log = np.broadcast_to(np.asarray(log, bool), (k,)).copy()
        if np.any(self.log & (self.x0 <= 0)):
            raise ValueError("a log-scaled parameter must be positive at the optimum")  # internal: callers log-scale only positive bounds
        sc = np.abs(self.x0) if scale is None else np.abs(np.asarray(scale, float))
        self.scale = np.where(sc > 0, sc, 1.0)
        lo, hi = (np.full(k, -np.inf), np.full(k, np.inf)) if bounds is None else bounds
        self.lo, self.hi = self.to_u(np.asarray(lo, float)), self.to_u(np.asarray(hi, float))

    def to_x(self, u):
        u = np.asarray(u, float)
        return np.where(self.log, self.x0 * np.exp(np.where(self.log, u, 0.0)),
                        self.x0 + u * self.scale)

    def to_u(self, x):
        x = np.asarray(x, float)
        with np.errstate(divide="ignore", invalid="ignore"):
            lg = np.log(np.where(self.log, x, 1.0) / np.where(self.log, self.x0, 1.0))
        lg = np.where(self.log & (x <= 0), -np.inf, lg)
        return np.where(self.log, lg, (x - self.x0) / self.scale)


class _Objective:
    """chi^2 on the profile's variables, counting evaluations; a non-finite
    residual gives chi^2 = inf (the step is then shortened)."""

    def __init__(self, residuals, coords, index, fd_step, inner_max_nfev, tol, crossing_tol):
        self.residuals, self.c, self.i = residuals, coords, index
        self.fd_step, self.max_nfev, self.tol = fd_step, inner_max_nfev, tol
        self.crossing_tol = crossing_tol
        self.others = np.array([j for j in range(coords.x0.size) if j != index], int)
        self.n = 0

    def r(self, u):
        self.n += 1
        return np.asarray(self.residuals(self.c.to_x(u)), float)

    def chi2(self, u):
        r = self.r(u)
        return float(r @ r) if np.all(np.isfinite(r)) else np.inf

    def full(self, ui, uo):
        u = np.empty(self.c.x0.size)
        u[self.i], u[self.others] = ui, uo
        return u

    def reoptimize(self, ui, guess):
        """(others, chi^2) minimising chi^2 at u_i = ``ui`` from ``guess``."""
        if self.others.size == 0:
            return guess, self.chi2(self.full(ui, guess))
        lo, hi = self.c.lo[self.others], self.c.hi[self.others]
        start = np.clip(guess, lo, hi)
        fd = ForwardDifferences(lambda uo: self.r(self.full(ui, uo)), self.fd_step, hi)
        try:
            sol = optimize.least_squares(fd, start, jac=fd.jac, bounds=(lo, hi),
                                         xtol=self.tol, ftol=self.tol, gtol=self.tol,
                                         max_nfev=self.max_nfev or 30 * self.others.size)
        except ValueError:          # a non-finite residual inside the optimiser
            return start, np.inf
        return sol.x, float(2 * sol.cost) if np.all(np.isfinite(sol.fun)) else np.inf


def wald_halfwidths(residuals: Residuals, x_opt, *, log=False, scale=None, thresh=3.84,
                    fd_step: float = 1e-6, jacobian=None) -> np.ndarray:
    """Half-widths sqrt(thresh * [(J'J)^-1]_ii) of the linearised intervals,
    in the profile's variables (log(x/x*) for a log-scaled parameter,
    (x - x*)/scale otherwise); infinite for a parameter that loads on a
    direction the Jacobian cannot see (J'J singular). ``jacobian``: J in
    those variables, else forward differences with ``fd_step``."""
    c = _Coords(x_opt, log, scale, None)
    if jacobian is None:
        fd = ForwardDifferences(lambda u: residuals(c.to_x(u)), fd_step,
                                np.full(c.x0.size, np.inf))
        jacobian = fd.jac(np.zeros(c.x0.size))
    w, V, good = principal_directions(jacobian)
    var = (V[:, good] ** 2 / w[good]).sum(axis=1)
    if np.any(~good):
        var[np.abs(V[:, ~good]).max(axis=1) > 1e-3] = np.inf
    return np.sqrt(thresh * var)


@dataclass(frozen=True)
class _Side:
    """One direction of the traced profile: points (u_i, others, delta chi^2)
    in tracing order, the refined crossing (None if open) and why it stopped."""

    points: list
    crossing: float | None
    why: str


def _trace(obj: _Objective, direction: int, h0: float, thresh: float, chi0: float,
           max_points: int) -> _Side:
    """Walk u_i from 0 in ``direction`` with Raue's adaptive step until
    delta chi^2 crosses ``thresh`` or the bound is reached."""
    bound = obj.c.hi[obj.i] if direction > 0 else obj.c.lo[obj.i]
    target, h, h_min = thresh / 5.0, h0, 10 * obj.fd_step
    pts = [(0.0, obj.c.x0[obj.others] * 0.0, 0.0)]
    while len(pts) <= max_points:
        u_prev, o_prev, d_prev = pts[-1]
        u_try = u_prev + direction * h
        at_bound = direction * (u_try - bound) >= 0
        if at_bound:
            u_try = bound
        if u_try == u_prev:
            return _Side(pts, None, "bound")
        guess = o_prev
        if len(pts) > 1 and pts[-1][0] != pts[-2][0]:
            slope = (o_prev - pts[-2][1]) / (u_prev - pts[-2][0])
            guess = o_prev + slope * (u_try - u_prev)
        o_new, c_new = obj.reoptimize(u_try, guess)
        d_new = c_new - chi0
        if (not np.isfinite(d_new) or d_new - d_prev > 2 * target) and h > h_min:
            h /= 2
            continue
        if not np.isfinite(d_new):
            return _Side(pts, None, "the objective failed beyond the last point")
        pts.append((u_try, o_new, d_new))
        if d_new >= thresh:
            return _Side(pts, _refine(obj, pts[-2], pts[-1], thresh, chi0), "crossed")
        if at_bound:
            return _Side(pts, None, "bound")
        if d_new - d_prev < target / 2:
            h *= 2
    return _Side(pts, None, f"still below the threshold after {max_points} points")


def _refine(obj, below, above, thresh, chi0):
    """u_i where delta chi^2 = thresh between two traced points (brentq),
    each evaluation re-optimising the others from the nearer point."""
    def g(ui):
        near = below if abs(ui - below[0]) <= abs(ui - above[0]) else above
        return obj.reoptimize(ui, near[1])[1] - chi0 - thresh
    a, b = below[0], above[0]
    if not np.isfinite(above[2]):
        return b
    return float(optimize.brentq(g, a, b, xtol=obj.crossing_tol * abs(b - a), maxiter=40))


def profile_likelihood(residuals: Residuals, x_opt: Sequence[float], index: int, *,
                       coords: Coordinates = Coordinates(),
                       confidence: Confidence = Confidence(), tracing: Tracing = Tracing(),
                       name: str | None = None, jacobian=None) -> LikelihoodProfile:
    """Profile likelihood interval of parameter ``index``.

    ``residuals(x)``: weighted residuals (chi^2 = sum r^2) at the parameter
    vector ``x`` (natural units); ``x_opt``: the least-squares optimum;
    ``coords``: bounds, log scaling and scales (:class:`Coordinates`);
    ``confidence``: the threshold (:class:`Confidence`); ``tracing``: steps
    and limits (:class:`Tracing`); ``jacobian``: d r / d u at the optimum, if
    known (else forward differences)."""
    c = _Coords(x_opt, coords.log, coords.scale, coords.bounds)
    thr = confidence.threshold()
    t = tracing
    obj = _Objective(residuals, c, int(index), t.fd_step, t.inner_max_nfev, t.inner_tol,
                     t.crossing_tol)
    chi0 = obj.chi2(np.zeros(c.x0.size))
    hw = float(wald_halfwidths(residuals, x_opt, log=coords.log, scale=coords.scale, thresh=thr,
                               fd_step=t.fd_step, jacobian=jacobian)[index])
    obj.n += c.x0.size + 1 if jacobian is None else 0
    h0 = 0.1 * hw if np.isfinite(hw) and hw > 0 else 0.1
    sides = [_trace(obj, d, h0, thr, chi0, t.max_points) for d in (-1, 1)]
    return _assemble(obj, sides, hw, thr, confidence.level, chi0, name, t.rel_tol)


def _assemble(obj, sides, hw, thr, level, chi0, name, rel_tol) -> LikelihoodProfile:
    c, i = obj.c, obj.i
    pts = sorted(sides[0].points[1:] + sides[1].points, key=lambda p: p[0])
    full = np.array([c.to_x(obj.full(p[0], p[1])) for p in pts])
    ends = []
    for side, bound in zip(sides, (c.lo[i], c.hi[i])):
        if side.crossing is not None:
            ends.append(float(c.to_x(obj.full(side.crossing, np.zeros(len(obj.others))))[i]))
        else:
            ends.append(float(c.to_x(obj.full(bound, np.zeros(len(obj.others))))[i])
                        if np.isfinite(bound) else None)
    open_lo, open_hi = sides[0].crossing is None, sides[1].crossing is None
    wald = tuple(float(c.to_x(obj.full(s * hw, np.zeros(len(obj.others))))[i])
                 if np.isfinite(hw) else s * np.inf for s in (-1.0, 1.0))
    msgs = [f"{'lower' if k == 0 else 'upper'}: {s.why}" for k, s in enumerate(sides)
            if s.crossing is None]
    trust = not (open_lo or open_hi) and np.isfinite(hw) and all(
        abs(abs(s.crossing) - hw) <= rel_tol * hw for s in sides)
    d = np.array([p[2] for p in pts])
    if d.min() < -0.05 * thr:
        msgs.append(f"the profile found chi^2 {-d.min():.3g} below the given optimum: "
                    "the fit had not converged")
        trust = False
    return LikelihoodProfile(name or f"x[{i}]", i, float(c.x0[i]), ends[0], ends[1], open_lo,
                             open_hi, wald, bool(trust), thr, level, full[:, i], d, full, obj.n,
                             "; ".join(msgs))


def linear_check(residuals: Residuals, x_opt: Sequence[float], index: int, *,
                 coords: Coordinates = Coordinates(), thresh: float = 3.84, jacobian=None,
                 fd_step: float = 1e-6, rel_tol: float = 0.1) -> tuple:
    """A cheap screen for a Wald interval (two evaluations): (ok, ratios).

    At both ends of the Wald interval of parameter ``index``, moves the
    others along the linearised profile path (the least-squares response of
    the others to the change of x_index, from the Jacobian) and compares the
    actual delta chi^2 there with ``thresh``, which it equals for a model
    linear in its parameters. ``ok`` is False when either ratio falls outside
    [1/(1 + rel_tol)^2, 1/(1 - rel_tol)^2] (for a profile that is quadratic
    near each end, a side longer or shorter than the Wald half-width by more
    than ``rel_tol``: the test of :func:`profile_likelihood`), when an end
    lies beyond a bound, or when the Jacobian cannot determine the
    parameter: then trace the profile. ``coords``: :class:`Coordinates`."""
    log, scale = coords.log, coords.scale
    c = _Coords(x_opt, log, scale, coords.bounds)
    k = c.x0.size
    if jacobian is None:
        fd = ForwardDifferences(lambda u: residuals(c.to_x(u)), fd_step, np.full(k, np.inf))
        jacobian = fd.jac(np.zeros(k))
    hw = float(wald_halfwidths(residuals, x_opt, log=log, scale=scale, thresh=thresh,
                               jacobian=jacobian)[index])
    if not np.isfinite(hw):
        return False, (np.nan, np.nan)
    others = [j for j in range(k) if j != index]
    path = np.zeros(k)
    path[index] = 1.0
    if others:
        Jo = jacobian[:, others]
        path[others] = -np.linalg.lstsq(Jo, jacobian[:, index], rcond=None)[0]
    r0 = np.asarray(residuals(c.x0), float)
    ratios = []
    for s in (-1.0, 1.0):
        u = s * hw * path
        if np.any(u < c.lo) or np.any(u > c.hi):
            return False, (np.nan, np.nan)
        r = np.asarray(residuals(c.to_x(u)), float)
        ratios.append(float((r @ r - r0 @ r0) / thresh))
    ok = all((1 + rel_tol) ** -2 <= q <= (1 - rel_tol) ** -2 for q in ratios)
    return bool(ok), tuple(ratios)


def jacobian_in_profile_variables(jac_x, x_opt, *, log=False, scale=None) -> np.ndarray:
    """d r / d u from d r / d x (columns per parameter in its own units):
    times x* for a log-scaled parameter (u = log(x / x*)), times ``scale``
    (default |x*|, 1 where x* = 0) otherwise (u = (x - x*) / scale)."""
    c = _Coords(x_opt, log, scale, None)
    return np.asarray(jac_x, float) * np.where(c.log, c.x0, c.scale)


def profiles(residuals: Residuals, x_opt: Sequence[float], names: Sequence[str], *,
             every: bool = False, coords: Coordinates = Coordinates(),
             confidence: Confidence = Confidence(), tracing: Tracing = Tracing(),
             jacobian=None) -> dict:
    """name -> :class:`LikelihoodProfile` for the parameters ``names`` (in the order of
    ``x_opt``): every one when ``every``, else those whose linearised
    interval fails :func:`linear_check` (two evaluations each). ``jacobian``:
    d r / d u at the optimum (see :func:`jacobian_in_profile_variables`),
    else forward differences with ``tracing.fd_step``."""
    if jacobian is None:
        c = _Coords(x_opt, coords.log, coords.scale, None)
        fd = ForwardDifferences(lambda u: residuals(c.to_x(u)), tracing.fd_step,
                                np.full(c.x0.size, np.inf))
        jacobian = fd.jac(np.zeros(c.x0.size))
    thr = confidence.threshold()
    out = {}
    for k, name in enumerate(names):
        if not every and linear_check(residuals, x_opt, k, coords=coords, thresh=thr,
                                      jacobian=jacobian, fd_step=tracing.fd_step,
                                      rel_tol=tracing.rel_tol)[0]:
            continue
        out[name] = profile_likelihood(residuals, x_opt, k, coords=coords,
                                       confidence=confidence, tracing=tracing, name=name,
                                       jacobian=jacobian)
    return out


def __getattr__(name):
    """``Profile``: the old name of :class:`LikelihoodProfile` (deprecated:
    ``acausal.mechanics.planar.polyline.Profile`` is a cam's polyline)."""
    if name == "Profile":
        import warnings
        warnings.warn("acausal.studies.profile.Profile is now LikelihoodProfile",
                      DeprecationWarning, stacklevel=2)
        return LikelihoodProfile
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
