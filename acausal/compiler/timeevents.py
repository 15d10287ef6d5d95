r"""Time events: the discontinuities of ``time`` found in the equations.

A relation whose sides depend on ``time``, parameters and discrete values
only (``time >= step.startTime`` in a ``Piecewise``), or ``floor``/
``ceiling`` of such an expression (the period count of a pulse), changes
its value at instants that are known without integrating. Modelica keeps
such a relation constant between events and switches it at an event; so
does this stage. Each one is replaced by a discrete value (a *time
switch*, :class:`TimeSwitch`): the equations see it constant while IDA
integrates, and the hybrid loop (:mod:`acausal.runtime.timeevents`) stops
the integrator exactly at the next instant where one changes (IDA's stop
time), sets it, re-initialises and restarts: the event is recorded in
``res.events``.

What becomes a time switch (``g`` an expression of time, parameters and
discrete values only):

* ``g > 0``, ``g >= 0``, ``g < 0``, ``g <= 0`` (any two sides), when ``g``
  is affine in time (``a*time + b`` with ``a``, ``b`` free of time): its
  instant ``-b/a`` is computed from the current parameters and discrete
  values, so a parameter of the instant (a step time) is a run-time value;
* ``floor(g)``, ``ceiling(g)`` with ``g`` affine in time: the next instant
  is where ``g`` reaches the next integer (a periodic event: one after
  the other, as a pulse's periods);
* ``Heaviside``, ``sign``, ``Abs``, ``Min`` and ``Max`` of such expressions
  are first written as ``Piecewise`` (their kinks become relations).

A relation of time that is not affine (``sin(w*time) > 0``) becomes a
switch too, but its instants are found as IDA finds any root (a root
function ``g`` and an event that sets the switch), not by a stop time.

The value of a switch at an instant is its value just after it (the right
limit: ``time >= c`` and ``time > c`` are both true at ``time = c``), so
the value at ``t0`` and after every event does not depend on round-off.
Conditions that involve continuous variables are not time events: they
are left to the components' own :class:`~acausal.lang.declare.Event`\\ s.
"""
from dataclasses import dataclass

import sympy as sp

from ..lang.declare import Event
from ..lang.fastdiff import diff
from ..lang.symbols import time

_RELATIONS = (sp.StrictGreaterThan, sp.GreaterThan, sp.StrictLessThan, sp.LessThan)


@dataclass
class TimeSwitch:
    """A relation or floor of time replaced by the discrete value ``symbol``.

    ``kind``: ``"relation"`` (``symbol`` is 1 while ``g > 0``, else 0) or
    ``"floor"`` (``symbol`` = floor(g)). ``g = slope*time + offset``, both
    expressions of parameters and discrete values (``slope`` None when ``g``
    is not affine in time: ``root`` is then an event that IDA locates).
    ``text`` says what it is, for messages and the event log."""

    symbol: sp.Symbol
    kind: str
    g: sp.Expr
    slope: object
    offset: object
    owner: str
    text: str
    log: bool = True

    @property
    def name(self):
        """Its name in ``res.events``."""
        return f"{self.owner}.time_event" if self.owner else "time_event"


def _time_only(expr, allowed):
    return expr.has(time) and expr.free_symbols <= allowed


def _affine(g):
    """(slope, offset) when ``g`` is affine in time, else (None, None)."""
    a = diff(g, time)
    if a.has(time):
        return None, None
    return a, g.xreplace({time: 0})


class _Finder:
    """Replaces the time relations and floors of expressions by switches."""

    def __init__(self, flat):
        self.flat = flat
        self.allowed = ({time} | {i.symbol for i in flat.params.values()}
                        | {i.symbol for i in flat.discretes.values()})
        self.switches = {}      # key -> TimeSwitch
        self.events = []        # root events of non-affine relations

    def rewrite(self, expr, owner):
        if not isinstance(expr, sp.Basic) or not expr.has(time):
            return expr
        return self._walk(expr, owner)

    def _walk(self, e, owner):
        if not e.args or not e.has(time):
            return e
        args = tuple(self._walk(a, owner) for a in e.args)
        if args != e.args:
            e = e.func(*args)
        return self._transform(e, owner)

    def _transform(self, e, owner):
        if not _time_only(e, self.allowed):
            return e
        if isinstance(e, sp.floor):
            return self._floor(e.args[0], owner, e) if _affine(e.args[0])[0] is not None else e
        if isinstance(e, sp.ceiling):
            if _affine(e.args[0])[0] is None:
                return e
            return -self._floor(-e.args[0], owner, e)
        if isinstance(e, _RELATIONS):
            g = e.lhs - e.rhs if isinstance(e, (sp.StrictGreaterThan, sp.GreaterThan)) \
                else e.rhs - e.lhs
            return sp.StrictGreaterThan(self._relation(g, owner, e), sp.Rational(1, 2))
        rewritten = _as_piecewise(e)
        if rewritten is not None:
            return self._walk(rewritten, owner)
        return e

    def _floor(self, g, owner, orig):
        key = ("floor", sp.srepr(g))
        sw = self.switches.get(key)
        if sw is None:
            a, b = _affine(g)
            sw = self._new("floor", g, a, b, owner, f"each time {g} reaches an integer")
            self.switches[key] = sw
        return sw.symbol

    def _relation(self, g, owner, orig):
        key = ("relation", sp.srepr(g))
        sw = self.switches.get(key)
        if sw is None:
            a, b = _affine(g)
            text = f"time = {-b / a}" if a is not None else f"where {g} = 0 ({orig})"
            sw = self._new("relation", g, a, b, owner, text)
            self.switches[key] = sw
            if a is None:
                self.events.append(_root_event(sw))
        return sw.symbol

    def _new(self, kind, g, a, b, owner, text):
        from .flat import VarInfo
        from ..lang.declare import Start
        k = len(self.switches)
        base = f"{owner}." if owner else ""
        sym = sp.Symbol(f"{base}_time_switch{k}")
        self.allowed.add(sym)
        self.flat.discretes[sym.name] = VarInfo(sym, Start(0.0, True), "1",
                                                f"time switch: {text}", owner, internal=True)
        return TimeSwitch(sym, kind, g, a, b, owner, text)


def _root_event(sw):
    """The event that sets a switch whose relation is not affine in time:
    IDA locates the root of ``g``; the switch takes the sign of ``g`` just
    after it (of its rate when ``g`` is zero there)."""
    rate = diff(sw.g, time)

    def action(state):
        g = float(sw.g.xreplace(_values(state, sw.g)))
        if g == 0.0:
            g = float(rate.xreplace(_values(state, rate)))
        state[sw.symbol] = 1.0 if g > 0 else 0.0
    return Event(sw.name, sw.g, 0, action)


def _values(state, expr):
    out = {time: state.t}
    for s in expr.free_symbols:
        if s != time:
            out[s] = state[s]
    return out


def _as_piecewise(e):
    """``e`` written with Piecewise when it is a function with a kink or a
    jump (Heaviside, sign, Abs, Min, Max), else None."""
    if isinstance(e, sp.Heaviside):
        g = e.args[0]
        return sp.Piecewise((0, g < 0), (1, True))
    if isinstance(e, sp.sign):
        g = e.args[0]
        return sp.Piecewise((1, g > 0), (-1, g < 0), (0, True))
    if isinstance(e, sp.Abs):
        g = e.args[0]
        return sp.Piecewise((g, g >= 0), (-g, True))
    if isinstance(e, (sp.Min, sp.Max)):
        args = list(e.args)
        out = args[0]
        for a in args[1:]:
            cond = (out <= a) if isinstance(e, sp.Min) else (out >= a)
            out = sp.Piecewise((out, cond), (a, True))
        return out
    return None


def find_time_switches(flat):
    """Replace the time relations and floors of ``flat``'s equations (and of
    its events' and assertions' expressions) by time switches; returns the
    switches (also added to ``flat.discretes``, marked internal) and adds
    the root events of the non-affine ones to ``flat.events``."""
    finder = _Finder(flat)
    for eq in flat.equations:
        eq.expr = finder.rewrite(eq.expr, eq.origin if "(" not in eq.origin else "")
    for ev in flat.events:
        ev.expr = finder.rewrite(ev.expr, ev.owner or "")
    for a in flat.assertions:
        a.expr = finder.rewrite(a.expr, a.owner or "")
    flat.events.extend(finder.events)
    for ev in finder.events:
        ev.owner = next(sw.owner for sw in finder.switches.values() if sw.name == ev.name)
    return list(finder.switches.values())
