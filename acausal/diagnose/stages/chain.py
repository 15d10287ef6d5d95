"""The diagnosis's main stages, each a function of small dataclasses
returning a new one (none mutates its input), with the tasks it sends to
the executor run through a :class:`.context.Context`:

calibrate -> candidates -> fit -> decide -> cross-validate -> rank ->
extend; the family members (:mod:`.families`), the located term
(:mod:`.locate`), the intervals (:mod:`.intervals`), the next experiment
(:mod:`.nextexp`) and the views (:mod:`.views`) are stages of their own
modules. :mod:`acausal.diagnose.run` chains them, each as
``stage(ctx, state) -> state``.

The worker-side units of work are in :mod:`.tasks`; the statistics in
:mod:`.stats`; :mod:`acausal.diagnose.report` renders the result.
"""
from __future__ import annotations

import dataclasses
import math
import os
from dataclasses import dataclass, field

import numpy as np

from ...studies.calibrate import model_dataset
from ...data import DataError
from ...errors import AcausalError, DiagnosisError  # noqa: F401  (DiagnosisError re-exported)
from ...modelfile import compile_file
from . import pairscreen as pscreen
from . import pairsearch as ps
from . import stats as st
from . import verdict as vd
from .context import Context, longest_first, run_tasks  # noqa: F401 (run_tasks re-exported)
from .fitting import DirectionalHeldout, Fit, directional_heldout, heldout_rms, \
    whitened_heldout
from .screen import Unfitted
from ..library.loader import FamilyIndex, family_index, load_library
from ..problem import NOMINAL, Candidate, FitSettings, Param, Problem, free_param, pair_of
from .tasks import CandidateFit, FitTask, LooTask, Starts, calibrate_nominal, fit_candidate, \
    penalty_of, \
    refit_without
from .tasks import MAX_TRACE_SAMPLES, MIN_TRACE_SAMPLES, thin_traces  # noqa: F401 (re-exported)

# What ends a fit is its evaluations (FitSettings.evals_per_param: issue 24, "the budget
# is measured in simulations"); its wall time is a guard against a pathological run
# only, one that no fit reaches on a loaded machine. At 12 x the nominal fit and at
# least 60 s it could: a stick-slip pair's window is 700 simulations of 35 ms, 25 s on
# a quiet host and past 60 s on one loaded three times over, so where such a fit (or
# a leave-one-out refit, at a third of it) stopped, and the verdict, could depend on the
# machine's load
BUDGET_FACTOR = 120.0  # a fit's wall-time guard: this many times the nominal fit ...
BUDGET_MIN_S = 600.0   # ... and at least this long [s]
SMALL_N = 100         # at most this many values and ...
SMALL_EXPERIMENTS = 12  # ... experiments: exact leave-one-out for the SMALL_TOP ...
SMALL_TOP = 6         # ... best candidates (the linearised shortcut is poor on few data)
DRIFT = 0.25          # a free parameter moved by more than this fraction of its prior


# -- setup -------------------------------------------------------------------------------
def load_problem(model_path, data_folder, library=None, settings=None):
    """(Problem, Dataset) after checking the inputs (one clear message)."""
    model_path, data_folder = os.path.abspath(model_path), os.path.abspath(data_folder)
    mf, cm = compile_file(model_path)
    try:
        ds = model_dataset(model_path, data_folder)
    except DataError as exc:
        raise DiagnosisError(exc.message, file=exc.file, line=exc.line,
                             column=exc.column) from None
    if not ds.experiments:
        raise DiagnosisError(f"{data_folder}: no experiments")
    ds = thin_traces(ds, say=True)
    if not any(e.measures or e.trace is not None for e in ds.experiments):
        raise DiagnosisError(f"{data_folder}: no measured values (no measures, no traces)")
    free = tuple(free_param(n, cm.params[cm.param_index(n)].default, lo, hi)
                 for n, (lo, hi) in mf.free.items())
    lib = load_library(library).name
    return Problem(model_path, data_folder, lib, free, settings or FitSettings()), ds


def _select(items, wanted, what):
    if wanted is None:
        return list(items)
    wanted = [wanted] if isinstance(wanted, str) else list(wanted)
    unknown = [w for w in wanted if w not in items]
    if unknown:
        raise DiagnosisError(f"unknown {what} {', '.join(map(repr, unknown))}; "
                             f"known: {', '.join(items)}")
    return [i for i in items if i in wanted]


def _heads(lib):
    """The library's hypotheses without the non-head members of its
    families (those are fitted where their head is competitive: :mod:`.families`)."""
    later = {m for ms in (getattr(lib, "FAMILIES", None) or {}).values() for m in ms[1:]}
    return {k: v for k, v in lib.HYPOTHESES.items() if k not in later}


def candidates(problem: Problem, hypotheses=None, locations=None) -> tuple:
    """Stage 2: every (hypothesis, location) the model graph offers, with
    the extension's parameters (neutral starts). ``locations``: paths
    (exact, or a prefix followed by '.') to keep. Without ``hypotheses``,
    a family's members other than its head are left to :mod:`.families`."""
    lib = load_library(problem.library)
    graph = lib.graph_of(problem.model_path)
    if hypotheses is not None and not list(hypotheses):
        raise DiagnosisError("--hypotheses: the list is empty; known: "
                             + ", ".join(lib.HYPOTHESES))
    if locations is not None and not list(locations):
        raise DiagnosisError("--locations: the list is empty")
    out, offered = [], []
    for hid in _select(_heads(lib) if hypotheses is None else lib.HYPOTHESES, hypotheses,
                       "hypothesis"):
        hyp = lib.HYPOTHESES[hid]
        for loc in hyp.candidates(graph):
            offered.append(loc)
            if locations is not None and not any(
                    loc == w or loc.startswith(w + ".") for w in locations):
                continue
            params = tuple(Param.from_spec(s) for s in hyp.params(graph, loc))
            out.append(Candidate(hid, loc, params))
    if locations is not None:      # a location no candidate is at: a typo, not "no cause"
        unused = [w for w in locations
                  if not any(loc == w or loc.startswith(w + ".") for loc in offered)]
        if unused:
            known = sorted(set(offered))
            raise DiagnosisError(
                f"--locations {', '.join(map(repr, unused))}: no candidate of the "
                f"{'chosen ' if hypotheses else ''}hypotheses is there; the model graph "
                f"offers {len(known)} locations: {', '.join(known[:12])}"
                + (", ..." if len(known) > 12 else ""))
    return tuple(out)


# -- stage 1: calibrate ---------------------------------------------------------------------
@dataclass
class NominalFit:
    """Stage 1's result: the nominal model's fit (its free parameters
    calibrated) and what the free parameters did. (Not
    :class:`acausal.studies.calibrate.Calibration`, a calibration study's
    result.)"""

    nominal: CandidateFit
    drift: tuple = ()             # Drift of each free parameter

    @property
    def fit(self):
        return self.nominal.fit


@dataclass(frozen=True)
class Drift:
    name: str
    prior: float
    calibrated: float
    relative: float               # (calibrated - prior) / |prior|
    far: bool                     # moved by more than DRIFT and beyond its 95 % interval


def _drift(problem, fit):
    out = []
    for p in problem.free:
        v = fit.values[p.name]
        rel = (v - p.prior) / abs(p.prior) if p.prior else float("inf") if v else 0.0
        lo, hi = fit.ci95.get(p.name, (-math.inf, math.inf))
        outside = not (lo <= p.prior <= hi)
        out.append(Drift(p.name, p.prior, v, rel, abs(rel) > DRIFT and outside))
    return tuple(out)


def calibrate(ctx: Context, problem: Problem) -> NominalFit:
    """Stage 1: the nominal model's free parameters by weighted output error
    (multi-start and growing window: :func:`.tasks.calibrate_nominal`)."""
    task = FitTask(problem, NOMINAL, problem.free)
    nominal = ctx.run(calibrate_nominal, [task], "calibrating")[0]
    if not nominal.ok:
        why = nominal.error or (nominal.fit.message if nominal.fit else "no fit")
        raise DiagnosisError(f"the nominal model could not be fitted: {why}")
    return NominalFit(nominal, _drift(problem, nominal.fit))


# -- stage 3: fit ---------------------------------------------------------------------------
def fit_tasks(problem: Problem, cal: NominalFit, cands) -> list:
    """One :class:`FitTask` per candidate, starting from the calibrated
    free parameters (their priors kept for the uncalibrated starts)."""
    f0 = cal.fit
    free = tuple(Param(p.name, f0.values[p.name], p.low, p.high, p.scale, p.prior)
                 for p in problem.free)
    budget = _budget(cal)
    absorb = (list(f0.names), f0.jacobian)
    return [FitTask(problem, c, free, absorb, budget) for c in cands]


def fit(ctx: Context, problem: Problem, cal: NominalFit, cands) -> tuple:
    """Stage 3: every candidate fitted (:func:`.tasks.fit_candidate`)."""
    tasks = fit_tasks(problem, cal, cands)
    return tuple(ctx.run(fit_candidate, tasks, "fitting candidates"))


# -- stage 3b: pairs ------------------------------------------------------------------------
PAIR_TOP = 4          # pairs among the best this many single candidates (tested, distinct)
PAIR_OWN = 2          # own parameters of the simplest pair (two one-parameter laws)


def pairs_needed(dec) -> bool:
    """Search pairs when a discrepancy is found and the best single cause
    still leaves misfit beyond the instrument (S/(n-k) above OVERDISPERSION),
    or does not explain the held-out data (its linearised held-out error
    above :func:`.stats.heldout_threshold`: a free shape parameter can fit
    the training data of two laws and still miss the held-out experiment,
    issue 24's power drag at n = 2.61, training 1.15 and held-out 2.69),
    or has more parameters of its own than a pair of two one-parameter
    laws (``PAIR_OWN``): such a pair could fit as well with fewer, and
    only fitted can parsimony judge it (independent cam, Coulomb friction
    + quadratic drag at the cam, four runs: Stribeck friction at the cam,
    three parameters, reached the noise and no pair was searched)."""
    if not (dec.discrepancy and dec.rows):
        return False
    if dec.c_hat > st.OVERDISPERSION:
        return True
    best = dec.rows[0]
    if "+" not in best.candidate.hypothesis and len(best.own) > PAIR_OWN:
        return True
    return not vd.explains(best, vd.threshold_of(best.fit.n, best, max(len(best.loo), 1)))


def pair_candidates(problem: Problem, dec, top=PAIR_TOP, places=None) -> tuple:
    """Pairs among the ``top`` best tested single candidates (two
    hypotheses, or one at two sites: the second's sub-model renamed; two
    members of one family at one site are never a pair:
    :func:`.pairscreen.same_cause`), each parameter seeded from its single
    fit (its neutral value kept as the prior); of pairs at rigidly tied
    sites (``places``: :meth:`.kinematics.Kinematics.places`) only the
    first. The best single's pairs with every other candidate are screened
    by :func:`search_pairs` (:mod:`.pairsearch`), every pair of singles by
    :mod:`.pairscreen`."""
    if load_library(problem.library).build_pair is None:
        return ()
    index = family_index(problem.library)
    singles = _singles(dec)[:top]
    ab = [(a, b) for i, a in enumerate(singles) for b in singles[i + 1:]]
    return _first_placed((_pair(a, b) for a, b in ab
                          if not pscreen.same_cause(index, a.candidate, b.candidate, places)),
                         places)


def _first_placed(cands, places, done=()) -> tuple:
    """``cands`` without those whose key is in ``done`` (candidate keys);
    with rigidly tied ``places`` (:func:`.pairscreen.placed_key`), also
    without those whose place key is one of ``done``'s or an earlier one's
    (either order of a pair)."""
    if not places:
        return tuple(c for c in cands if c.key not in done)
    seen = {pscreen.placed_key(zip(h.split("+"), loc.split("+")), places) for h, loc in done}
    return tuple(pscreen.first_of_each(cands, lambda c: pscreen.placed_key(c.members(), places),
                                       seen))


def _singles(dec):
    return [r for r in dec.rows if "+" not in r.candidate.hypothesis and r.starts.tested]


def partners(dec, done, index=None, places=None) -> tuple:
    """The best tested single's pairs with every other single candidate
    (tested alone or not: a free parameter may have absorbed it), the
    partner at its neutral value, at another site or at the same site when
    of another family (``index``: :class:`~..library.loader.FamilyIndex`;
    None: each hypothesis its own family); pairs whose key is in ``done``
    (candidate keys), or with rigidly tied ``places`` whose place key
    (:func:`.pairscreen.placed_key`) is one of those or an earlier pair's,
    are left out (:func:`_first_placed`)."""
    singles = _singles(dec)
    if not singles:
        return ()
    index = index or FamilyIndex({}, {})
    best = singles[0]
    pairs = (_pair(best, r, neutral=True) for r in dec.rows
             if "+" not in r.candidate.hypothesis
             and not pscreen.same_cause(index, best.candidate, r.candidate, places))
    return _first_placed(pairs, places, done)


@dataclass(frozen=True)
class PairSearch:
    """The pair search's outcome: the pair ``fits``, the simulations the
    short screening fits spent (``screen_n_sim``), the linearised screen of
    every pair (``screened``: how many pairs it predicted, ``within_reach``,
    ``fitted`` among those, the share of the predicted gain it was given as
    uncertainty, ``share``) and the pairs left unfitted within reach
    (``unfitted``: :class:`.screen.Unfitted`)."""

    fits: tuple = ()
    screen_n_sim: int = 0
    screened: int = 0
    within_reach: int = 0
    fitted: int = 0
    share: float = pscreen.SHARE
    unfitted: tuple = ()


def search_pairs(ctx: Context, problem: Problem, cal: NominalFit, dec: Decision,
                 places=None) -> PairSearch:
    """Stage 3b: the pairs among the best singles (:func:`pair_candidates`)
    fitted; the best single's pairs with every other candidate screened by
    short fits, the best few fitted in full (:mod:`.pairsearch`); every pair
    of singles screened by a linearised step from the singles' own fits,
    and those within reach of the best fitted in full, in two rounds
    (:mod:`.pairscreen`); then the best pair with a simpler member of a
    family in place of a richer one, fitted briefly from it. ``places``
    (:meth:`.kinematics.Kinematics.places`): rigidly tied sites are one
    place, and a pair is searched at one placement only (its other
    placements are refined from its fit afterwards:
    :func:`.kinematics.placements`, :func:`placement_tasks`)."""
    if load_library(problem.library).build_pair is None:
        return PairSearch()
    index = family_index(problem.library)
    top = pair_candidates(problem, dec, places=places)
    tasks = fit_tasks(problem, cal, top)
    budget = _budget(cal)
    others = partners(dec, {c.key for c in top}, index, places)
    screened = ctx.run(ps.screen_pair, ps.screen_tasks(problem, _singles(dec)[0], others),
                       "screening pairs") if others else []
    best = _singles(dec)[0] if others else None
    tasks += ps.full_tasks(problem, cal, ps.keep(best, screened) if best else [], budget)
    done = {_pair_key(t.candidate) for t in tasks}
    placed = {pscreen.placed_key(t.candidate.members(), places) for t in tasks}
    preds = pscreen.screen_all(cal.fit, problem.free, dec.rows, index, dec.c_hat,
                               places=places)
    preds = _unplaced(preds, done, placed, places)
    first, _ = pscreen.picks([p for p in preds if p.key not in done])
    attempted = done | {p.key for p in first}
    tasks += [_predicted_task(problem, cal, p, budget) for p in first]
    singles = {r.candidate.key: r for r in _singles(dec)}
    fits = ctx.run(fit_candidate, [with_floors(t, singles) for t in tasks], "fitting pairs")
    n = cal.fit.n
    fitted = {_pair_key(r.candidate): st.aicc(r.fit.cost, n, r.fit.k, dec.c_hat)
              for r in fits if r.ok}
    more, left = [], []
    if fitted:
        more, left = pscreen.more_picks(preds, fitted, min(fitted.values()),
                                        pscreen.MAX_FITS - len(first), attempted)
    if more:
        fits += ctx.run(fit_candidate, [with_floors(_predicted_task(problem, cal, p, budget),
                                                    singles) for p in more],
                        "fitting pairs within the screen's reach")
        fitted.update({_pair_key(r.candidate): st.aicc(r.fit.cost, n, r.fit.k, dec.c_hat)
                       for r in fits if r.ok})
    if left:   # within reach beyond MAX_FITS: a short fit from the step's point each
        # (issue 24: no plausible rival is left unfitted for a budget)
        fits += ctx.run(fit_candidate, [with_floors(_predicted_task(problem.briefly(), cal, p,
                                                                    budget), singles)
                                        for p in left],
                        "fitting the other pairs within reach, briefly")
        fitted.update({_pair_key(r.candidate): st.aicc(r.fit.cost, n, r.fit.k, dec.c_hat)
                       for r in fits if r.ok})
    share = pscreen.observed_share(preds, fitted) if preds else pscreen.SHARE
    simpler = [with_floors(t, singles) for t in ps.simpler_tasks(
        problem, cal, fits, dec.c_hat, budget, {t.candidate.key for t in tasks})]
    fits += ctx.run(fit_candidate, simpler, "fitting simpler mates") if simpler else []
    got = {_pair_key(r.candidate) for r in fits if r.ok}
    left = [p for p in left if p.key not in got]        # a simpler mate may be one of them
    reach = {p.key for p in first + more + left}
    return PairSearch(tuple(fits), sum(r.n_sim for r in screened), len(preds),
                      len(reach), len(first) + len(more), share,
                      tuple(Unfitted(p.label, p.aicc) for p in left))


def _unplaced(preds, done, placed, places):
    """The screen's predictions ``preds`` without the other placements of
    the pairs already being fitted (``placed``: their place keys; a pair is
    fitted at one placement of rigidly tied sites, its others refined from
    its fit); the prediction of a pair being fitted itself (its key in
    ``done``) stays: the observed share compares it with the fit."""
    def place(p):
        return pscreen.placed_key((p.a.candidate.key, p.b.candidate.key), places)
    return [p for p in preds if p.key in done or place(p) not in placed]


def _pair_key(cand) -> frozenset:
    """The set of a pair's (hypothesis, location) members (either order)."""
    return frozenset((h, loc) for h, loc, _ in cand.members())


def _predicted_task(problem, cal, pred, budget) -> FitTask:
    """The full fit of a screened pair (:class:`.pairscreen.Predicted`),
    seeded from the singles' fits and, as one more start, at the point the
    linearised step predicts (the free parameters with it)."""
    S, d = pscreen.predict(cal.fit, problem.free, pred.a, pred.b,
                           {p.name: (p.low, p.high) for r in (pred.a, pred.b)
                            for p in r.candidate.params}.__getitem__)
    cand = _pair(pred.a, pred.b)
    task = fit_tasks(problem, cal, [cand])[0]
    if d is None:
        return task
    f0, k0 = cal.fit, cal.fit.k
    own = [pred.a.fit.values[p.name] for p in pred.a.candidate.params] + \
          [pred.b.fit.values[p.name] for p in pred.b.candidate.params]
    stepped = tuple(q.moved(min(max(v + float(x), q.low), q.high))
                    for q, v, x in zip(cand.params, own, d[k0:]))
    by = {p.name: p for p in problem.free}
    free = tuple(float(min(max(pred.a.fit.values[nm] + pred.b.fit.values[nm] - f0.values[nm]
                               + float(x), by[nm].low), by[nm].high))
                 for nm, x in zip(f0.names, d[:k0]))
    order = [p.name for p in problem.free]
    seed_free = tuple(free[f0.names.index(nm)] for nm in order)
    return dataclasses.replace(task, candidate=dataclasses.replace(cand, params=stepped),
                               seed_free=seed_free)


def _budget(cal):
    return max(BUDGET_MIN_S, BUDGET_FACTOR * cal.nominal.wall_s)


def member_refit_tasks(problem: Problem, cal, dec) -> list:
    """When the best row is a pair: each of its members alone, started from
    the pair's fit (its own parameters and the free parameters at the
    pair's values; one refinement on the whole record from the best scored
    start: :meth:`.problem.Problem.from_fit`). A pair earns
    its second cause only against the best each member can do alone, and a
    single fit can miss its minimum where the pair found it (breaker,
    position_dependent_force seed 6000: the coil slope alone ended at S
    3066, above the nominal 2803, while the pair with Hunt-Crossley had
    it at 21281 and S 693; the slope alone reaches 695 from there on the
    whole record, where a first window of 30 % led it back to its bound)."""
    best = dec.rows[0] if dec.rows else None
    if best is None or "+" not in best.candidate.hypothesis:
        return []
    rows = {r.candidate.key: r for r in dec.rows}
    v = best.fit.values
    out = []
    for h, loc, names in best.candidate.members():
        single = rows.get((h, loc))
        if single is None:
            continue
        cand = dataclasses.replace(single.candidate, params=tuple(
            p.moved(v[n]) for p, n in zip(single.candidate.params, names)))
        task = fit_tasks(problem.from_fit(), cal, [cand])[0]
        out.append(dataclasses.replace(task, free=tuple(p.moved(v[p.name]) for p in task.free)))
    return out


def placement_tasks(problem: Problem, cal, moves) -> list:
    """The :class:`FitTask` of each (fitted row, candidate) of
    :func:`.kinematics.placements` (a pair at another placement of rigidly
    tied sites, seeded from the row's fit converted through the ratio): one
    refinement on the whole record (:meth:`.problem.Problem.from_fit`), the
    free parameters starting at the row's values."""
    out = []
    for row, cand in moves:
        v = row.fit.values
        task = fit_tasks(problem.from_fit(), cal, [cand])[0]
        out.append(dataclasses.replace(task, free=tuple(p.moved(v[p.name]) for p in task.free)))
    return out


def with_floors(task: FitTask, singles: dict) -> FitTask:
    """``task`` (a pair's fit) with a floor at each member's own fit: the
    free parameters and the member's own at its single fit (``singles``:
    rows by candidate key), the other member neutral. The pair then ends
    no higher than either member alone (:attr:`.tasks.FitTask.floors`);
    on the cam follower's friction + drag, 5 of 15 pairs had ended 1-9
    AICc units above their own member on three runs, 8 of 20 on four (up
    to 2,350), holding it with the other member neutral."""
    cand = task.candidate
    if "+" not in (cand.hypothesis or ""):
        return task
    out = []
    for h, loc, names in cand.members():
        row = singles.get((h, loc))
        if row is None or row.fit is None or not row.fit.ok:
            continue
        v = row.fit.values
        own = {n: v[p.name] for n, p in zip(names, row.candidate.params)}
        out.append(tuple(v.get(q.name, q.start) for q in task.free)
                   + tuple(own.get(p.name, p.prior) for p in cand.params))
    return dataclasses.replace(task, floors=tuple(out))


def _pair(a, b, neutral=False) -> Candidate:
    """The pair of rows ``a`` and ``b``, seeded from their fits (``b`` at
    its neutral values when ``neutral``)."""
    ca, cb = a.candidate, b.candidate
    return pair_of(
        Candidate(ca.hypothesis, ca.location,
                  tuple(p.moved(a.fit.values[p.name]) for p in ca.params)),
        Candidate(cb.hypothesis, cb.location,
                  tuple(p.moved(p.prior if neutral else b.fit.values[p.name])
                        for p in cb.params)))


# -- stage 4: decide ------------------------------------------------------------------------
@dataclass(frozen=True)
class Row:
    """One fitted candidate, scored (a ranking row)."""

    candidate: Candidate
    fit: Fit
    starts: Starts
    loo: dict
    aicc: float
    lr_p: float
    heldout_rmse: float
    heldout_exact: bool = False
    # the held-out error beyond the parameters' uncertainty without each
    # experiment (:func:`.fitting.whitened_heldout`; NaN until ranked)
    heldout_white: float = float("nan")
    # its part within the parameters' directions, per held-out experiment
    # (:func:`.fitting.directional_heldout`; empty until ranked)
    heldout_dir: DirectionalHeldout = field(default_factory=DirectionalHeldout)

    @property
    def k(self):
        return self.fit.k

    @property
    def S(self):
        return self.fit.cost

    @property
    def train_rmse(self):
        return self.fit.rms()

    @property
    def own(self):
        """Names of the extension's parameters."""
        return [p.name for p in self.candidate.params]


@dataclass
class Decision:
    """Is there a discrepancy (stats.discrepancy_decision), with the scored
    candidates (by AICc, QAICc when even the best leaves misfit)."""

    rows: tuple                   # Row, sorted by (aicc, heldout)
    failed: tuple                 # CandidateFit that could not be fitted
    chi2: dict
    runs: list
    decision: dict
    c_hat: float
    a0: float
    alpha: float

    @property
    def discrepancy(self):
        return bool(self.decision["discrepancy"])


def _runs(ds, f0):
    """Runs tests of the nominal residuals: one per (experiment, trace signal)."""
    groups, sigs = np.asarray(f0.groups), np.asarray(f0.signals)
    out = []
    for e in ds.experiments:
        if e.trace is None:
            continue
        for var in e.trace.signals:
            m = (groups == e.name) & (sigs == var)
            if np.sum(m) >= 20:
                d = st.runs_test(f0.residuals[m])
                d.update(experiment=e.name, signal=var)
                out.append(d)
    return out


def _lowest_per_key(fits):
    """One fit per candidate key, the lowest in S (a candidate refitted
    from another start, e.g. a pair's member alone: :func:`member_refit_tasks`)."""
    best = {}
    for r in fits:
        k = r.candidate.key
        if k not in best or r.fit.cost < best[k].fit.cost:
            best[k] = r
    return list(best.values())


def decide(ds, cal: NominalFit, fits, alpha=st.ALPHA) -> Decision:
    """Stage 4: score every fitted candidate and decide whether there is a
    discrepancy (chi-square, runs, likelihood ratio of the best candidate)."""
    f0 = cal.fit
    n = f0.n
    good = _lowest_per_key([r for r in fits if r.ok])
    fitted = {r.candidate.key for r in good}
    failed = tuple(r for r in fits if not r.ok and r.candidate.key not in fitted)
    c_hat = st.overdispersion([(f0.cost, n, f0.k)] + [(r.fit.cost, n, r.fit.k) for r in good])
    rows = [Row(r.candidate, r.fit, r.starts, r.loo, st.aicc(r.fit.cost, n, r.fit.k, c_hat),
                st.lr_test(f0.cost, r.fit.cost, r.fit.k - f0.k), heldout_rms(r.loo))
            for r in good]
    rows.sort(key=lambda r: (r.aicc, r.heldout_rmse))
    chi2 = st.chi2_test(f0.cost, n, f0.k, alpha / 3)
    runs = _runs(ds, f0)
    lr = dict(p_value=min(r.lr_p for r in rows), m=len(rows)) if rows else None
    return Decision(tuple(rows), failed, chi2, runs, st.discrepancy_decision(chi2, runs, lr, alpha),
                    c_hat, st.aicc(f0.cost, n, f0.k, c_hat), alpha)


# -- stage 5: cross-validate ------------------------------------------------------------------
@dataclass
class CrossValidation:
    """Exact leave-one-experiment-out residuals: candidate key -> experiment
    -> residual vector (the nominal model under key (None, None))."""

    exact: dict = field(default_factory=dict)

    def residuals(self, key, linear):
        """Experiment -> held-out residuals of ``key``: exact where refitted,
        else ``linear`` (the linearised ones)."""
        return self.exact.get(key) or linear

    def heldout(self, key, linear):
        return heldout_rms(self.residuals(key, linear))


def _loo_tasks(problem, ds, jobs, budget):
    out = []
    s = problem.settings
    for cand, f in jobs:
        bounds = {p.name: p for p in problem.free + cand.params}
        params = tuple(bounds[nm].moved(f.values[nm]) for nm in f.names)
        for e in ds.experiments:
            out.append(LooTask(problem, cand, params, e.name, max(5, s.max_nfev // 4),
                               budget / 3))
    return out


def cross_validate(ctx: Context, problem: Problem, ds, cal: NominalFit, dec: Decision,
                   exact=True) -> CrossValidation:
    """Stage 5: refit the nominal model and the best candidate without each
    experiment (the SMALL_TOP best on small datasets, where the linearised
    shortcut is poor); not checkpointed."""
    if not exact or len(ds.experiments) < 2:
        return CrossValidation()
    n = cal.fit.n
    jobs = [(NOMINAL, cal.fit)]
    if n <= SMALL_N and len(ds.experiments) <= SMALL_EXPERIMENTS:
        jobs += [(r.candidate, r.fit) for r in dec.rows[:SMALL_TOP]]
    elif dec.discrepancy and dec.rows:
        jobs.append((dec.rows[0].candidate, dec.rows[0].fit))
    budget = _budget(cal)
    out = {}
    for r in ctx.run(refit_without, _loo_tasks(problem, ds, jobs, budget), "leave-one-out",
                     checkpoint=False):
        out.setdefault(r.candidate.key, {})[r.held] = r.residuals
    return CrossValidation(out)


# -- stage 6: rank ----------------------------------------------------------------------------
@dataclass
class Ranking:
    """Ranked rows with the exact held-out errors, the classes the data
    cannot tell apart, and the verdict: ``cause`` (index of the named row
    or None), ``after`` (the row the gain is measured with: the named one,
    or the best when a discrepancy is found but nothing named), ``weak``
    (reasons not to name)."""

    rows: tuple
    classes: list
    cause: int | None
    after: int | None
    runner: int | None
    weak: list
    untested: tuple               # Row whose extension was never tested
    heldout0: float
    heldout: tuple = ()           # each row's held-out residual vector (None: one missing)
    verdict: vd.Verdict | None = None   # the verdict's kind, reasons and held-out threshold

    @property
    def kind(self) -> str:
        """The verdict's kind (:data:`.verdict.KINDS`)."""
        if self.verdict is not None:
            return self.verdict.kind
        return "named" if self.cause is not None else "weak" if self.after is not None \
            else "no_discrepancy"

    def row(self, i):
        return None if i is None else self.rows[i]

    @property
    def named(self):
        return self.row(self.cause)

    def heldout_no_worse(self, i, j) -> bool:
        """Is row ``i``'s held-out error no worse than row ``j``'s
        (:func:`.stats.heldout_no_worse`: paired on their residual vectors
        where both are known)?"""
        vec = self.heldout or (None,) * len(self.rows)
        a, b = self.rows[i], self.rows[j]
        return st.heldout_no_worse(dict(heldout=vec[i], heldout_rmse=a.heldout_rmse),
                                   dict(heldout=vec[j], heldout_rmse=b.heldout_rmse))

    @property
    def best(self):
        return self.row(self.after)


def _ci_rel(row: Row):
    """The largest determination of the row's amplitude parameters: the
    smallest, over its parameters, of the 95 % half-width relative to the
    distance from that parameter's own neutral value (the prior: where the
    extension changes nothing), i.e. to the size of the effect it fits
    (:func:`.verdict.param_checks`; shape parameters, which have no neutral
    value, are left out). None when the row has no parameter of its own.
    A cause is poorly determined only when no amplitude parameter of a
    member is determined (:func:`.verdict.determination_reasons`): a
    Coulomb + viscous friction with b known to 0.06 % and F ~ 0 is a viscous
    friction with F undetermined, not a poorly determined cause. (Until
    issue 24 only the first parameter was looked at, so an undetermined
    Stribeck excess dF slipped through.) A law switch's restitution shift is
    neutral where the new law matches the model's damping (Hunt-Crossley:
    de = 0.034 for the breaker's 0.74 under Lankarani-Nikravesh): a truth
    with the model's restitution under the other law fits de = -0.0002 +-
    0.0002, a well determined effect of -0.034."""
    if not row.own:
        return None
    rels = [c.rel for c in vd.param_checks(row) if not c.shape]
    return min(rels) if rels else None


def _coarse(ds, f0):
    """The nominal misfit's RMS in resolution steps, over signals that have
    a resolution (the largest such ratio); None if none has one."""
    ratios = []
    sigs = np.asarray(f0.signals)
    for s, inst in ds.instrument.items():
        m = sigs == s
        if inst.resolution > 0 and np.any(m):
            rms_floor = float(np.sqrt(np.mean(f0.residuals[m] ** 2)))
            ratios.append(rms_floor * inst.floor() / inst.resolution)
    return max(ratios) if ratios else None


def _untested_reasons(untested, best):
    return [f"{r.candidate.label} was not tested: its parameter stayed at its neutral value "
            f"from every start and has no local effect there, so it cannot be ruled out"
            for r in untested if r is not best][:3]


def _acted_in(best) -> set:
    """Keys (hypothesis, location) of the members of a best pair whose
    parameters left their neutral values in it: a member that was not
    tested alone (a free parameter stood in for it) acted there, and is
    not a rival of the pair it belongs to."""
    if best is None or "+" not in best.candidate.hypothesis:
        return set()
    params = {p.name: p for p in best.candidate.params}
    return {(h, loc) for h, loc, names in best.candidate.members()
            if any(abs(best.fit.values[n] - params[n].prior)
                   > 1e-3 * (abs(params[n].scale) or 1.0) for n in names)}


def _pair_reasons(best, rows, n, experiments):
    """A pair is named only when it beats each of its single members by
    STRONG AICc units and on the held-out data: a lower held-out error, or
    the pair explains them (:func:`.verdict.explains`: the plain threshold,
    or the whitened rescue when one experiment alone determines a
    parameter) where the single does not (cam follower, Coulomb friction +
    quadratic drag: plain 6.92 against the friction alone's 4.26, but
    whitened 0.999 with directional p = 0.45, where the friction alone
    leaves the drag unexplained)."""
    if "+" not in best.candidate.hypothesis:
        return []
    out = []
    for h, loc, _ in best.candidate.members():
        single = next((r for r in rows if r.candidate.key == (h, loc)), None)
        if single is None:
            continue
        d = single.aicc - best.aicc
        held = best.heldout_rmse < single.heldout_rmse or (
            _explains(best, n, experiments) and not _explains(single, n, experiments))
        if d < st.STRONG or not held:
            out.append(f"the pair does not earn its second cause against {h} at {loc} alone "
                       f"(dAICc {d:.1f}, needs {st.STRONG:g}; held-out {best.heldout_rmse:.3g} "
                       f"against {single.heldout_rmse:.3g}, and the single "
                       + ("explains them too)" if _explains(single, n, experiments) else
                          "does not explain them either)" if not _explains(best, n, experiments)
                          else "does not explain them)"))
    return out


AT_BOUND = 1e-6      # of a parameter's range: a fitted value this close to a bound is at it


def _bound_reasons(best):
    """A cause whose own parameter ran to a bound of its declared range
    (other than its neutral value) is a law that cannot reach the data at a
    plausible size: not named (blind case: a torque setting in above a speed
    was named as power drag at the bound of its coefficient)."""
    out = []
    shapes = vd.shape_names(best.candidate)    # judged as laws: verdict.law_notes
    for p in best.candidate.params:
        v, span = best.fit.values.get(p.name), p.high - p.low
        if v is None or not math.isfinite(span) or span <= 0 or p.name in shapes:
            continue
        for bound in (p.low, p.high):
            if abs(v - bound) <= AT_BOUND * span and bound != p.prior:
                out.append(f"the cause's parameter {p.name} ran to the bound {bound:.4g} of "
                           f"its range: the law cannot follow the data at a plausible size")
    return out


def _unfitted_reasons(unfitted):
    """Screened plausible rivals left unfitted (none since issue 24: the
    family stage fits every one, :func:`.families.fit_members`; kept for a
    caller that passes its own)."""
    return [f"{u.label} was screened as a plausible rival (one-step predicted AICc "
            f"{u.predicted_aicc:.1f}) but not fitted, so it cannot be ruled out"
            for u in unfitted][:3]


def _scored(r, cv: CrossValidation):
    """The row with its held-out errors: plain, whitened and directional
    (the held-out residuals and the penalty taken once)."""
    res, pen = cv.residuals(r.candidate.key, r.loo), penalty_of(r.candidate)
    return dataclasses.replace(
        r, heldout_rmse=cv.heldout(r.candidate.key, r.loo),
        heldout_exact=r.candidate.key in cv.exact,
        heldout_white=whitened_heldout(r.fit, res, pen),
        heldout_dir=directional_heldout(r.fit, res, pen))


def rank(ds, cal: NominalFit, dec: Decision, cv: CrossValidation, unfitted=(),
         same: vd.SameCause | None = None) -> Ranking:
    """Stage 6: exact held-out errors in, classes, and the verdict
    (:mod:`.verdict`): a cause is named only when its held-out error is
    within :func:`.stats.heldout_threshold` ("not explained by the
    library" otherwise, never "weak") and no weak-evidence rule objects; it
    is never named while a rival candidate is untested, or screened as
    plausible and left unfitted (``unfitted``: :class:`.screen.Unfitted`), nor
    while its class holds another cause that explains the held-out data
    (``same``: which candidates name the same cause, :func:`.verdict.class_rivals`)."""
    rows = tuple(_scored(r, cv) for r in dec.rows)
    held0 = cv.heldout(NOMINAL.key, cal.nominal.loo)
    if dec.discrepancy:
        rows = _explaining_first(rows, cal.fit.n, len(ds.experiments))
    vectors = tuple(_heldout_vector(cv, r, ds) for r in rows)
    classes = st.equivalence_classes([dict(aicc=r.aicc, heldout_rmse=r.heldout_rmse, heldout=h)
                                      for r, h in zip(rows, vectors)]) if rows else []
    runner = _runner(rows, classes, cal.fit.n, len(ds.experiments))
    acted = _acted_in(rows[0] if rows else None)
    untested = tuple(r for r in rows if not r.starts.tested and r.candidate.key not in acted)
    best = 0 if rows else None
    threshold = vd.threshold_of(cal.fit.n, rows[0] if rows else None, len(ds.experiments))
    reasons, rivals = [], []
    if dec.discrepancy and rows:
        b = rows[0]
        reasons = [vd.Reason(code, text) for code, text in st.weak_reasons(st.Evidence(
            n=cal.fit.n, k=b.k, d_null=dec.a0 - b.aicc,
            d_runner=None if runner is None else rows[runner].aicc - b.aicc,
            heldout_nominal=held0, heldout_best=b.heldout_rmse, ci_rel=None,
            c_hat=dec.c_hat, coarse=_coarse(ds, cal.fit), heldout_threshold=threshold.rms,
            rescued=vd.rescued(b, threshold)))]
        reasons += vd.determination_reasons(b)
        same = same or vd.SameCause()
        rivals = vd.class_rivals(rows, classes[0], 0, same,
                                 lambda r: _explains(r, cal.fit.n, len(ds.experiments)))
        reasons += vd.rival_reasons(rows, rivals, 0)
        reasons += [vd.Reason("untested_rival", t) for t in _untested_reasons(untested, b)]
        reasons += [vd.Reason("unfitted_rival", t) for t in _unfitted_reasons(unfitted)]
        reasons += [vd.Reason("pair_not_earned", t) for t in _pair_reasons(b, rows, cal.fit.n, len(ds.experiments))]
        reasons += [vd.Reason("at_bound", t) for t in _bound_reasons(b)]
    verdict = vd.with_partial(vd.judge(dec.discrepancy, rows, threshold, reasons), rows,
                              rivals, same)
    cause = best if verdict.kind == "named" else None
    after = best if dec.discrepancy else None
    return Ranking(rows, classes, cause, after, runner, verdict.weak, untested, held0, vectors,
                   verdict)


def _explaining_first(rows, n, experiments):
    """The rows with the one to judge first: the best by AICc, unless it
    leaves the held-out data unexplained (:func:`.verdict.explains`) and a
    row within ``STRONG`` AICc units of it explains them; then the best
    such row (a name must explain the held-out data: cam follower, Coulomb
    friction at the follower, held-out 1.08, 0.65 units behind a pair that
    reached 5976.2 in training and 2.27 held out). A row that explains them
    by the plain threshold goes before one that explains them only by the
    whitened rescue (:func:`.verdict.rescued`, the weaker ground). A pair
    so chosen yields to one of its own members that explains them too
    within ``STRONG`` units (the simpler law: on that cam both the pair
    with a hardening spring and the friction alone are rescued, whitened
    0.997, and the pair's second cause would not be earned)."""
    out = rows
    for judged in (_explains_plainly, _explains):
        if not rows or judged(rows[0], n, experiments):
            break
        j = next((j for j, r in enumerate(rows[1:], 1) if r.aicc - rows[0].aicc <= st.STRONG
                  and judged(r, n, experiments)), None)
        if j is not None:
            out = (rows[j],) + rows[:j] + rows[j + 1:]
            break
    return _member_first(out, n, experiments)


def _member_first(rows, n, experiments):
    """The rows with a single member of the first row (a pair) first, when
    it explains the held-out data within ``STRONG`` AICc units of the pair."""
    if not rows or "+" not in rows[0].candidate.hypothesis \
            or not _explains(rows[0], n, experiments):
        return rows
    keys = {(h, loc) for h, loc, _ in rows[0].candidate.members()}
    j = next((j for j, r in enumerate(rows[1:], 1) if r.candidate.key in keys
              and r.aicc - rows[0].aicc <= st.STRONG and _explains(r, n, experiments)), None)
    return rows if j is None else (rows[j],) + rows[:j] + rows[j + 1:]


def _runner(rows, classes, n, experiments):
    """The best row outside the first class that could be named instead:
    when the first row explains the held-out data, a rival that does not is
    no rival (it fits the training data only)."""
    heads = [c[0] for c in classes[1:]]
    if not heads:
        return None
    if rows and _explains(rows[0], n, experiments):
        heads = [i for i in heads if _explains(rows[i], n, experiments)]
    return heads[0] if heads else None


def _explains_plainly(row, n, experiments) -> bool:
    """Does ``row`` explain the held-out data by the plain threshold alone?"""
    h = row.heldout_rmse
    return bool(math.isfinite(h) and h <= vd.threshold_of(n, row, experiments).rms)


def _explains(row, n, experiments) -> bool:
    """Does ``row`` explain the held-out data, against the threshold for its
    own k (:func:`.verdict.threshold_of`, :func:`.verdict.explains`)?"""
    return vd.explains(row, vd.threshold_of(n, row, experiments))


def _heldout_vector(cv, row, ds):
    """The row's held-out residuals (exact where refitted, else linearised),
    experiment by experiment in the dataset's order; None when one is missing."""
    got = cv.residuals(row.candidate.key, row.loo)
    parts = [got.get(e.name) for e in ds.experiments]
    if not got or any(p is None for p in parts):
        return None
    return np.concatenate([np.atleast_1d(p) for p in parts])


# -- stage 7: extend ---------------------------------------------------------------------
def _append_second(problem, lib, part, row, path):
    """Append the second hypothesis of a pair to a written model file: its
    statements (after the first's), its title, law and fitted values in the
    file's docstring beside the first's, and its parameters with their fit
    bounds in ``free_parameters``."""
    from pathlib import Path
    from ..library.hypotheses import file_defaults
    from ...modelfile import load_model_file
    h, loc, names = part
    hyp, prefix = lib.HYPOTHESES[h], names[0].split(".")[0]
    if getattr(hyp, "prefix", prefix) != prefix:     # the same hypothesis at two sites
        hyp = hyp.renamed(prefix)
    mf = load_model_file(problem.model_path)
    vals = file_defaults(mf, h, loc, h=hyp)
    vals.update({k: row.fit.values[k] for k in names})
    graph = lib.graph_of(problem.model_path)
    specs = {sp.name: sp for sp in hyp.params(graph, loc)}
    code = hyp.code(loc, vals).replace("hypothesis_specs =", "hypothesis_specs_2 =")
    values = "\n".join(
        f"    {n} = {float(vals[n]):.6g} [{specs[n].unit}]  ({specs[n].desc})"
        if n in specs else f"    {n} = {float(vals[n]):.6g}" for n in names)
    doc = (f"Second hypothesis {h!r} at {loc!r}: {getattr(hyp, 'title', h)}. "
           f"{getattr(hyp, 'explanation', '')}\n\nLaw: {getattr(hyp, 'law', '')}.\n"
           f"Values:\n{values}\n\n")
    bounds = ", ".join(f"{n!r}: ({specs[n].low!r}, {specs[n].high!r})"
                       for n in names if n in specs)
    text = Path(path).read_text()
    i = text.find("Written by acausal.diagnose")
    if i >= 0:
        text = text[:i] + doc + text[i:]
    text = text.replace(" extended by the hypothesis ", " extended by the hypotheses ", 1)
    first = text.find("\n", text.find(" extended by the hypotheses "))
    if first >= 0 and " and " not in text[:first]:
        text = text[:first].rstrip(".") + f" and {h!r} at {loc!r}." + text[first:]
    text += "\n" + code
    if bounds:
        text += f"free_parameters.update({{{bounds}}})\n"
    Path(path).write_text(text)


def extend(problem: Problem, ranking: Ranking, out_dir) -> str | None:
    """Stage 7: the extended model file of the named cause (or None): the
    library writes the original plus the hypothesis with its fitted values;
    the calibrated free parameters are set before the hypothesis is applied
    (a hypothesis may rebind a parameter of the component it extends)."""
    row = ranking.named
    if row is None:
        return None
    from pathlib import Path
    lib = load_library(problem.library)
    c = row.candidate
    parts = c.members()
    target = Path(out_dir) / f"{Path(problem.model_path).stem}_{c.hypothesis.replace('+', '_')}.py"
    free = problem.free_names
    h0, l0, names0 = parts[0]
    path = str(lib.write_extended_model(problem.model_path, h0, l0,
                                        {k: row.fit.values[k] for k in names0}, str(target)))
    if len(parts) > 1:
        _append_second(problem, lib, parts[1], row, path)
    if not free:
        return path
    lines = ["# calibrated free parameters (acausal diagnose)"]
    for name in free:
        comp, _, pname = name.rpartition(".")
        target_expr = f"model.find({comp!r})" if comp else "model"
        lines.append(f"{target_expr}.set({pname}={float(row.fit.values[name])!r})")
    text = Path(path).read_text()
    i = text.find("\n# hypothesis ")
    if i < 0:
        raise DiagnosisError(f"{path}: cannot place the calibrated values (no "
                             f"'# hypothesis' line written by the library)")
    Path(path).write_text(text[:i + 1] + "\n".join(lines) + "\n\n" + text[i + 1:])
    return path


def __getattr__(name):
    """``Calibration``: the old name of :class:`NominalFit` (deprecated: a
    calibration study's result is :class:`acausal.studies.calibrate.Calibration`)."""
    if name == "Calibration":
        import warnings
        warnings.warn("acausal.diagnose.stages.chain.Calibration is now NominalFit",
                      DeprecationWarning, stacklevel=2)
        return NominalFit
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
