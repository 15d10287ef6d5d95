"""Stage: where the library falls short. When a discrepancy is found and
no library cause explains it (no cause named, or the named one still
leaves misfit beyond the instrument), the generic term of :mod:`.generic`
is fitted at every node of a body; the node whose term removes most of the
misfit (by AICc, with its held-out error) locates the discrepancy.

The verdict "not explained by the library" needs: the best generic term
beats the best library candidate by more than ``MARGIN`` AICc units and by
held-out error, and it reaches closer to the instrument floor.

Degenerate directions are pinned before the fit (:func:`pin_rows`): the
spline reproduces constants and straight lines exactly, so its constant
and linear parts can do what a free parameter acting at the node does (a
spring's stiffness, a damper's coefficient), and its position and
velocity parts share one constant. Fitted with the free parameters, those
directions are undetermined: the fit trades them off, converges slowly and
the located shape zigzags. Each direction of the weights whose effect on
the data a free parameter reproduces (to ``PIN_TOL``), or that has no
effect on the data (``NULL_TOL``), gets a stiff penalty row, so the term
is fitted orthogonal to the free parameters' Jacobian columns and they
keep what they can explain. The position and velocity parts' shared
constant is pinned by construction: the velocity part carries no force at
rest (:func:`at_rest_row`).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import stats as st
from .fitting import effective_k, heldout_rms, scaled_columns
from ..library.generic import GENERIC, N_V, N_X, SMOOTH, hats, penalty, shape
from ..problem import Candidate, Param
from .chain import fit_tasks
from .tasks import dataset_of, fit_candidate, model_of, penalty_of

MARGIN = 10.0    # AICc units by which the generic term must beat the library
PIN_TOL = 0.05   # a free parameter whose effect on the data the term reproduces to 5 %
                 # (relative residual of the least-squares match) is degenerate with it
NULL_TOL = 1e-6  # directions of the weights with no effect on the data (singular value
                 # relative to the largest); the position and velocity parts' shared
                 # constant is pinned by construction (at_rest_row)
PIN_WEIGHT = 1e3  # pin rows' size relative to the term's largest singular value
STEP = 1e-4      # finite-difference step (of each weight's / free parameter's scale)


@dataclass
class Term:
    """The generic term fitted at one node."""

    node: str                     # the body's path (its node)
    members: tuple                # components with a connector on that node
    S: float
    aicc: float
    heldout_rmse: float
    ranges: tuple                 # (x_lo, x_hi, v_lo, v_hi) of the knots
    shape: dict                   # generic.shape of the fitted weights
    values: dict


@dataclass
class Location:
    """The located discrepancy: terms best first, and the verdict."""

    terms: tuple = ()
    unexplained: bool = False
    node: str | None = None
    reason: str = ""
    nearest: str | None = None    # the best library candidate, for comparison
    nearest_why: str = ""
    skipped: str = ""             # why the stage did not run, if it did not
    wall_s: float = 0.0
    details: dict = field(default_factory=dict)


def needed(dec, rk) -> bool:
    """Run the stage when a discrepancy is found and no cause is named or
    the best fit still leaves misfit beyond the instrument."""
    return dec.discrepancy and (rk.named is None or dec.c_hat > st.OVERDISPERSION)


def generic_candidates(problem, n=1):
    """(Candidate, knot ranges, members) of the generic term at every body
    node; ``n`` data values set the penalty's weight (generic.SMOOTH per value)."""
    from ..library.graph import ModelGraph
    from ..library.nominal import nominal_result
    from ...modelfile import load_model_file
    graph = ModelGraph(load_model_file(problem.model_path).model,
                       result=nominal_result(problem.model_path))
    out = []
    for loc in GENERIC.candidates(graph):
        params = tuple(Param(s.name, s.initial, s.low, s.high, s.scale, s.initial)
                       for s in GENERIC.params(graph, loc))
        out.append((Candidate(GENERIC.id, loc, params, penalty(N_X, N_V, SMOOTH * n)),
                    tuple(GENERIC.ranges(graph, loc)),
                    tuple(sorted({p.owner.path for p in
                                  graph.nodes[graph.node(graph.components[loc].flange)]}))))
    return out


def degenerate_directions(Jg, Jf):
    """Orthonormal rows (in the term's scaled weights) of the directions the
    data cannot tell apart: the (near) null space of ``Jg`` and, for each
    free parameter's column of ``Jf`` that the term reproduces to
    ``PIN_TOL``, the least-squares weights that reproduce it."""
    from scipy.linalg import orth
    _, s, Vt = np.linalg.svd(Jg, full_matrices=False)
    if s.size == 0 or s[0] == 0:
        return np.zeros((0, Jg.shape[1])), 0.0
    dirs = [Vt[i] for i in range(s.size) if s[i] < NULL_TOL * s[0]]
    for j in np.asarray(Jf).T:
        nj = np.linalg.norm(j)
        if nj == 0:
            continue
        w = np.linalg.lstsq(Jg, j, rcond=NULL_TOL)[0]
        if np.linalg.norm(Jg @ w - j) < PIN_TOL * nj and np.linalg.norm(w) > 0:
            dirs.append(w / np.linalg.norm(w))
    if not dirs:
        return np.zeros((0, Jg.shape[1])), float(s[0])
    return orth(np.array(dirs).T).T, float(s[0])


def pin_rows(task):
    """Penalty rows pinning the generic term's degenerate directions (module
    doc) at the calibrated free parameters and zero weights: the term's
    and the free parameters' data Jacobians by forward differences, one
    simulation of every experiment per column. Returns (rows, the term's
    largest singular value); no rows when the term cannot be simulated."""
    p, cand = task.problem, task.candidate
    base = {**{q.name: q.start for q in task.free}, **{q.name: q.start for q in cand.params}}
    try:
        ds, pair, b = dataset_of(p), model_of(p, cand), p.settings.integrator
        # no step backwards at an upper bound here (the term's weights start
        # at 0, far inside theirs); the residuals at the base are shared
        r0, Jg = scaled_columns(pair, ds, base, cand.params, STEP, b, inside=False)
        Jf = scaled_columns(pair, ds, base, task.free, STEP, b, r0, inside=False)[1]
    except Exception:  # noqa: BLE001 - the fit reports the failure; nothing to pin
        return np.zeros((0, len(cand.params))), 0.0
    Q, s0 = degenerate_directions(Jg, Jf)
    return PIN_WEIGHT * s0 * Q, s0


def at_rest_row(ranges):
    """The row that pins the velocity part's force at rest, f_v(0) = 0 (on
    the weights over their scale, which is one for all of them): the
    position and velocity parts share a constant, which this gives to the
    position part. The data cannot tell them apart, but the finite-difference
    Jacobian of an adaptive simulation only shows it to about 1e-3, above
    ``NULL_TOL``. None when the velocity range does not reach 0."""
    v_lo, v_hi = ranges[2], ranges[3]
    if not v_lo <= 0.0 <= v_hi:
        return None
    return np.concatenate([np.zeros(N_X), hats(0.0, v_lo, v_hi, N_V)[0]])


def _pinned(ctx, problem, cal, gens):
    """The generic candidates with their degenerate directions pinned."""
    import dataclasses
    tasks = fit_tasks(problem, cal, [g[0] for g in gens])
    out = []
    for g, (rows, s0) in zip(gens, ctx.run(pin_rows, tasks, "pinning", checkpoint=False)):
        rest = at_rest_row(g[1])
        if rest is not None and s0 > 0:
            rows = np.vstack([rows, PIN_WEIGHT * s0 * rest / np.linalg.norm(rest)])
        P = np.vstack([np.asarray(g[0].penalty, float), rows])
        out.append((dataclasses.replace(g[0], penalty=P),) + tuple(g[1:]))
    return out


def _term(r, n, c_hat, ranges, members):
    """The fitted term; its AICc counts the parameters the fit spends
    (:func:`.fitting.effective_k`): pinned directions and the smoothing
    penalty's ties are not free parameters."""
    f = r.fit
    k = effective_k(f, penalty_of(r.candidate))
    return Term(r.candidate.location, members, f.cost, st.aicc(f.cost, n, k, c_hat),
                heldout_rms(r.loo), ranges, shape(f.values, GENERIC.prefix, ranges),
                dict(f.values))


def locate(ctx, problem, cal, dec, rk) -> Location:
    """Fit the generic term at every body node (module doc)."""
    import time
    if not needed(dec, rk):
        return Location(skipped="not needed: no discrepancy, or a cause explains it")
    t0 = time.perf_counter()
    gens = generic_candidates(problem, cal.fit.n)
    if not gens:
        return Location(skipped="the model has no body node")
    gens = _pinned(ctx, problem, cal, gens)
    # the term is linear in its weights: refined from zero weights (with the
    # calibrated free parameters) only; Latin-hypercube splines are random
    # wiggles that cost a refinement each and start nowhere useful
    tasks = fit_tasks(problem.one_start(), cal, [g[0] for g in gens])
    results = ctx.run(fit_candidate, tasks, "locating")
    n = cal.fit.n
    terms = sorted((_term(r, n, dec.c_hat, g[1], g[2]) for r, g in zip(results, gens) if r.ok),
                   key=lambda t: t.aicc)
    out = _verdict(terms, dec, rk, n)
    out.wall_s = time.perf_counter() - t0
    return out


def _verdict(terms, dec, rk, n) -> Location:
    if not terms:
        return Location(skipped="no generic term could be fitted")
    best_t = terms[0]
    lib = rk.best
    lib_aicc = lib.aicc if lib is not None else dec.a0
    lib_held = lib.heldout_rmse if lib is not None else rk.heldout0
    nearest = lib.candidate.label if lib is not None else None
    k = lib.k if lib is not None else 0
    left = np.sqrt(lib.S / max(n - k, 1)) if lib is not None else float("nan")
    why = (f"the best library candidate ({nearest}) leaves {left:.3g}x the noise floor (RMS) "
           f"and a held-out error of {lib_held:.3g}; the generic term at {best_t.node} "
           f"leaves {np.sqrt(best_t.S / n):.3g}x and {best_t.heldout_rmse:.3g}"
           if lib is not None else "")
    beats = (lib_aicc - best_t.aicc > MARGIN and best_t.heldout_rmse < lib_held
             and best_t.S < (lib.S if lib is not None else np.inf))
    unexplained = bool(beats and rk.named is None)
    reason = (f"the generic term at {best_t.node} is {lib_aicc - best_t.aicc:.1f} AICc units "
              f"better than the best library candidate" if beats else
              "the generic terms do not beat the library's best candidate")
    return Location(tuple(terms), unexplained, best_t.node if unexplained else None, reason,
                    nearest, why)
