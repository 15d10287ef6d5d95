"""A located discrepancy: a generic, smooth, regularised force (torque) at
a node of the model graph, for effects no library hypothesis models.

At the node of a body (a joint site) :class:`GenericForce` adds

    f = sum_i a_i H_i(x) + sum_j b_j H_j(v)

on the body against the frame, ``x``/``v`` the body's position and
velocity, ``H`` piecewise-linear hat functions (a linear spline) on
``N_X``/``N_V`` equally spaced knots over the range the nominal run covers
(padded by 10 %). The weights are fitted with the free parameters by output
error, with a second-difference penalty (:func:`penalty`) that keeps the
term smooth. Fitted at every node, the term that removes most of the
misfit locates the discrepancy in the mechanism (where Kennedy and
O'Hagan's discrepancy function locates it in output space only), and its
shape against x and v (:func:`shape`) shows what it is: a dead band, a
softening, a velocity threshold.
"""
from __future__ import annotations

import numpy as np
import sympy as sp

from .domain import domain_of
from .hypotheses import Hypothesis, build_extended

N_X = 9          # knots in position (a feature of 1/8 of the range is resolved)
N_V = 17         # knots in velocity. With 5, a torque that sets in above a speed was no
                 # better fitted than quadratic drag (docs/diagnosis.md). With 9 (knots
                 # 7.3 rad/s apart on the torsion rig) its law, which bends at 10 and 20
                 # rad/s, was not representable: the best 9-knot term zigzagged between
                 # knots to match the energy lost per cycle (data cost 1.6 n, shape 84 %
                 # RMS off the truth's net of its linear part); with 17 the same fit
                 # reaches the noise (1.02 n) and the shape is 13 % off
                 # (tests/diagnose/test_blind_rig.py).
SMOOTH = 1.0     # penalty weight on second differences, per data value: a second
                 # difference of one typical force/3 (the weights' scale) costs as much
                 # as every value missing by one noise floor. With a weight of 1 in all
                 # (not per value) the penalty did nothing: on the rig's threshold case
                 # a 9+9-knot term fitted to 1.28 floors RMS but its leave-one-out error
                 # was 11.7 with the penalty and without (knots that one experiment
                 # alone reaches extrapolate freely); with the weight n it was 1.9.
PAD = 0.1        # knot range padding (fraction of the nominal range)


def hats(z, lo, hi, n):
    """Values (len(z) x n) of the n hat functions on [lo, hi] at z."""
    z = np.atleast_1d(np.asarray(z, float))
    knots = np.linspace(lo, hi, n)
    h = (hi - lo) / (n - 1)
    return np.maximum(0.0, 1.0 - np.abs(z[:, None] - knots[None, :]) / h)


def penalty(n_x=N_X, n_v=N_V, weight=SMOOTH):
    """Second-difference rows over the x weights and the v weights (on
    value/scale): sum of squares added to S."""
    def d2(n):
        return np.diff(np.eye(n), 2, axis=0)
    P = np.zeros((n_x - 2 + n_v - 2, n_x + n_v))
    P[:n_x - 2, :n_x] = d2(n_x)
    P[n_x - 2:, n_x:] = d2(n_v)
    return np.sqrt(weight) * P


def shape(values, prefix, ranges, n=101):
    """The fitted term on grids: dict x, f_x (the position part), v, f_v
    (the velocity part), from the weights ``values`` (name -> value)."""
    x_lo, x_hi, v_lo, v_hi = ranges
    a = np.array([values[f"{prefix}.a{i}"] for i in range(N_X)])
    b = np.array([values[f"{prefix}.b{j}"] for j in range(N_V)])
    x = np.linspace(x_lo, x_hi, n)
    v = np.linspace(v_lo, v_hi, n)
    return dict(x=x, f_x=hats(x, x_lo, x_hi, N_X) @ a, v=v, f_v=hats(v, v_lo, v_hi, N_V) @ b)


class GenericForce(Hypothesis):
    id = "generic_force"
    title = "A generic force at a node (located discrepancy)"
    prefix = "gen"
    site_kinds = ("joint",)
    fixed = {"x_lo": -1.0, "x_hi": 1.0, "v_lo": -1.0, "v_hi": 1.0}
    law = (f"f = sum_i a_i H_i(x) + sum_j b_j H_j(v): linear splines on {N_X} knots in "
           f"the body's position and {N_V} in its velocity over the nominal run's range")
    explanation = ("Not a physical law: a smooth correction that shows where in the "
                   "mechanism, and as what function of position and velocity, the model "
                   "misses a force.")
    distinguishing_experiment = "Read the term's shape against position and velocity."

    def candidates(self, graph):
        return [s.path for s in graph.joints]

    def ranges(self, graph, location):
        dom = domain_of(graph.components[location])
        out = []
        for name in (dom.across, dom.rate):
            z = graph._series(f"{location}.{name}")
            lo, hi = (float(np.min(z)), float(np.max(z))) if z is not None else (-1.0, 1.0)
            pad = PAD * (hi - lo) if hi > lo else 1.0
            out += [lo - pad, hi + pad]
        return out

    def defaults(self, graph, location):
        return dict(zip(("x_lo", "x_hi", "v_lo", "v_hi"), self.ranges(graph, location)))

    def params(self, graph, location):
        dom = domain_of(graph.components[location])
        F = graph.typical(location)["force"]
        out = [self._spec(f"a{i}", -2 * F, 2 * F, dom.force_unit, f"position spline weight "
                          f"{i} at {location}", scale=F / 3) for i in range(N_X)]
        return out + [self._spec(f"b{j}", -2 * F, 2 * F, dom.force_unit, f"velocity spline "
                                 f"weight {j} at {location}", scale=F / 3) for j in range(N_V)]

    def _extend(self, model, graph, hyp, location, vals):
        body = model.find(location)
        dom = domain_of(body)
        rng = {k: self._par(hyp, vals, k, dom.length_unit if k[0] == "x" else dom.rate_unit,
                            f"knot range {k}") for k in self.fixed}
        f = 0
        for var, n, c, (lo, hi) in ((getattr(body, dom.across), N_X, "a", ("x_lo", "x_hi")),
                                    (getattr(body, dom.rate), N_V, "b", ("v_lo", "v_hi"))):
            h = (rng[hi] - rng[lo]) / (n - 1)
            for i in range(n):
                w = self._par(hyp, vals, f"{c}{i}", dom.force_unit, f"spline weight {c}{i}")
                f += w * sp.Max(0, 1 - sp.Abs(var - (rng[lo] + i * h)) / h)
        hyp.term = dom.source(f)
        model.connect(hyp.term.flange, body.flange)


GENERIC = GenericForce()


def build(path, location, values=None):
    """(ModelFile, CompiledModel) of the model file with the generic term at
    ``location`` (cached per process as :func:`.hypotheses.build_extended`)."""
    return build_extended(path, GENERIC.id, location, values, h=GENERIC)
