r"""Time events at run time: when the next one is, and what it sets.

The compiler replaced the relations and floors of ``time`` by discrete
values, *time switches* (:mod:`acausal.compiler.timeevents`); components may
declare :class:`~acausal.lang.declare.TimeEvent`\\ s (a table's breakpoints).
A :class:`TimeSchedule` serves the hybrid loop (:mod:`acausal.runtime.hybrid`):

* :meth:`TimeSchedule.update` sets every switch to its value just after
  ``t`` (the right limit, so no round-off decides it) and runs the actions
  of the time events due at ``t``; the loop calls it at the start and
  before every segment, and re-initialises when it changed a value;
* :meth:`TimeSchedule.next` is the next instant, which ends the next
  segment exactly (IDA's stop time, on both backends).

Instants closer than :data:`MERGE` of the time scale (round-off of the
same instant computed two ways, a pulse's period and its width at 100 %)
are one event.
"""
import math
import weakref

import numpy as np
import sympy as sp

from ..lang.symbols import time
from .events import EventState

MERGE = 256 * np.finfo(float).eps   # instants closer than this (x time scale) are one
_SWITCHES = weakref.WeakKeyDictionary()   # compiled model -> its compiled time switches


class _Due:
    """What ``res.events`` and the chattering guard see of a time event."""

    def __init__(self, name, owner, log=True):
        self.name, self.owner, self.log = name, owner, log


def _function(expr, cm):
    """``fn(p, d)``: ``expr`` (of parameters and discrete values) at the
    parameter vector ``p`` and discrete values ``d``."""
    expr = sp.sympify(expr).xreplace(cm._subs) if cm._subs else sp.sympify(expr)
    pidx = {s: i for i, s in enumerate(cm.param_syms)}
    didx = {s: i for i, s in enumerate(cm.disc_syms)}
    used = sorted(expr.free_symbols, key=lambda s: s.name)
    bad = [s for s in used if s not in pidx and s not in didx]
    if bad:
        from ..errors import ModelError
        raise ModelError(f"time event {expr}: {bad[0].name} is not a parameter or discrete value")
    if not used:
        value = float(expr)
        return lambda p, d: value
    plain = [sp.Symbol(f"_te{k}") for k in range(len(used))]
    f = sp.lambdify(plain, expr.xreplace(dict(zip(used, plain))), "math")
    at = [(0, pidx[s]) if s in pidx else (1, didx[s]) for s in used]
    return lambda p, d: float(f(*[(p, d)[w][i] for w, i in at]))


class _Switch:
    """A compiled time switch: its slot in the discrete values and its
    slope and offset as functions of (p, d)."""

    def __init__(self, sw, cm):
        self.sw = sw
        self.j = cm.disc_syms.index(sw.symbol)
        self.affine = sw.slope is not None
        if self.affine:
            self.a, self.b = _function(sw.slope, cm), _function(sw.offset, cm)
        else:
            self.g = _function_t(sw.g, cm)
            self.rate = _function_t(sp.diff(sw.g, time), cm)
        self.due = _Due(sw.name, sw.owner, sw.log)

    def value(self, t, p, d, tol):
        """The switch's value just after ``t``."""
        if not self.affine:
            g = self.g(t, p, d)
            if g == 0.0:
                g = self.rate(t, p, d)
            return 1.0 if g > 0 else 0.0
        a, b = self.a(p, d), self.b(p, d)
        if self.sw.kind == "relation":
            if a != 0.0 and abs(t + b / a) <= tol:
                return 1.0 if a > 0 else 0.0      # at its instant: the side after it
            return 1.0 if a * t + b > 0 else 0.0
        g = a * t + b
        m = round(g)
        if a != 0.0 and abs(g - m) <= abs(a) * tol:
            return float(m if a > 0 else m - 1)   # at an integer: the value after it
        return float(math.floor(g))

    def instant(self, p, d):
        """Its next instant from the value in ``d`` (inf: none, or found by IDA)."""
        if not self.affine:
            return math.inf
        a, b = self.a(p, d), self.b(p, d)
        if a == 0.0:
            return math.inf
        if self.sw.kind == "relation":
            return -b / a
        n = d[self.j]
        return (n + 1 - b) / a if a > 0 else (n - b) / a

    def next(self, t, p, d, tol):
        """Its first instant after ``t`` (inf: none, or found by IDA)."""
        r = self.instant(p, d)
        return r if r > t + tol else math.inf


def _function_t(expr, cm):
    """``fn(t, p, d)`` of an expression of time, parameters and discrete values."""
    tsym = sp.Symbol("_te_time")
    expr = sp.sympify(expr).xreplace(cm._subs) if cm._subs else sp.sympify(expr)
    pidx = {s: i for i, s in enumerate(cm.param_syms)}
    didx = {s: i for i, s in enumerate(cm.disc_syms)}
    used = sorted((s for s in expr.free_symbols if s != time), key=lambda s: s.name)
    plain = [sp.Symbol(f"_te{k}") for k in range(len(used))]
    f = sp.lambdify([tsym] + plain, expr.xreplace(dict(zip(used + [time], plain + [tsym]))),
                    "math")
    at = [(0, pidx[s]) if s in pidx else (1, didx[s]) for s in used]
    return lambda t, p, d: float(f(t, *[(p, d)[w][i] for w, i in at]))


class TimeSchedule:
    """The time events of one run of model ``cm`` (a sensitivity run's base
    model) at parameters ``p``; ``span`` is the run's time span (it scales
    the tolerance of "the same instant")."""

    def __init__(self, cm, p, t0, t_end):
        self.cm, self.p = cm, np.asarray(p, float)
        funcs = _SWITCHES.get(cm)
        if funcs is None:   # made once per model
            funcs = _SWITCHES[cm] = [_Switch(sw, cm) for sw in cm.flat.time_switches]
        self.switches = funcs
        self.events = list(cm.flat.time_events)
        self.nd = len(cm.disc_syms)
        self.scale = max(abs(t0), abs(t_end), t_end - t0, 1e-300)
        self.pending = {}       # time event -> its next instant (from the last next())

    def empty(self):
        return not self.switches and not self.events

    def tol(self, t):
        return MERGE * max(self.scale, abs(t))

    def update(self, t, d, obs=None, start=False):
        """(discrete values after the events due at ``t``, the events that
        fired: objects with ``name``, ``owner``, ``log``). ``d`` may be longer
        than the model's discrete values (a sensitivity run's): the rest is
        kept."""
        d = list(d)
        base = d[:self.nd]
        fired = []
        tol = self.tol(t)
        due = [ev for ev in self.events if start or abs(self.pending.get(ev, math.inf) - t)
               <= tol]
        if due:
            state = EventState(self.cm, self.p, base, t, obs)
            for ev in due:
                ev.action(state)
                if not start:
                    fired.append(_Due(ev.name, ev.owner, ev.log))
        # floors first (relations may use them), in the order they were made
        for kind in ("floor", "relation"):
            for sw in self.switches:
                if sw.sw.kind != kind:
                    continue
                v = sw.value(t, self.p, base, tol)
                if v != base[sw.j]:
                    base[sw.j] = v
                    if not start:
                        fired.append(sw.due)
        d[:self.nd] = base
        return d, fired

    def next(self, t, d):
        """The first time event after ``t`` (inf: none)."""
        base = list(d[:self.nd])
        tol = self.tol(t)
        out = math.inf
        for sw in self.switches:
            out = min(out, sw.next(t, self.p, base, tol))
        if self.events:
            state = EventState(self.cm, self.p, base, t, None)
            for ev in self.events:
                r = float(ev.next_time(state))
                self.pending[ev] = r if r > t + tol else math.inf
                out = min(out, self.pending[ev])
        return out

    def time_sensitivity(self, t, d, pidx):
        """d(instant)/dp of the time event at ``t`` for the parameters of
        indices ``pidx`` (central differences of the instant of the first
        switch due at ``t``, with the discrete values ``d`` before it; zero
        for a component's time event, whose instants are not expressions)."""
        base = list(d[:self.nd])
        tol = self.tol(t)
        out = np.zeros(len(pidx))
        for sw in self.switches:
            if abs(sw.instant(self.p, base) - t) > tol:
                continue
            for j, k in enumerate(pidx):
                h = 1e-6 * (abs(self.p[k]) if self.p[k] != 0 else 1.0)
                q1, q2 = self.p.copy(), self.p.copy()
                q1[k] += h
                q2[k] -= h
                out[j] = (sw.instant(q1, base) - sw.instant(q2, base)) / (2 * h)
            break
        return out
