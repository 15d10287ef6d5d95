"""Output-error fits used by the diagnosis: one model (a model file, or a
model file extended with a hypothesis) fitted to a dataset by weighted least
squares with the event-correct simulation, plus its leave-one-experiment-out
errors (exact refits, or the linearised shortcut from the Jacobian).

Residuals are the calibration's (:func:`acausal.calibrate.residual_vector`):
(simulated - measured) / sigma, sigma the instrument floor of the signal, so
every number here is in units of the noise floor (1 = what the instrument
alone explains).
"""
from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
from scipy import optimize, stats

from ..calibrate import FD_STEP, ForwardDifferences, resolve, residual_vector
from ..data import Dataset
from ..errors import AcausalError

PENALTY = 1e3   # weighted residual given to every sample of a failed simulation
MAX_STEPS = 5000  # solver steps between two outputs beyond which a run counts as failed
# Finite differences (FD_STEP of each parameter's scale, absolute; see
# acausal.calibrate): the residuals of an adaptive, event-located simulation
# are not smooth below about 1e-6 relative. On the breaker, dS/d(bh) from
# forward differences changes sign between steps 1e-6 and 1e-5 and settles
# only from 1e-4 (within 2 % from 1e-4 to 1e-2). With scipy's relative step
# of 1e-5 the trust region collapsed on that noise and a quadratic-drag fit
# stopped at a tenth of its true value.


@dataclass
class Fit:
    """The result of one output-error fit (picklable, plain arrays)."""

    names: list                       # fitted parameters, in order
    values: dict                      # name -> value
    cost: float                       # S = sum of squared weighted residuals
    residuals: np.ndarray             # weighted residual vector at the optimum
    jacobian: np.ndarray              # d residual / d parameter (parameter units)
    groups: list                      # experiment name of each residual
    signals: list                     # signal name of each residual
    ci95: dict = field(default_factory=dict)
    n_sim: int = 0
    wall_s: float = 0.0
    ok: bool = True
    message: str = ""

    @property
    def n(self):
        return int(self.residuals.size)

    @property
    def k(self):
        return len(self.names)

    def rms(self, mask=None):
        r = self.residuals if mask is None else self.residuals[mask]
        return float(np.sqrt(np.mean(r ** 2))) if r.size else float("nan")


def subset(dataset: Dataset, names) -> Dataset:
    """The dataset restricted to the experiments ``names`` (same instrument)."""
    keep = set(names)
    return Dataset(dataset.folder, [e for e in dataset.experiments if e.name in keep],
                   dataset.instrument)


def weighted_residuals(model, dataset, params):
    """(vector, groups, signals) of weighted residuals for ``params``."""
    vec, labels, _ = residual_vector(resolve(model), dataset, params,
                                     options={"max_steps": MAX_STEPS})
    return vec, [g for g, _ in labels], [s for _, s in labels]


class _OutOfTime(Exception):
    """The fit's time budget is spent (raised inside the optimiser)."""


def fit(model, dataset, names, x0, low, high, scale, *, fixed=None, starts=None,
        max_nfev=60, tol=1e-8, budget_s=None, absorb=None, max_evals=None) -> Fit:
    """Weighted output-error least squares over ``names``.

    ``x0``, ``low``, ``high``, ``scale``: per-name start, bounds and typical
    magnitude (the optimiser works on value/scale). ``fixed``: other
    parameter overrides. ``starts``: extra starting points (dicts name ->
    value, merged into ``x0``); the one with the smallest cost is refined
    (a cheap guard against a local minimum when a hypothesis's parameter
    starts where it has no effect). ``budget_s``: wall-time budget; when it
    is spent the best point seen so far is kept (``message`` says so) and
    the Jacobian is taken there by one more finite-difference pass.
    ``max_evals``: the same after this many evaluations of the residuals
    (counting finite-difference ones; deterministic, unlike the budget).
    ``absorb``: (names, jacobian) of parameters calibrated beforehand (the
    nominal fit's free parameters and its Jacobian, rows as this dataset's
    residuals): each starting point is then scored after a linearised
    re-calibration of those parameters, and moved there. Without it a start
    is scored with the free parameters as they are, which favours "no
    effect" whenever they already absorb part of the effect (a viscous
    coefficient absorbing quadratic drag).
    """
    t0 = time.perf_counter()
    pair = resolve(model)
    fixed = dict(fixed or {})
    names = list(names)
    x0 = np.array([float(x0[n]) for n in names])
    lo = np.array([float(low[n]) for n in names])
    hi = np.array([float(high[n]) for n in names])
    sc = np.array([abs(float(scale[n])) or 1.0 for n in names])
    n_sim = [0]
    n_exp = len(dataset.experiments)
    size = [None]

    seen = {"cost": np.inf, "x": None}
    timed = [True]

    n_eval = [0]

    def evaluate(x):
        if timed[0] and budget_s is not None and time.perf_counter() - t0 > budget_s:
            raise _OutOfTime(f"stopped at the time budget ({budget_s:.0f} s)")
        if timed[0] and max_evals is not None and n_eval[0] >= max_evals:
            raise _OutOfTime(f"stopped after {max_evals} evaluations")
        n_eval[0] += 1
        n_sim[0] += n_exp
        params = {**fixed, **dict(zip(names, x))}
        try:
            vec = weighted_residuals(pair, dataset, params)[0]
            size[0] = vec.size
            if not np.all(np.isfinite(vec)):
                vec = np.nan_to_num(vec, nan=PENALTY, posinf=PENALTY, neginf=-PENALTY)
        except AcausalError:
            if size[0] is None:
                raise
            vec = np.full(size[0], PENALTY)
        c = float(vec @ vec)
        if c < seen["cost"]:
            seen.update(cost=c, x=np.array(x, float))
        return vec

    candidates = [np.clip(x0, lo, hi)]
    for st in starts or []:
        x = x0.copy()
        for i, n in enumerate(names):
            if n in st:
                x[i] = st[n]
        candidates.append(np.clip(x, lo, hi))
    best, best_cost = None, np.inf
    a_idx, a_jac = None, None
    if absorb is not None and absorb[0]:
        a_idx = np.array([names.index(n) for n in absorb[0]])
        a_jac = np.asarray(absorb[1], float)
    for x in candidates:
        try:
            r = evaluate(x)
        except AcausalError:
            continue
        except _OutOfTime:
            break
        c = float(r @ r)
        if a_jac is not None and a_jac.shape[0] == r.size:
            d = np.linalg.lstsq(a_jac, -r, rcond=None)[0]
            moved = np.clip(x[a_idx] + d, lo[a_idx], hi[a_idx])
            rr = r + a_jac @ (moved - x[a_idx])
            c = float(rr @ rr)
            x = x.copy()
            x[a_idx] = moved
        if c < best_cost:
            best, best_cost = x, c
    if best is None:
        return Fit(names, dict(zip(names, x0.tolist())), float("inf"), np.zeros(0),
                   np.zeros((0, len(names))), [], [], n_sim=n_sim[0],
                   wall_s=time.perf_counter() - t0, ok=False,
                   message="every starting point failed to simulate")
    ok, message = True, ""
    if names:
        try:
            fd = ForwardDifferences(lambda z: evaluate(z * sc), FD_STEP, hi / sc)
            sol = optimize.least_squares(fd, best / sc, jac=fd.jac,
                                         bounds=(lo / sc, hi / sc), x_scale=1.0,
                                         xtol=tol, ftol=tol, gtol=tol, max_nfev=max_nfev)
            x = sol.x * sc
            message = sol.message
            ok = sol.status >= 0     # 0: max_nfev reached (still usable)
            J = sol.jac / sc
        except _OutOfTime as stop:
            timed[0] = False
            x = seen["x"] if seen["x"] is not None else best
            message = f"{stop}; best point kept"
            J = fd.jac(x / sc) / sc      # the same differences, at the kept point
    else:
        x = best
        J = np.zeros((0, 0))
    r, groups, signals = weighted_residuals(pair, dataset, {**fixed, **dict(zip(names, x))})
    n_sim[0] += n_exp
    if names:
        J = J.reshape(r.size, len(names))
    else:
        J = np.zeros((r.size, 0))
    values = dict(zip(names, x.tolist()))
    out = Fit(names, values, float(r @ r), r, J, groups, signals, n_sim=n_sim[0],
              wall_s=time.perf_counter() - t0, ok=bool(ok), message=str(message))
    out.ci95 = confidence(out, positive=[n for n, l in zip(names, lo) if l > 0])
    return out


def confidence(f: Fit, level=0.95, positive=()) -> dict:
    """Intervals from the Jacobian at the optimum (Student t), the covariance
    scaled by max(1, S/(n-k)): never narrower than the instrument model says,
    wider when the fit leaves misfit beyond the noise. A parameter in
    ``positive`` (its lower bound is above zero: a stiffness, a mass) gets its
    interval on the logarithm, as :func:`acausal.calibrate.least_squares`
    does: asymmetric, never crossing zero."""
    n, k = f.n, f.k
    if k == 0:
        return {}
    dof = n - k
    v = np.array([f.values[nm] for nm in f.names], float)
    sc = np.where(v != 0, np.abs(v), 1.0)
    Js = f.jacobian * sc                     # columns per relative change
    norms = np.linalg.norm(Js, axis=0)
    live = norms > 1e-9 * max(norms.max(initial=0.0), 1e-300)
    cov = np.full((k, k), np.inf)
    if np.any(live):
        JtJ = Js[:, live].T @ Js[:, live]
        w, V = np.linalg.eigh(JtJ)
        good = w > 1e-12 * w.max()
        inv = (V[:, good] / w[good]) @ V[:, good].T
        sub = np.full(JtJ.shape, np.inf)
        # a parameter that loads on an unidentifiable direction gets no interval
        blind = np.abs(V[:, ~good]).max(axis=1) > 1e-3 if np.any(~good) else \
            np.zeros(len(w), bool)
        ok = ~blind
        sub[np.ix_(ok, ok)] = inv[np.ix_(ok, ok)]
        cov[np.ix_(live, live)] = sub
    s2 = f.cost / dof if dof > 0 else 1.0
    sd = np.sqrt(np.clip(np.diag(cov), 0, None) * max(s2, 1.0)) * sc
    q = stats.t.ppf(0.5 + level / 2, dof) if dof > 0 else stats.norm.ppf(0.5 + level / 2)
    out = {}
    for name, s, scale in zip(f.names, sd, sc):
        v = f.values[name]
        if name in positive and v > 0:
            # the columns of Js are derivatives per relative change, i.e. per
            # unit of log(value): s / scale is the standard deviation of log(value)
            w = q * s / scale
            out[name] = (float(v * np.exp(-w)), float(v * np.exp(w)))
        else:
            out[name] = (float(v - q * s), float(v + q * s))
    return out


def linear_loo(f: Fit) -> dict:
    """Leave-one-experiment-out residuals predicted from the full fit.

    For experiment G, one Gauss-Newton step from the optimum without G's
    rows: delta = -lstsq(J[-G], r[-G]); predicted held-out residuals
    r[G] + J[G] delta. Exact for a model linear in its parameters (the
    classical PRESS residuals); a first-order estimate otherwise, and free
    (no simulation). Returns experiment -> residual vector.
    """
    groups = np.asarray(f.groups)
    out = {}
    for g in dict.fromkeys(f.groups):
        m = groups == g
        if f.k == 0 or not np.any(~m):
            out[g] = f.residuals[m]
            continue
        delta = np.linalg.lstsq(f.jacobian[~m], -f.residuals[~m], rcond=None)[0]
        out[g] = f.residuals[m] + f.jacobian[m] @ delta
    return out


def heldout_rms(loo: dict) -> float:
    """RMS of all held-out residuals (noise-floor units)."""
    r = np.concatenate([np.atleast_1d(v) for v in loo.values()]) if loo else np.zeros(0)
    return float(np.sqrt(np.mean(r ** 2))) if r.size else float("nan")
