"""Which second causes the pair search fits beside the best single one: a
short screening fit of the best single paired with every other candidate
at another site, then full fits of the few best.

The pairs among the few best single candidates (:func:`.stages.pair_candidates`)
miss a second cause that a free parameter absorbs: alone it fits badly
(quadratic drag at a joint whose viscous damper is free; dry friction at a
shaft whose viscous friction is free), ranks low, or even stays at its
neutral value from every start ("not tested"). A first-order score test at
the best fit's point missed such a cause in a blind case (the latch: the
right partner third, at 2306 of the 17000 the pair removes): the gain is
far from linear. Here the gain is measured by fitting.

Screening (:func:`screen_pair`, one task per partner, on the workers): the
pair model's free parameters and the best single's own start from the best
single's fit, the partner's from its neutral value and :data:`SCREEN_LHS`
Latin-hypercube points over its bounds. Each start is scored after a
linearised re-fit of the free parameters and the best single's own
(its fit's Jacobian), then the best start is refined by least squares on
the whole record for at most :data:`SCREEN_EVALS` (k + 1) residual
evaluations (a few Gauss-Newton steps with forward differences). The
:data:`SCREEN_KEEP` partners whose screened pair ends lowest in S (and
below the best single's S) get a full pair fit (:func:`.tasks.fit_candidate`)
seeded from the screened point: the free parameters there, the calibrated
ones kept as priors.

Simpler mates (:func:`simpler_tasks`): when the best fitted pair holds a
family member with more parameters than another member of its family (Coulomb
+ viscous friction where Coulomb friction would do), the pair with the
simpler member in its place is fitted briefly (one refinement), seeded from
the best pair's fit: the shared parameters (by name within the sub-model,
``F``) and the free parameters at its values. The ranking then compares the
two (:func:`.families.prefer_simplest`): an extra parameter the data do not
support (AICc, held-out error) does not take the name. Without this the
simpler pair was never fitted (it is neither among the best singles' pairs
nor a screened partner) and the richer one was named with its extra
parameter near neutral (the two-mass pair case: b = 9e-6).
"""
from __future__ import annotations

import dataclasses
import itertools
from dataclasses import dataclass

import numpy as np

from . import stats as st
from .fitting import Budget, Objective, finish, refine_or_keep, score_starts
from ..library.loader import family_index, load_library
from ..problem import Candidate, Param, Problem, pair_of
from .tasks import FitTask, bounds_of, dataset_of, lhs_values, model_of

SCREEN_LHS = 2        # Latin-hypercube starts of the partner besides its neutral value
SCREEN_EVALS = 4      # residual evaluations per fitted parameter (+1) of a screening fit
SCREEN_KEEP = 3       # full pair fits of the best screened partners
SCREEN_NFEV = 8       # least-squares iterations of a screening fit (the budget ends it first)


@dataclass(frozen=True)
class PairScreenTask:
    """Screen ``pair`` (the best single first, its parameters seeded from
    its fit; the partner second, at neutral) with the free parameters
    ``free`` (Param, start = the best single's fit); ``absorb`` = (names,
    Jacobian) of the best single's fit."""

    problem: Problem
    pair: Candidate
    free: tuple
    absorb: tuple


@dataclass
class Screened:
    """The end point of one screening fit (picklable)."""

    pair: Candidate
    cost: float
    values: dict
    n_sim: int
    error: str | None = None


def screen_starts(task: PairScreenTask, n_first: int):
    """The starts over free + pair parameters: everything at its seed, the
    partner at neutral, then at :data:`SCREEN_LHS` points over its bounds."""
    params = list(task.free) + list(task.pair.params)
    x0 = np.array([p.start for p in params])
    second = list(task.pair.params[n_first:])
    out = [x0]
    for x in lhs_values(second, SCREEN_LHS, task.problem.settings.seed):
        y = x0.copy()
        y[len(params) - len(second):] = x
        out.append(y)
    return out


def screen_pair(task: PairScreenTask) -> Screened:
    """The screening fit of one pair (module doc); never raises."""
    p, pair = task.problem, task.pair
    params = list(task.free) + list(pair.params)
    names = [q.name for q in params]
    lo, hi, sc = bounds_of(params)
    s = p.settings
    try:
        obj = Objective(model_of(p, pair), dataset_of(p), names, backend=s.integrator,
                        budget=Budget(evals=SCREEN_EVALS * (len(names) + 1)))
        n_first = len(pair.params) - len(pair.members()[1][2])
        scored = score_starts(obj, screen_starts(task, n_first), lo, hi, task.absorb)
        if not scored:
            return Screened(pair, float("inf"), {}, obj.n_sim, "every start failed")
        f = finish(obj, *refine_or_keep(obj, scored[0][1], lo, hi, sc, SCREEN_NFEV, s.tol), lo)
        return Screened(pair, f.cost if f.ok or np.isfinite(f.cost) else float("inf"),
                        f.values, obj.n_sim)
    except Exception as exc:  # noqa: BLE001 - a pair that cannot be built is left out
        return Screened(pair, float("inf"), {}, 0, f"{type(exc).__name__}: {exc}")


def screen_tasks(problem: Problem, best, pairs) -> list:
    """One :class:`PairScreenTask` per pair candidate (the best single first)."""
    f = best.fit
    free = tuple(q.moved(f.values[q.name]) for q in problem.free)
    absorb = (list(f.names), f.jacobian)
    return [PairScreenTask(problem, c, free, absorb) for c in pairs]


def full_tasks(problem: Problem, cal, screened, budget) -> list:
    """The :class:`FitTask` of each kept pair, seeded from its screened
    point (free parameters there; priors and bounds as declared)."""
    out = []
    for r in screened:
        v = r.values
        free = tuple(q.moved(v.get(q.name, cal.fit.values[q.name])) for q in problem.free)
        cand = dataclasses.replace(r.pair, params=tuple(q.moved(v.get(q.name, q.start))
                                                        for q in r.pair.params))
        out.append(FitTask(problem, cand, free, (list(cal.fit.names), cal.fit.jacobian),
                           budget))
    return out


def keep(best, screened, n=SCREEN_KEEP) -> list:
    """The ``n`` screened pairs lowest in S, each below the best single's."""
    ok = [r for r in screened if r.error is None and np.isfinite(r.cost)
          and r.cost < best.fit.cost]
    return sorted(ok, key=lambda r: r.cost)[:n]


def simpler_tasks(problem: Problem, cal, fits, c_hat, budget, done=()) -> list:
    """:class:`FitTask` (one refinement each) of the best fitted pair (by
    AICc) with each of its family members replaced by every member of the
    same family with fewer parameters that can act at its site, seeded from
    the best pair's fit (module doc); pairs whose key is in ``done`` are
    left out, and so is one hypothesis twice at one site (its two
    magnitudes would add: not identifiable)."""
    pairs = [r for r in fits if r.ok and "+" in r.candidate.hypothesis]
    if not pairs:
        return []
    n = cal.fit.n
    best = min(pairs, key=lambda r: st.aicc(r.fit.cost, n, r.fit.k, c_hat))
    lib, index = load_library(problem.library), family_index(problem.library)
    graph = lib.graph_of(problem.model_path)
    v = best.fit.values
    options = []
    for h, loc, names in best.candidate.members():
        seeds = {nm.partition(".")[2]: v[nm] for nm in names}
        options.append([_member(lib, graph, m, loc, seeds) for m in (h,) + index.mates(h)
                        if m == h or _fewer(lib, graph, m, loc, len(names))])
    free = tuple(q.moved(v[q.name]) for q in problem.free)
    absorb = (list(cal.fit.names), cal.fit.jacobian)
    out = []
    for a, b in itertools.product(*options):
        cand = pair_of(a, b)
        if a.key != b.key and cand.key != best.candidate.key and cand.key not in done:
            out.append(FitTask(problem.one_start(), cand, free, absorb, budget))
    return out


def _fewer(lib, graph, mid, loc, k) -> bool:
    """Whether member ``mid`` acts at ``loc`` with fewer than ``k`` parameters."""
    h = lib.HYPOTHESES.get(mid)
    return h is not None and loc in h.candidates(graph) and len(h.params(graph, loc)) < k


def _member(lib, graph, mid, loc, seeds) -> Candidate:
    """Member ``mid`` at ``loc``, each parameter seeded from ``seeds`` (its
    name within the sub-model -> value) where it has one."""
    return Candidate(mid, loc, tuple(Param.from_spec(s, seeds.get(s.name.partition(".")[2]))
                                     for s in lib.HYPOTHESES[mid].params(graph, loc)))
