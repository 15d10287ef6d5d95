"""A located discrepancy: a generic, smooth, regularised force (torque) at
a node of the model graph, for effects no library hypothesis models.

At the node of a body (a joint site) :class:`GenericForce` adds

    f = sum_i a_i H_i(x) + sum_j b_j H_j(v)

on the body against the frame, ``x``/``v`` the body's position and
velocity, ``H`` piecewise-linear hat functions (a linear spline) on
``N_X``/``N_V`` equally spaced knots over the range the model file's nominal
run covers (padded by 10 %; the located stage spans the calibrated runs of
every experiment instead, :func:`knot_ranges`); each part is one
:class:`~acausal.lang.splines.HatSum` node, evaluated on the interval of
``x`` (``v``) only. The weights are fitted with the free parameters by output
error, with a second-difference penalty (:func:`penalty`) that keeps the
term smooth. Fitted at every node, the term that removes most of the
misfit locates the discrepancy in the mechanism (where Kennedy and
O'Hagan's discrepancy function locates it in output space only), and its
shape against x and v (:func:`shape`) shows what it is: a dead band, a
softening, a velocity threshold.
"""
from __future__ import annotations

import os

import numpy as np

from ...lang.splines import HatSum
from ...runtime.model import compile_model
from ...errors import ModelError
from ...modelfile import load_model_file
from .domain import domain_of
from .graph import ModelGraph
from .hypotheses import Hypothesis, build_extended, file_defaults
from .nominal import nominal_result

N_X = 9          # knots in position of the plain term (a feature of 1/8 of the range is
                 # resolved); the located stage chooses from X_LADDER by cross-validation
N_V = 17         # knots in velocity. With 5, a torque that sets in above a speed was no
                 # better fitted than quadratic drag (docs/diagnosis.md). With 9 (knots
                 # 7.3 rad/s apart on the torsion rig) its law, which bends at 10 and 20
                 # rad/s, was not representable: the best 9-knot term zigzagged between
                 # knots to match the energy lost per cycle (data cost 1.6 n, shape 84 %
                 # RMS off the truth's net of its linear part); with 17 the same fit
                 # reaches the noise (1.02 n) and the shape is 13 % off
                 # (tests/diagnose/test_blind_rig.py).
X_LADDER = (9, 17, 33, 65)   # position resolutions the located stage chooses among: each
                 # one's knots are a subset of the next's (2^m + 1 knots), so a coarser
                 # spline is exactly a finer one (:func:`refine_matrix`) and every
                 # resolution is scored from the finest one's data Jacobian. 65 knots
                 # (8 per cycle over 80 % of the padded range) show 6-8 cycles of a
                 # position-periodic force; 33 show 3-4
V_LADDER = (9, 17, 33)       # velocity resolutions, likewise
SMOOTH = 1.0     # penalty weight on second differences, per data value: a second
                 # difference of one typical force/3 (the weights' scale) costs as much
                 # as every value missing by one noise floor. With a weight of 1 in all
                 # (not per value) the penalty did nothing: on the rig's threshold case
                 # a 9+9-knot term fitted to 1.28 floors RMS but its leave-one-out error
                 # was 11.7 with the penalty and without (knots that one experiment
                 # alone reaches extrapolate freely); with the weight n it was 1.9.
                 # The default of the plain term; the located stage chooses the weight
                 # of each part by cross-validation (stages/locate.py, SMOOTH_GRID)
PAD = 0.1        # knot range padding (fraction of the nominal range)


RANGE_NAMES = ("x_lo", "x_hi", "v_lo", "v_hi")   # the term's fixed parameters: knot ranges


def knot_ranges(x, v):
    """(x_lo, x_hi, v_lo, v_hi): the knots' ranges over the position series
    ``x`` and the velocity series ``v`` (arrays, or lists of arrays: one per
    run), each padded by ``PAD`` of its span (by 1 when it does not move;
    the span -1 .. 1 when the series is missing or has no finite value)."""
    out = []
    for z in (x, v):
        z = (np.concatenate([np.ravel(np.asarray(a, float)) for a in z])
             if isinstance(z, (list, tuple)) and z else
             None if z is None or isinstance(z, (list, tuple)) else np.asarray(z, float))
        z = None if z is None else z[np.isfinite(z)]
        lo, hi = (float(np.min(z)), float(np.max(z))) if z is not None and z.size else (-1.0, 1.0)
        pad = PAD * (hi - lo) if hi > lo else 1.0
        out += [lo - pad, hi + pad]
    return tuple(out)


def range_values(ranges, prefix="gen"):
    """((name, value), ...) of the term's knot ranges as fixed parameter
    values (``Candidate.fixed``): ``gen.x_lo``, ..."""
    return tuple((f"{prefix}.{k}", float(r)) for k, r in zip(RANGE_NAMES, ranges))


def hats(z, lo, hi, n):
    """Values (len(z) x n) of the n hat functions on [lo, hi] at z."""
    z = np.atleast_1d(np.asarray(z, float))
    knots = np.linspace(lo, hi, n)
    h = (hi - lo) / (n - 1)
    return np.maximum(0.0, 1.0 - np.abs(z[:, None] - knots[None, :]) / h)


def refine_matrix(n_coarse, n_fine):
    """T (n_fine x n_coarse): the fine spline weights that reproduce a coarse
    spline on the same range exactly, w_fine = T w_coarse (the coarse knots
    are a subset of the fine ones: (n_fine - 1) a multiple of (n_coarse - 1))."""
    if (n_fine - 1) % (n_coarse - 1):
        raise ValueError(f"{n_coarse} knots are not a subset of {n_fine}")  # internal
    return hats(np.linspace(0.0, 1.0, n_fine), 0.0, 1.0, n_coarse)


def second_differences(n):
    """The (n-2) x n second-difference rows."""
    return np.diff(np.eye(n), 2, axis=0)


def penalty(n_x=N_X, n_v=N_V, weight=SMOOTH, weight_v=None):
    """Second-difference rows over the x weights and the v weights (on
    value/scale): sum of squares added to S. ``weight`` on the x part and
    ``weight_v`` (default: the same) on the v part."""
    weight_v = weight if weight_v is None else weight_v
    P = np.zeros((n_x - 2 + n_v - 2, n_x + n_v))
    P[:n_x - 2, :n_x] = np.sqrt(weight) * second_differences(n_x)
    P[n_x - 2:, n_x:] = np.sqrt(weight_v) * second_differences(n_v)
    return P


def resolution(values, prefix):
    """(n_x, n_v): the knot counts of a term from its weights' names."""
    def count(c):
        return sum(1 for k in values if k.startswith(f"{prefix}.{c}")
                   and k[len(prefix) + 2:].isdigit())
    return count("a"), count("b")


def basis(ranges, n_x, n_v, x, v):
    """(H_x, H_v): the hat values of the position part at ``x`` and of the
    velocity part at ``v`` (rows per point)."""
    x_lo, x_hi, v_lo, v_hi = ranges
    return hats(x, x_lo, x_hi, n_x), hats(v, v_lo, v_hi, n_v)


def shape(values, prefix, ranges, n=101, cov=None):
    """The fitted term on grids: dict x, f_x (the position part), v, f_v
    (the velocity part), from the weights ``values`` (name -> value), at
    the resolution their names give. ``cov``: the weights' covariance
    (x weights then v weights); adds ``f_x_sd`` and ``f_v_sd``, the
    standard deviation of each part on its grid (the band the data
    support: :func:`band`)."""
    n_x, n_v = resolution(values, prefix)
    x_lo, x_hi, v_lo, v_hi = ranges
    a = np.array([values[f"{prefix}.a{i}"] for i in range(n_x)])
    b = np.array([values[f"{prefix}.b{j}"] for j in range(n_v)])
    x = np.linspace(x_lo, x_hi, n)
    v = np.linspace(v_lo, v_hi, n)
    Hx, Hv = basis(ranges, n_x, n_v, x, v)
    out = dict(x=x, f_x=Hx @ a, v=v, f_v=Hv @ b)
    if cov is not None:
        out.update(band(cov, Hx, Hv))
    return out


def band(cov, Hx, Hv):
    """Standard deviations of the position part H_x a and the velocity
    part H_v b from the weights' covariance (x weights first)."""
    cov = np.asarray(cov, float)
    n_x = Hx.shape[1]
    Cx, Cv = cov[:n_x, :n_x], cov[n_x:, n_x:]
    return dict(f_x_sd=np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", Hx, Cx, Hx), 0.0)),
                f_v_sd=np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", Hv, Cv, Hv), 0.0)))


class GenericForce(Hypothesis):
    """The generic term with ``n_x`` position knots and ``n_v`` velocity
    knots (the id is the same at every resolution; the weights' names
    give it: :func:`resolution`)."""

    id = "generic_force"
    title = "A generic force at a node (located discrepancy)"
    prefix = "gen"
    site_kinds = ("joint",)
    fixed = {"x_lo": -1.0, "x_hi": 1.0, "v_lo": -1.0, "v_hi": 1.0}
    explanation = ("Not a physical law: a smooth correction that shows where in the "
                   "mechanism, and as what function of position and velocity, the model "
                   "misses a force.")
    distinguishing_experiment = "Read the term's shape against position and velocity."

    def __init__(self, n_x=N_X, n_v=N_V):
        self.n_x, self.n_v = int(n_x), int(n_v)
        self.law = (f"f = sum_i a_i H_i(x) + sum_j b_j H_j(v): linear splines on {self.n_x} "
                    f"knots in the body's position and {self.n_v} in its velocity over the "
                    f"nominal run's range")

    def candidates(self, graph):
        return [s.path for s in graph.joints]

    def ranges(self, graph, location):
        """The knot ranges at ``location`` from the model file's nominal run
        (:func:`knot_ranges`); the located stage takes them from the
        calibrated runs of every experiment instead (the range the data
        cover), through the candidate's fixed values (:func:`range_values`)."""
        dom = domain_of(graph.components[location])
        return list(knot_ranges(graph._series(f"{location}.{dom.across}"),
                                graph._series(f"{location}.{dom.rate}")))

    def defaults(self, graph, location):
        return dict(zip(("x_lo", "x_hi", "v_lo", "v_hi"), self.ranges(graph, location)))

    def params(self, graph, location):
        dom = domain_of(graph.components[location])
        F = graph.typical(location)["force"]
        out = [self._spec(f"a{i}", -2 * F, 2 * F, dom.force_unit, f"position spline weight "
                          f"{i} at {location}", scale=F / 3) for i in range(self.n_x)]
        return out + [self._spec(f"b{j}", -2 * F, 2 * F, dom.force_unit, f"velocity spline "
                                 f"weight {j} at {location}", scale=F / 3)
                      for j in range(self.n_v)]

    def _extend(self, model, graph, hyp, location, vals):
        body = model.find(location)
        dom = domain_of(body)
        rng = {k: self._par(hyp, vals, k, dom.length_unit if k[0] == "x" else dom.rate_unit,
                            f"knot range {k}") for k in self.fixed}
        f = 0
        for var, n, c, (lo, hi) in ((getattr(body, dom.across), self.n_x, "a", ("x_lo", "x_hi")),
                                    (getattr(body, dom.rate), self.n_v, "b", ("v_lo", "v_hi"))):
            w = [self._par(hyp, vals, f"{c}{i}", dom.force_unit, f"spline weight {c}{i}")
                 for i in range(n)]
            # one node, evaluated on x's interval only (lang.splines: the sum of
            # hats written out cost half of every simulation of a 65-knot term)
            f += HatSum(var, rng[lo], rng[hi], *w)
        hyp.term = dom.source(f)
        model.connect(hyp.term.flange, body.flange)


GENERIC = GenericForce()
_BUILT = {}


def build(path, location, values=None):
    """(ModelFile, CompiledModel) of the model file with the generic term at
    ``location`` (cached per process as :func:`.hypotheses.build_extended`)."""
    return build_extended(path, GENERIC.id, location, values, h=GENERIC)


def build_at(path, location, n_x, n_v, beside=None, hypotheses=None):
    """(ModelFile, CompiledModel) of the model file with the generic term of
    ``n_x`` x ``n_v`` knots at the node ``location`` and, when ``beside`` =
    (hypothesis id, its location) is given, that library hypothesis
    (looked up in ``hypotheses``, id -> object) applied first: the term
    beside a named cause. The fixed parameters' defaults come from the
    unextended file's nominal run; cached per process."""
    apath = os.path.abspath(path)
    key = (apath, os.path.getmtime(apath) if os.path.exists(apath) else None,
           location, int(n_x), int(n_v), beside)
    hit = _BUILT.get(key)
    if hit is None:
        mf = load_model_file(apath)
        graph = ModelGraph(mf.model, result=nominal_result(apath))
        gen = GenericForce(n_x, n_v)
        parts = [(gen, location)]
        if beside is not None:
            if hypotheses is None or beside[0] not in hypotheses:
                raise ModelError(f"generic term beside {beside[0]!r}: no such hypothesis "
                                 f"in the library")
            parts.insert(0, (hypotheses[beside[0]], beside[1]))
        defaults = [file_defaults(mf, h.id, loc, graph, h) for h, loc in parts]
        for (h, loc), d in zip(parts, defaults):
            h.apply(mf.model, loc, d)
        if mf.experiment.stop is not None:
            mf.model.event(mf.experiment.stop.event(mf.model))
        hit = _BUILT[key] = (mf, compile_model(mf.model))
    return hit


def members(candidate):
    """(beside, node, n_x, n_v) of a candidate carrying the generic term:
    hypothesis ``generic_force`` at a node, or ``h+generic_force`` at
    ``site+node`` (the term beside cause ``h`` at ``site``)."""
    hs, ls = candidate.hypothesis.split("+"), candidate.location.split("+")
    if len(hs) > 2 or hs[-1] != GENERIC.id:
        raise ModelError(f"not a generic-term candidate: {candidate.hypothesis!r}")
    names = {p.name: 0.0 for p in candidate.params if p.name.startswith(GENERIC.prefix + ".")}
    n_x, n_v = resolution(names, GENERIC.prefix)
    beside = (hs[0], ls[0]) if len(hs) == 2 else None
    return beside, ls[-1], n_x, n_v


def carries_generic(candidate) -> bool:
    """Whether a candidate is the generic term (alone or beside a cause)."""
    return candidate.hypothesis is not None and GENERIC.id in candidate.hypothesis.split("+")


def model_for(model_path, candidate, hypotheses=None):
    """The (ModelFile, CompiledModel) a generic-term candidate is fitted on
    (:func:`members`), its fixed values (``candidate.fixed``: the knot
    ranges) as the compiled model's defaults; ``hypotheses``: the
    library's, for a term beside a cause."""
    beside, node, n_x, n_v = members(candidate)
    if beside is None and (n_x, n_v) == (GENERIC.n_x, GENERIC.n_v):
        mf, cm = build(model_path, node)
    else:
        mf, cm = build_at(model_path, node, n_x, n_v, beside, hypotheses)
    fixed = dict(getattr(candidate, "fixed", ()) or ())
    return (mf, cm.with_defaults(fixed)) if fixed else (mf, cm)
