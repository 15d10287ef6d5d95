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

from ..library.loader import FamilyIndex, family_index, load_library  # noqa: F401 (re-exported)
from ..problem import Candidate, Param
from .screen import screened
from .chain import fit_tasks
from .tasks import fit_candidate

TOP = 4               # members are fitted at the sites of the TOP best single candidates


def heads(dec, index: FamilyIndex, top=TOP) -> list:
    """The competitive head rows: family heads among the ``top`` best tested
    single candidates."""
    singles = [r for r in dec.rows if "+" not in r.candidate.hypothesis
               and r.starts.tested][:top]
    return [r for r in singles if r.candidate.hypothesis in index.of
            and index.is_head(r.candidate.hypothesis)]


def _seeded(spec, head_values, head_prefix):
    short = spec.name.partition(".")[2]
    return Param.from_spec(spec, head_values.get(f"{head_prefix}.{short}"))


def member_candidates(problem, dec, index: FamilyIndex, done=()) -> list:
    """[(Candidate, head row)] of every other member at each competitive
    head's site (not already fitted: ``done`` keys)."""
    lib = load_library(problem.library)
    rows = heads(dec, index)
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


def fit_members(ctx, problem, cal, dec) -> Members:
    """Stage: the other members of each competitive family, fitted at the
    head's site with the free parameters starting from the head's fit, and
    the members elsewhere that a one-step score screen finds promising
    (:mod:`.screen`; only when a discrepancy is found: on data the model
    explains there is no cause class to refine)."""
    if not dec.discrepancy:
        return Members()
    index = family_index(problem.library)
    done = {r.candidate.key for r in dec.rows} | {r.candidate.key for r in dec.failed}
    pairs = member_candidates(problem, dec, index, done)
    tasks = fit_tasks(problem, cal, [c for c, _ in pairs])
    tasks = [dataclasses.replace(t, free=tuple(p.moved(head.fit.values[p.name])
                                               for p in t.free))
             for t, (_, head) in zip(tasks, pairs)]
    rest = other_members(problem, dec, index, done | {c.key for c, _ in pairs})
    # a screened member starts where the step predicts: one refinement suffices
    screen = screened(ctx, problem, cal, dec, rest)
    tasks += [dataclasses.replace(t, seed_free=free) for t, (_, free) in zip(
        fit_tasks(problem.one_start(), cal, [c for c, _ in screen.picks]), screen.picks)]
    fits = tuple(ctx.run(fit_candidate, tasks, "fitting family members")) if tasks else ()
    return Members(fits, screen.unfitted)


def other_members(problem, dec, index: FamilyIndex, done) -> list:
    """Every non-head member at every site where its head was fitted (the
    user's choice of hypotheses and locations holds), not in ``done``
    (keys), each from its own start."""
    lib = load_library(problem.library)
    graph = lib.graph_of(problem.model_path)
    sites = {(index.family(r.candidate.hypothesis), r.candidate.location) for r in dec.rows
             if r.candidate.hypothesis in index.of and index.is_head(r.candidate.hypothesis)}
    out = []
    for fam, ms in index.members.items():
        for mid in ms[1:]:
            h = lib.HYPOTHESES.get(mid)
            if h is None:
                continue
            for loc in h.candidates(graph):
                if (mid, loc) not in done and (fam, loc) in sites:
                    out.append(Candidate(mid, loc, tuple(_seeded(s, {}, "")
                                                         for s in h.params(graph, loc))))
    return out


PARSIMONY = 2.0       # AICc units: an extra parameter that gains less is uninformative


def _family_sites(candidate, index: FamilyIndex):
    """The sorted (family, location) of a candidate's members (one, or two
    for a pair): rows with equal keys differ only in their families' laws."""
    if candidate.hypothesis is None:
        return None
    hs, ls = candidate.hypothesis.split("+"), candidate.location.split("+")
    return tuple(sorted((index.family(h), loc) for h, loc in zip(hs, ls)))


def prefer_simplest(rk, index: FamilyIndex):
    """The ranking with the named (and best) row moved to the member of the
    same family at the same site with the fewest parameters whose AICc is
    within PARSIMONY units of it: a law with an extra parameter that gains
    less than 2 AICc units is not supported by the data (Arnold, "Uninformative
    parameters and model selection using Akaike's Information Criterion",
    J. Wildlife Management 74 (2010) 1175-1178; Burnham and Anderson 2002,
    sec. 2.6). Coulomb friction is then named rather than Coulomb + viscous
    with a viscous term the data cannot see. The simpler member must also
    predict the held-out data no worse (:meth:`.stages.Ranking.heldout_no_worse`).
    A pair is compared with the pairs at the same sites whose members are of
    the same families (the best pair's simpler mates are fitted for this:
    :func:`.pairsearch.simpler_tasks`). Rows and classes are unchanged."""
    if rk.after is None:
        return rk
    best = rk.rows[rk.after]
    sites = _family_sites(best.candidate, index)
    mates = [i for i, r in enumerate(rk.rows) if _family_sites(r.candidate, index) == sites
             and r.aicc <= best.aicc + PARSIMONY and r.starts.tested
             and rk.heldout_no_worse(i, rk.after)]
    # equal k: a member that only refines its head (stick-slip: Coulomb friction that
    # also holds a stopped body) yields to the head within the margin (issue 24)
    pick = min(mates, key=lambda i: (rk.rows[i].k, rk.rows[i].candidate.hypothesis
                                     in index.refines, rk.rows[i].aicc), default=rk.after)
    if pick == rk.after:
        return rk
    return dataclasses.replace(rk, after=pick,
                               cause=pick if rk.cause is not None else None)
