"""Stage: hypotheses as families. Where an effect has several standard laws
(friction: Coulomb, Coulomb + viscous, Stribeck; drag: v|v|, v^n; spring
nonlinearity: cubic, bilinear, dead band; contact damping: restitution
falling linearly or as a power of the impact speed, or the Hunt-Crossley,
Lankarani-Nikravesh or Flores law), the library declares them as one
family (``FAMILIES``: cause class -> member ids, the first the head).

How many fits: the head is fitted at every site with the other candidates;
the other members only at the sites where the head is competitive (among
the ``TOP`` best tested single candidates), each seeded from the head's fit
(the free parameters at the head's values, a member's parameter of the same
name at the head's value: Coulomb's F seeds the Stribeck and the viscous
member's F, the quadratic drag's c the power law's). That bounds the extra
fits by TOP x (members - 1) and spends them where the class is plausible;
fitting every member everywhere would multiply the fit stage by up to 3.
The members are then ranked with everything else (AICc, held-out error);
:class:`FamilyIndex` tells the report and the JSON which family (cause
class) and member a row is.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import math

import numpy as np

from ..library.loader import FamilyIndex, family_index, load_library  # noqa: F401 (re-exported)
from ..problem import Candidate, Param
from .pairscreen import first_of_each, place_of
from .screen import screened
from .chain import fit_tasks
from .tasks import fit_candidate
from .verdict import explains, param_checks

TOP = 4               # members are fitted at the sites of the TOP best single candidates


def heads(dec, index: FamilyIndex, top=TOP, places=None) -> list:
    """The competitive head rows: family heads among the ``top`` best tested
    single candidates; of heads at rigidly tied sites (``places``:
    :meth:`.kinematics.Kinematics.places`) only the first, whose members
    stand for the others' (their other placements are refined from their
    fits: :func:`.kinematics.placements`)."""
    singles = [r for r in dec.rows if "+" not in r.candidate.hypothesis
               and r.starts.tested][:top]
    return first_of_each((r for r in singles if r.candidate.hypothesis in index.of
                          and index.is_head(r.candidate.hypothesis)),
                         lambda r: (r.candidate.hypothesis, place_of(places, r.candidate.location)))


def _seeded(spec, head_values, head_prefix):
    short = spec.name.partition(".")[2]
    return Param.from_spec(spec, head_values.get(f"{head_prefix}.{short}"))


def member_candidates(problem, dec, index: FamilyIndex, done=(), places=None) -> list:
    """[(Candidate, head row)] of every other member at each competitive
    head's site (not already fitted: ``done`` keys; ``places``: :func:`heads`)."""
    lib = load_library(problem.library)
    rows = heads(dec, index, places=places)
    if not rows:
        return []
    graph = lib.graph_of(problem.model_path)
    out = []
    for r in rows:
        hid, loc = r.candidate.hypothesis, r.candidate.location
        prefix = r.candidate.params[0].name.partition(".")[0] if r.candidate.params else ""
        for mid in index.members[index.family(hid)][1:]:
            h = lib.HYPOTHESES.get(mid)
            if h is None or (mid, loc) in done or loc not in h.candidates(graph):
                continue
            params = tuple(_seeded(s, r.fit.values, prefix) for s in h.params(graph, loc))
            out.append((Candidate(mid, loc, params), r))
    return out


@dataclass(frozen=True)
class Members:
    """The family stage's outcome: the members' fits and the screened
    members left unfitted (:class:`.screen.Unfitted`)."""

    fits: tuple = ()
    unfitted: tuple = ()


def fit_members(ctx, problem, cal, dec, places=None) -> Members:
    """Stage: the other members of each competitive family, fitted at the
    head's site with the free parameters starting from the head's fit, and
    the members elsewhere that a one-step score screen finds promising
    (:mod:`.screen`; only when a discrepancy is found: on data the model
    explains there is no cause class to refine). ``places``
    (:meth:`.kinematics.Kinematics.places`): rigidly tied sites are one
    place, and a member is fitted or screened at one of them only."""
    if not dec.discrepancy:
        return Members()
    index = family_index(problem.library)
    done = {r.candidate.key for r in dec.rows} | {r.candidate.key for r in dec.failed}
    pairs = member_candidates(problem, dec, index, done, places)
    tasks = fit_tasks(problem, cal, [c for c, _ in pairs])
    tasks = [dataclasses.replace(t, free=tuple(p.moved(head.fit.values[p.name])
                                               for p in t.free))
             for t, (_, head) in zip(tasks, pairs)]
    rest = other_members(problem, dec, index, done | {c.key for c, _ in pairs}, places)
    # every member the screen finds within reach is fitted (issue 24: no
    # rival is left unfitted for a budget); a screened member starts where
    # the step predicts, so one refinement suffices, and beyond the budget
    # (in simulations, from the measured speed of a simulation) a short one
    screen = screened(ctx, problem, cal, dec, rest, max_fits=None)
    tasks += screened_tasks(problem, cal, dec, screen.picks)
    fits = tuple(ctx.run(fit_candidate, tasks, "fitting family members")) if tasks else ()
    return Members(fits, screen.unfitted)


SCREEN_FIT_S = 120.0  # seconds of simulation (one core) the screened members' full fits may use


def seconds_per_simulation(dec, cal) -> float:
    """The measured time of one simulation of one experiment with the fits'
    backend: the median over the candidate fits so far (the nominal
    calibration's when there are none) of their last least-squares run's
    CPU time over their simulations. CPU time, not wall time: how many
    screened members get a full fit does not depend on what else the
    machine runs (on a host loaded twice over, wall time would halve them)."""
    rates = [r.fit.cpu_s / r.fit.n_sim for r in dec.rows
             if getattr(r.fit, "n_sim", 0) > 0 and getattr(r.fit, "cpu_s", 0) > 0]
    if rates:
        return float(np.median(rates))
    f0 = cal.fit
    return float(f0.cpu_s / f0.n_sim) if f0.n_sim and f0.cpu_s > 0 else 0.0


def full_fit_simulations(problem, cand, experiments) -> int:
    """The most simulations one refinement of ``cand`` may take: every
    experiment, ``evals_per_param`` (k + 1) evaluations (the refinement's
    cap, :mod:`.tasks`)."""
    k = len(problem.free) + len(cand.params)
    return experiments * problem.settings.evals_per_param * (k + 1)


def screened_tasks(problem, cal, dec, picks, seconds=SCREEN_FIT_S) -> list:
    """The fit tasks of the screened members ``picks`` ((candidate, free
    values), most promising first): each refined once from the best of its
    start and the step's point while their simulations fit the budget
    (``seconds`` of simulation over :func:`seconds_per_simulation`: with the
    compiled backend's 5-10 ms per breaker simulation that is 12000-24000
    simulations, a dozen full fits); the rest briefly
    (:meth:`.problem.Problem.briefly`: ``SHORT_EVALS`` (k + 1) evaluations
    on the whole record from the step's point): every plausible rival is
    fitted before the verdict."""
    if not picks:
        return []
    per = seconds_per_simulation(dec, cal)
    budget = seconds / per if per > 0 else float("inf")
    experiments = max(len(set(cal.fit.groups)), 1)
    short = problem.briefly()
    out, used = [], 0.0
    for cand, free in picks:
        cost = full_fit_simulations(problem, cand, experiments)
        full = used + cost <= budget or not out
        used += cost if full else 0.0
        task = fit_tasks(problem.one_start() if full else short, cal, [cand])[0]
        out.append(dataclasses.replace(task, seed_free=free))
    return out


def other_members(problem, dec, index: FamilyIndex, done, places=None) -> list:
    """Every non-head member at every site where its head was fitted (the
    user's choice of hypotheses and locations holds), not in ``done``
    (keys), each from its own start; at rigidly tied sites (``places``)
    only where neither it nor the same member at a site of its place is in
    ``done`` or already taken."""
    lib = load_library(problem.library)
    graph = lib.graph_of(problem.model_path)
    sites = {(index.family(r.candidate.hypothesis), r.candidate.location) for r in dec.rows
             if r.candidate.hypothesis in index.of and index.is_head(r.candidate.hypothesis)}
    found = [(mid, loc, h) for fam, ms in index.members.items() for mid in ms[1:]
             if (h := lib.HYPOTHESES.get(mid)) is not None
             for loc in h.candidates(graph) if (fam, loc) in sites]
    kept = first_of_each(found, lambda f: (f[0], place_of(places, f[1])),
                         {(h, place_of(places, loc)) for h, loc in done})
    return [Candidate(mid, loc, tuple(_seeded(s, {}, "") for s in h.params(graph, loc)))
            for mid, loc, h in kept]


PARSIMONY = 2.0       # AICc units: an extra parameter that gains less is uninformative


def _family_sites(candidate, index: FamilyIndex):
    """The sorted (family, location) of a candidate's members (one, or two
    for a pair): rows with equal keys differ only in their families' laws."""
    if candidate.hypothesis is None:
        return None
    hs, ls = candidate.hypothesis.split("+"), candidate.location.split("+")
    return tuple(sorted((index.family(h), loc) for h, loc in zip(hs, ls)))


def extra_parameters(rich, simple) -> list:
    """The parameters of ``rich`` that its simpler mate ``simple`` lacks
    (by their names within the sub-model: Stribeck's dF and v_s over
    Coulomb's F; one name per missing occurrence, all of rich's with that
    name when a pair holds it twice)."""
    from collections import Counter
    short = lambda c: [p.name.partition(".")[2] for p in c.params]  # noqa: E731
    missing = Counter(short(rich.candidate)) - Counter(short(simple.candidate))
    return [p.name for p in rich.candidate.params if missing[p.name.partition(".")[2]] > 0]


def earns_extras(rk, i, j) -> bool:
    """Does the richer row ``i`` earn its extra parameters over its simpler
    mate ``j`` (issue 24): every extra amplitude parameter's 95 % interval
    excludes its neutral value (:func:`.verdict.param_checks`; a shape
    parameter of a member whose amplitude is neutral does nothing) and the
    richer row predicts the held-out data better (the simpler one's held-out
    error is worse by the paired test of :meth:`.stages.Ranking.heldout_no_worse`)."""
    rich, simple = rk.rows[i], rk.rows[j]
    extras = set(extra_parameters(rich, simple))
    checks = [c for c in param_checks(rich) if c.name in extras and not c.shape]
    excluded = all(not (c.ci95[0] <= c.neutral <= c.ci95[1]) and all(
        math.isfinite(x) for x in c.ci95) for c in checks)
    return bool(excluded and not rk.heldout_no_worse(j, i))


def prefer_simplest(rk, index: FamilyIndex):
    """The ranking with the named (and best) row moved to the member of the
    same family at the same site with the fewest parameters the data
    support. A richer member keeps the name over a simpler one only when it
    earns its extra parameters (:func:`earns_extras`: their 95 % intervals
    exclude their neutral values AND it improves the held-out error; issue
    24: Stribeck had been named with dF = 0.09 [-0.07, 0.25] where plain
    Coulomb reached the same held-out error, 1.0025 against 1.0032) and
    comes more than PARSIMONY AICc units ahead (a law with an extra
    parameter that gains less than 2 AICc units is not supported by the
    data: Arnold, "Uninformative parameters and model selection using
    Akaike's Information Criterion", J. Wildlife Management 74 (2010)
    1175-1178; Burnham and Anderson 2002, sec. 2.6). The simpler member
    must predict the held-out data no worse, and when a cause is named, or
    the best row explains the held-out data, it must itself explain them
    (within the verdict's threshold). A pair is compared with the pairs at the same sites whose
    members are of the same families (the best pair's simpler mates are
    fitted for this: :func:`.pairsearch.simpler_tasks`). Rows and classes
    are unchanged."""
    if rk.after is None:
        return rk
    best = rk.rows[rk.after]
    sites = _family_sites(best.candidate, index)
    threshold = getattr(rk.verdict, "threshold", None)

    def supported(i):
        r = rk.rows[i]
        if not r.starts.tested:
            return False
        near = r.aicc <= best.aicc + PARSIMONY and rk.heldout_no_worse(i, rk.after)
        if r.k == best.k:
            # equal k: a member that only refines its head (stick-slip: Coulomb
            # friction that also holds a stopped body) yields to the head within
            # the margin (issue 24)
            return near and best.candidate.hypothesis in index.refines \
                and r.candidate.hypothesis not in index.refines
        if r.k > best.k:
            return False
        if threshold is not None and (rk.cause is not None or explains(best, threshold)) \
                and not explains(r, threshold):
            # the simpler member stands for the richer one only when it explains
            # the held-out data as the richer one does, named or not (a weak
            # verdict had moved the gain's row from Stribeck friction, which
            # explains them, to Coulomb friction 23 AICc units worse, which does not)
            return False
        return near or not earns_extras(rk, rk.after, i)

    mates = [i for i, r in enumerate(rk.rows)
             if i != rk.after and _family_sites(r.candidate, index) == sites and supported(i)]
    pick = min(mates, key=lambda i: (rk.rows[i].k, rk.rows[i].aicc), default=rk.after)
    if pick == rk.after:
        return rk
    v = rk.verdict
    return dataclasses.replace(rk, after=pick, cause=pick if rk.cause is not None else None,
                               verdict=v if v is None else dataclasses.replace(
                                   v, heldout=rk.rows[pick].heldout_rmse))
