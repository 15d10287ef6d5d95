"""The result of a diagnosis (:class:`Diagnosis`, picklable) and its JSON
views: :func:`summary` (``diagnosis.json``, the command's ``--json``) and
:func:`details` (``candidates.json``: every fit in full)."""
from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ...data import Dataset
from ..library.loader import FamilyIndex
from ..problem import Problem
from ..stages.chain import CrossValidation, Decision, NominalFit, Ranking
from ..stages.intervals import Intervals
from ..stages.kinematics import Kinematics
from ..stages.locate import Location
from ..stages.nextexp import NextStep
from ..stages.stats import OVERDISPERSION
from ..stages import verdict as vd
from ..stages.views import Views


@dataclass(frozen=True, kw_only=True)
class Diagnosis:
    """Everything the stages produced (:mod:`acausal.diagnose.run`), built by
    keyword. ``calibration``: the nominal fit; ``n_candidates``: candidates
    fitted in the fit stage; ``cv``: the exact leave-one-out refits;
    ``extended_model``: the file written for the named cause (None: none
    named); ``views``, ``next_experiment``, ``location``, ``intervals``,
    ``kinematics``: None when their stage did not run; ``families``: the
    library's families (None: it has none); ``timing``: the stages' wall
    times and simulation counts; ``tied``: the
    :class:`~.stages.kinematics.SiteEquivalence` of the shown row's members."""

    problem: Problem
    dataset: Dataset
    calibration: NominalFit
    n_candidates: int
    decision: Decision
    cv: CrossValidation
    ranking: Ranking
    extended_model: str | None = None
    views: Views | None = None
    next_experiment: NextStep | None = None
    timing: dict = field(default_factory=dict)
    location: Location | None = None
    intervals: Intervals | None = None
    families: FamilyIndex | None = None
    kinematics: Kinematics | None = None
    tied: tuple = ()

    @property
    def verdict(self) -> vd.Verdict:
        """The diagnosis's verdict (:data:`.stages.verdict.KINDS`): the
        ranking's, turned into "not explained by the library" when the
        located generic term beats every library candidate
        (:mod:`.stages.locate`) while none is named."""
        v = self.ranking.verdict or vd.Verdict(self.ranking.kind)
        loc = self.location
        if v.kind == "weak" and loc is not None and loc.unexplained:
            return vd.Verdict("not_explained", (vd.Reason("generic", loc.reason),) + v.reasons,
                              v.threshold, v.heldout, v.laws)
        return v


def num(x):
    x = float(x)
    return x if math.isfinite(x) else None


def clean(obj):
    """JSON-safe copy: non-finite floats -> None, numpy scalars -> Python."""
    if isinstance(obj, dict):
        return {str(k): clean(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [clean(v) for v in obj]
    if isinstance(obj, (bool, np.bool_)):
        return bool(obj)
    if isinstance(obj, (int, np.integer)):
        return int(obj)
    if isinstance(obj, (float, np.floating)):
        return num(obj)
    return obj


def _directional(d) -> dict | None:
    """A row's directional held-out test (:func:`..stages.fitting.directional_heldout`):
    its Bonferroni p, the worst experiment and each experiment's statistic
    and degrees of freedom."""
    if d is None or not d.stats:
        return None
    return dict(p=num(d.p), worst=d.worst,
                folds={h: dict(stat=num(x), dof=d.dofs[h]) for h, x in d.stats.items()})


def gain(d: Diagnosis) -> dict:
    f0, best = d.calibration.fit, d.ranking.best
    before = dict(train=f0.rms(), heldout=d.ranking.heldout0)
    after = dict(before) if best is None else dict(
        train=best.fit.rms(), heldout=d.cv.heldout(best.candidate.key, best.loo))
    return dict(before={k: num(v) for k, v in before.items()},
                after={k: num(v) for k, v in after.items()})


def parameters(row) -> dict:
    out = {}
    for name in row.fit.names:
        lo, hi = row.fit.ci95.get(name, (float("nan"),) * 2)
        out[name] = dict(value=row.fit.values[name], ci95=[num(lo), num(hi)])
    return out


def _equivalent(d: Diagnosis):
    rk = d.ranking
    if not d.decision.discrepancy or not rk.classes:
        return []
    return [dict(cause=rk.rows[i].candidate.hypothesis, location=rk.rows[i].candidate.location)
            for i in rk.classes[0] if rk.cause is None or i != rk.cause]


def family_of(d: Diagnosis, hid):
    """The cause class (family) of hypothesis ``hid``: its own id without families."""
    return d.families.family(hid) if d.families is not None else hid


def _causes(d, row):
    """One entry per cause of a named single or pair: its family (cause
    class), member (the law), own parameters, and the kinematically
    equivalent sites (:func:`equivalent_sites`) with why this site is shown."""
    every = parameters(row)
    out = []
    for h, loc, names in row.candidate.members():
        tied = next((t for t in d.tied if (t.cause, t.location) == (h, loc)), None)
        out.append(dict(cause=h, location=loc, family=family_of(d, h), member=h,
                        parameters={k: every[k] for k in names},
                        equivalent_sites=equivalent_sites(tied),
                        site_reason=None if tied is None else tied.reason))
    return out


def equivalent_sites(tied) -> list:
    """The sites kinematically tied to a cause's (``kinematics.SiteEquivalence``
    or None): each with its rate ratio (its rate per the cause's site's),
    the ratio's spread, the cause's parameters converted through the ratio
    (``in_range``: inside the range the hypothesis declares there), and the
    same hypothesis's own fit there (null when not fitted) with its
    AICc against the cause's and whether the data tell the two apart."""
    if tied is None:
        return []
    return [dict(location=s.location, ratio=num(s.ratio), spread=num(s.spread),
                 parameters={k: None if v is None else num(v) for k, v in s.values},
                 in_range=bool(s.in_range),
                 fitted=None if not s.fitted else dict(
                     parameters={k: num(v) for k, v in s.fitted}, daicc=num(s.daicc),
                     same_class=bool(s.in_class)))
            for s in tied.sites]


def cause_class(d: Diagnosis):
    """The best candidate's family at its site, every member fitted there
    (best first) and the misfit the best member leaves (RMS in floors,
    sqrt(S/(n-k))): named as a class even when no cause is named. None with
    no discrepancy or when the best candidate is a pair."""
    rk, best = d.ranking, d.ranking.best
    if best is None or "+" in best.candidate.hypothesis:
        return None
    hid, loc = best.candidate.key
    fam = family_of(d, hid)
    rows = [r for r in rk.rows if r.candidate.location == loc
            and "+" not in r.candidate.hypothesis and family_of(d, r.candidate.hypothesis) == fam]
    left = math.sqrt(best.S / max(best.fit.n - best.k, 1))
    return dict(family=fam, location=loc, member=hid, named=rk.named is not None,
                leftover_floors=num(left), within_floor=bool(left ** 2 <= OVERDISPERSION),
                members=[dict(member=r.candidate.hypothesis, aicc=num(r.aicc),
                              daicc=num(r.aicc - best.aicc), S=num(r.S),
                              heldout_rmse=num(r.heldout_rmse),
                              values={k: r.fit.values[k] for k in r.own}) for r in rows])


def summary(d: Diagnosis) -> dict:
    """The JSON summary (docs/diagnosis.md lists the keys)."""
    rk = d.ranking
    named = rk.named
    causes = [] if named is None else _causes(d, named)
    return dict(
        notes=list(getattr(d.dataset, "notes", [])),
        discrepancy=d.decision.discrepancy,
        cause=None if named is None else named.candidate.hypothesis,
        location=None if named is None else named.candidate.location,
        equivalent_causes=_equivalent(d),
        parameters={} if named is None else parameters(named),
        ranking=[dict(cause=r.candidate.hypothesis, location=r.candidate.location,
                      aicc=num(r.aicc), heldout_rmse=num(r.heldout_rmse),
                      heldout_whitened=num(getattr(r, "heldout_white", float("nan"))),
                      heldout_directional=_directional(getattr(r, "heldout_dir", None)))
                 for r in rk.rows],
        gain=gain(d),
        extended_model=d.extended_model,
        causes=causes,
        unexplained=unexplained(d),
        next_experiment=None if d.next_experiment is None else clean(
            d.next_experiment.to_dict()),
        profile_ci95={} if d.intervals is None else clean(d.intervals.to_dict()),
        cause_class=cause_class(d),
        failed=failed(d),
        verdict=verdict(d),
    )


def candidates(d: Diagnosis, singles=3) -> list:
    """The best candidates of each kind with their held-out errors (floors):
    the ``singles`` best single causes, the best pair, the best located
    generic term; each ``{kind, cause, location, aicc, heldout_rmse}``."""
    rk = d.ranking
    out = [dict(kind="single", cause=r.candidate.hypothesis, location=r.candidate.location,
                aicc=num(r.aicc), heldout_rmse=num(r.heldout_rmse))
           for r in [r for r in rk.rows if "+" not in r.candidate.hypothesis][:singles]]
    pair = next((r for r in rk.rows if "+" in r.candidate.hypothesis), None)
    if pair is not None:
        out.append(dict(kind="pair", cause=pair.candidate.hypothesis,
                        location=pair.candidate.location, aicc=num(pair.aicc),
                        heldout_rmse=num(pair.heldout_rmse)))
    if d.location is not None and d.location.terms:
        t = d.location.terms[0]
        out.append(dict(kind="generic", cause="generic_force", location=t.node,
                        aicc=num(t.aicc), heldout_rmse=num(t.heldout_rmse)))
    return out


def verdict(d: Diagnosis) -> dict:
    """The verdict (:attr:`Diagnosis.verdict`) as JSON: ``kind``
    (no_discrepancy, named, weak, not_explained), ``reasons`` (``{code,
    text}``: the weak rules that object, or why the held-out data are not
    explained), ``heldout_threshold`` (the most a held-out RMS error reaches
    on noise alone, with its derivation), ``heldout_rmse`` (of the best
    candidate), ``candidates`` (:func:`candidates`; with a discrepancy),
    ``laws`` (shape parameters away from the standard laws or at a bound:
    a mixture of laws?), ``undetermined`` (the named cause's parameters
    whose intervals reach their neutral values, flagged) and ``partial``
    (a weak verdict whose only objection is a tie with other causes: the
    causes every tied candidate holds, with their values and sites, and the
    undecided rest, :class:`.stages.verdict.Partial`; else null)."""
    v = d.verdict
    named = d.ranking.named
    return clean(dict(
        kind=v.kind, reasons=[dict(code=r.code, text=r.text) for r in v.reasons],
        heldout_threshold=None if v.threshold is None else v.threshold.to_dict(),
        heldout_rmse=v.heldout,
        candidates=candidates(d) if d.decision.discrepancy else [],
        laws=[x.to_dict() for x in v.laws],
        caveats=[dict(code=r.code, text=r.text) for r in getattr(v, "caveats", ())],
        partial=None if getattr(v, "partial", None) is None else v.partial.to_dict(),
        undetermined=[] if named is None else [c.to_dict() for c in vd.undetermined(named)]))


def failed(d: Diagnosis) -> list:
    """The candidates that could not be built or fitted, each with its
    reason (a candidate the library offers but cannot compile at a site is
    not silently dropped)."""
    return [dict(cause=r.candidate.hypothesis, location=r.candidate.location,
                 error=r.error or (r.fit.message if r.fit is not None else ""))
            for r in d.decision.failed]


def unexplained(d: Diagnosis) -> dict:
    """``value``: the discrepancy is not explained by the library (the
    verdict's kind); ``node``: with ``value``, the node of the located
    generic term's best fit (lowest held-out error over every node, tied
    sites or not: :func:`.stages.locate.node_ranking`), else the node of a
    term that beats the library (None); ``heldout_rmse``: that term's
    held-out error (the best library candidate's when no term was fitted);
    ``beats_library``: the term beats the best library candidate
    (:mod:`.stages.locate`); ``nodes``: every node's term, best first
    (``{node, heldout_rmse, fitted, aicc, resolution}``); ``tied_nodes``:
    those the held-out data cannot tell from the best; ``beside``: the
    term fitted beside a single cause (:func:`beside_of`); ``why``: with
    ``value`` and no node, why no node could be judged (one line);
    ``nearest`` and ``nearest_heldout_rmse``: the best library candidate."""
    from ..stages.locate import node_ranking, no_node_reason
    loc, best = d.location, d.ranking.best
    value = d.verdict.kind == "not_explained"
    ranking = node_ranking(loc) if loc is not None else []
    out = dict(value=value, node=None, heldout_rmse=None, beside=None, beats_library=bool(
        loc is not None and loc.unexplained), nodes=ranking, tied_nodes=[], why=None,
        nearest=(best.candidate.label if best is not None and (value or ranking) else None),
        nearest_heldout_rmse=num(best.heldout_rmse) if best is not None else None)
    if not value:
        if loc is not None and loc.unexplained and ranking:
            out.update(node=loc.node, heldout_rmse=ranking[0]["heldout_rmse"])
        return clean(out)
    if ranking:
        out.update(node=ranking[0]["node"], heldout_rmse=ranking[0]["heldout_rmse"],
                   tied_nodes=list(loc.tied_nodes), beside=beside_of(loc))
    else:
        out.update(heldout_rmse=num(best.heldout_rmse) if best is not None else None,
                   why=no_node_reason(loc))
    return clean(out)


def beside_of(loc) -> dict | None:
    """The located term fitted beside a single cause (:mod:`.stages.locate`):
    ``{cause, location, values, node, heldout_rmse, aicc, alone_heldout_rmse,
    alone_aicc, second_force}`` (``values``: the cause's parameters refitted
    with the term; ``alone_*``: the cause fitted alone; ``second_force``: the
    term beside it beats it alone), or None when it was not fitted."""
    t, c = loc.beside, loc.beside_cause
    if t is None or not c:
        return None
    return dict(cause=c["cause"], location=c["location"], values=dict(c["values"]),
                node=t.node, heldout_rmse=num(t.heldout_rmse), aicc=num(t.aicc),
                alone_heldout_rmse=num(c["alone_heldout"]), alone_aicc=num(c["alone_aicc"]),
                second_force=bool(loc.second_force))


def _one(label, f, extra):
    return dict(label, k=f.k, S=num(f.cost), train_rmse=num(f.rms()), values=f.values,
                ci95={k: [num(a), num(b)] for k, (a, b) in f.ci95.items()},
                n_sim=f.n_sim, wall_s=f.wall_s, message=f.message, **extra)


def _starts(s):
    return dict(scored=s.scored, refined=s.refined, converged=s.converged, tested=s.tested)


def details(d: Diagnosis) -> dict:
    """Every fit in full (for scripts and tests): the nominal model, then the
    candidates in rank order, and the decision."""
    cal, dec, rk = d.calibration, d.decision, d.ranking
    out = dict(
        nominal=_one(dict(cause=None, location=None), cal.fit,
                     dict(aicc=num(dec.a0), starts=_starts(cal.nominal.starts))),
        free_drift=[dict(name=x.name, prior=x.prior, calibrated=x.calibrated,
                         relative=x.relative, far=x.far) for x in cal.drift],
        candidates=[_one(dict(cause=r.candidate.hypothesis, location=r.candidate.location,
                              family="+".join(family_of(d, h) for h, _, _ in
                                              r.candidate.members())),
                         r.fit, dict(aicc=num(r.aicc), heldout_rmse=num(r.heldout_rmse),
                                     lr_p=num(r.lr_p), starts=_starts(r.starts)))
                    for r in rk.rows],
        failed=failed(d),
        located=[dict(node=t.node, members=list(t.members), S=num(t.S), aicc=num(t.aicc),
                      heldout_rmse=num(t.heldout_rmse), values=t.values,
                      ranges=list(t.ranges), resolution=list(t.resolution),
                      smoothing=list(t.smooth), fitted=t.fitted)
                 for t in (d.location.terms if d.location is not None else ())],
        located_choices=(d.location.details or {}) if d.location is not None else {},
        decision=dec.decision, overdispersion=dec.c_hat, weak_evidence=rk.weak,
        timing=d.timing)
    return clean(out)
