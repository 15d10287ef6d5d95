"""Which second causes the pair search tries beside the best single one: a
first-order score test at the best fit's point.

The pair search (:func:`.stages.pair_candidates`) pairs the few best single
candidates. A second cause that a free parameter half-absorbs (quadratic
drag at a joint whose viscous damper is free) fits badly alone, ranks low
and is never paired, although with the best single cause it would explain
what that one leaves. Here each other tested candidate's own parameters
are perturbed from their neutral values at the best fit's free parameters
(one simulation of every experiment per parameter, of the candidate's own
model), their data columns are made orthogonal to the best fit's Jacobian,
and the candidates whose columns explain most of the best fit's residuals
are paired with it (Rao's score test; the Jacobians at the candidates' own
single fits are taken where a free parameter stood in for them, and missed
such a cause in a blind case, docs/diagnosis.md).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import AcausalError
from .fitting import weighted_residuals
from .problem import Candidate, Problem
from .tasks import dataset_of, model_of

STEP = 1e-2      # of each parameter's scale (the fits' own step is 1e-3: a smaller
                 # one meets the adaptive solver's noise; this one is for a score only)


@dataclass(frozen=True)
class ScoreTask:
    """The data columns of ``candidate``'s own parameters at its neutral
    values and the free parameters ``free`` (name -> value)."""

    problem: Problem
    candidate: Candidate
    free: tuple


def own_columns(task: ScoreTask):
    """Forward-difference columns (per unit of each parameter's scale), or
    None when the candidate's model does not simulate there."""
    p, cand = task.problem, task.candidate
    base = {**dict(task.free), **{q.name: q.prior for q in cand.params}}
    try:
        ds, pair = dataset_of(p), model_of(p, cand)
        r0 = weighted_residuals(pair, ds, base, p.settings.integrator)[0]
        cols = []
        for q in cand.params:
            h = STEP * (abs(q.scale) or 1.0)
            h = h if base[q.name] + h <= q.high else -h
            r = weighted_residuals(pair, ds, {**base, q.name: base[q.name] + h},
                                   p.settings.integrator)[0]
            cols.append((r - r0) / (h / (abs(q.scale) or 1.0)))
    except AcausalError:
        return None
    return np.array(cols).T


def gains(best_fit, columns) -> list:
    """Score of each column block: the squared norm of the best fit's
    residuals on the blocks's span made orthogonal to the best fit's
    Jacobian (nan when a block is missing or does not match)."""
    f = best_fit
    Q = np.linalg.qr(f.jacobian)[0] if f.jacobian.size else np.zeros((f.n, 0))
    out = []
    for J in columns:
        if J is None or J.shape[0] != f.residuals.size or not np.all(np.isfinite(J)):
            out.append(float("nan"))
            continue
        size = np.linalg.norm(J)
        J = J - Q @ (Q.T @ J)
        U, s, _ = np.linalg.svd(J, full_matrices=False)
        U = U[:, s > 1e-8 * size]          # what the best fit's columns cannot do
        if U.shape[1] == 0:
            out.append(0.0)
            continue
        out.append(float(np.sum((U.T @ f.residuals) ** 2)))
    return out


def complements(problem, best, rows, ex, n, run_tasks) -> list:
    """The ``n`` rows of ``rows`` that best complete ``best`` (module doc)."""
    if not rows or n <= 0:
        return []
    free = tuple((name, best.fit.values[name]) for name in problem.free_names)
    tasks = [ScoreTask(problem, r.candidate, free) for r in rows]
    cols = run_tasks(ex, own_columns, tasks, "scoring pairs", False)
    g = gains(best.fit, cols)
    order = sorted((i for i in range(len(rows)) if np.isfinite(g[i]) and g[i] > 0),
                   key=lambda i: -g[i])
    return [rows[i] for i in order[:n]]
