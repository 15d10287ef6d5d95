"""Forward sensitivities as an observer of the hybrid loop: the
:class:`SensitivityObserver` integrates the augmented model of
:mod:`.sensitivity` in place of the model and carries the sensitivities
through the events (Maly & Petzold 1996 for the sensitivity DAE; Galan,
Feehery & Barton 1999, "Parametric sensitivity functions for hybrid
discrete/continuous systems", Appl. Numer. Math. 31, for the jumps):

* start (:meth:`SensitivityObserver.on_start`): the states' sensitivities
  from the consistent-initialisation equations by the implicit function
  theorem, the algebraic ones re-solved;
* each event (:meth:`~SensitivityObserver.on_event`): its time's derivative
  ``dtau/dp = -(g_y s + g_y' s' + g_p + g_d sd) / (g_y y' + g_t)`` at the
  located point polished (re-solved from the equations);
* each mode change (:meth:`~SensitivityObserver.on_mode_change`): the
  discrete values' sensitivities (the actions' directional derivatives), the
  states' sensitivities' jump ``(y'- - y'+) dtau/dp``, the algebraic ones
  re-solved;
* the result (:meth:`~SensitivityObserver.finish`): the base model's
  :class:`~acausal.runtime.result.Result` with its :class:`Sensitivities`.
"""
from dataclasses import dataclass

import numpy as np
import sympy as sp

from ..errors import UnknownNameError, UsageError
from ..lang.fastdiff import diff
from .events import EventState
from .initialize import reinitialize
from .linalg import choose_guesses, event_matrix, jacobians, lstsq_scaled
from .observe import expression_column
from .observer import RunObserver
from .result import Result, Rows


class SensitivityObserver(RunObserver):
    """The sensitivities of one run with respect to the parameters of the
    augmented model ``sm`` (:class:`acausal.runtime.sensitivity.SensitivityModel`):
    the hooks of the hybrid loop (:mod:`.observer`) and the bookkeeping
    between them (the instant's event-time sensitivity ``dtau``, those of
    every logged event, the discrete values' sensitivities ``sd_all`` and
    their stored rows)."""

    def __init__(self, sm):
        self.sm = sm
        self.p = self.serve = self.span = None     # set by on_start
        self.dtau = np.zeros(sm.m)       # of the instant being handled
        self.sd_all = np.zeros((sm.m, len(sm.base.disc_syms)))   # of every discrete value
        self.noted = {}                  # index in run.events -> dtau/dp (m)
        self.pending = {}                # event index -> dtau/dp of the events about to log
        self.SD = []                     # sd_all of every stored row, by blocks
        self._polished = None            # the last polished point (see polish)

    # -- the hooks ---------------------------------------------------------------
    def system(self, cm, atol, p):
        """The augmented model, with ``atol / |p_j|`` on the sensitivities."""
        return self.sm, self.sm.atol(atol, p)

    def on_start(self, run, point, d, cb, starts):
        """(Y, Y', d, callbacks) of the augmented system at the consistent
        initial point of the base model: the states' sensitivities from the
        initial equations (implicit function theorem), the rest re-solved."""
        # serve(model, d): that model's callbacks in mode d, as the run's
        # backend serves them (compiled C on the compiled backend)
        self.p, self.serve = run.p, run.serve
        self.span = max(float(run.t_end - run.t0), 1e-300)
        sm, cm = self.sm, self.sm.base
        t0, y, yp = point
        d_aug = list(d) + [0.0] * len(sm.sd_syms)
        cb = self.serve(sm, d_aug)
        # F_p and the observed variables' o_p: the sensitivity rows at s = 0
        zero = sm.pack(y, np.zeros((sm.m, sm.n))), sm.pack(yp, np.zeros((sm.m, sm.n)))
        r = np.zeros(len(sm.dae.y))
        cb.res(t0, zero[0], zero[1], r)
        nobs = len(cm.var_names)
        op = np.asarray(cb.observe(t0, *zero), float)[nobs:].reshape(sm.m, nobs)
        ds = initial_state_sensitivities(
            cm, self.serve(cm, d), self.p, point, d, starts,
            ParameterDerivatives(tuple(sm.pidx), sm.unpack(r)[1], op))
        S = np.zeros((sm.m, sm.n))
        S[:, :sm.ns] = ds
        Y, YP = sm.pack(y, S), sm.pack(yp, np.zeros((sm.m, sm.n)))
        Y, YP = self.reinit(t0, Y, YP, d_aug)
        return Y, YP, d_aug, cb

    def on_rows(self, run, count):
        self.SD.append(np.tile(self.sd_all.ravel(), (count, 1)))

    def on_event(self, run, point, d, fired, kind):
        """The event-time sensitivities of ``fired`` (kept for :meth:`on_log`):
        those of the events a segment located (``"observer"``, ``"instant"``;
        the instant's is the first's), a time event's (``"time"``: the
        derivative of its instant,
        :meth:`acausal.runtime.timeevents.TimeSchedule.time_sensitivity`,
        also the instant's), or the instant's own (``"recheck"``: the event
        iteration fires at the instant)."""
        if kind == "time":
            self.dtau[:] = run.schedule.time_sensitivity(point.t, d, self.sm.pidx)
            self.pending = {ev: self.dtau.copy() for ev in fired}
        elif kind == "recheck":
            # an event found when the instant's event iteration rechecks the
            # conditions happens at the instant's time: its time derivative
            # is the instant's dtau/dp, copied (the array is zeroed when the
            # instant ends: on_instant_end)
            self.pending = {i: self.dtau.copy() for i in fired}
        else:
            self.pending = self.event_times(point, d, fired, current=kind == "instant")

    def on_log(self, run, k, key):
        self.noted[k] = np.asarray(self.pending[key], float)

    def on_actions(self, run, events, point, d_before, observed):
        """Observer events' actions ran: the sensitivities of the discrete
        values they record, in the rows from their time on."""
        cm = self.sm.base
        t, Y, YP = point
        for ev in events:
            i = cm.events.index(ev)
            dtau = np.nan_to_num(self.pending.get(i, np.zeros(self.sm.m)))
            self.sd_all = self._action_sensitivities([ev], point, d_before, observed, dtau)
        self.SD[-1][run.T[-1] >= t] = self.sd_all.ravel()

    def on_instant_end(self, run):
        self.dtau[:] = 0.0

    def finish(self, run, rows, stats, status, message):
        """The base model's result with its :class:`Sensitivities`."""
        sm = self.sm
        T, Y, YP, D = rows
        nd = len(sm.base.disc_syms)
        # the rows the run kept (a limit may have trimmed them: run.trim)
        kept = [sd[:len(t)] for sd, t in zip(self.SD, run.T)]
        SD = np.concatenate(kept) if kept else np.zeros((0, self.sd_all.size))
        E = np.full((len(run.events), sm.m), np.nan)
        for k, v in self.noted.items():
            if k < len(run.events):
                E[k] = v
        sens = Sensitivities(sm, run.p, rows, SD.reshape(len(T), sm.m, nd), E)
        base = Rows(T, sm.unpack(Y)[0], sm.unpack(YP)[0], D[:, :nd])
        return Result(sm.base, run.p, base, list(run.events), stats, status, message, sens)

    # -- re-initialisation -----------------------------------------------------------

    def reinit(self, t, Y, YP, d_aug, rates=True):
        """The re-initialisation of the augmented system at ``t`` (states and
        their sensitivities kept): the base model's
        (:func:`acausal.runtime.initialize.reinitialize`), then the
        sensitivity rows, linear in ``(s_alg, s'_states)`` with the base
        iteration matrix, in one solve; with ``rates``, y' of every algebraic
        slot as the initialisation's algebraic rates give it."""
        sm, cm = self.sm, self.sm.base
        n, ns = sm.n, sm.ns
        cb = self.serve(cm, d_aug[:len(cm.disc_syms)])
        (y, S), (yp, Sp) = sm.unpack(Y), sm.unpack(YP)
        y, yp = reinitialize(cm, cb, t, y, yp)
        S, Sp = S.copy(), Sp.copy()
        S[:, ns:] = 0.0
        Sp[:, :ns] = 0.0
        cba = self.serve(sm, d_aug)
        r = np.zeros(len(sm.dae.y))
        cba.res(t, sm.pack(y, S), sm.pack(yp, Sp), r)
        Jy, Jyp = jacobians(cb, t, y, yp, n)
        J = np.hstack([Jy[:, ns:], Jyp[:, :ns]])
        rhs = -sm.unpack(r)[1].T                          # n x m
        try:
            X = np.linalg.solve(J, rhs)
        except np.linalg.LinAlgError:
            X = np.linalg.lstsq(J, rhs, rcond=None)[0]
        S[:, ns:] = X[:n - ns].T
        Sp[:, :ns] = X[n - ns:].T
        Y, YP = sm.pack(y, S), sm.pack(yp, Sp)
        if rates:
            YP = self.rates(cba, t, Y, YP)
        return Y, YP

    def rates(self, cb, t, Y, YP):
        """``YP`` with y' of every algebraic slot of the augmented system
        (callbacks ``cb``), as the initialisation's algebraic rates give it:
        ``J x = -(F_t + F_y(states) y'_states)`` for x = (y' of the
        algebraic slots, y'' of the states), solved by blocks with the
        generated Jacobian
        (:meth:`acausal.runtime.sensitivity.SensitivityModel.block_solve`);
        the right side is a central difference of the augmented residual
        along the solution."""
        sm = self.sm
        N, nsa = len(sm.dae.y), sm.ns * (1 + sm.m)
        if N == nsa:
            return YP
        Y, YP = np.asarray(Y, float), np.array(YP, dtype=float)
        J, _ = event_matrix(cb, t, Y, YP, nsa)
        move = np.zeros(N)
        move[:nsa] = YP[:nsa]
        dt = 1e-6 * max(1.0, abs(t))
        saved = list(cb.count)
        rhs = -_central(lambda h: _residual(cb, t + h, Y + h * move, YP), dt)
        x = sm.block_solve(J, rhs)
        cb.count[:] = saved     # these are not solver step attempts
        if np.all(np.isfinite(x)):
            YP[nsa:] = x[:N - nsa]
        return YP

    # -- events ------------------------------------------------------------------
    def polish(self, t, Y, YP, d_aug):
        """The point IDA located a root at, with its algebraic unknowns and
        derivatives re-solved from the (augmented) equations: IDA's
        interpolated values there meet them only to the tolerance. The last
        one is kept: a mode change polishes the point its event time did."""
        last = self._polished
        if (last is not None and last[0] == t and np.array_equal(last[1], Y)
                and np.array_equal(last[2], YP) and last[3] == list(d_aug)):
            return last[4], last[5]
        out = self.reinit(t, Y, YP, d_aug, rates=False)
        self._polished = (t, np.array(Y), np.array(YP), list(d_aug)) + out
        return out

    def event_time(self, t, Y, YP, d_aug, i, rates):
        """dtau/dp (m) of root ``i`` at the (polished) point ``(t, Y, Y')``;
        ``rates`` = (y', y'') of the base model there."""
        sm = self.sm
        nd = len(sm.base.disc_syms)
        (y, S), (yp, Sp) = sm.unpack(Y), sm.unpack(YP)
        Gy, Gyp, Gt, Gp, Gd = sm.rootgrad(t, y, yp, self.p, d_aug[:nd])
        sd = sm.sd_of(d_aug)
        num = S @ Gy[i] + Sp @ Gyp[i] + Gp[i] + sd @ Gd[i]
        rate = Gy[i] @ rates[0] + Gyp[i] @ rates[1] + Gt[i]
        if rate == 0 or not np.isfinite(rate):
            return np.full(sm.m, np.nan)   # a grazing root: tau is not differentiable
        return -num / rate

    def event_times(self, point, d_aug, fired, current=False):
        """index -> dtau/dp of each fired event at ``point``; with ``current``
        the first one is the instant's (the one its mode changes jump by)."""
        t, Y, YP = point
        n_ev = len(self.sm.base.events)
        fired = [i for i in fired if i < n_ev]
        if not fired:
            return {}
        Y, YP = self.polish(t, Y, YP, d_aug)
        rates = _rates(self.sm, self.serve(self.sm.base, d_aug[:len(self.sm.base.disc_syms)]),
                       t, Y, YP)
        taus = {i: self.event_time(t, Y, YP, d_aug, i, rates) for i in fired}
        if current and taus:
            first = taus[min(taus)]
            self.dtau[:] = np.where(np.isfinite(first), first, 0.0)
        return taus

    def on_mode_change(self, run, events, point, d_before, d_after, observed):
        """After ``events``' actions changed the discrete values from
        ``d_before`` to ``d_after`` (augmented, the sensitivities still those
        before) at ``point`` with base observed values ``observed``: the new
        discrete sensitivities, the re-initialised point and the jump of the
        states' sensitivities. Returns (d, callbacks, Y, Y')."""
        sm = self.sm
        nd = len(sm.base.disc_syms)
        t = point.t
        Y, YP = self.polish(t, point.y, point.yp, d_before)
        self.sd_all = self._action_sensitivities(events, (t, Y, YP), d_before, observed,
                                                 self.dtau)
        d_new = list(d_after[:nd]) + self.sd_all[:, sm.dyn].ravel().tolist()
        cb = self.serve(sm, d_new)
        Y1, YP1 = self.reinit(t, Y, YP, d_new, rates=False)
        ns = sm.ns
        jump = (np.asarray(YP)[:ns] - YP1[:ns])[None, :] * self.dtau[:, None]   # m x ns
        if np.any(jump != 0):
            y, S = sm.unpack(Y1)
            S[:, :ns] += jump
            Y1, YP1 = self.reinit(t, sm.pack(y, S), YP1, d_new, rates=False)
        YP1 = self.rates(cb, t, Y1, YP1)
        return d_new, cb, Y1, YP1

    def _action_sensitivities(self, events, point, d_before, obs, dtau):
        """The sensitivities of every discrete value after ``events``' actions
        (m x nd; ``self.sd_all`` before them): the actions' directional
        derivative along the total derivative of what they read (the
        observed values at the event time ``t + dtau dp``, the parameters,
        the discrete values), by central differences."""
        sm, cm = self.sm, self.sm.base
        t, Y, YP = point
        nd, nobs = len(cm.disc_syms), len(cm.var_names)
        sd = self.sd_all.copy()
        if not any(ev.action is not None for ev in events):
            return sd
        out = np.asarray(self.serve(sm, d_before).observe(t, Y, YP), float)
        dobs = out[nobs:].reshape(sm.m, nobs)
        odot = self._observed_rate(t, Y, YP, d_before)
        obs = np.asarray(obs, float)[:nobs]
        for j, k in enumerate(sm.pidx):
            h = 1e-6 * (abs(self.p[k]) if self.p[k] != 0 else 1.0)
            vals, written = [], np.zeros(nd, bool)
            for sgn in (1.0, -1.0):
                q = self.p.copy()
                q[k] += sgn * h
                given = np.asarray(d_before[:nd], float) + sgn * h * sd[j]
                st = EventState(cm, q, list(given), t + sgn * h * dtau[j],
                                list(obs + sgn * h * (dobs[j] + odot * dtau[j])))
                for ev in events:
                    if ev.action is not None:
                        ev.action(st)
                vals.append(np.array(st.d[:nd], float))
                written |= vals[-1] != given
            # a value no action wrote keeps its sensitivity exactly
            sd[j] = np.where(written, (vals[0] - vals[1]) / (2 * h), sd[j])
        return sd

    def _observed_rate(self, t, Y, YP, d_aug):
        """d(observed)/dt along the solution, by a central difference."""
        sm = self.sm
        nobs = len(sm.base.var_names)
        obs = self.serve(sm, d_aug).observe
        dt = 1e-7 * self.span
        Y, YP = np.asarray(Y, float), np.asarray(YP, float)
        a = np.asarray(obs(t + dt, Y + dt * YP, YP), float)[:nobs]
        b = np.asarray(obs(t - dt, Y - dt * YP, YP), float)[:nobs]
        return (a - b) / (2 * dt)


def _residual(cb, t, Y, YP):
    r = np.zeros(len(Y))
    cb.res(t, Y, YP, r)
    return r


def _central(f, h):
    """(f(h) - f(-h)) / 2h."""
    return (f(h) - f(-h)) / (2 * h)


def _rates(sm, cb, t, Y, YP):
    """(y', y'') of the base model (its callbacks ``cb``) at a consistent point: y' of the states
    from ``YP``, y' of the algebraic unknowns and y'' of the states from the
    equations differentiated once along the solution,
    ``[F_y(alg) F_y'(states)] [y'_alg; y''_states] = -(F_t + F_y(states) y'_states)``
    (as the initialisation's algebraic rates; F_t by a central
    difference)."""
    cm, n, ns = sm.base, sm.n, sm.ns
    y, yp = sm.unpack(Y)[0], sm.unpack(YP)[0]
    ydot, ydd = np.array(yp, float), np.zeros(n)
    if n == ns and not any(s is not None for s in cm.dae.yp):
        return ydot, ydd
    Jy, Jyp = jacobians(cb, t, y, yp, n)
    dt = 1e-7 * max(1.0, abs(t))
    rp, rm = np.zeros(n), np.zeros(n)
    cb.res(t + dt, y, yp, rp)
    cb.res(t - dt, y, yp, rm)
    rhs = -((rp - rm) / (2 * dt) + Jy[:, :ns] @ yp[:ns])
    J = np.hstack([Jy[:, ns:], Jyp[:, :ns]])
    try:
        sol = np.linalg.solve(J, rhs)
    except np.linalg.LinAlgError:
        sol = np.linalg.lstsq(J, rhs, rcond=None)[0]
    ydot[ns:] = sol[:n - ns]
    ydd[:ns] = sol[n - ns:]
    return ydot, ydd


@dataclass(frozen=True)
class ParameterDerivatives:
    """At one consistent point: the parameters' positions ``pidx`` in the
    model's parameter vector, d residuals / d p_j (``Fp``, m x n, rows
    ordered as y) and d observed variables / d p_j (``op``, m x observed)."""

    pidx: tuple
    Fp: np.ndarray
    op: np.ndarray


def initial_state_sensitivities(cm, cb, p, point, d, starts, dp: ParameterDerivatives):
    """d(states)/dp (m x ns) at the consistent initial ``point`` (t0, y, y')
    of model ``cm`` (``cb``: its callbacks; ``p`` the parameters, ``d`` the
    discrete values, ``starts`` the run's start values): the initial system
    (residuals, fixed starts, imposed guesses; see
    :mod:`acausal.runtime.initialize`) differentiated with respect to each
    parameter of ``dp`` and solved for ``dz = (dy, dy'_states)`` (implicit
    function theorem)."""
    t0, y, yp = point
    n, ns = len(cm.dae.y), cm.dae.n_states
    Jy, Jyp = jacobians(cb, t0, y, yp, n)
    rows = [np.hstack([Jy, Jyp[:, :ns]])]
    fixed = cm.fixed_starts(p, starts)
    if fixed:
        F = np.asarray(cm.fixed_jacobian()(t0, *y, *yp, *p, *d), float)
        rows.append(F.reshape(len(fixed), n + ns))
    A = np.vstack(rows)
    guesses = choose_guesses(A, ns, cm.state_guess_order())
    G = np.zeros((len(guesses), n + ns))
    for a, k in enumerate(guesses):
        G[a, k] = 1.0
    A = np.vstack([A, G])
    B = np.zeros((A.shape[0], len(dp.pidx)))      # one right-hand side per parameter
    for j, k in enumerate(dp.pidx):
        h = 1e-6 * (abs(p[k]) if p[k] != 0 else 1.0)
        qp, qm = np.array(p, float), np.array(p, float)
        qp[k] += h
        qm[k] -= h
        dv = np.array([_start_derivative(cm, name, k, p, starts) for _, _, name in fixed])
        dg = (cm.guess_vector(qp, starts) - cm.guess_vector(qm, starts)) / (2 * h)
        rhs = [-dp.Fp[j]]
        if fixed:
            rhs.append(-(dp.op[j][[kk for kk, _, _ in fixed]] - dv))
        rhs.append(np.array([dg[kk] for kk in guesses]))
        B[:, j] = np.concatenate(rhs)
    return lstsq_scaled(A, B)[:ns].T


def _start_derivative(cm, name, k, p, starts):
    """d(fixed start value of variable ``name``)/d(parameter ``k``): the start
    value is a number (0), an override for this run (0) or an expression of
    parameters (differentiated symbolically)."""
    value = cm.flat.variables[name].start.value
    if (starts and name in starts) or not isinstance(value, sp.Basic) or value.is_number:
        return 0.0
    e = value.xreplace(cm.artefact.parameters.bindings)
    de = diff(e, cm.param_syms[k])
    return float(de.xreplace(dict(zip(cm.param_syms, map(float, p)))))


class Sensitivities:
    """The sensitivities a run stored (``Result.sensitivity`` reads them):
    the augmented model ``sm``, the parameters ``p``, the augmented ``rows``
    (:class:`~acausal.runtime.result.Rows`), the discrete values'
    sensitivities ``SD`` (rows x parameters x discrete values) and the
    logged events' ``E`` (events x parameters)."""

    def __init__(self, sm, p, rows, SD, E):
        self.sm, self.p, self.t = sm, p, rows.t
        self.Y, self.YP, self.D, self.SD, self.events = rows.y, rows.yp, rows.d, SD, E
        self._obs = None

    def names(self):
        return list(self.sm.names)

    def _j(self, param):
        if param not in self.sm.names:
            raise UsageError(f"no sensitivity with respect to {param!r}: the run computed "
                             f"them for {', '.join(self.sm.names)} (simulate(sensitivities=...))")
        return self.sm.names.index(param)

    def observed(self):
        """rows x m x len(var_names): d(variable)/d(parameter) at every row."""
        if self._obs is None:
            sm = self.sm
            nobs = len(sm.base.var_names)
            out = np.empty((len(self.t), sm.m, nobs))
            cache = {}
            for k in range(len(self.t)):
                key = tuple(self.D[k])
                cb = cache.get(key)
                if cb is None:
                    cb = cache[key] = sm.callbacks(self.p, list(key))
                o = np.asarray(cb.observe(self.t[k], self.Y[k], self.YP[k]), float)
                out[k] = o[nobs:].reshape(sm.m, nobs)
            self._obs = out
        return self._obs

    def of(self, var, param):
        j = self._j(param)
        names = self.sm.base.var_names
        discretes = [s.name for s in self.sm.base.disc_syms]
        if var in discretes:
            return self.SD[:, j, discretes.index(var)]
        if var not in names:
            if var in self.sm.names or var in [e.name for e in self.sm.base.params]:
                return np.full(len(self.t), 1.0 if var == param else 0.0)
            raise UnknownNameError(f"no variable {var!r} in the result", variable=var)
        k = names.index(var)
        if self._obs is None:
            col = self._column(k, j)
            if col is not None:
                return col
        return self.observed()[:, j, k]

    def _column(self, k, j):
        """d(observed variable k)/d(parameter j) at every row, its expression
        alone over all rows of each mode at once (:func:`.observe.expression_column`,
        checked against the per-row callback); None when it cannot be
        vectorised. A fit's Jacobian reads one or two measured variables:
        every variable's sensitivities row by row in Python took 90 % of a
        sensitivity Jacobian (the geared drive, 3 parameters, 2026-11-29)."""
        sm = self.sm
        nobs = len(sm.base.var_names)

        def build():
            return (sm.observed_sensitivity(k, j), sm.dae.y, sm.dae.yp, sm.base.param_syms,
                    sm.disc_syms)

        def per_row(i):
            cb = sm.callbacks(self.p, list(self.D[i]))
            return cb.observe(self.t[i], self.Y[i], self.YP[i])[nobs + j * nobs + k]
        return expression_column(sm, ("sensitivity", k, j), build,
                                 (self.p, self.t, self.Y, self.YP, self.D), per_row)

    def event(self, param):
        return self.events[:, self._j(param)]

    def measure(self, result, fn, param, rel_step=1e-6):
        """d fn(result) / d param for a measure ``fn`` (any function of a
        result): a central difference of ``fn`` over the result moved to
        first order along the sensitivities (unknowns, discrete values, event
        times and the rows at events with them, the parameter itself), so no
        simulation is repeated and the difference is exact for measures that
        are linear in what they read (event times, values at events,
        discrete values) and second-order accurate for others."""
        j = self._j(param)
        k = self.sm.pidx[j]
        h = rel_step * (abs(self.p[k]) if self.p[k] != 0 else 1.0)
        return (fn(self._moved(result, j, h)) - fn(self._moved(result, j, -h))) / (2 * h)

    def _moved(self, result, j, h):
        """``result`` with parameter j moved by ``h``, to first order."""
        sm = self.sm
        y, S = sm.unpack(self.Y)
        yp, Sp = sm.unpack(self.YP)
        dtau = np.nan_to_num(self.events[:, j])
        shift = np.zeros(len(self.t))
        for (te, _), dt in zip(result.events, dtau):
            shift[self.t == te] = dt      # rows at an event move with it
        p = np.array(self.p, float)
        p[sm.pidx[j]] += h
        T = self.t + h * shift
        Ym = y + h * (S[:, j] + yp * shift[:, None])
        D = self.D[:, :self.SD.shape[2]] + h * self.SD[:, j]
        events = [(te + h * dt, name) for (te, name), dt in zip(result.events, dtau)]
        return Result(sm.base, p, Rows(T, Ym, yp + h * Sp[:, j], D), events, result.stats,
                      result.status, result.message)
