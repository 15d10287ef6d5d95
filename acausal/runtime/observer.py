"""The hooks of the hybrid loop (:mod:`.hybrid`): what a run does besides
integrating, as PyBaMM's solver callbacks do (``on_experiment_start``,
``on_step_end``, ...): the loop calls one :class:`RunObserver` at fixed
points and has no other branch for what it does.

:class:`RunObserver` itself is the plain run: the solver integrates the
model, a mode change re-initialises it (:func:`acausal.runtime.initialize.reinitialize`),
the result is the stored rows. An observer that integrates more than the
model (the forward sensitivities, :class:`acausal.runtime.sensitivity_run.SensitivityObserver`)
overrides :meth:`~RunObserver.system`, :meth:`~RunObserver.on_start`,
:meth:`~RunObserver.on_mode_change` and :meth:`~RunObserver.finish`.

The order of the calls in a run::

    system -> on_start -> (on_rows | on_event -> on_log ... -> [on_actions]
                           -> [on_mode_change] -> on_instant_end)* -> finish

``on_event`` comes before the actions of the events it names, with
``kind``: ``"observer"`` (observer events located inside a segment; their
actions run, then ``on_actions``), ``"instant"`` (the events that ended a
segment), ``"time"`` (time events and switches due at the start of a
segment, :mod:`.timeevents`), ``"recheck"`` (events of the event iteration
at the same instant). The stored rows may be cut to their first ``n``
after the fact (``run.trim``, a row limit): an observer keeping rows of its
own keeps as many as ``run.T`` has.
"""
from typing import NamedTuple

from .initialize import reinitialize
from .result import Result


class Point(NamedTuple):
    """A point of the solution: time ``t``, unknowns ``y`` and derivatives ``yp``."""
    t: float
    y: object
    yp: object


class RunObserver:
    """The plain run (see the module doc); subclass it to observe or extend one."""

    def system(self, cm, atol, p):
        """(the model the solver integrates, its absolute tolerances) for
        compiled model ``cm`` with tolerances ``atol`` at parameters ``p``."""
        return cm, atol

    def on_start(self, run, point, d, cb, starts):
        """At the consistent initial point of the model (discrete values
        ``d``, callbacks ``cb``; ``starts``: the run's start overrides):
        returns (y, y', d, callbacks) of the integrated system there."""
        return point.y, point.yp, d, cb

    def on_rows(self, run, count):
        """``count`` output rows were stored (``run.T[-1]`` ...)."""

    def on_event(self, run, point, d, fired, kind):
        """Events ``fired`` (indices into ``cm.events``; for ``kind`` "time"
        the time events themselves) are about to act at ``point`` in mode
        ``d``; ``kind`` as in the module doc."""

    def on_log(self, run, k, key):
        """Event ``key`` (as ``on_event`` named it) is logged as
        ``run.events[k]`` (about to be appended)."""

    def on_actions(self, run, events, point, d_before, observed):
        """Observer ``events``' actions ran at ``point`` (discrete values
        before them ``d_before``; ``observed``: every variable there)."""

    def on_mode_change(self, run, events, point, d_before, d, observed):
        """``events``' actions changed the discrete values from ``d_before``
        to ``d`` at ``point`` (``observed``: every variable there, before
        the change): returns (d, callbacks, y, y') of the new mode,
        re-initialised there (states kept)."""
        cb = run.callbacks(d)
        y, yp = reinitialize(run.cm, cb, point.t, point.y, point.yp)
        return d, cb, y, yp

    def on_instant_end(self, run):
        """The events of one instant (those that ended a segment and their
        event iteration) are done."""

    def finish(self, run, rows, stats, status, message):
        """The :class:`~acausal.runtime.result.Result` of the stored ``rows``
        (:class:`~acausal.runtime.result.Rows`)."""
        return Result(run.cm, run.p, rows, list(run.events), stats, status, message)
