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
parameters' columns of the nominal fit, one Gauss-Newton step predicts the
cost it would reach, S_pred = min_d |r0 + J d|^2, and so its AICc. Members
whose predicted AICc comes within max(``MARGIN``, ``SHARE`` x the best
candidate's gain over the nominal) of the best candidate's are fitted (at
most ``MAX_FITS``, the most promising first). A linear step misjudges a
nonlinear member either way, hence the generous margin: on the breaker's
Hunt-Crossley case (4 floors) the member's step predicted 533.3 where the
best candidate (a flexible hook) had 523.0 and the nominal 833, just
outside a margin of 10 units.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..errors import AcausalError
from . import stats as st
from .fitting import scaled_columns
from .problem import Candidate, Problem
from .tasks import dataset_of, model_of

STEP = 1e-2       # of each parameter's scale (a score only: the fits' own step is 1e-3)
MARGIN = 10.0     # AICc units within which a predicted member is fitted, or ...
SHARE = 0.2       # ... this share of the best candidate's AICc gain over the nominal
MAX_FITS = 4      # screened members fitted at most


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


def predicted_step(r0, J_own, J_free):
    """(S_pred, d) with d = argmin |r0 + [J_free J_own] d|^2 and S_pred its
    value ((nan, None) if the shapes differ or a value is not finite)."""
    if J_own.shape[0] != r0.size or (J_free.size and J_free.shape[0] != r0.size):
        return float("nan"), None
    A = np.hstack([J_free, J_own]) if J_free.size else J_own
    if not (np.all(np.isfinite(A)) and np.all(np.isfinite(r0))):
        return float("nan"), None
    d = np.linalg.lstsq(A, -r0, rcond=None)[0]
    r = r0 + A @ d
    return float(r @ r), d


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


def screened(problem, cal, dec, cands, ex, run_tasks) -> list:
    """[(candidate, free values)] of the candidates of ``cands`` whose
    predicted AICc comes within reach of the best row's, most promising
    first, each with the predicted step as a second start: its own
    parameters' (in the candidate) and the free parameters' (module doc)."""
    if not cands or not dec.rows:
        return []
    f0 = cal.fit
    free = tuple((n, f0.values[n]) for n in problem.free_names)
    outs = run_tasks(ex, start_columns, [ScreenTask(problem, c, free) for c in cands],
                     "screening family members", False)
    best = dec.rows[0].aicc
    reach = best + max(MARGIN, SHARE * (dec.a0 - best))
    scored = []
    for c, o in zip(cands, outs):
        if o is None:
            continue
        S, d = predicted_step(o[0], o[1], f0.jacobian)
        a = st.aicc(S, f0.n, f0.k + len(c.params), dec.c_hat) if np.isfinite(S) else np.inf
        if a < reach:
            scored.append((a, _stepped(c, d[f0.k:]), _free_step(problem, f0, d[:f0.k])))
    scored.sort(key=lambda t: t[0])
    return [(c, free) for _, c, free in scored[:MAX_FITS]]
