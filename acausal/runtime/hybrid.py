"""Stage 6: the hybrid simulation loop around SUNDIALS IDA (scikit-sundae).

IDA integrates until a root function crosses zero. Then the owning
component's event action changes discrete values (a contact mode, a stick/
slip mode), the algebraic unknowns and derivatives are recomputed
consistently, events flagged ``recheck`` are iterated to a fixed point, and
integration restarts (the hybrid DAE scheme of Barton and Pantelides 1994,
"Modeling of combined discrete/continuous processes", AIChE J. 40). Time
events (:mod:`.timeevents`) end a segment exactly at their instant. Output:
requested times, plus both sides of every event. A burst of events in a tiny
window stops the run with a :class:`ChatteringError` naming the component.

What a run does besides (the forward sensitivities) is a
:class:`~acausal.runtime.observer.RunObserver` whose hooks the loop calls at
fixed points (:mod:`.observer`); the loop itself has no branch for it.
"""
import os
import sys
import time as _time
from collections import Counter, deque
from dataclasses import dataclass, fields
from typing import NamedTuple

import numpy as np

from .backends import BACKENDS, BackendError, make_solver
from ..errors import ChatteringError, Interrupted, LimitError, ModelError, OutputGridError, \
    SolverError, UsageError
from .events import EventState
from .initialize import ask_components, initial_point, reinitialize, suspect_parameters
from .nominal import nominal_atol
from .observer import Point, RunObserver
from .result import Rows
from .timeevents import TimeSchedule

CHATTER_COUNT = 100     # this many firings of one event (root) ...
CHATTER_SPAN = 1e-9     # ... within this fraction of the time span is chattering
MAX_ITER = 20           # event iterations at one instant
DEFAULT_BACKEND = "sundae"
SAME_INSTANT = 256 * np.finfo(float).eps   # (relative) times closer than this are one
MAX_ROWS = 1_000_000    # stored output rows, by default (each 8 bytes per unknown, twice)
WINDOW_S = 0.25         # wall time per integration window when watched [s]
PROGRESS_DELAY_S = 2.0  # a progress bar shows once a run has lasted this long [s]
ROW_FACTOR = 3          # memory of a stored row: its arrays, the result's copy, the CSV


class _StopRequest:
    """A request to stop the running simulations now, keeping their rows
    (the command line's Ctrl-C and SIGTERM handler, a memory watchdog):
    :func:`request_stop` sets ``reason``; each run checks it between solver
    calls and, through its wrapped residual or the compiled backend's
    guard, inside them. ``active``: runs in progress in this process;
    ``armed``: a handler may request a stop (the command line's), so runs
    check for it inside their solver calls too."""
    reason = None
    active = 0
    armed = False


STOP = _StopRequest()


def request_stop(reason):
    """Ask the running simulation(s) to stop with their partial result;
    False when none is running (the caller then interrupts as it would, and
    nothing is left set: a request made between runs stopped the next run of
    the process at its start, as 'interrupted')."""
    if STOP.active <= 0:
        return False
    STOP.reason = reason
    return True


@dataclass(frozen=True)
class RunOptions:
    """The settings of one run: the keywords of :func:`simulate` besides
    ``t_end``, ``t0``, ``params`` and ``sensitivities`` (see there)."""
    rtol: float = 1e-6
    atol: object = 1e-8
    output_step: object = None
    output_times: object = None
    max_step: object = None
    max_steps: int = 100000
    atol_algebraic: object = None
    backend: object = None
    max_rows: object = MAX_ROWS
    max_wall: object = None
    max_total_steps: object = None
    progress: bool = False
    linsolver: str = "auto"
    max_memory: object = None

    @classmethod
    def of(cls, options):
        """The settings of ``simulate``'s keywords ``options``."""
        for name in options:
            if name not in _RUN_OPTIONS:
                raise TypeError(f"simulate() got an unexpected keyword argument {name!r}")
        return cls(**options)


_RUN_OPTIONS = frozenset(f.name for f in fields(RunOptions))


def _output_times(t0, t_end, output_step, output_times):
    if output_times is not None:
        ts = np.asarray(output_times, dtype=float).ravel()
        if not (ts[1:] >= ts[:-1]).all():    # (the diagnosis's sample times are sorted)
            ts = np.sort(ts)
        return ts[(ts >= t0) & (ts <= t_end)]
    if output_step == 0:   # every internal step of the solver
        return np.array([t0, t_end], dtype=float)
    step = output_step or (t_end - t0) / 500.0
    n = int(np.floor((t_end - t0) / step + 1e-9))
    ts = t0 + step * np.arange(n + 1)
    if ts[-1] < t_end - 1e-12 * max(1.0, abs(t_end)):
        ts = np.append(ts, t_end)
    return ts


def _atol(cm, atol):
    """A scalar, or a dict of absolute tolerances by variable name (any
    variable that is, up to sign, one of the solver's unknowns: ``mass.v``
    works whether the solver keeps ``mass.v`` or ``der(mass.s)``), with
    ``"*"`` the default for the others."""
    if not isinstance(atol, dict):
        return float(atol)
    slots = cm.slot_names()
    default = float(atol.get("*", 1e-8))
    out = np.full(len(cm.dae.y), default)
    for name, value in atol.items():
        if name == "*":
            continue
        hits = [i for i, names in enumerate(slots) if name in names]
        if not hits:
            raise ModelError(f"atol: {name!r} is not (up to sign) one of the solver's "
                             "unknowns: " + ", ".join(n[0] for n in slots))
        out[hits[0]] = float(value)
    return out


def atol_vector(cm, atol, atol_algebraic):
    """The absolute tolerances of a run of ``cm``: ``atol`` (a scalar, or a
    dict by variable name with ``"*"`` the default), with ``atol_algebraic``
    on the algebraic unknowns (those after the states) when given: their
    magnitudes (forces, accelerations) can be far from the states' and the
    local error test on them can make IDA fail to make progress."""
    atol = _atol(cm, atol)
    if atol_algebraic is None:
        return atol
    if not (atol_algebraic > 0 and np.isfinite(atol_algebraic)):
        raise UsageError(f"atol_algebraic must be a positive number, got {atol_algebraic!r}")
    vec = np.broadcast_to(np.asarray(atol, dtype=float), (len(cm.dae.y),)).copy()
    vec[cm.dae.n_states:] = float(atol_algebraic)
    return vec


class _Run:
    """One run: the model the solver integrates (``cm``), the parameters,
    the solver options, the stored rows and events, and the observer."""

    def __init__(self, cm, p, span, opts, backend="sundae", observer=None):
        self.cm, self.p = cm, np.asarray(p, float)
        self.backend = backend
        self.t0, self.t_end = span
        self.opts = opts    # rtol, atol, max_step, max_num_steps, linsolver (the backend's)
        self.observer = observer or RunObserver()
        self.T, self.Y, self.YP, self.D = [], [], [], []
        self.events, self.event_log = [], []
        self.firings = {}    # (owner, event name) -> times of its last CHATTER_COUNT firings
        self.nfev = self.njev = self.steps = self.rows = 0
        self._served = {}
        self.rechecks = [i for i, e in enumerate(cm.events) if e.recheck]  # (_event_iteration)

    def record(self, t, y, yp, d):
        self.T.append(np.atleast_1d(np.asarray(t, float)))
        self.Y.append(np.atleast_2d(np.asarray(y, float)))
        self.YP.append(np.atleast_2d(np.asarray(yp, float)))
        D = np.empty((len(self.T[-1]), len(d)))
        D[:] = d
        self.D.append(D)
        self.observer.on_rows(self, len(self.T[-1]))
        self.rows += len(self.T[-1])

    def trim(self, n):
        """Keep only the first ``n`` stored rows (at least the first)."""
        n = max(int(n), 1)
        if self.rows <= n:
            return
        kept = 0
        for k, block in enumerate(self.T):
            if kept + len(block) >= n:
                m = n - kept
                for blocks in (self.T, self.Y, self.YP, self.D):
                    blocks[k] = blocks[k][:m]
                    del blocks[k + 1:]
                break
            kept += len(block)
        self.rows = n

    def callbacks(self, d):
        """Mode ``d``'s callbacks of the integrated model (:meth:`serve`)."""
        return self.serve(self.cm, d)

    def serve(self, model, d):
        """``model``'s callbacks in mode ``d`` as this run's backend serves
        them (the compiled backend's call C: :meth:`SegmentSolver.serve`),
        made once per model and mode of the run (contacts switch back and
        forth; a sensitivity run serves its augmented model and the base model)."""
        key = (id(model),) + tuple(map(float, d))
        cb = self._served.get(key)
        if cb is None:
            cb = self._served[key] = self.solver().serve(model, self.p, list(key[1:]))
        return cb

    def solver(self):
        """The segment solver of this run (:mod:`acausal.runtime.backends`), made once."""
        if getattr(self, "_solver", None) is None:
            self._solver = make_solver(self.backend, self.cm, self.p, self.opts)
            self.backend = self._solver.name
        return self._solver

    def result(self, status="ok", message=""):
        stats = dict(nfev=self.nfev, njev=self.njev, steps=self.steps,
                     events=len(self.events), backend=self.backend)
        solver = getattr(self, "_solver", None)
        if solver is not None and solver.detail:
            stats["backend_detail"] = solver.detail
        if solver is not None and solver.fallback:
            stats["backend_fallback"] = solver.fallback
        n = len(self.cm.dae.y)
        T = _concat(self.T, 0) if self.T else np.zeros(0)
        rows = Rows(T, _concat(self.Y, n), _concat(self.YP, n),
                    _concat(self.D, len(self.cm.disc_syms)))
        return self.observer.finish(self, rows, stats, status, message)


def _concat(blocks, width):
    """The row blocks ``blocks`` as one array (``width`` columns when none)."""
    return np.concatenate(blocks) if blocks else np.zeros((0, width))


class _State(NamedTuple):
    """Where the loop is: the point ``(t, y, y')``, the discrete values ``d``
    and their callbacks ``cb``, and whether a terminal event fired."""
    t: float
    y: np.ndarray
    yp: np.ndarray
    d: list
    cb: object
    stop: bool


def simulate(cm, t_end=1.0, t0=0.0, params=None, sensitivities=None, **options):
    """Simulate a :class:`~acausal.runtime.model.CompiledModel` from ``t0``
    to ``t_end`` (or until a terminal event). ``params`` overrides
    parameter values, and the start values of variables whose start is
    fixed, by dotted path (both are runtime values: nothing is recompiled).
    The other keywords (:class:`RunOptions`):

    ``rtol`` (1e-6), ``atol`` (1e-8; a scalar, or a dict by variable name,
    ``"*"`` the default) and ``atol_algebraic``: ``atol`` applies to every
    unknown unless ``atol_algebraic`` is given: then the algebraic unknowns
    (forces, torques, dummy derivatives, constrained positions; everything
    but the selected states) get that absolute tolerance instead. IDA puts
    them into its local error test (and Newton convergence test); one that
    is computed as the small difference of large terms (a cam force
    balancing a kilonewton preload) and crosses zero can then fail the test
    with a tight SI ``atol`` at every step there, so that the step size
    collapses. A large value (e.g. 1e-2) practically leaves them out of the
    error test (like IDA's ``suppressalg``, which scikit-sundae does not
    expose); their accuracy then follows from the states'. Default
    ``None``: ``atol`` for all, as before.

    ``output_step`` (default: 500 intervals; 0: every internal step of the
    solver) or ``output_times``; ``max_step``; ``max_steps`` (100000: IDA's
    limit between two outputs).

    ``backend`` chooses the integrator (:mod:`acausal.runtime.backends`):
    ``"sundae"`` (the reference) or ``"compiled"`` (IDA calling generated
    C); ``None`` takes the environment variable ``ACAUSAL_BACKEND``, else
    :data:`DEFAULT_BACKEND`. ``res.stats["backend"]`` says which one ran.

    Limits (each stops the run with a :class:`~acausal.errors.LimitError`
    that keeps the partial result and names the component whose events
    dominate): ``max_rows`` stored output rows (checked before the run for
    the requested output grid, and during it); ``max_wall`` seconds of wall
    time; ``max_total_steps`` solver steps in the whole run (``max_steps``
    is IDA's limit between two outputs). ``progress``: a progress bar on
    stderr, shown once a run has lasted 2 s (it does not change the
    solution). With a wall or step limit the time span is integrated in
    windows of about a quarter of a second of wall time each (see
    :class:`_Watch`). ``max_memory`` (bytes): the stored rows are also
    capped so that they fit in it (about :data:`ROW_FACTOR` x 8 bytes per
    stored number); a requested output grid that does not fit is refused
    before the run. A stop requested by :func:`request_stop` (the command
    line's Ctrl-C and SIGTERM) ends the run like a limit, with an
    :class:`~acausal.errors.Interrupted` error holding the partial result.
    Every limit keeps the rows computed up to the stop, also when it falls
    inside one solver call (the solver's own steps, ``output_step=0``).

    ``linsolver``: IDA's linear solver, see
    :meth:`acausal.runtime.model.CompiledModel.linear_solver` (``"auto"``
    chooses band for large models with a narrow band, else dense).

    ``sensitivities``: names of free parameters; the run then also integrates
    the forward sensitivities of every unknown with respect to them, with
    their jumps at events (:mod:`acausal.runtime.sensitivity`), on either
    backend: ``res.sensitivity("body.x", "spring.c")`` is
    d(body.x)/d(spring.c) at every ``res.t``,
    ``res.event_sensitivity("spring.c")`` the derivatives of the event times."""
    wall0 = _time.perf_counter()
    s = RunOptions.of(options)
    _check_times(t0, t_end, s.rtol, s.atol, s.max_rows, s.max_wall, s.max_total_steps,
                 s.max_memory)
    _check_output_size(cm, t0, t_end, s.output_step, s.output_times, s.max_rows, s.max_memory)
    run, state = _start(cm, (t0, t_end), params, s, _backend(s.backend), sensitivities)
    tout = _output_times(t0, t_end, s.output_step, s.output_times)
    run.record(t0, state.y, state.yp, state.d)
    max_rows = _row_cap(cm, s.max_rows, s.max_memory)
    watch = _Watch(run, wall0, max_rows, s.max_wall, s.max_total_steps, s.progress)
    STOP.active += 1
    try:
        _integrate(run, watch, state, tout, s.output_step == 0)
    except SolverError as exc:
        exc.result = exc.result or run.result("failed", str(exc))
        exc.result.stats["wall_s"] = _time.perf_counter() - wall0
        raise
    finally:
        STOP.active -= 1
        if STOP.active == 0:
            STOP.reason = None     # the request is answered
        watch.close()
    res = run.result()
    res.stats["wall_s"] = _time.perf_counter() - wall0
    res.stats["compile_s"] = cm.compile_s
    return res


def _observer(cm, sensitivities):
    """The run's observer: the plain run, or the forward sensitivities with
    respect to the parameters ``sensitivities``."""
    if not sensitivities:
        return RunObserver()
    from .sensitivity import sensitivity_model
    from .sensitivity_run import SensitivityObserver
    return SensitivityObserver(sensitivity_model(cm, sensitivities))


def _start(cm, span, params, settings, backend, sensitivities):
    """The run and where its loop starts (:class:`_State`): the consistent
    point at ``t0``, after the event iteration there."""
    params, starts = cm.split_overrides(params)
    p = cm.param_vector(params)
    d = cm.discrete_start()
    atol = nominal_atol(cm, atol_vector(cm, settings.atol, settings.atol_algebraic),
                        settings.rtol, settings.atol)
    observer = _observer(cm, sensitivities)
    model, atol = observer.system(cm, atol, p)
    opts = dict(rtol=settings.rtol, atol=atol, max_step=settings.max_step or 0.0,
                max_num_steps=settings.max_steps, linsolver=settings.linsolver)
    t0 = span[0]
    run = _Run(model, p, span, opts, backend, observer)
    run.schedule = TimeSchedule(cm, p, *span)
    d, _ = run.schedule.update(t0, d, start=True)   # the time switches' values at t0
    cb = run.serve(cm, d)
    y, yp = initial_point(cm, p, d, cb, t0, starts)
    y, yp, d, cb = observer.on_start(run, Point(t0, y, yp), d, cb, starts)
    run.cb_d = list(d)
    return run, _State(t0, *_event_iteration(run, cb, t0, y, yp, d))


def _integrate(run, watch, state, tout, every_step, t_stop=None):
    """The hybrid loop: segments between events (each ends at a terminal
    root, a time event, the end or a window of the watch), observer roots,
    event actions with re-initialisation and event iteration; output is
    recorded in ``run``. It ends at ``t_stop`` (default: the run's end) or at
    a terminal event, and returns the :class:`_State` it reached."""
    t, y, yp, d, cb, stop = state
    t_end = run.t_end if t_stop is None else t_stop
    while not stop and t < t_end - SAME_INSTANT * max(abs(t), abs(t_end)):
        if not run.schedule.empty():
            y, yp, d, cb, stop = _time_events(run, cb, Point(t, y, yp), d)
            if stop:
                break
        tspan = _tspan(t, tout, t_end, watch.horizon(t), run.schedule.next(t, d))
        seg = watch.solve(run.solver(), watch.wrap(cb, tspan), d, tspan, y, yp,
                          every_step=every_step)
        run.nfev += seg.nfev
        run.njev += seg.njev
        run.steps += seg.steps
        if watch.stopping:     # a limit or a stop request inside the call: keep its rows
            st = np.asarray(seg.t, float)
            keep = (st > float(run.T[-1][-1])) & np.r_[False, np.diff(st) > 0]
            if watch.stopping == "rows" and watch.max_rows is not None:
                keep[np.cumsum(keep) > max(int(watch.max_rows) - run.rows, 0)] = False
            if keep.any():
                run.record(np.asarray(seg.t)[keep], np.asarray(seg.y)[keep],
                           np.asarray(seg.yp)[keep], d)
            raise watch._error(watch.stopping, float(run.T[-1][-1]))
        if len(seg.t) > 1:
            run.record(seg.t[1:], seg.y[1:], seg.yp[1:], d)
        if seg.status < 0:
            _observers(run, cb, seg, d)   # those located before it (a dead-centre warning)
            raise _failure(run, run.cm, seg, cb)
        t, y, yp = float(seg.t[-1]), np.array(seg.y[-1]), np.array(seg.yp[-1])
        watch.check(t)
        d, fired = _observers(run, cb, seg, d)
        if d != run.cb_d:
            cb = run.callbacks(d)
        run.cb_d = list(d)
        if seg.status != 2:
            if tspan[-1] < t_end:   # the end of a window of the watch
                continue
            break
        d_before = list(d)
        y, yp, d, cb, stop = _handle(run, cb, Point(t, y, yp), d, fired)
        if list(d) != d_before:
            run.record(t, y, yp, d)
    return _State(t, y, yp, d, cb, stop)



class Stepper:
    """The hybrid loop advanced on demand, one interval at a time (a
    co-simulation's doStep, :mod:`acausal.interop.fmu`).

    ``Stepper(cm, params, t0, **options)`` initialises at ``t0`` exactly as
    :func:`simulate` does (the consistent start, then the event iteration);
    ``options`` are :func:`simulate`'s ``t_end`` (the end of the whole run,
    which sizes the chattering guard), ``rtol``, ``atol``, ``atol_algebraic``,
    ``max_step``, ``max_steps``, ``backend``, ``linsolver`` and
    ``output_step``. :meth:`advance` integrates to a later time across every
    event on the way (each interval starts the integrator afresh, as an event
    does); :meth:`set_parameters` changes free parameters between intervals
    (the states are kept, the algebraic unknowns and derivatives
    re-initialised, then the event iteration runs). ``keep=True`` keeps every
    output row on :meth:`result` (on the ``output_step`` grid, 0: every
    solver step), for measures of the run so far; else only the last point.
    ``stopped`` is True once a terminal event fired; ``t, y, yp, d`` is the
    point reached."""

    OPTIONS = dict(t_end=1.0, rtol=1e-6, atol=1e-8, atol_algebraic=None, max_step=None,
                   max_steps=100000, backend=None, linsolver="auto", output_step=None)

    def __init__(self, cm, params=None, t0=0.0, keep=False, **options):
        unknown = sorted(set(options) - set(self.OPTIONS))
        if unknown:
            raise UsageError(f"Stepper: unknown option {unknown[0]!r}; options: "
                             + ", ".join(self.OPTIONS))
        o = {**self.OPTIONS, **options}
        wall0 = _time.perf_counter()
        self.cm, self.keep, self.t_end = cm, keep, float(o["t_end"])
        self.output_step = o["output_step"] if keep else None
        settings = RunOptions.of({k: v for k, v in o.items()
                                  if k not in ("t_end", "output_step")})
        run, state = _start(cm, (t0, self.t_end), params, settings, _backend(o["backend"]),
                            None)
        _, y, yp, d, cb, stop = state
        self.run, self.cb, self.stopped = run, cb, stop
        self.t, self.y, self.yp, self.d = float(t0), y, yp, list(d)
        self.grid = (_output_times(t0, self.t_end, self.output_step, None)
                     if keep and self.output_step != 0 else np.zeros(0))
        run.record(t0, y, yp, d)
        self.watch = _Watch(run, wall0, None, None, None, False)

    def advance(self, t_to):
        """Integrate from :attr:`t` to ``t_to`` (or to a terminal event before
        it: then :attr:`stopped`). A solver failure raises its SolverError."""
        t_to = float(t_to)
        if self.stopped or not t_to > self.t:
            return
        if not self.keep:   # only the last point is kept
            run = self.run
            for rows in (run.T, run.Y, run.YP, run.D):
                rows[:] = [rows[-1][-1:]]
        tout = self.grid[(self.grid > self.t) & (self.grid < t_to)]
        tout = np.append(tout, t_to)
        state = _State(self.t, self.y, self.yp, self.d, self.cb, False)
        t, y, yp, d, cb, stop = _integrate(self.run, self.watch, state, tout,
                                           self.output_step == 0, t_stop=t_to)
        self.t, self.y, self.yp, self.d, self.cb = float(t), y, yp, list(d), cb
        self.stopped = bool(stop)

    def set_parameters(self, values):
        """Set free parameters (name -> value, checked against their bounds)
        at the current time; a change re-initialises the algebraic unknowns
        and derivatives (the states are kept) and runs the event iteration."""
        cm, run = self.cm, self.run
        p = run.p.copy()
        for name, value in values.items():
            i = cm.param_index(name)
            p[i] = cm.param_vector({name: value})[i]
        if np.array_equal(p, run.p):
            return
        run.p[:] = p
        run._served.clear()
        run._solver = None   # a new segment solver takes the new values
        cb = run.callbacks(self.d)
        run.cb_d = list(self.d)
        y, yp = reinitialize(cm, cb, self.t, self.y, self.yp)
        y, yp, d, cb, stop = _event_iteration(run, cb, self.t, y, yp, self.d)
        self.y, self.yp, self.d, self.cb = y, yp, list(d), cb
        self.stopped = self.stopped or bool(stop)
        run.record(self.t, y, yp, d)

    def observed(self):
        """The values of ``cm.var_names`` at the current point."""
        return np.asarray(self.cb.observe(self.t, self.y, self.yp), dtype=float)

    def result(self):
        """The :class:`Result` of the run so far (see ``keep``)."""
        return self.run.result("stopped" if self.stopped else "ok")


# ---------------------------------------------------------------------------
# Limits and progress of a run (output rows, wall time, steps)
# ---------------------------------------------------------------------------


def _output_count(t0, t_end, output_step, output_times):
    """Rows the requested output grid will store (before building it)."""
    if output_times is not None:
        return len(output_times)
    if output_step == 0:
        return 2
    step = output_step or (t_end - t0) / 500.0
    return (t_end - t0) / step + 1


def _count(n):
    """A count as '1,000,001' (exact below 1e9), else '5e+13'."""
    return f"{n:,.0f}" if n < 1e9 else f"{n:.3g}"


def _row_bytes(cm):
    """Bytes one stored output row takes, all copies counted (:data:`ROW_FACTOR`)."""
    return ROW_FACTOR * 8 * (2 * len(cm.dae.y) + len(cm.discretes) + 1)


def _row_cap(cm, max_rows, max_memory):
    """``max_rows``, lowered so that the stored rows fit in ``max_memory``."""
    if max_memory is None:
        return max_rows
    cap = max(2, int(max_memory // _row_bytes(cm)))
    return cap if max_rows is None else min(max_rows, cap)


def _check_times(t0, t_end, rtol, atol, max_rows, max_wall, max_total_steps, max_memory):
    """The run's times, tolerances and limits are numbers in range (a
    UsageError naming the one that is not; -1 or nan reached IDA and
    numpy as tracebacks)."""
    def bad(name, value, what):
        raise UsageError(f"{name} = {value!r}: must be {what}", variable=name)
    for name, value in (("t0", t0), ("t_end", t_end)):
        if not isinstance(value, (int, float, np.floating, np.integer)) or \
                not np.isfinite(value):
            bad(name, value, "a finite number")
    if not t_end >= t0:     # (t_end = t0: the consistent initial point alone, as linearize asks)
        bad("t_end", t_end, f"at or after t0 = {t0:g} s")
    if not (isinstance(rtol, (int, float, np.floating)) and 0 < rtol < 1):
        bad("rtol", rtol, "a number between 0 and 1")
    atols = list(atol.values()) if isinstance(atol, dict) else \
        np.ravel(np.asarray(atol, dtype=float)).tolist() if not isinstance(atol, str) else [atol]
    if not all(isinstance(a, (int, float)) and np.isfinite(a) and a > 0 for a in atols):
        bad("atol", atol, "a finite number > 0")
    for name, value in (("max_rows", max_rows), ("max_wall", max_wall),
                        ("max_total_steps", max_total_steps), ("max_memory", max_memory)):
        if value is not None and not (np.isfinite(value) and value > 0):
            bad(name, value, "a number > 0 (or None: no limit)")


def _check_output_size(cm, t0, t_end, output_step, output_times, max_rows, max_memory=None):
    """Refuse, before allocating it, an output grid of more than ``max_rows``
    rows, or of more than ``max_memory`` bytes."""
    n = _output_count(t0, t_end, output_step, output_times)
    need = n * _row_bytes(cm)
    grid = ("the output times" if output_times is not None else
            f"the output grid (every {output_step or (t_end - t0) / 500:g} s from {t0:g} "
            f"to {t_end:g} s)")
    if max_rows is not None and n > max_rows:
        raise OutputGridError(
            f"{grid} has {_count(n)} rows (~{need / 1e9:.3g} GB), more than max_rows = "
            f"{_count(max_rows)}: choose a larger output step, output_step=0 (the solver's own "
            "steps), a shorter t_end, or raise max_rows (--max-rows)", t=t0)
    if max_memory is not None and need > max_memory:
        raise OutputGridError(
            f"{grid} has {_count(n)} rows, which need about {need / 1e9:.3g} GB, more than the "
            f"memory limit {max_memory / 1e9:.3g} GB: choose a larger output step, a shorter "
            "t_end, or raise the limit (--max-memory)", t=t0)


def _tspan(t, tout, t_end, horizon, t_event=np.inf):
    """Times of the next solver call: ``t``, then the output times (``tout``,
    sorted) after it,
    up to ``t_end`` (which ends the span), or up to ``horizon`` when a watch
    cuts the run into windows (at least one output time), or up to the
    next time event ``t_event`` (which then ends the span: the solver
    stops exactly there)."""
    # an output time closer to t than IDA can step (it refuses a tout within
    # 100 unit round-offs of t: an output 1 ulp after a time event) is t
    after = t + SAME_INSTANT * max(abs(t), abs(t_end))
    i = int(np.searchsorted(tout, after, "right"))    # (``tout`` is sorted) tout[i:] > after
    if t_event < t_end and (horizon is None or t_event <= horizon):
        j = max(i, int(np.searchsorted(tout, t_event, "left")))
        return np.concatenate([[t], tout[i:j], [t_event]])
    later = tout[i:]
    if horizon is not None and horizon < t_end:
        cut = later[later <= horizon]
        if len(cut) == 0:
            cut = later[:1] if len(later) else np.array([horizon])
        return np.concatenate([[t], cut])
    return np.concatenate([[t], later if len(later) and later[-1] >= t_end
                           else np.append(later, t_end)])


class _Watch:
    """The limits and the progress bar of one run.

    Between two solver calls: the stored rows, the wall time, the steps and
    a stop request (:data:`STOP`) are checked (:meth:`check`), the progress
    bar moves. With a wall or step limit the span is cut into windows
    (:meth:`horizon`) sized to take about ``WINDOW_S`` of wall time each
    (every window restarts IDA, like an event). Inside a solver call the
    residual is wrapped (:meth:`wrap`; the compiled backend calls
    :meth:`guard` each time its output buffer fills): a call that runs far
    past a limit, stores every step past ``max_rows``, or meets a stop
    request, is ended (``stopping`` says why) and the rows it computed
    until then are kept: the Python residual then returns NaN, so that IDA
    gives up at its last accepted step and returns what it has (scikit-sundae
    loses a call's rows when the residual raises), and the compiled
    backend's guard returns True."""

    def __init__(self, run, wall0, max_rows, max_wall, max_total_steps, progress):
        self.run, self.wall0 = run, wall0
        self.max_rows, self.max_wall, self.max_steps = max_rows, max_wall, max_total_steps
        self.windowed = max_wall is not None or max_total_steps is not None
        self.span = run.t_end - run.t0
        self.dt = self.span * 1e-4   # grows by up to 8x a window
        self.bar = _progress_bar(self.span) if progress else None
        self.t_call = None
        self.counter = None
        self.every_step = False
        self.stopping = None

    def horizon(self, t):
        return t + self.dt if self.windowed else None

    def wrap(self, cb, tspan):
        """``cb`` with its residual checking the limits and moving the
        progress bar every 64 calls (when limits are set, a bar is shown,
        a stop may be requested or the call stores every step, as a
        two-point ``tspan`` does; else ``cb`` itself); once the call is
        to stop, the residual is NaN and the Jacobian is not evaluated."""
        res, count, calls = cb.res, cb.count, [0]
        self.counter = count
        if not self.windowed and self.bar is None and len(tspan) != 2 and not STOP.armed:
            return cb

        def checked(t, y, yp, r):
            if self.stopping:
                r[:] = np.nan
                return
            calls[0] += 1
            if calls[0] % 64 == 0:
                self.stopping = self._hard(count[0])
                self._show(t)
                if self.stopping:
                    # IDA's message about the failure it is led into is caught
                    # by the backend (backends.sundae), which prints nothing
                    r[:] = np.nan
                    return
            res(t, y, yp, r)

        def jacobian(fn):
            def jac(*args):
                if not self.stopping:
                    fn(*args)
            return jac
        return cb._replace(res=checked, jac=jacobian(cb.jac), jac_csc=jacobian(cb.jac_csc))

    def _show(self, t):
        if self.bar is not None and t - self.run.t0 > self.bar.n:
            self.bar.update(t - self.run.t0 - self.bar.n)

    def _hard(self, steps_now):
        """Why the current solver call must end now, or None: a stop
        request; a limit exceeded (far exceeded when windows will stop the
        run at their end; exactly when the call stores every step, which
        no window cuts)."""
        if STOP.reason:
            return "interrupt"
        steps = self.run.steps + steps_now
        wall = _time.perf_counter() - self.wall0
        exact = self.every_step
        if self.max_wall is not None and wall > (
                self.max_wall if exact else 1.25 * self.max_wall + 1.0):
            return "wall"
        if self.max_steps is not None and steps > (
                self.max_steps if exact else 1.25 * self.max_steps + 1000):
            return "steps"
        if (self.every_step and self.max_rows is not None
                and self.run.rows + steps_now > self.max_rows):
            return "rows"   # every step is stored (a two-point span)
        return None

    def guard(self, steps_now, t=None):
        """The compiled backend's check, each time its output buffer fills:
        True to end the call (its rows are kept). ``t``: the last row's
        time, shown on the progress bar (a run of one long segment showed
        its bar only at its end)."""
        if t is not None:
            self._show(t)
        self.stopping = self.stopping or self._hard(steps_now)
        return bool(self.stopping)

    def solve(self, solver, cb, d, tspan, y, yp, every_step):
        """One segment of ``solver`` (:mod:`acausal.runtime.backends`) over ``tspan``;
        a limit far exceeded inside it (seen by the wrapped residual of a
        Python backend, or the compiled backend's guard) or a stop request
        ends the call early, with ``stopping`` set."""
        self.t_call = _time.perf_counter()
        self.every_step = len(tspan) == 2
        solver.guard = self.guard
        try:
            return solver.solve(cb, d, float(tspan[0]), y, yp, tspan[1:], every_step)
        finally:
            # no cycle solver -> watch -> run -> solver: the run's IDA handle
            # goes back to the backend's pool as soon as the run is dropped
            solver.guard = None

    def check(self, t):
        """After a solver call that reached ``t``: limits, progress, next window."""
        run, now = self.run, _time.perf_counter()
        if self.t_call is not None and self.windowed:
            took = max(now - self.t_call, 1e-6)
            self.dt *= min(8.0, max(0.25, WINDOW_S / took))
        if self.bar is not None:
            self._show(t)
            self.bar.set_postfix(steps=run.steps, events=len(run.events), refresh=False)
        if STOP.reason:
            raise self._error("interrupt", t)
        if self.max_rows is not None and run.rows > self.max_rows:
            raise self._error("rows", t)
        if self.max_wall is not None and now - self.wall0 > self.max_wall:
            raise self._error("wall", t)
        if self.max_steps is not None and run.steps > self.max_steps:
            raise self._error("steps", t)

    def _error(self, which, t):
        run = self.run
        what = {"rows": ("more than max_rows = {:g} stored output rows", self.max_rows),
                "wall": ("the wall-time limit max_wall = {:g} s", self.max_wall),
                "steps": ("the step limit max_total_steps = {:g}", self.max_steps),
                "interrupt": ("{}", STOP.reason)}[which]
        what = what[0].format(what[1])
        if which == "rows" and self.max_rows is not None:
            run.trim(int(self.max_rows))
        t_last = float(run.T[-1][-1]) if run.T else t
        why = (_dominant(run) if which not in ("rows", "interrupt") else
               "an output step, a shorter t_end or a larger max_rows (--max-rows) stores less"
               if which == "rows" else "the result up to there is kept")
        msg = (f"stopped at t = {t_last:.6g} s of {run.t_end:g} s by {what} "
               f"({run.steps} steps, {len(run.events)} events, "
               f"{_time.perf_counter() - self.wall0:.3g} s): {why}")
        cls = Interrupted if which == "interrupt" else LimitError
        return cls(msg, t=t_last, component=_dominant_owner(run),
                   result=run.result("stopped", msg))

    def close(self):
        if self.bar is not None:
            self.bar.close()


def _progress_bar(span):
    from tqdm import tqdm
    return tqdm(total=span, desc="simulate", unit="s", file=sys.stderr, delay=PROGRESS_DELAY_S,
                bar_format="{desc}: {percentage:3.0f}%|{bar}| t = {n:.4g}/{total:.4g} s "
                           "[{elapsed}<{remaining}{postfix}]")


def _dominant_owner(run, last=1000):
    owners = Counter(o for _, o in run.event_log[-last:])
    return owners.most_common(1)[0][0] if owners else None


def _dominant(run, last=1000):
    """Which component's events dominate the recent ones, in words."""
    recent = run.event_log[-last:]
    if not recent:
        return ("no events: the time went into the solver's own steps (a long span, or a "
                "stiff model: a very stiff spring or contact, a very light body)")
    owner, n = Counter(o for _, o in recent).most_common(1)[0]
    names = Counter(nm for (tt, nm) in run.events[-last:]).most_common(2)
    return (f"{100 * n / len(recent):.0f}% of the last {len(recent)} events are in {owner} "
            f"({', '.join(nm for nm, _ in names)})")


def _backend(name):
    """The backend to run: ``name``, else the ``ACAUSAL_BACKEND`` environment
    variable, else :data:`DEFAULT_BACKEND`."""
    name = name or os.environ.get("ACAUSAL_BACKEND") or DEFAULT_BACKEND
    if name not in BACKENDS:
        raise BackendError(f"unknown backend {name!r}; choose one of: {', '.join(BACKENDS)}")
    return name


# ---------------------------------------------------------------------------
# Events: observer roots, the events that end a segment, time events, the
# event iteration
# ---------------------------------------------------------------------------


def _observers(run, cb, seg, d):
    """Run the actions of observer events located during the segment (it
    did not stop for them), in time order; the discrete values they record
    are written into the rows from their time on. Returns the discrete
    values and the events that ended the segment (without its observers)."""
    cm = run.cm
    d = list(d)
    n_ev = len(cm.events)
    final = []
    last = len(seg.roots) - 1
    for k, root in enumerate(seg.roots):
        obs = [i for i in root.fired if i < n_ev and cm.events[i].observer]
        if k == last and seg.status == 2:
            final = [i for i in root.fired if i not in obs]
        if not obs:
            continue
        te = root.t
        point = Point(te, root.y, root.yp)
        state = EventState(cm, run.p, d, te, cb.observe(te, root.y, root.yp))
        before = list(d)
        run.observer.on_event(run, point, d, obs, "observer")
        for i in obs:
            _log_event(run, te, cm.events[i], i)
            cm.events[i].action(state)
        for j, (a, b) in enumerate(zip(before, d)):
            if a != b:
                if j in cm.dynamic_discretes():
                    raise SolverError(
                        f"{cm.events[obs[0]].owner}: observer event {cm.events[obs[0]].name!r} "
                        f"changed {cm.discretes[j].symbol.name}, which the equations use; "
                        "make it a regular event", t=te, component=cm.events[obs[0]].owner)
                rows = run.T[-1] >= te
                run.D[-1][rows, j] = b
        run.observer.on_actions(run, [cm.events[i] for i in obs], point, before,
                                state.observed)
    return d, final


def _handle(run, cb, point, d, fired):
    """The events ``fired`` that ended a segment at ``point``: their actions,
    the new mode re-initialised and the event iteration; returns (y, y', d,
    callbacks, stop)."""
    cm = run.cm
    n_ev = len(cm.events)
    t, y, yp = point
    d = list(d)
    d_before = list(d)
    obs = cb.observe(t, y, yp)
    state = EventState(cm, run.p, d, t, obs)
    stop = False
    run.observer.on_event(run, point, d, fired, "instant")
    for i in fired:
        if i >= n_ev:
            a = cm.assertions[i - n_ev]
            raise SolverError(f"{a.owner}: {a.message} (at t = {t:.6g} s)", t=t,
                              component=a.owner, result=run.result("failed", a.message))
        ev = cm.events[i]
        _log_event(run, t, ev, i)
        if ev.action is not None:
            ev.action(state)
        if ev.terminal:
            stop = True
    if state.changed:
        d, cb, y, yp = run.observer.on_mode_change(run, [cm.events[i] for i in fired], point,
                                                   d_before, d, obs)
        y, yp, d, cb, stop2 = _event_iteration(run, cb, t, y, yp, d)
        stop = stop or stop2
    run.observer.on_instant_end(run)
    return y, yp, d, cb, stop


def _time_events(run, cb, point, d):
    """The time events due at ``point`` (:mod:`acausal.runtime.timeevents`):
    the switches set to their values after its time, the due time events'
    actions run and logged; a changed mode is re-initialised and iterated
    like any event's, and recorded after the row before it."""
    t, y, yp = point
    obs = cb.observe(t, y, yp)
    d_new, fired = run.schedule.update(t, d, obs)
    if fired:
        run.observer.on_event(run, point, d, fired, "time")
    for ev in {ev.name: ev for ev in fired}.values():   # one entry per name and instant
        _log_event(run, t, ev, ev)
    stop = False
    if list(d_new) != list(d):
        d, cb, y, yp = run.observer.on_mode_change(run, [], point, list(d), d_new, obs)
        y, yp, d, cb, stop = _event_iteration(run, cb, t, y, yp, d)
        run.record(t, y, yp, d)
    run.observer.on_instant_end(run)
    return y, yp, d, cb, stop


def _event_iteration(run, cb, t, y, yp, d):
    """Fire ``recheck`` events whose condition is violated at this instant."""
    cm = run.cm
    checks = run.rechecks
    if not checks:
        return y, yp, d, cb, False
    g = np.zeros(cm.n_roots)
    for _ in range(MAX_ITER):
        cb.roots(t, y, yp, g)
        obs = cb.observe(t, y, yp)
        state = EventState(cm, run.p, list(d), t, obs)
        violated = [i for i in checks if (cm.events[i].direction < 0 and g[i] < 0)
                    or (cm.events[i].direction > 0 and g[i] > 0)]
        if violated:
            run.observer.on_event(run, Point(t, y, yp), d, violated, "recheck")
        fired = []
        for i in violated:
            ev = cm.events[i]
            _log_event(run, t, ev, i)
            fired.append(ev)
            if ev.action is not None:
                ev.action(state)
        if not state.changed:
            return y, yp, d, cb, False
        d, cb, y, yp = run.observer.on_mode_change(run, fired, Point(t, y, yp), d, state.d,
                                                   obs)
    raise ChatteringError(f"event iteration did not settle at t = {t:.6g} s "
                          f"({MAX_ITER} mode changes at one instant) in "
                          + ", ".join(sorted({cm.events[i].owner for i in checks})), t=t)


def _log_event(run, t, ev, key):
    """Record event ``ev`` in ``res.events`` (telling the observer: ``key``
    is its index in ``cm.events``, or the time event itself), unless it is
    bookkeeping (``Event(log=False)``); a ChatteringError when this same
    event (one root of one component) has fired CHATTER_COUNT times within
    CHATTER_SPAN of the run's span: its mode logic toggles without time
    advancing (Zeno). Many different roots firing at one instant (199
    contacts of a Newton's cradle closing at t = 0) are not chattering: each
    fires once."""
    if ev.log:
        run.observer.on_log(run, len(run.events), key)
        run.events.append((t, ev.name))
    run.event_log.append((t, ev.owner))
    times = run.firings.get((ev.owner, ev.name))
    if times is None:
        times = run.firings[ev.owner, ev.name] = deque(maxlen=CHATTER_COUNT)
    times.append(t)
    if len(times) == CHATTER_COUNT and \
            t - times[0] <= CHATTER_SPAN * max(run.t_end - run.t0, 1e-300):
        raise ChatteringError(
            f"chattering: event {ev.name} of {ev.owner} fired {CHATTER_COUNT} times between "
            f"t = {times[0]:.9g} and {t:.9g} s; the mode logic does not settle", t=t,
            component=ev.owner, result=run.result("failed", "chattering"))


def _failure(run, cm, sol, cb):
    """A SolverError naming the component whose equation is worst off."""
    r = type("Last", (), dict(t=float(np.atleast_1d(sol.t)[-1]), y=np.atleast_2d(sol.y)[-1],
                              yp=np.atleast_2d(sol.yp)[-1], message=sol.message))
    t = float(r.t)
    n = len(cm.dae.y)
    res = np.zeros(n)
    comp = None
    try:
        cb.res(t, np.array(r.y), np.array(r.yp), res)
        bad = ~np.isfinite(res)
        k = int(np.argmax(bad)) if bad.any() else int(np.argmax(np.abs(res)))
        org = cm.dae.origins[k]
        comp = getattr(org, "origin", None)
    except Exception:  # the residual itself may fail at the bad point
        pass
    nonfinite = [nm for nm, v in zip(cm.var_names, _safe_obs(cb, t, r)) if not np.isfinite(v)]
    where = f" in {comp}" if comp else ""
    extra = f"; non-finite values: {', '.join(nonfinite[:5])}" if nonfinite else ""
    atol = np.broadcast_to(np.asarray(run.opts["atol"], float), (n,))
    if (getattr(sol, "status", None) == -3 and not nonfinite and n > cm.dae.n_states
            and not np.any(atol[cm.dae.n_states:] > atol[:cm.dae.n_states].max())):
        extra += (f"; the step size collapsed in the error test, which also covers the "
                  f"{n - cm.dae.n_states} algebraic unknowns (forces, torques): if one of "
                  "them is a small difference of large terms, give them their own absolute "
                  "tolerance (Experiment(atol_algebraic=...) or simulate(atol_algebraic=...), "
                  "in their SI units)")
    suspect = suspect_parameters(cm, run.p)
    if suspect:
        extra += ("; " + ", ".join(f"parameter {nm} = {v:g} [{u}] is far from its default "
                                   f"{dv:g}" for nm, v, dv, u in suspect)
                  + ": check its value and unit")
    who = "IDA failed" if cm.dae.n_states else "solving the equations (no states) failed"
    message = f"{who} at t = {t:.9g} s{where}: {r.message}{extra}"
    result = run.result("failed", r.message)
    hint = ask_components(cm.model, "solver_failure", [comp] if comp else [], message, t,
                          result)
    if hint is not None:
        return hint
    return SolverError(message, t=t, component=comp, result=result,
                       variable=suspect[0][0] if suspect else None)


def _safe_obs(cb, t, r):
    try:
        return cb.observe(t, np.array(r.y), np.array(r.yp))
    except Exception:
        return []
