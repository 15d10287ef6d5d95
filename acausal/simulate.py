"""Stage 6: the hybrid simulation loop around SUNDIALS IDA (scikit-sundae).

IDA integrates until a root function crosses zero. Then the owning
component's event action changes discrete values (a contact mode, a stick/
slip mode), the algebraic unknowns and derivatives are recomputed
consistently, events flagged ``recheck`` are iterated to a fixed point, and
integration restarts. Output: requested times, plus both sides of every
event. A burst of events in a tiny window stops the run with a
:class:`ChatteringError` naming the component.
"""
import time as _time

import numpy as np
from sksundae.ida import IDA

from .errors import ChatteringError, SolverError
from .initialize import ask_components, initial_point, reinitialize
from .result import Result

CHATTER_COUNT = 100     # this many events ...
CHATTER_SPAN = 1e-9     # ... within this fraction of the time span is chattering
MAX_ITER = 20           # event iterations at one instant


class EventState:
    """What an event action sees: ``state[symbol]`` reads a variable, a
    discrete value or a parameter at the event; ``state[discrete] = v`` sets a
    discrete value."""

    def __init__(self, cm, p, d, t, obs):
        self.cm, self.p, self.d, self.t, self._obs = cm, p, d, t, obs
        self.changed = False

    def _find(self, sym):
        name = getattr(sym, "name", sym)
        for j, dsc in enumerate(self.cm.discretes):
            if dsc.symbol.name == name:
                return "d", j
        if name in self._index():
            return "v", self._index()[name]
        for j, prm in enumerate(self.cm.params):
            if prm.name == name:
                return "p", j
        for s, expr in self.cm._subs.items():   # a parameter bound to others
            if s.name == name:
                return "b", expr
        raise KeyError(f"event action asked for {name!r}, which is not in the model")

    def _index(self):
        idx = getattr(self, "_idx", None)
        if idx is None:
            idx = self._idx = {n: k for k, n in enumerate(self.cm.var_names)}
        return idx

    def __getitem__(self, sym):
        kind, j = self._find(sym)
        if kind == "b":
            return float(j.xreplace(dict(zip(self.cm.param_syms, self.p))))
        return {"d": self.d, "v": self._obs, "p": self.p}[kind][j]

    def __setitem__(self, sym, value):
        kind, j = self._find(sym)
        if kind != "d":
            raise KeyError(f"event actions may only set discrete values, not {sym}")
        if self.d[j] != value:
            self.d[j] = float(value)
            self.changed = True


def _output_times(t0, t_end, output_step, output_times):
    if output_times is not None:
        ts = np.asarray(sorted(output_times), dtype=float)
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
            from .errors import ModelError
            raise ModelError(f"atol: {name!r} is not (up to sign) one of the solver's "
                             "unknowns: " + ", ".join(n[0] for n in slots))
        out[hits[0]] = float(value)
    return out


def _atol_vector(cm, atol, atol_algebraic):
    """``atol`` (see :func:`_atol`), with ``atol_algebraic`` on the algebraic
    unknowns (those after the states) when given: their magnitudes (forces,
    accelerations) can be far from the states' and the local error test on
    them can make IDA fail to make progress."""
    atol = _atol(cm, atol)
    if atol_algebraic is None:
        return atol
    if not (atol_algebraic > 0 and np.isfinite(atol_algebraic)):
        raise ValueError(f"atol_algebraic must be a positive number, got {atol_algebraic!r}")
    vec = np.broadcast_to(np.asarray(atol, dtype=float), (len(cm.dae.y),)).copy()
    vec[cm.dae.n_states:] = float(atol_algebraic)
    return vec


class _Run:
    def __init__(self, cm, p, t0, t_end, rtol, atol, max_step, max_steps):
        self.cm, self.p = cm, np.asarray(p, float)
        self.t0, self.t_end = t0, t_end
        self.opts = dict(rtol=rtol, atol=atol, max_step=max_step or 0.0,
                         max_num_steps=max_steps)
        self.T, self.Y, self.YP, self.D = [], [], [], []
        self.events, self.event_log = [], []
        self.nfev = self.njev = self.steps = 0
        ev = cm.events
        self.directions = [e.direction for e in ev] + [-1] * len(cm.assertions)

    def record(self, t, y, yp, d):
        self.T.append(np.atleast_1d(np.asarray(t, float)))
        self.Y.append(np.atleast_2d(np.asarray(y, float)))
        self.YP.append(np.atleast_2d(np.asarray(yp, float)))
        self.D.append(np.tile(np.asarray(d, float), (len(self.T[-1]), 1)))

    def solver(self, cb):
        """The IDA object of this run, made once: its callbacks dispatch to the
        current mode's generated functions (``self.cb``), so a mode change
        only swaps them (creating an IDA object costs more than a segment of
        a short contact)."""
        self.cb = cb
        if getattr(self, "_ida", None) is not None:
            return self._ida
        kw = dict(self.opts)
        alg = list(range(self.cm.dae.n_states, len(self.cm.dae.y)))
        if alg:
            kw["algebraic_idx"] = alg

        def res(t, y, yp, r):
            self.cb[0](t, y, yp, r)

        def jac(t, y, yp, r, cj, J):
            self.cb[1](t, y, yp, r, cj, J)
        if self.cm.n_roots:
            def roots(t, y, yp, g):
                self.cb[2](t, y, yp, g)
            roots.terminal = [not e.observer for e in self.cm.events] + \
                [True] * len(self.cm.assertions)
            self._roots = roots
            roots.direction = list(self.directions)
            kw.update(eventsfn=roots, num_events=self.cm.n_roots)
        self._ida = IDA(res, jacfn=jac, **kw)
        return self._ida

    def result(self, status="ok", message=""):
        stats = dict(nfev=self.nfev, njev=self.njev, steps=self.steps,
                     events=len(self.events))
        n = len(self.cm.dae.y)
        cat = (lambda blocks, w: np.concatenate(blocks) if blocks else np.zeros((0, w)))
        return Result(self.cm, self.p, cat(self.T, 0) if self.T else np.zeros(0),
                      cat(self.Y, n), cat(self.YP, n), cat(self.D, len(self.cm.discretes)),
                      list(self.events), stats, status, message)


def simulate(cm, t_end=1.0, t0=0.0, params=None, rtol=1e-6, atol=1e-8, output_step=None,
             output_times=None, max_step=None, max_steps=100000, atol_algebraic=None):
    """Simulate a :class:`CompiledModel` from ``t0`` to ``t_end`` (or until a
    terminal event). ``params`` overrides parameter values by dotted path.

    ``atol`` applies to every unknown unless ``atol_algebraic`` is given: then
    the algebraic unknowns (forces, torques, dummy derivatives, constrained
    positions; everything but the selected states) get that absolute
    tolerance instead. IDA puts them into its local error test (and Newton
    convergence test); one that is computed as the small difference of large
    terms (a cam force balancing a kilonewton preload) and crosses zero can
    then fail the test with a tight SI ``atol`` at every step there, so that
    the step size collapses. A large value (e.g. 1e-2) practically leaves
    them out of the error test (like IDA's ``suppressalg``, which
    scikit-sundae does not expose); their accuracy then follows from the
    states'. Default ``None``: ``atol`` for all, as before."""
    wall0 = _time.perf_counter()
    p = cm.param_vector(params)
    d = cm.discrete_start()
    run = _Run(cm, p, t0, t_end, rtol, _atol_vector(cm, atol, atol_algebraic), max_step,
               max_steps)
    cb = cm.callbacks(p, d)
    run.cb_d = list(d)
    y, yp = initial_point(cm, p, d, cb, t0)
    y, yp, d, cb, stop = _event_iteration(run, cb, t0, y, yp, d, initial=True)
    tout = _output_times(t0, t_end, output_step, output_times)
    run.record(t0, y, yp, d)
    t = t0
    try:
        while not stop and t < t_end:
            ida = run.solver(cb)
            later = tout[tout > t]
            tspan = np.concatenate([[t], later if len(later) and later[-1] >= t_end
                                    else np.append(later, t_end)])
            # two points: IDA reports every internal step (output_step=0)
            _reset_event_log(getattr(run, "_roots", None))
            sol = ida.solve(tspan, y, yp)
            if len(tspan) == 2 and output_step != 0 and len(sol.t) > 2:
                # IDA reported every internal step; keep what was asked for
                keep = np.r_[0, len(sol.t) - 1]
                sol_t, sol_y, sol_yp = sol.t[keep], sol.y[keep], sol.yp[keep]
            else:
                sol_t, sol_y, sol_yp = sol.t, sol.y, sol.yp
            run.nfev += sol.nfev
            run.njev += sol.njev
            run.steps += cb[5][0]
            cb[5][0] = 0
            if sol.status < 0:
                if len(sol_t) > 1:
                    run.record(sol_t[1:], sol_y[1:], sol_yp[1:], d)
                raise _failure(run, cm, sol, cb)
            run.record(sol_t[1:], sol_y[1:], sol_yp[1:], d)
            t, y, yp = float(sol.t[-1]), np.array(sol.y[-1]), np.array(sol.yp[-1])
            d, final_fired = _observers(run, cb, sol, d)
            if d != run.cb_d:
                cb = cm.callbacks(run.p, d)
            run.cb_d = list(d)
            if sol.status != 2:
                break
            fired = final_fired
            d_before = list(d)
            y, yp, d, cb, stop = _handle(run, cb, t, y, yp, d, fired)
            if list(d) != d_before:
                run.record(t, y, yp, d)
    except SolverError as exc:
        exc.result = exc.result or run.result("failed", str(exc))
        exc.result.stats["wall_s"] = _time.perf_counter() - wall0
        raise
    res = run.result()
    res.stats["wall_s"] = _time.perf_counter() - wall0
    res.stats["compile_s"] = cm.compile_s
    return res


def _reset_event_log(roots):
    """scikit-sundae keeps the located roots (and per-event counts that decide
    when to stop) on the events function; one IDA object serves every
    segment of a run, so clear them before each segment."""
    if roots is not None and hasattr(roots, "_i"):
        for name in ("_i", "_t", "_y", "_yp"):
            getattr(roots, name).clear()
        roots._i_cnt[:] = 0


def _observers(run, cb, sol, d):
    """Run the actions of observer events IDA located during the segment (it
    did not stop for them), in time order; the discrete values they record
    are written into the rows from their time on. Returns the discrete
    values and the events that ended the segment (without its observers)."""
    cm = run.cm
    roots = getattr(run, "_roots", None)
    if roots is None or not getattr(roots, "_i", None):
        return d, [i for i, s_ in enumerate(sol.i_events[-1]) if s_ != 0] \
            if sol.status == 2 else []
    d = list(d)
    n_ev = len(cm.events)
    final = []
    last = len(roots._i) - 1
    for k, (flags, te, ye, ype) in enumerate(zip(roots._i, roots._t, roots._y, roots._yp)):
        fired = [i for i, s_ in enumerate(flags) if s_ != 0]
        obs = [i for i in fired if i < n_ev and cm.events[i].observer]
        if k == last and sol.status == 2:
            final = [i for i in fired if i not in obs]
        if not obs:
            continue
        state = EventState(cm, run.p, d, te, cb[4](te, ye, ype))
        before = list(d)
        for i in obs:
            _log_event(run, te, cm.events[i])
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
    return d, final


def _handle(run, cb, t, y, yp, d, fired):
    cm = run.cm
    n_ev = len(cm.events)
    d = list(d)
    obs = cb[4](t, y, yp)
    state = EventState(cm, run.p, d, t, obs)
    stop = False
    for i in fired:
        if i >= n_ev:
            a = cm.assertions[i - n_ev]
            raise SolverError(f"{a.owner}: {a.message} (at t = {t:.6g} s)", t=t,
                              component=a.owner, result=run.result("failed", a.message))
        ev = cm.events[i]
        _log_event(run, t, ev)
        if ev.action is not None:
            ev.action(state)
        if ev.terminal:
            stop = True
    if state.changed:
        cb = cm.callbacks(run.p, d)
        y, yp = reinitialize(cm, cb, t, y, yp)
        y, yp, d, cb, stop2 = _event_iteration(run, cb, t, y, yp, d)
        stop = stop or stop2
    return y, yp, d, cb, stop


def _event_iteration(run, cb, t, y, yp, d, initial=False):
    """Fire ``recheck`` events whose condition is violated at this instant."""
    cm = run.cm
    checks = [i for i, e in enumerate(cm.events) if e.recheck]
    if not checks:
        return y, yp, d, cb, False
    g = np.zeros(cm.n_roots)
    for _ in range(MAX_ITER):
        cb[2](t, y, yp, g)
        obs = cb[4](t, y, yp)
        state = EventState(cm, run.p, list(d), t, obs)
        for i in checks:
            ev = cm.events[i]
            if (ev.direction < 0 and g[i] < 0) or (ev.direction > 0 and g[i] > 0):
                _log_event(run, t, ev)
                if ev.action is not None:
                    ev.action(state)
        if not state.changed:
            return y, yp, d, cb, False
        d = state.d
        cb = cm.callbacks(run.p, d)
        y, yp = reinitialize(cm, cb, t, y, yp)
    raise ChatteringError(f"event iteration did not settle at t = {t:.6g} s "
                          f"({MAX_ITER} mode changes at one instant) in "
                          + ", ".join(sorted({cm.events[i].owner for i in checks})), t=t)


def _log_event(run, t, ev):
    run.events.append((t, ev.name))
    run.event_log.append((t, ev.owner))
    if len(run.event_log) >= CHATTER_COUNT:
        t_first = run.event_log[-CHATTER_COUNT][0]
        span = CHATTER_SPAN * max(run.t_end - run.t0, 1e-300)
        if t - t_first <= span:
            owners = sorted({o for _, o in run.event_log[-CHATTER_COUNT:]})
            raise ChatteringError(
                f"chattering: {CHATTER_COUNT} events between t = {t_first:.9g} and "
                f"{t:.9g} s in {', '.join(owners)}; the mode logic does not settle", t=t,
                component=owners[0], result=run.result("failed", "chattering"))


def _failure(run, cm, sol, cb):
    """A SolverError naming the component whose equation is worst off."""
    r = type("Last", (), dict(t=float(np.atleast_1d(sol.t)[-1]), y=np.atleast_2d(sol.y)[-1],
                              yp=np.atleast_2d(sol.yp)[-1], message=sol.message))
    t = float(r.t)
    n = len(cm.dae.y)
    res = np.zeros(n)
    comp = None
    try:
        cb[0](t, np.array(r.y), np.array(r.yp), res)
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
    message = f"IDA failed at t = {t:.9g} s{where}: {r.message}{extra}"
    result = run.result("failed", r.message)
    hint = ask_components(cm.model, "solver_failure", [comp] if comp else [], message, t,
                          result)
    if hint is not None:
        return hint
    return SolverError(message, t=t, component=comp, result=result)


def _safe_obs(cb, t, r):
    try:
        return cb[4](t, np.array(r.y), np.array(r.yp))
    except Exception:
        return []
