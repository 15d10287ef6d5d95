"""Which family members away from the competitive heads' sites deserve a
fit: a one-step score screen (Gauss-Newton from each member's start).

:func:`.families.fit_members` fits a family's other members where its head
ranks among the best single candidates. A head can be a poor stand-in for
its members: on the breaker, a contact whose damping follows Hunt-Crossley
was fitted by the head (restitution falling linearly with the impact
speed) at S = 854 while a flexible hook reached 543; the Hunt-Crossley
member was never fitted, and the flexible link was named with confidence
(docs/diagnosis.md, "Family members screened").

Here every other member at every site where it applies is evaluated at its
start (its parameters at their initial values, the free parameters
calibrated) together with forward-difference columns of its own
parameters, one simulation of every experiment each. With the free
parameters' columns of the nominal fit, one Gauss-Newton step bounded to
the parameters' ranges predicts the cost it would reach, S_pred = min_d
|r0 + J d|^2, and so its AICc. Members whose predicted AICc comes within
max(``MARGIN``, ``SHARE`` x the best candidate's gain over the nominal) of
the best candidate's are fitted (at most ``MAX_FITS``, the most promising
first); the others within reach are returned as unfitted, and no cause is
named over them (:func:`.stages.rank`).

A linear step misjudges a nonlinear member either way, hence the generous
share. On the breaker's Hunt-Crossley case (4 floors) the member's step
predicted 533.3 where the best candidate (a flexible hook) had 523.0 and
the nominal 833. On a dead band hidden in the wipe spring (4.8 floors) the
step from b = 0 predicted an AICc of 586.2, a gain of 70 % of the best
candidate's (a constant load at the hook, 540.0 from a nominal 696.5);
fitted, the dead band reached 540.0, as good as the best, and joined its
class (with a share of 0.2 it had been left out, and the constant load
was named with a class that lacked the truth).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np
from scipy.optimize import lsq_linear

from ...errors import AcausalError
from . import stats as st
from .fitting import scaled_columns
from ..problem import Candidate, Problem
from .tasks import dataset_of, model_of

STEP = 1e-2       # of each parameter's scale (a score only: the fits' own step is 1e-3)
MARGIN = 10.0     # AICc units within which a predicted member is fitted, or ...
SHARE = 0.5       # ... this share of the best candidate's AICc gain over the nominal
MAX_FITS = 6      # screened members fitted at most


@dataclass(frozen=True)
class ScreenTask:
    """Evaluate ``candidate`` at its start with the free parameters at
    ``free`` ((name, value) pairs)."""

    problem: Problem
    candidate: Candidate
    free: tuple


def start_columns(task: ScreenTask):
    """(residuals at the start, columns of the candidate's own parameters
    per unit of their scale), or None when its model does not simulate."""
    p, cand = task.problem, task.candidate
    base = {**dict(task.free), **{q.name: q.start for q in cand.params}}
    try:
        return scaled_columns(model_of(p, cand), dataset_of(p), base, cand.params, STEP,
                              p.settings.integrator)
    except AcausalError:
        return None


def predicted_step(r0, J_own, J_free, bounds=None):
    """(S_pred, d) with d = argmin |r0 + [J_free J_own] d|^2 within
    ``bounds`` ((low, high) arrays of d, or None for none) and S_pred its
    value ((nan, None) if the shapes differ or a value is not finite).

    The step is bounded because an unbounded one credits a member with gains
    it cannot reach: on the breaker, Coulomb + viscous friction at the hook
    was predicted 590.8 from a negative friction torque (a driving load) and
    took a fit slot from the member that held the truth; fitted, it stayed at
    the nominal 764.1 (docs/diagnosis.md, "Family members screened")."""
    if J_own.shape[0] != r0.size or (J_free.size and J_free.shape[0] != r0.size):
        return float("nan"), None
    A = np.hstack([J_free, J_own]) if J_free.size else J_own
    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(r0))):
        return float("nan"), None
    if bounds is None or not A.shape[1]:
        d = np.linalg.lstsq(A, -r0, rcond=None)[0]
    else:
        c = np.linalg.norm(A, axis=0)
        c[c == 0] = 1.0                      # columns of unit norm: K's is ~1e-8
        lo, hi = bounds[0] * c, bounds[1] * c
        d = lsq_linear(A / c, -r0, bounds=(lo, hi), method="bvls").x / c
    r = r0 + A @ d
    return float(r @ r), d


def step_bounds(problem, f0, cand):
    """(low, high) of the step d of :func:`predicted_step`: the free
    parameters' in parameter units (``f0``'s order), the candidate's own per
    unit of scale, so that every point the step reaches lies in the bounds."""
    by = {p.name: p for p in problem.free}
    lo = [by[n].low - f0.values[n] for n in f0.names]
    hi = [by[n].high - f0.values[n] for n in f0.names]
    for q in cand.params:
        s = abs(q.scale) or 1.0
        lo.append((q.low - q.start) / s)
        hi.append((q.high - q.start) / s)
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return lo, np.maximum(hi, lo + 1e-300 + 1e-12 * np.abs(lo))


def _stepped(cand, d_own):
    """The candidate with its parameters' starts moved by the predicted step
    (per unit of scale; clipped to the bounds); their neutral values stay
    the priors, so the fit scores both starts."""
    return dataclasses.replace(cand, params=tuple(
        q.moved(q.start + float(x) * (abs(q.scale) or 1.0)) for q, x in zip(cand.params, d_own)))


def _free_step(problem, f0, d_free):
    """The free parameters' values after the predicted step (the nominal
    fit's Jacobian is in parameter units), clipped to their bounds: the
    step's own part alone is not the point it predicts (a bilinear open
    spring on the breaker: 548 predicted, 11859 with the free parameters
    left at their calibrated values)."""
    step = dict(zip(f0.names, np.asarray(d_free, float).tolist()))
    return tuple(float(min(max(f0.values[p.name] + step.get(p.name, 0.0), p.low), p.high))
                 for p in problem.free)


@dataclass(frozen=True)
class Unfitted:
    """A member the screen found plausible but had no fit slot for: it
    stays a possible rival, so no cause is named over it."""

    label: str
    predicted_aicc: float


@dataclass(frozen=True)
class Screen:
    """The screen's outcome: ``picks`` ((candidate, free values) to fit,
    most promising first) and ``unfitted`` (:class:`Unfitted`, beyond
    ``MAX_FITS``)."""

    picks: tuple = ()
    unfitted: tuple = ()


def screened(ctx, problem, cal, dec, cands, max_fits=MAX_FITS) -> Screen:
    """The candidates of ``cands`` whose predicted AICc comes within reach
    of the best row's, most promising first, each with the predicted step as
    a second start: its own parameters' (in the candidate) and the free
    parameters' (module doc). Those beyond ``max_fits`` are returned as
    unfitted (None: every one within reach is a pick; the family stage
    fits them all, :func:`.families.fit_members`)."""
    if not cands or not dec.rows:
        return Screen()
    f0 = cal.fit
    free = tuple((n, f0.values[n]) for n in problem.free_names)
    outs = ctx.run(start_columns, [ScreenTask(problem, c, free) for c in cands],
                   "screening family members", checkpoint=False, progress=False)
    best = dec.rows[0].aicc
    reach = best + max(MARGIN, SHARE * (dec.a0 - best))
    scored = []
    for c, o in zip(cands, outs):
        if o is None:
            continue
        S, d = predicted_step(o[0], o[1], f0.jacobian, step_bounds(problem, f0, c))
        a = st.aicc(S, f0.n, f0.k + len(c.params), dec.c_hat) if np.isfinite(S) else np.inf
        if a < reach:
            scored.append((a, _stepped(c, d[f0.k:]), _free_step(problem, f0, d[:f0.k])))
    scored.sort(key=lambda t: t[0])
    cut = len(scored) if max_fits is None else max_fits
    return Screen(tuple((c, at) for _, c, at in scored[:cut]),
                  tuple(Unfitted(c.label, a) for a, c, _ in scored[cut:]))
