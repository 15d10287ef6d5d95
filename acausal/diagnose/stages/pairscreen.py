"""A linearised screen of every pair of single candidates, from the
singles' own fits (no simulation), and which of them get a full fit.

Why: the pairs among the few best singles and the best single's screened
partners (:mod:`.pairsearch`) miss a pair whose members both fit badly
alone. Dry friction plus quadratic drag in a free decay: the drag dominates
at large amplitude, Coulomb friction alone fits badly and ranks low, so
the true pair was never fitted (issue 24).

The prediction (:func:`predict`). Each single ``a`` was fitted: residuals
``r_a`` at its point (free parameters ``f_a``, own parameters ``t_a``)
and the Jacobian ``J_a`` there. The nominal fit gives ``r_0`` and the free
parameters' columns ``J_0``. The pair's residuals are predicted by the
superposition of the two singles' effects, each linearised at its own
fitted point::

    r(f, t_a, t_b) ~ r_a + r_b - r_0 + J_0 g + A_a u_a + A_b u_b

with ``A`` a single's own columns, ``u`` its parameters' moves from its
fitted point and ``g = f - f_a - f_b + f_0`` the free parameters' move.
The predicted cost is the bounded least-squares minimum over (g, u_a,
u_b), every parameter kept in its declared range
(:func:`.screen.predicted_step`). It is exact when the residuals are
linear in the parameters (a test), and it starts from each member's
*fitted* effect, not from its first-order column at neutral: a law whose
column is weak at its neutral point (a dead band, a clearance, Coulomb
friction against a strong drag) is screened by what it did when fitted.
What it misses is the interaction of the two causes beyond first order.

Which pairs: two different hypotheses anywhere, or one hypothesis at two
sites; two members of one family at one site are never a pair (they
would share one effect: the family's best single member stands for them,
and :func:`.pairsearch.simpler_tasks` swaps members of the best pair);
one site with two different families is a pair (a constant load and dry
friction at one body).

How many are fitted (:func:`picks`): each prediction is given an
uncertainty ``U = MARGIN + SHARE x (its predicted AICc gain over its
better member alone)``: the screen is trusted on what one member explains
alone (a fit) and not on what the second adds. A pair is fitted when its
optimistic AICc (prediction - U) reaches the best pair's pessimistic one
(min over pairs of prediction + U), at most :data:`MAX_FITS`, the most
promising first. After the first fits, :func:`more_picks` measures reach
against the best pair actually fitted (usually far below every
prediction), and the pairs within it not yet fitted get a second round.
Pairs still within reach beyond :data:`MAX_FITS` are fitted briefly
(:meth:`.problem.Problem.briefly`, from the step's point); one whose
fit fails is returned as unfitted: no cause is named over it. The largest under-prediction the
fitted pairs showed (:func:`observed_share`) is reported, not used: the
true pair beats its prediction by many times its predicted gain (dry
friction + drag: 3.0 times), and a share widened to it put every pair
within reach on the latch (more than MAX_FITS unfitted, no cause named).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import stats as st
from .screen import predicted_step

MARGIN = 10.0     # AICc units of uncertainty of every prediction, plus ...
SHARE = 0.5       # ... this share of its predicted gain over its better member alone
MAX_FITS = 8      # pairs fitted in full from this screen, both rounds together


@dataclass(frozen=True)
class Predicted:
    """One pair's screen: the two single rows (``a`` before ``b`` in the
    ranking), the predicted cost ``S`` and AICc, the better member's AICc
    (``single_aicc``) and the prediction's uncertainty ``u`` (AICc)."""

    a: object
    b: object
    S: float
    aicc: float
    single_aicc: float
    u: float

    @property
    def key(self):
        return frozenset((self.a.candidate.key, self.b.candidate.key))

    @property
    def gain(self) -> float:
        """Predicted AICc gain over the better member alone (>= 0)."""
        return max(0.0, self.single_aicc - self.aicc)

    @property
    def label(self):
        return f"{self.a.candidate.label} + {self.b.candidate.label}"


def same_cause(index, a, b, places=None) -> bool:
    """Whether single candidates ``a`` and ``b`` cannot form a pair: one
    hypothesis at one site, or two members of one family at one site
    (``index``: :class:`~..library.loader.FamilyIndex`); ``places``: site ->
    place (:meth:`.kinematics.Kinematics.places`: rigidly tied sites are one
    place; None or a site not in it: each site its own)."""
    if place_of(places, a.location) != place_of(places, b.location):
        return False
    return a.hypothesis == b.hypothesis or index.family(a.hypothesis) == index.family(
        b.hypothesis)


def place_of(places, loc):
    """The place of site ``loc`` (:func:`same_cause`)."""
    return loc if not places else places.get(loc, loc)


def first_of_each(items, key, seen=()) -> list:
    """``items`` in order, each kept only when ``key(item)`` is neither in
    ``seen`` nor an earlier item's."""
    seen, out = set(seen), []
    for it in items:
        k = key(it)
        if k not in seen:
            seen.add(k)
            out.append(it)
    return out


def placed_key(members, places=None) -> frozenset:
    """The set of a candidate's (hypothesis, place) members (``members``:
    [(hypothesis, location, ...)], :meth:`~..problem.Candidate.members`): a
    pair at rigidly tied sites has the key of the same pair at the others."""
    return frozenset((m[0], place_of(places, m[1])) for m in members)


def _columns(fit, names):
    idx = [fit.names.index(n) for n in names]
    return fit.jacobian[:, idx] if idx else np.zeros((fit.n, 0))


def predict(f0, free, a, b, bounds_of_param):
    """(S_pred, d) of the pair of fitted singles ``a`` and ``b`` (rows or
    fits with ``.fit`` and ``.candidate``) from the nominal fit ``f0``
    (module doc); ``free``: the free parameters (Param, with bounds);
    ``bounds_of_param(name)`` -> (low, high) of a candidate's parameter.
    (nan, None) when the residual vectors do not match."""
    fa, fb = a.fit, b.fit
    if not (fa.residuals.shape == fb.residuals.shape == f0.residuals.shape):
        return float("nan"), None
    own_a = [p.name for p in a.candidate.params]
    own_b = [p.name for p in b.candidate.params]
    base = fa.residuals + fb.residuals - f0.residuals
    J_own = np.hstack([_columns(fa, own_a), _columns(fb, own_b)])
    J_free = f0.jacobian
    lo, hi = [], []
    by = {p.name: p for p in free}
    for n in f0.names:            # g = f - f_a - f_b + f_0: f within its bounds
        off = fa.values[n] + fb.values[n] - f0.values[n]
        lo.append(by[n].low - off)
        hi.append(by[n].high - off)
    for fit, names in ((fa, own_a), (fb, own_b)):
        for n in names:
            low, high = bounds_of_param(n)
            lo.append(low - fit.values[n])
            hi.append(high - fit.values[n])
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    hi = np.maximum(hi, lo + 1e-300 + 1e-12 * np.abs(lo))
    return predicted_step(base, J_own, J_free, (lo, hi))


def screen_all(f0, free, rows, index, c_hat, done=(), places=None) -> list:
    """:class:`Predicted` of every admissible pair of the single ``rows``
    (module doc), best predicted AICc first; pairs whose key set is in
    ``done`` (frozensets of the two singles' keys) are left out. With
    ``places`` (:func:`same_cause`), a pair at rigidly tied sites is left
    out after the best predicted one of its place key (:func:`placed_key`):
    its fit would be that pair's again."""
    singles = [r for r in rows if "+" not in r.candidate.hypothesis and r.fit is not None]
    bounds = {p.name: (p.low, p.high) for r in singles for p in r.candidate.params}
    n, k0 = f0.n, f0.k
    out = []
    for i, a in enumerate(singles):
        for b in singles[i + 1:]:
            if same_cause(index, a.candidate, b.candidate, places):
                continue
            if frozenset((a.candidate.key, b.candidate.key)) in done:
                continue
            S, _ = predict(f0, free, a, b, bounds.__getitem__)
            if not np.isfinite(S):
                continue
            k = k0 + len(a.candidate.params) + len(b.candidate.params)
            aicc = st.aicc(S, n, k, c_hat)
            single = min(a.aicc, b.aicc)
            gain = max(0.0, single - aicc)
            out.append(Predicted(a, b, S, aicc, single, MARGIN + SHARE * gain))
    out.sort(key=lambda p: p.aicc)
    if places:
        out = first_of_each(out, lambda p: placed_key((p.a.candidate.key, p.b.candidate.key),
                                                      places))
    return out


def within_reach(preds, best_aicc, share=SHARE) -> list:
    """The predictions whose optimistic AICc (prediction - MARGIN - share x
    gain) reaches ``best_aicc``."""
    return [p for p in preds if p.aicc - (MARGIN + share * p.gain) <= best_aicc]


def picks(preds, limit=MAX_FITS):
    """(to fit, within reach but beyond ``limit``): first round, against the
    best pessimistic prediction (min of prediction + U)."""
    if not preds:
        return [], []
    best = min(p.aicc + p.u for p in preds)
    reach = within_reach(preds, best)
    return reach[:limit], reach[limit:]


def observed_share(preds, fitted_aicc) -> float:
    """The largest share of its predicted gain by which a fitted pair beat
    its prediction (``fitted_aicc``: pair key -> fitted AICc), at least
    :data:`SHARE`: how far the screen was seen to under-predict."""
    share = SHARE
    for p in preds:
        got = fitted_aicc.get(p.key)
        if got is None or not np.isfinite(got):
            continue
        under = p.aicc - got - MARGIN            # better than predicted, beyond the margin
        if under > 0:
            share = max(share, under / max(p.gain, MARGIN))
    return share


def more_picks(preds, fitted_aicc, best_fitted, limit, attempted=()):
    """(to fit now, left unfitted within reach): the predictions not yet
    fitted (nor ``attempted``: keys) whose optimistic AICc reaches the best
    pair fitted (``best_fitted``, AICc); at most ``limit``. The share is
    the stated :data:`SHARE`, not the one the fitted pairs showed
    (:func:`observed_share`, reported): the pair that holds the truth
    usually beats its prediction by many times its predicted gain (the
    interaction the screen leaves out), and that share made every pair
    "within reach" on the latch (module doc)."""
    share = SHARE
    left = [p for p in preds if p.key not in fitted_aicc and p.key not in attempted]
    reach = within_reach(left, best_fitted, share)
    return reach[:max(0, limit)], reach[max(0, limit):]
