"""The naming rule and the verdict (issue 24).

A diagnosis ends in one of four verdicts (:data:`KINDS`):

* ``no_discrepancy``: the calibrated model explains the data (the
  discrepancy test, :mod:`.stats`);
* ``named``: a cause (or a pair) is named. It must explain the held-out
  data: its leave-one-experiment-out RMS error (in instrument floors) is
  within :func:`.stats.heldout_threshold`, the largest held-out error that
  noise alone reaches on data the model explains (one-sided level
  ``ALPHA``); and no rule of the "weak" kind objects;
* ``not_explained``: the best candidate leaves the held-out data beyond
  that threshold: nothing in the library explains them. The verdict lists
  the best candidates (single, pair, located generic term) with their
  held-out errors, and a family member whose shape parameter stands in for
  a mixture of laws (a drag exponent far from the standard laws' 1 and 2)
  is said to be one. This is never called "weak";
* ``weak``: the best candidate explains the held-out data, but the data
  cannot decide: the rivals are tied, the effect is not strong, its
  parameters are not determined, a rival is untested, ... Each reason comes
  with its :class:`Reason` code and its numbers.

Parameters are judged one by one (:func:`param_checks`): each amplitude
parameter against its own neutral value (where the extension changes
nothing); shape parameters (a drag exponent, a Stribeck speed, a knee
deflection: the extension is neutral through its amplitude whatever their
value) have no neutral value and are judged against the physical range
and the standard laws instead (:func:`law_notes`).
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

from . import stats as st

KINDS = ("no_discrepancy", "named", "weak", "not_explained")

# Standard values of a family member's shape parameter (the laws it joins):
# power drag's exponent is viscous at n = 1 and quadratic at n = 2. A
# hypothesis may declare its own as ``standard_shapes = {short name: values}``;
# this table is the fallback for the library's members that do not (yet).
STANDARD_SHAPES = {"power_drag": {"n": (1.0, 2.0)}}


@dataclass(frozen=True)
class Reason:
    """Why a cause is not named: ``code`` (one of :data:`WEAK_CODES` for a
    weak verdict, ``heldout`` for "not explained") and the sentence with its
    numbers."""

    code: str
    text: str


# what each weak reason means (the report and the JSON say which applies)
WEAK_CODES = {
    "few_data": "too few data per fitted parameter",
    "not_strong": "the effect is not strong (AICc gain over no extension)",
    "rival_tied": "a rival that is another cause is tied (in the best candidate's class, or "
                  "outside it within a few AICc units)",
    "no_heldout_gain": "the held-out error does not fall enough",
    "poorly_determined": "no parameter of the cause is determined",
    "leaves_misfit": "the best fit leaves misfit on the training data",
    "coarse": "the data are coarse against the instrument's resolution",
    "untested_rival": "a rival could not be tested",
    "unfitted_rival": "a plausible rival was not fitted",
    "pair_not_earned": "a pair does not earn its second cause",
    "at_bound": "a parameter ran to the bound of its range",
    "law_out_of_range": "a shape parameter left its physical range",
    "nothing_fitted": "no candidate could be fitted",
}


@dataclass(frozen=True)
class ParamCheck:
    """One parameter of a cause: its value and 95 % interval, its neutral
    value (None for a shape parameter), ``rel`` the interval's half-width
    over the distance from the neutral value, ``determined`` rel <
    :data:`.stats.CI_REL` (a shape parameter: a finite interval)."""

    name: str
    value: float
    ci95: tuple
    neutral: float | None
    rel: float
    determined: bool

    @property
    def shape(self):
        return self.neutral is None

    def to_dict(self):
        lo, hi = self.ci95
        return dict(name=self.name, value=_num(self.value), ci95=[_num(lo), _num(hi)],
                    neutral=None if self.neutral is None else _num(self.neutral),
                    relative_halfwidth=_num(self.rel), determined=bool(self.determined))

    def sentence(self):
        lo, hi = self.ci95
        return (f"{self.name} = {self.value:.4g} [{lo:.4g}, {hi:.4g}] is undetermined: its "
                f"95 % half-width is {self.rel:.0%} of its distance from its neutral value "
                f"{self.neutral:.4g} (needs below {st.CI_REL:.0%})")


@dataclass(frozen=True)
class LawNote:
    """A family member's shape parameter that left its physical range (ran
    to a bound) or lies away from every standard law (``standard``, whose
    95 % interval excludes them all): the member may stand in for a mixture
    of laws."""

    cause: str
    location: str
    parameter: str
    value: float
    ci95: tuple
    standard: tuple
    at_bound: bool
    text: str

    def to_dict(self):
        return dict(cause=self.cause, location=self.location, parameter=self.parameter,
                    value=_num(self.value), ci95=[_num(x) for x in self.ci95],
                    standard=list(self.standard), at_bound=self.at_bound, text=self.text)


@dataclass(frozen=True)
class Verdict:
    """The verdict of the ranking (:data:`KINDS`), the reasons behind it,
    the held-out threshold it was judged with, the held-out error of the
    row judged (the best), and the law notes of that row."""

    kind: str
    reasons: tuple = ()                       # Reason
    threshold: st.HeldoutThreshold | None = None
    heldout: float | None = None
    laws: tuple = ()                          # LawNote
    caveats: tuple = ()                       # Reason: what a name rests on (rescue_note)
    partial: Partial | None = None            # weak by a tie alone: what every tied row holds

    @property
    def weak(self) -> list:
        """The weak-evidence sentences (empty unless ``kind`` is weak)."""
        return [r.text for r in self.reasons] if self.kind == "weak" else []


def _num(x):
    x = float(x)
    return x if math.isfinite(x) else None


# -- parameters ---------------------------------------------------------------------------
def shape_names(candidate) -> set:
    """Names of the candidate's shape parameters: within one member (one
    hypothesis of a pair), a parameter whose neutral start is not zero
    beside another parameter (the extension is neutral through that one).
    A single parameter is always an amplitude (a law switch's restitution
    shift: neutral where the new law matches the model's damping)."""
    params = {p.name: p for p in candidate.params}
    out = set()
    for _, _, names in candidate.members():
        if len(names) < 2:
            continue
        out |= {n for n in names if n in params and params[n].prior != 0.0}
    return out


def param_checks(row) -> list:
    """:class:`ParamCheck` of each of the row's own parameters."""
    shapes = shape_names(row.candidate)
    out = []
    for p in row.candidate.params:
        v = row.fit.values.get(p.name)
        if v is None:
            continue
        lo, hi = row.fit.ci95.get(p.name, (float("nan"), float("nan")))
        finite = math.isfinite(lo) and math.isfinite(hi)
        if p.name in shapes:
            out.append(ParamCheck(p.name, v, (lo, hi), None, float("nan"), finite))
            continue
        rel = float((hi - lo) / 2 / abs(v - p.prior)) if finite and v != p.prior else math.inf
        out.append(ParamCheck(p.name, v, (lo, hi), p.prior, rel, rel < st.CI_REL))
    return out


def undetermined(row) -> list:
    """The amplitude parameters of ``row`` left undetermined (their 95 %
    interval reaches within twice its half-width of the neutral value)."""
    return [c for c in param_checks(row) if not c.shape and not c.determined]


def determination_reasons(row) -> list:
    """A cause whose member has no determined amplitude parameter is
    poorly determined (each parameter judged against its own neutral
    value: a Coulomb + viscous friction with b known to 0.06 % and F ~ 0 is
    determined, through b; its F is flagged, not the cause)."""
    checks = {c.name: c for c in param_checks(row)}
    out = []
    for h, loc, names in row.candidate.members():
        amp = [checks[n] for n in names if n in checks and not checks[n].shape]
        if amp and not any(c.determined for c in amp):
            worst = "; ".join(f"{c.name} {c.rel:.0%}" for c in amp)
            out.append(Reason("poorly_determined", (
                f"{h} at {loc} is poorly determined: no parameter's 95 % half-width is below "
                f"{st.CI_REL:.0%} of its distance from its neutral value ({worst})")))
    return out


def _hypotheses(lib=None) -> dict:
    """The library's hypotheses by id ({} for a stub library without the table)."""
    from ..library.loader import load_library
    try:
        return load_library(lib).HYPOTHESES
    except Exception:  # noqa: BLE001 - a stub library without the table: nothing declared
        return {}


def same_laws(lib=None) -> dict:
    """hypothesis id -> its ``same_law`` table (:class:`SameCause`): the laws
    a family member becomes at a standard value of a shape parameter, as
    the library's hypotheses declare them (none for a library without)."""
    return {hid: dict(h.same_law) for hid, h in _hypotheses(lib).items()
            if getattr(h, "same_law", None)}


def _standard(hid, short, lib=None):
    hyp = _hypotheses(lib).get(hid)
    declared = getattr(hyp, "standard_shapes", None) if hyp is not None else None
    table = declared if declared is not None else STANDARD_SHAPES.get(hid, {})
    return tuple(table.get(short, ()))


def law_notes(row, lib=None) -> list:
    """:class:`LawNote` of each shape parameter of ``row`` that ran to a
    bound of its range (the law left its physical range) or whose 95 %
    interval excludes every standard value declared for it (a power drag
    exponent of 2.61 +- 0.01: neither viscous nor quadratic)."""
    if row is None:
        return []
    shapes = shape_names(row.candidate)
    params = {p.name: p for p in row.candidate.params}
    out = []
    for h, loc, names in row.candidate.members():
        for n in names:
            if n not in shapes:
                continue
            p, v = params[n], row.fit.values.get(n)
            if v is None:
                continue
            lo, hi = row.fit.ci95.get(n, (float("nan"), float("nan")))
            span = p.high - p.low
            at = (math.isfinite(span) and span > 0
                  and min(abs(v - p.low), abs(v - p.high)) <= AT_BOUND * span)
            std = _standard(h, n.partition(".")[2], lib)
            away = bool(std) and math.isfinite(lo) and math.isfinite(hi) and not any(
                lo <= s <= hi for s in std)
            if not (at or away):
                continue
            laws = " and ".join(f"{s:g}" for s in std)
            text = (f"{h} at {loc}: its shape parameter {n} = {v:.4g} ran to the bound of "
                    f"its physical range [{p.low:.4g}, {p.high:.4g}]" if at else
                    f"{h} at {loc}: its shape parameter {n} = {v:.4g} [{lo:.4g}, {hi:.4g}] "
                    f"lies away from the standard laws ({n.partition('.')[2]} = {laws})")
            out.append(LawNote(h, loc, n, v, (lo, hi), std, bool(at),
                               text + ": a mixture of laws?"))
    return out


AT_BOUND = 1e-6      # of a parameter's range: a fitted value this close to a bound is at it


# -- rivals in the best candidate's class ---------------------------------------------------
@dataclass(frozen=True)
class SameCause:
    """Which candidates name the same cause: the same cause class (family:
    Coulomb, Stribeck and stick-slip friction are one) at the same site or
    at a site kinematically tied to it (``kinematics``: a
    :class:`.kinematics.Kinematics`, or None). ``families`` maps a
    hypothesis id to its family (a :class:`.loader.FamilyIndex`, or None:
    every hypothesis is its own)."""

    families: object = None
    kinematics: object = None
    same_law: dict = dataclasses.field(default_factory=dict)
    # hypothesis id -> {shape parameter's short name: {standard value: the
    # hypothesis whose law it is there}} (power drag at n = 1 is viscous
    # damping): a member whose shape parameter's 95 % interval holds such a
    # value names that law's cause too

    def _family(self, hid):
        return self.families.family(hid) if self.families is not None else hid

    def causes(self, row, h, loc, names) -> set:
        """The (family, site) pairs member ``h`` at ``loc`` of ``row`` names:
        its family, and the family of each law its shape parameters' 95 %
        intervals reach (``same_law``), at ``loc`` and its tied sites."""
        fams = {self._family(h)}
        for short, laws in self.same_law.get(h, {}).items():
            name = next((n for n in names if n.partition(".")[2] == short), None)
            lo, hi = row.fit.ci95.get(name, (math.nan, math.nan)) if name else (math.nan,) * 2
            fams |= {self._family(other) for value, other in laws.items()
                     if math.isfinite(lo) and math.isfinite(hi) and lo <= value <= hi}
        tied = self.kinematics.tied(loc) if self.kinematics is not None else []
        return {(f, s) for f in fams for s in [loc] + [o for o, _, _ in tied]}

    def covers(self, a, b) -> bool:
        """Does row ``a`` name every cause of row ``b`` (a pair holding
        ``b``'s cause, or ``b``'s cause at a tied site, by another member of
        its family, or by a law that becomes it at a standard shape)?"""
        mine = [self.causes(a, h, loc, ns) for h, loc, ns in a.candidate.members()]
        return all(any(self.causes(b, h, loc, ns) & s for s in mine)
                   for h, loc, ns in b.candidate.members())


def class_rivals(rows, cls, best, same: SameCause, explaining) -> list:
    """Indices of the rows in the best row's class (``cls``: the data
    cannot tell them apart by AICc and held-out error) that name another
    cause: neither holds the other's causes (:meth:`SameCause.covers`; a
    pair that adds a cause to the best, or a single member of a best pair,
    is judged by the pair rule instead), and the row explains the held-out
    data itself (``explaining(row)``; a rival that fits the training data
    only is no rival). Until issue 24's cam friction + drag at 30 floors
    such a class was listed as "the data cannot tell it from" beside a
    plain name: Stribeck friction at the cam was named while the same law at
    the follower (1.3 AICc units better in training, held-out 5.8 against
    5.0 floors, both explaining them beyond their parameters' spread) was in
    its class; the truth was friction + drag at the cam."""
    b = rows[best]
    return [i for i in cls if i != best and explaining(rows[i])
            and not same.covers(rows[i], b) and not same.covers(b, rows[i])]


def rival_reasons(rows, rivals, best, shown=3) -> list:
    """The ``rival_tied`` reasons of :func:`class_rivals`, with the numbers."""
    b = rows[best]
    out = []
    for i in rivals[:shown]:
        r = rows[i]
        out.append(Reason("rival_tied", (
            f"the data cannot tell it from {r.candidate.label}, another cause: AICc "
            f"{r.aicc - b.aicc:+.1f} units from it, held-out error {r.heldout_rmse:.3g} against "
            f"{b.heldout_rmse:.3g} floors, and it explains the held-out data too")))
    if len(rivals) > shown:
        out.append(Reason("rival_tied", f"and {len(rivals) - shown} more such rival(s) in its class"))
    return out


# -- what every tied candidate shares -------------------------------------------------------
@dataclass(frozen=True)
class SharedCause:
    """A cause that the best candidate and every rival tied with it hold
    (:func:`partial`): its ``family`` (cause class), the best candidate's
    law (``member``) and site (``location``) with its fitted parameters
    (``values``), ``sites``: every site a tied candidate puts it at (one
    site, or kinematically tied ones: the site is decided too), and
    ``spread``: parameter -> (lowest, highest) value over the tied
    candidates that hold the same law at the same site."""

    family: str
    member: str
    location: str
    sites: tuple
    values: dict
    spread: dict

    @property
    def site_decided(self) -> bool:
        return len(self.sites) == 1

    def to_dict(self):
        return dict(family=self.family, cause=self.member, location=self.location,
                    sites=list(self.sites), site_decided=self.site_decided,
                    values={k: _num(v) for k, v in self.values.items()},
                    spread={k: [_num(a), _num(b)] for k, (a, b) in self.spread.items()})

    def sentence(self):
        vals = ", ".join(
            f"{k} = {v:.4g}" + (f" ({self.spread[k][0]:.4g} to {self.spread[k][1]:.4g} "
                                f"over the tied candidates)" if k in self.spread
                                and self.spread[k][0] != self.spread[k][1] else "")
            for k, v in self.values.items())
        where = (f"at {self.location}" if self.site_decided else
                 f"at {' or '.join(self.sites)} (its site is undecided)")
        return f"a {self.family}-family law (the best's: {self.member}) {where}: {vals}"


@dataclass(frozen=True)
class Partial:
    """What a weak verdict can still name when its only objection is a tie
    with rivals that name other causes (``rival_tied``): the causes every
    tied candidate holds (``shared``: :class:`SharedCause`), and the rest,
    which the data leave undecided (``undecided``: each tied candidate's
    other causes, "law at site"); ``tied``: the candidates' labels, best
    first. The next experiment (:mod:`.nextexp`) splits them."""

    shared: tuple
    undecided: tuple
    tied: tuple

    def to_dict(self):
        return dict(shared=[c.to_dict() for c in self.shared], undecided=list(self.undecided),
                    tied=list(self.tied))

    def sentence(self):
        head = "; ".join(c.sentence() for c in self.shared)
        rest = (f"; undecided between the tied candidates: {', '.join(self.undecided)}"
                if self.undecided else "")
        return (f"every one of the {len(self.tied)} tied candidates holds {head}{rest}")


NOTHING_ELSE = "no other cause"   # a tied row that holds the shared causes alone


def partial(rows, tied, same: SameCause):
    """The :class:`Partial` name of the tied rows (indices into ``rows``,
    the best first: the best and its :func:`class_rivals`), or None when
    they share no cause. A member of the best row is shared when every tied
    row has a member of its family (:meth:`SameCause.causes`: a law that
    becomes the family's at a standard shape counts); its site is decided
    when every one puts it at the best's site or a site tied to it (cam
    friction + drag at 30 floors: Coulomb friction at the cam in every
    tied pair, the drag at the cam or at the follower)."""
    if len(tied) < 2:
        return None
    best, others = rows[tied[0]], [rows[i] for i in tied[1:]]
    shared, families = [], set()
    for h, loc, names in best.candidate.members():
        fam = same._family(h)
        home = {s for f, s in same.causes(best, h, loc, names) if f == fam}
        sites, at_home = [loc], True
        for r in others:
            hits = [(mh, ml, mn) for mh, ml, mn in r.candidate.members()
                    if any(f == fam for f, _ in same.causes(r, mh, ml, mn))]
            if not hits:
                break
            sites += [ml for _, ml, _ in hits]
            at_home &= any(ml in home for _, ml, _ in hits)
        else:
            values = {n: best.fit.values[n] for n in names if n in best.fit.values}
            spread = {}
            for n in values:
                got = [r.fit.values[n] for r in [best] + others if n in r.fit.values
                       and any(mh == h and ml == loc for mh, ml, _ in r.candidate.members())]
                spread[n] = (min(got), max(got))
            shared.append(SharedCause(fam, h, loc, (loc,) if at_home else
                                      tuple(dict.fromkeys(sites)), values, spread))
            families.add(fam)
    if not shared:
        return None
    undecided = []
    for r in [best] + others:
        rest = [f"{mh} at {ml}" for mh, ml, mn in r.candidate.members()
                if not any(f in families for f, _ in same.causes(r, mh, ml, mn))]
        undecided += rest or [NOTHING_ELSE]
    if undecided == [NOTHING_ELSE] * len(undecided):
        undecided = []
    return Partial(tuple(shared), tuple(dict.fromkeys(undecided)),
                   tuple(r.candidate.label for r in [best] + others))


# -- the verdict ----------------------------------------------------------------------------
def threshold_of(n, row, experiments) -> st.HeldoutThreshold:
    """The held-out threshold for ``row`` (its k fitted parameters) on ``n``
    values in ``experiments`` experiments."""
    return st.heldout_threshold(n, row.k if row is not None else 0, experiments)


DIRECTIONAL_LEVEL = st.HELDOUT_LEVEL   # the directional part's level (Bonferroni p)


def explains(row, threshold) -> bool:
    """Does ``row`` explain the held-out data? Its plain held-out RMS is
    within the threshold, or the excess is what its parameters' own
    uncertainty without one experiment allows (:func:`rescued`)."""
    h = row.heldout_rmse
    return bool(math.isfinite(h) and h <= threshold.rms) or rescued(row, threshold)


def rescued(row, threshold) -> bool:
    """The plain held-out error exceeds the threshold, which assumes every
    experiment carries an equal share of the information, but both parts
    of the whitened error pass: the whole (:func:`.fitting.whitened_heldout`,
    within the threshold) and its part within the parameters' directions
    (:func:`.fitting.directional_heldout`, p >= ``DIRECTIONAL_LEVEL``). Then
    one experiment alone determines a parameter (the fastest run a drag,
    the only run that does not stop a bearing's viscous loss), and without
    it the others predict it only to within that parameter's spread: on
    the independent cam and gear cases, the right friction + drag pairs
    (plain 4.41 and 1.30 floors, whitened 1.0002 and 0.9993). The
    whitened whole alone also passed a wrong law, a bilinear spring
    absorbing the cam's out-of-library detent (plain 1.76, whitened
    1.008): its 60 floors^2 within the three parameter directions of the
    first run (p = 1.4e-12) are what the directional part sees
    (docs/independent_cases_2026-11-27.md)."""
    h = row.heldout_rmse
    if not math.isfinite(h) or h <= threshold.rms:
        return False
    white = getattr(row, "heldout_white", float("nan"))
    d = getattr(row, "heldout_dir", None)
    p = d.p if d is not None else float("nan")
    return bool(math.isfinite(white) and white <= threshold.rms
                and math.isfinite(p) and p >= DIRECTIONAL_LEVEL)


def rescue_note(row, threshold) -> Reason:
    """What a name judged by :func:`rescued` rests on, with its numbers."""
    d = row.heldout_dir
    return Reason("heldout_one_experiment", (
        f"its plain held-out error, {row.heldout_rmse:.4g} floors, exceeds {threshold.rms:.4g} "
        f"(the threshold assumes every experiment carries an equal share): without one "
        f"experiment the others determine a parameter only loosely. Beyond that spread the "
        f"error is {row.heldout_white:.4f} floors (whitened), and within the parameters' "
        f"directions p = {d.p:.3g} (worst experiment {d.worst}); an experiment that "
        f"determines the same parameter again would confirm the law"))


def unexplained_reason(row, threshold, notes=()) -> Reason:
    white = getattr(row, "heldout_white", float("nan"))
    text = (f"the best candidate, {row.candidate.label}, leaves a held-out error of "
            f"{row.heldout_rmse:.4g} floors, above {threshold.rms:.4g}, the most that noise "
            f"alone reaches ({threshold.sentence()})")
    if math.isfinite(white):
        text += f"; {white:.4g} beyond its parameters' uncertainty without each experiment"
        d = getattr(row, "heldout_dir", None)
        p = d.p if d is not None else float("nan")
        if white <= threshold.rms and math.isfinite(p):
            text += (f" (within the threshold), but within its parameters' directions p = "
                     f"{p:.3g} < {DIRECTIONAL_LEVEL:g} (worst without experiment {d.worst}): "
                     f"the law fits every run only with other values without one of them")
    if notes:
        text += "; " + "; ".join(x.text for x in notes)
    return Reason("heldout", text)


def judge(discrepancy, rows, threshold, weak_reasons) -> Verdict:
    """The verdict (module doc) of the best row ``rows[0]`` given its weak
    reasons (:class:`Reason`, the can't-decide rules)."""
    if not discrepancy:
        return Verdict("no_discrepancy", threshold=threshold)
    if not rows:
        return Verdict("weak", (Reason("nothing_fitted", "no candidate could be fitted"),),
                       threshold)
    best = rows[0]
    notes = tuple(law_notes(best))
    if not explains(best, threshold):
        return Verdict("not_explained", (unexplained_reason(best, threshold, notes),),
                       threshold, best.heldout_rmse, notes)
    out = list(weak_reasons)
    out += [Reason("law_out_of_range", x.text) for x in notes if x.at_bound]
    caveats = (rescue_note(best, threshold),) if rescued(best, threshold) else ()
    return Verdict("weak" if out else "named", tuple(out), threshold, best.heldout_rmse,
                   notes, caveats)


def with_partial(v: Verdict, rows, rivals, same: SameCause) -> Verdict:
    """``v`` with its :class:`Partial` name when it is weak by the tie with
    ``rivals`` (:func:`class_rivals` of ``rows[0]``) alone: every other
    rule passed, so what every tied row holds is named, and the rest is
    left undecided."""
    if v.kind != "weak" or not rivals or any(r.code != "rival_tied" for r in v.reasons):
        return v
    return dataclasses.replace(v, partial=partial(rows, [0] + list(rivals), same))
