"""Stage: kinematically equivalent sites.

Two sites whose motions are tied by a (near-)constant ratio over the data
(a lever, gears, a four-bar over the range the experiments cover) are one
place to a cause that acts on a site's coordinate: a torque tau at the hook
does the same work as tau / r at the main shaft when the main shaft turns r
times as fast (virtual power), so the data cannot tell a friction at one
from a friction at the other. The breaker's hook and main shaft turn together
through the four-bar at a rate ratio of about -1.6e-3: hook friction of
0.74 N*m was reported as 460 N*m on the main shaft, and ``location`` and
``parameters`` then named the main shaft (issue 11).

Which sites are tied is read from the calibrated nominal simulation of every
experiment (:func:`kinematics`), not from the model graph: the graph says
that two bodies are linked, but not whether the link's ratio stays constant
over the range the data cover (a four-bar's does not in general; a spring
between two masses ties them only below its resonance). Each site's rate is
its coordinate's finite-difference derivative on the simulation's output
grid, all experiments joined; two sites are tied when the two rate series are
proportional within :data:`KIN_TOL` by two measures: the sine of the angle
between them (the RMS of the part of one that the best constant ratio leaves
over, relative to its size), and the variation of the pointwise rate ratio
itself over every sample of every experiment where the site it is divided
by moves (at least :data:`ACTIVE` of its peak rate; the 2nd to 98th
percentile of the ratio over the least-squares one, both ways round). The
angle alone averages a varying ratio away: on a slider-crank the guide and
the rod pin move at -r sin(theta) times the crank, a ratio varying from
0.68 r to r over the runs, and the angle called them tied "within 4.6 %"
while the data told them apart by 834 AICc units (issue 24); the ratio's
own variation is 38 % there, and 2.8 % on the breaker's hook and main
shaft (0.972 to 1.021 of the constant; angle 1.35 %). The ratio is the
least-squares constant.

A cause at a site tied to another is fitted at both before either is shown
(:func:`tied_tasks`, a stage of :mod:`acausal.diagnose.run` after the pair
search): the data, not the search's order, then compare the two sites.

For the named cause (:func:`equivalents`), the parameters at each tied site
are converted through the ratio (:func:`convert`: a parameter of dimension
force^a length^b scales by |r|^(b - a); a law that is not odd in the motion,
a constant load, also takes the sign of r), and the same hypothesis fitted
there, when it was, is reported beside them with its AICc. Which tied site
is shown first (:func:`prefer_site`) is never claimed to be the data's
choice: among the tied sites whose fits the data cannot tell apart (one
class, :func:`.stats.equivalence_classes`), the one whose coordinate is a
measured signal is shown, with that reason; otherwise the ranking's order
stands, and the report says that it is not evidence.
"""
from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..library.domain import DOMAINS, domain_name
from ..library.loader import family_index, load_library
from ..problem import NOMINAL, Candidate, Param, pair_of
from .pairscreen import same_cause
from .tasks import dataset_of, model_of
from .views import simulate_all

# Rate series whose best constant ratio leaves more than this fraction (RMS,
# relative) are not tied. 5 %: the converted parameter is then right to
# about that, half the 10 % the issue asks of a named parameter. Measured on
# the breaker's nominal run: hook and main shaft 1.3 % (the four-bar's ratio
# varies over the stroke), armature and hook far apart (the armature moves
# alone before the contact).
KIN_TOL = 0.05
# Samples where the divisor's rate is below this fraction of its peak are
# left out of the pointwise ratio (a turning point's ratio is 0/0).
ACTIVE = 0.1
RATIO_PCT = (2.0, 98.0)   # percentiles of the ratio's variation (a glitch at an event)
# A traced signal is a site's coordinate when their rates agree to this
# (ratio +1, spread): a sensor on the site's flange or the same variable. Not
# a looser "about +-1": on the planar breaker the cam pin turns at -1.0017
# times the hook (spread 4e-5) and its angle is not the measured hook angle.
SAME_TOL = 1e-3
# Sites tied this closely (the spread of :func:`tie`) are one place to the
# pair search (:meth:`Kinematics.places`): a cause at either moves the data as
# the same cause at the other does, to this fraction of its effect, so a
# pair fitted at one stands in the search for the same pair at the other
# (a rigid gear, a lever, a body and the joint that carries it; the geared
# drive's motor and load: 3e-14). The sites are still both fitted before
# either is shown (:func:`tied_candidates`). Not the looser ties of
# :data:`KIN_TOL`: the breaker's hook and main shaft (2.8 %) are told apart
# by the data when the effect is large.
RIGID_TOL = 1e-3


@dataclass(frozen=True)
class Tie:
    """Sites ``a`` and ``b`` move together: rate at b = ``ratio`` x rate at
    a; ``spread``: the larger of the sine of the angle between the two rate
    series and the pointwise ratio's relative variation (:func:`tie`)."""

    a: str
    b: str
    ratio: float
    spread: float


@dataclass(frozen=True)
class Kinematics:
    """The tied sites of a model over the data (``ties``), and ``measured``:
    (site, signal) pairs whose coordinate a traced signal records (the same
    rate, :data:`SAME_TOL`). ``message``: why nothing was found, when so."""

    ties: tuple = ()
    measured: tuple = ()
    message: str = ""

    def tied(self, loc) -> list:
        """[(other site, rate ratio other/``loc``, spread)] of ``loc``."""
        out = []
        for t in self.ties:
            if t.a == loc:
                out.append((t.b, t.ratio, t.spread))
            elif t.b == loc:
                out.append((t.a, 1.0 / t.ratio, t.spread))
        return out

    def signal_of(self, loc):
        """The traced signal that records ``loc``'s coordinate, or None."""
        return next((sig for site, sig in self.measured if site == loc), None)

    def places(self, tol=RIGID_TOL) -> dict:
        """site -> its place: the first (in name order) of the sites tied to
        it, directly or through others, within ``tol`` (:data:`RIGID_TOL`);
        only sites so tied are keys (any other site is its own place)."""
        rigid = [t for t in self.ties if t.spread <= tol]
        parent = {x: x for t in rigid for x in (t.a, t.b)}

        def root(x):
            while parent[x] != x:
                x = parent[x]
            return x

        for t in rigid:
            ra, rb = root(t.a), root(t.b)
            parent[max(ra, rb)] = min(ra, rb)
        return {x: root(x) for x in parent}


def rates(runs) -> np.ndarray:
    """The finite-difference rate of a coordinate over ``runs`` = [(t, x)]
    joined (steps of zero length, at events, left out)."""
    out = []
    for t, x in runs:
        t, x = np.asarray(t, float), np.asarray(x, float)
        dt = np.diff(t)
        keep = dt > 0
        out.append(np.diff(x)[keep] / dt[keep])
    return np.concatenate(out) if out else np.zeros(0)


def ratio_variation(va, vb, ratio) -> float:
    """How far the pointwise ratio vb/va strays from ``ratio`` where ``va``
    moves (at least :data:`ACTIVE` of its peak): the larger distance of its
    :data:`RATIO_PCT` percentiles from ``ratio``, relative to ``ratio``."""
    m = np.abs(va) >= ACTIVE * float(np.max(np.abs(va)))
    if not np.any(m) or ratio == 0.0:
        return float("inf")
    q = np.percentile(vb[m] / va[m] / ratio, RATIO_PCT)
    return float(np.max(np.abs(q - 1.0)))


def tie(va, vb, tol=KIN_TOL):
    """(ratio, spread) of rate series ``vb`` against ``va`` when tied
    (spread <= ``tol`` and the pointwise ratio within ``tol`` of the
    constant both ways round: :func:`ratio_variation`), else None (also
    when either does not move or a value is not finite). ``spread`` is the
    larger of the two measures."""
    va, vb = np.asarray(va, float), np.asarray(vb, float)
    if va.size == 0 or va.size != vb.size or not (np.all(np.isfinite(va))
                                                  and np.all(np.isfinite(vb))):
        return None
    na, nb = float(np.linalg.norm(va)), float(np.linalg.norm(vb))
    if na == 0.0 or nb == 0.0:
        return None
    ratio = float(va @ vb) / na ** 2
    # the sine of the angle between them, from the part of vb off va's line
    # (sqrt(1 - cos^2) loses half the digits: 1.5e-8 for exactly proportional rates)
    spread = float(np.linalg.norm(vb - ratio * va)) / nb
    if spread > tol:
        return None
    varies = max(ratio_variation(va, vb, ratio), ratio_variation(vb, va, 1.0 / ratio))
    return (ratio, max(spread, varies)) if varies <= tol else None


def ties_of(series: dict, tol=KIN_TOL) -> tuple:
    """Every tied pair among ``series`` (name -> rate series), in order."""
    names = list(series)
    out = []
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            got = tie(series[a], series[b], tol)
            if got is not None:
                out.append(Tie(a, b, *got))
    return tuple(out)


def coordinates(graph) -> dict:
    """site path -> the name of its coordinate (a body's position, a planar
    joint's axis angle) for every body and joint site of a 1-D domain."""
    out = {}
    for s in graph.sites("bodies") + graph.sites("joints"):
        comp = s.component
        dom = DOMAINS.get(domain_name(comp))
        if dom is None or s.path in out:
            continue
        flange = getattr(type(comp), "diagnosis_flange", None)
        out[s.path] = f"{s.path}.{flange}.{dom.across}" if flange else f"{s.path}.{dom.across}"
    return out


def kinematics(problem, cal, tol=KIN_TOL) -> Kinematics:
    """The stage: simulate the calibrated nominal model on every experiment
    (one run each, main process) and tie the sites' rates (module doc); an
    experiment whose run fails is left out."""
    lib = load_library(problem.library)
    try:
        coords = coordinates(lib.graph_of(problem.model_path))
    except Exception as exc:  # noqa: BLE001 - a stand-in library without sites
        return Kinematics(message=f"no sites: {type(exc).__name__}: {exc}")
    ds = dataset_of(problem)
    runs = [r for r in simulate_all(model_of(problem, NOMINAL), ds, cal.fit.values,
                                    problem.settings.integrator).values() if r is not None]
    if not coords or not runs:
        return Kinematics(message="no sites" if not coords else "every nominal run failed")
    signals = sorted({s for e in ds.experiments if e.trace is not None for s in e.trace.signals})
    series = {}
    for name, var in list(coords.items()) + [(s, s) for s in signals]:
        try:
            series[name] = rates([(res.t, res[var]) for res in runs])
        except KeyError:
            continue
    sites = [p for p in coords if p in series]
    ties = ties_of({p: series[p] for p in sites}, tol)
    measured = tuple((p, s) for p in sites for s in signals if s in series and p != s
                     and _same(tie(series[p], series[s], SAME_TOL)))
    return Kinematics(ties, measured)


def _same(got) -> bool:
    """A tie at ratio +1: the signal is the site's coordinate."""
    return got is not None and abs(got[0] - 1.0) <= SAME_TOL


# -- converting a cause's parameters --------------------------------------------------
def exponents(unit: str, domain: str):
    """(a, b): the powers of force and length in ``unit`` (a hypothesis
    parameter's unit in ``domain``: N, m in translational; N*m, rad in
    rotational); None when it does not reduce to them."""
    if unit.strip() in ("", "1", "-"):
        return 0, 0
    F, L, s, N, m, kg, rad = sp.symbols("F L s N m kg rad", positive=True)
    base = ({N: F, m: L, kg: F * s ** 2 / L, rad: 1} if domain == "translational" else
            {N: F / m, rad: L, kg: F * s ** 2 / (L * m ** 2)})
    try:
        expr = sp.sympify(unit.replace("^", "**"), locals=dict(N=N, m=m, kg=kg, rad=rad, s=s))
    except (sp.SympifyError, TypeError):
        return None
    powers = sp.powsimp(sp.expand_power_base(expr.xreplace(base), force=True)).as_powers_dict()
    if set(powers) - {F, L, s, 1}:
        return None
    return int(powers.get(F, 0)), int(powers.get(L, 0))


def convert(value, unit, domain, ratio, odd=True):
    """A parameter of a cause at one site as the same cause at a site that
    moves ``ratio`` times as fast: force / r, length x r, so a parameter of
    force^a length^b scales by |r|^(b - a); a law not odd in the motion (a
    constant load) also takes the sign of r on its force-like parameters.
    None when the unit does not reduce to force and length."""
    ab = exponents(unit, domain)
    if ab is None or ratio == 0:
        return None
    a, b = ab
    out = value * abs(ratio) ** (b - a)
    return out * (math.copysign(1.0, ratio) if not odd and a % 2 else 1.0)


@dataclass(frozen=True)
class EquivalentSite:
    """The named cause at a tied site: the rate ratio (its rate per the
    cause's site's), the cause's parameters converted through it
    (``values``: (name, value) pairs, named as at that site), the same
    hypothesis's own fit there (``fitted``, empty when it was not fitted),
    its AICc against the cause's (``daicc``), whether the data tell it
    apart from the cause (``in_class``: False when they do) and whether the
    converted values lie in the hypothesis's declared range at that site
    (``in_range``: a fit there cannot reach them otherwise)."""

    location: str
    ratio: float
    spread: float
    values: tuple
    fitted: tuple = ()
    daicc: float | None = None
    in_class: bool = False
    in_range: bool = True


@dataclass(frozen=True)
class SiteEquivalence:
    """One member of the named cause (``cause`` at ``location``), its tied
    sites and why ``location`` is the one shown (``reason``)."""

    cause: str
    location: str
    sites: tuple
    reason: str = ""


# -- the stage's verdict: which tied site is shown, and the cause at each ---------------
def _class_of(rk, i) -> list:
    return next((c for c in rk.classes if i in c), [i])


def _members(candidate) -> list:
    return sorted((h, loc) for h, loc, _ in candidate.members())


def _alternative(rk, row, i, site):
    """Index of the ranked row that is ``row`` with its member ``i`` at
    ``site`` instead, a pair's members in either order (None: not fitted)."""
    want = [(h, site if k == i else loc) for k, (h, loc, _) in
            enumerate(row.candidate.members())]
    return next((j for j, r in enumerate(rk.rows) if _members(r.candidate) == sorted(want)),
                None)


# -- a cause at a tied site is fitted at both sites before either is shown ---------------
TIED_REACH = 10.0   # rows within this many AICc units of the best get their tied sites fitted
TIED_ROWS = 3       # ... at most this many rows


def tied_candidates(problem, kin: Kinematics, rows, allowed=None) -> list:
    """The candidates to fit so that each of the best ``rows`` (within
    :data:`TIED_REACH` AICc units of the first, at most :data:`TIED_ROWS`) is
    also fitted with each member moved to each site tied to its own where
    its hypothesis can act: not yet among ``rows`` (either order of a
    pair), and within ``allowed(location)`` when given (the user's
    ``locations``). The moved member starts at its parameters converted
    through the rate ratio (:func:`convert`), the others at the row's fit."""
    if not kin.ties or not rows:
        return []
    have = {tuple(_members(r.candidate)) for r in rows}
    best = rows[0].aicc
    top = [r for r in rows if r.aicc <= best + TIED_REACH][:TIED_ROWS]
    return [c for _, c in _moves(problem, kin, top, have, allowed)]


def placements(problem, kin: Kinematics, fits, allowed=None, tol=RIGID_TOL,
               singles=False, fitted=()) -> list:
    """[(fit, candidate)]: each pair among ``fits`` (fitted candidates:
    ``.candidate``, ``.fit``; with ``singles``, each single cause too) with
    a member at a site rigidly tied to another (within ``tol``:
    :meth:`Kinematics.places`), that member moved there, seeded as
    :func:`tied_candidates` seeds it; none already among ``fits`` or
    ``fitted`` (other rows). The pair search and the family stage fit a cause
    at one placement of rigidly tied sites (:func:`.chain.search_pairs`,
    :func:`.families.fit_members`); these are its other placements, each a
    refinement of the converted fit."""
    rigid = dataclasses.replace(kin, ties=tuple(t for t in kin.ties if t.spread <= tol))
    moved = [f for f in fits if f.fit is not None and f.fit.ok and f.candidate.hypothesis
             and (singles or "+" in f.candidate.hypothesis)]
    if not rigid.ties or not moved:
        return []
    have = {tuple(_members(f.candidate)) for f in list(fits) + list(fitted)}
    return list(_moves(problem, rigid, moved, have, allowed))


def _moves(problem, kin: Kinematics, rows, have, allowed):
    """(row, candidate) for each of ``rows`` with one member moved to a site
    tied to its own (:func:`tied_candidates`); ``have``: member lists
    (sorted tuples) already fitted, extended with those returned."""
    lib = load_library(problem.library)
    graph = lib.graph_of(problem.model_path)
    index = family_index(problem.library)
    for row in rows:
        members = row.candidate.members()
        for i, (h, loc, names) in enumerate(members):
            hyp = lib.HYPOTHESES.get(h)
            if hyp is None:
                continue
            where = hyp.candidates(graph)
            for other, ratio, _ in kin.tied(loc):
                if other not in where or (allowed is not None and not allowed(other)):
                    continue
                want = [(hh, other if k == i else at) for k, (hh, at, _) in enumerate(members)]
                if tuple(sorted(want)) in have or (len(want) > 1 and same_cause(
                        index, Candidate(*want[0]), Candidate(*want[1]))):
                    continue
                cands = [_moved(lib, graph, row, k, other if k == i else at, ratio if k == i
                                else None) for k, (_, at, _) in enumerate(members)]
                cand = cands[0] if len(cands) == 1 else pair_of(*cands)
                have.add(tuple(sorted(want)))
                yield row, cand


def _moved(lib, graph, row, k, site, ratio):
    """Member ``k`` of ``row`` as a single candidate at ``site``, seeded
    from the row's fit, converted through ``ratio`` (None: the same site).
    A hypothesis's parameters correspond by position between sites (a
    friction force F on a body is a torque tau on a shaft)."""
    h, loc, names = row.candidate.members()[k]
    hyp = lib.HYPOTHESES[h]
    dom = domain_name(graph.components[loc]) if ratio is not None else None
    odd = getattr(hyp, "odd", True)
    here, there = hyp.params(graph, loc), hyp.params(graph, site)
    same = len(here) == len(there) == len(names)
    params = []
    for i, spec in enumerate(there):
        v = row.fit.values.get(names[i]) if same else None
        if v is not None and ratio is not None:
            v = convert(v, here[i].unit, dom, ratio, odd)
        params.append(Param.from_spec(spec, v))
    return Candidate(h, site, tuple(params))


def prefer_site(rk, kin: Kinematics):
    """The ranking with the shown (and named) row moved to the same cause at
    a tied site whose coordinate is a measured signal, when the shown row's
    site is not measured and the row there is tested and in the shown row's
    class (the data cannot tell the two apart). Rows and classes unchanged."""
    if rk.after is None or not kin.ties:
        return rk
    row, cls = rk.rows[rk.after], _class_of(rk, rk.after)
    for i, (_, loc, _) in enumerate(row.candidate.members()):
        if kin.signal_of(loc) is not None:
            continue
        for other, _, _ in kin.tied(loc):
            j = _alternative(rk, row, i, other)
            if (j is not None and j in cls and rk.rows[j].starts.tested
                    and kin.signal_of(other) is not None):
                return dataclasses.replace(rk, after=j,
                                           cause=j if rk.cause is not None else None)
    return rk


def equivalents(problem, kin: Kinematics, rk) -> tuple:
    """:class:`SiteEquivalence` of each member of the shown row (the named
    cause, or the best candidate) that has tied sites where its hypothesis
    can act."""
    row = rk.best
    if row is None or not kin.ties:
        return ()
    lib = load_library(problem.library)
    graph = lib.graph_of(problem.model_path)
    out = []
    for i, (h, loc, names) in enumerate(row.candidate.members()):
        hyp = lib.HYPOTHESES.get(h)
        if hyp is None:
            continue
        where = hyp.candidates(graph)
        sites = tuple(_at(rk, row, i, hyp, graph, other, ratio, spread)
                      for other, ratio, spread in kin.tied(loc) if other in where)
        if sites:
            out.append(SiteEquivalence(h, loc, sites, _reason(kin, loc, sites)))
    return tuple(out)


def _at(rk, row, i, hyp, graph, other, ratio, spread) -> EquivalentSite:
    """Member ``i`` of ``row`` at the tied site ``other`` (rate ratio
    ``ratio`` against its own site)."""
    h, loc, names = row.candidate.members()[i]
    prefix = names[0].partition(".")[0]
    dom = domain_name(graph.components[loc])
    odd = getattr(hyp, "odd", True)
    values, in_range = [], True
    for here, there, name in zip(hyp.params(graph, loc), hyp.params(graph, other), names):
        v = convert(row.fit.values[name], here.unit, dom, ratio, odd)
        values.append((f"{prefix}.{there.name.partition('.')[2]}", v))
        in_range = in_range and v is not None and there.low <= v <= there.high
    j = _alternative(rk, row, i, other)
    if j is None:
        return EquivalentSite(other, ratio, spread, tuple(values), in_range=in_range)
    alt = rk.rows[j]
    there = next(nm for hh, at, nm in alt.candidate.members() if (hh, at) == (h, other))
    fitted = tuple((nm, alt.fit.values[nm]) for nm in there)
    return EquivalentSite(other, ratio, spread, tuple(values), fitted, alt.aicc - row.aicc,
                          j in _class_of(rk, rk.after), in_range)


def _reason(kin: Kinematics, loc, sites) -> str:
    """Why ``loc`` is the site shown, never as the data's choice among
    sites they cannot tell apart."""
    same = [s.location for s in sites if s.in_class]
    sig = kin.signal_of(loc)
    if not same:
        return (f"`{loc}` is shown: the same cause at the tied site(s) "
                + ", ".join(f"`{s.location}`" + (" was not fitted" if s.daicc is None else
                                                 f" ranks {s.daicc:+.3g} AICc units apart")
                            + ("" if s.in_range else " (its converted parameters lie "
                               "outside the range declared there, which a fit cannot leave)")
                            for s in sites) + ".")
    txt = (f"The data cannot tell `{loc}` from " + ", ".join(f"`{x}`" for x in same)
           + ": the sites move together at a fixed ratio and the fits there are one class.")
    if sig is not None:
        return txt + f" `{loc}` is shown because its coordinate is the measured signal `{sig}`."
    lead = min(s.daicc for s in sites if s.in_class)
    return txt + (f" `{loc}` is shown because it ranks first by AICc ({lead:.3g} units "
                  f"ahead), which between tied sites is not evidence." if lead >= 0 else
                  f" `{loc}` is shown in the ranking's order, not by the data's choice.")
