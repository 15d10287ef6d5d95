"""Segments of a model with no states (every motion prescribed).

When the index reduction leaves no state, nothing is integrated: the
unknowns at each time follow from the equations at that time alone (an
explicit evaluation when every unknown is explicit, a Newton solve of the
remaining algebraic blocks otherwise, :func:`acausal.runtime.initialize.reinitialize`
with no state to keep). :class:`AlgebraicSolver` does that on the output
times, with the same contract as an integrator (:class:`SegmentSolver`):
it watches the root functions between consecutive points (the output
times, refined to at most ``max_step`` or 1/100 of the segment apart) and
locates a crossing by Brent's method on ``t``, so state events (a contact
that the prescribed motion closes, a Stop condition) and assertions are
found as IDA finds them, and time events end segments as for IDA.

It runs on the backend's own callbacks (``serve``): generated Python for
``sundae``, the compiled C for ``compiled``.
"""
import numpy as np
from scipy.optimize import brentq

from . import Root, Segment, SegmentSolver

SUBDIVISIONS = 100   # root checks per segment at least (without max_step)
XTOL = 1e-14         # Brent's tolerance on t, relative to the time scale
RES_TOL = 1e-8       # largest residual accepted at a point, relative to 1 + |J_i| |y|


class AlgebraicSolver(SegmentSolver):
    """A segment solver for a model with no states; ``serve`` and ``name``
    are those of the backend it stands in for."""

    def __init__(self, cm, p, opts, name, serve):
        self.cm, self.p = cm, np.asarray(p, float)
        self.name = name
        self.detail = "no states: the equations solved at each output time"
        self._serve = serve
        self.max_step = float(opts.get("max_step") or 0.0)
        ev = cm.events
        self.dirs = [e.direction for e in ev] + [-1] * len(cm.assertions)
        self.terminal = [not e.observer for e in ev] + [True] * len(cm.assertions)
        self.evals = 0

    def serve(self, model, p, d):
        return self._serve(model, p, d)

    def _point(self, cb, t, y, yp):
        """The unknowns at ``t`` (Newton from ``y``), or _NoSolution."""
        from ..initialize import reinitialize
        self.evals += 1
        y1, yp1 = reinitialize(self.cm, cb, t, y, yp)
        if len(y1):
            r = np.zeros(len(y1))
            cb[0](t, y1, yp1, r)
            bad = ~np.isfinite(r)
            if not bad.any() and np.any(np.abs(r) > RES_TOL):
                # each equation against the size of its terms, |J_i| |y| (the
                # initialisation's consistency test)
                n = len(y1)
                Jy, Jyp = np.zeros((n, n)), np.zeros((n, n))
                cb[3](t, y1, yp1, Jy, Jyp)
                bad = np.abs(r) > RES_TOL * (1.0 + np.abs(Jy) @ np.abs(y1))
            if bad.any():
                raise _NoSolution(t, y1, yp1, int(np.argmax(bad)))
        return y1, yp1

    def _roots(self, cb, t, y, yp):
        g = np.zeros(self.cm.n_roots)
        if len(g):
            cb[2](t, y, yp, g)
        return g

    def solve(self, cb, d, t, y, yp, tout, every_step):
        T, Y, YP = [t], [np.array(y, float)], [np.array(yp, float)]
        try:
            return self._solve(cb, t, y, yp, tout, every_step, (T, Y, YP))
        except _NoSolution as exc:
            T.append(exc.t), Y.append(exc.y), YP.append(exc.yp)
            org = self.cm.dae.origins[exc.row]
            what = org.describe() if hasattr(org, "describe") else str(org)
            return self._segment(T, Y, YP, -1, [], "no solution near the previous point "
                                 f"({what})")

    def _solve(self, cb, t, y, yp, tout, every_step, rows):
        tout = np.asarray(tout, float)
        span = float(tout[-1]) - t
        h = self.max_step if self.max_step > 0 else span / SUBDIVISIONS
        grid = np.union1d(tout, np.linspace(t, tout[-1], int(np.ceil(span / h)) + 1)[1:-1]) \
            if span > 0 else tout
        keep = set(tout.tolist())
        (T, Y, YP), roots = rows, []
        y, yp = np.array(y, float), np.array(yp, float)
        g0 = self._roots(cb, t, y, yp)
        t0, self.evals = t, 0
        for t1 in grid:
            y1, yp1 = self._point(cb, t1, y, yp)
            g1 = self._roots(cb, t1, y1, yp1)
            fired = self._crossed(g0, g1)
            if fired:
                tr, yr, ypr, fired = self._locate(cb, t0, t1, y, yp, g0, fired)
                roots.append(Root(tr, yr, ypr, fired))
                if any(self.terminal[i] for i in fired):
                    T.append(tr), Y.append(yr), YP.append(ypr)
                    return self._segment(T, Y, YP, 2, roots)
            if every_step or t1 in keep:
                T.append(float(t1)), Y.append(y1), YP.append(yp1)
            t0, y, yp, g0 = float(t1), y1, yp1, g1
        return self._segment(T, Y, YP, 0, roots)

    def _crossed(self, g0, g1):
        """Root functions that crossed zero from ``g0`` to ``g1`` in their
        direction (IDA's rule: a sign change, or reaching zero from a
        non-zero value)."""
        out = []
        for i, (a, b) in enumerate(zip(g0, g1)):
            if a == 0 or not (b == 0 or (a < 0) != (b < 0)):
                continue
            rising = b > a
            if self.dirs[i] == 0 or (self.dirs[i] > 0) == rising:
                out.append(i)
        return out

    def _locate(self, cb, t0, t1, y0, yp0, g0, fired):
        """The first crossing in (t0, t1] of the root functions ``fired``:
        Brent's method on each, the earliest kept (with every function that
        crossed by then)."""
        state = {"y": y0, "yp": yp0}

        def g_at(tt, i):
            y, yp = self._point(cb, tt, state["y"], state["yp"])
            return self._roots(cb, tt, y, yp)[i]

        tol = XTOL * max(abs(t0), abs(t1), t1 - t0)
        first = t1
        for i in fired:
            if g_at(t1, i) == 0.0:
                ti = t1
            else:
                ti = brentq(lambda tt: g_at(tt, i), t0, t1, xtol=tol, rtol=1e-15)
                # the side of the crossing: the end of the bracket past the root
                if (g_at(ti, i) < 0) == (g0[i] < 0) and g_at(ti, i) != 0.0:
                    ti = min(ti + tol, t1)
            first = min(first, ti)
        yr, ypr = self._point(cb, first, y0, yp0)
        g = self._roots(cb, first, yr, ypr)
        hit = [i for i in self._crossed(g0, g) if i in fired] or fired[:1]
        return float(first), yr, ypr, hit

    def _segment(self, T, Y, YP, status, roots, message="ok"):
        return Segment(np.array(T, float), np.array(Y, float).reshape(len(T), -1),
                       np.array(YP, float).reshape(len(T), -1), status, message, roots,
                       nfev=self.evals, njev=0, steps=max(len(T) - 1, 0))


class _NoSolution(Exception):
    """Newton found no point where the residual vanishes (``row``: the
    worst equation)."""

    def __init__(self, t, y, yp, row):
        super().__init__(t)
        self.t, self.y, self.yp, self.row = float(t), y, yp, row
