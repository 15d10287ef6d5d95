"""Anchors: the breaker (models/breaker_24kv.py, from its start just before
first contact to the hook's release, rtol 1e-8) in CasADi's IDAS on the same
equations, against each acausal backend, in one run. Prints the time per
simulation, the ratios and the THRT agreement. Target (issue 10): the
fastest acausal backend <= 2x CasADi IDAS.

CasADi is a benchmark-only extra (``pip install 'acausal[casadi]'``).

The CasADi side is what a user of CasADi would write for this hybrid DAE:
CasADi 3.8's IDAS plugin does not locate zero crossings (casadi#3682,
casadi#4393: its ``zero``/``transition`` events are ignored by IDAS), so each
mode is integrated over a grid of output times, the first sign change of
the mode's root functions (with their directions) is found on the grid and
refined by Illinois iterations on the end time of an integration from the
last grid point before it; the event actions are acausal's own (a few
Python operations per event). The DAE is acausal's reduced DAE, converted
from sympy to CasADi SX (F(t, y, y') = 0 in semi-explicit form: x' = w,
0 = F(t, x, z, w)); parameters and discrete values are integrator
parameters, so one integrator serves every mode. It starts from acausal's
consistent initial point (computed once, outside the timing).

    python benchmarks/anchors.py [--repeat N] [--no-jit] [--cpu]

``--cpu`` times CPU seconds of this process instead of wall time (every
engine here is single-threaded): steadier on a shared machine. The load
average is printed with the table.
"""
import argparse
import os
import sys
import time

import numpy as np
import sympy as sp

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.join(ROOT, "benchmarks"))

from timing import best_interleaved  # noqa: E402

from acausal.backends import compiled_available  # noqa: E402
from acausal.initialize import initial_point  # noqa: E402
from acausal.modelfile import compile_file, evaluate_measures  # noqa: E402
from acausal.simulate import EventState  # noqa: E402
from acausal.symbols import time as t_sym  # noqa: E402

PARAMS = {"contact.K": 6.25e8, "hook.bh": 0.219}
# the hand-written reference's absolute tolerances (benchmarks/breaker_speed.py)
ATOL = {"armature.mass.s": 1e-11, "armature.mass.v": 1e-8, "hook.phi": 1e-10,
        "hook.body.w": 1e-7, "*": 1e-10}


# -- sympy -> CasADi SX ----------------------------------------------------------
def to_casadi(expr, env, memo):
    """CasADi SX of a sympy expression; ``env`` maps symbols to SX."""
    import casadi as ca
    if expr in memo:
        return memo[expr]
    if expr.is_Symbol:
        out = env[expr]
    elif expr.is_Number:
        out = float(expr)
    elif expr in (sp.true, sp.false):
        out = 1.0 if expr == sp.true else 0.0
    elif isinstance(expr, sp.Piecewise):
        out = np.nan
        for val, cond in reversed(expr.args):
            v = to_casadi(val, env, memo)
            out = v if cond == sp.true else ca.if_else(to_casadi(cond, env, memo), v, out)
    else:
        a = [to_casadi(x, env, memo) for x in expr.args]
        out = _apply(expr, a, ca)
    memo[expr] = out
    return out


def _apply(expr, a, ca):
    name = type(expr).__name__
    if expr.is_Add:
        return sum(a[1:], a[0])
    if expr.is_Mul:
        out = a[0]
        for x in a[1:]:
            out = out * x
        return out
    if expr.is_Pow:
        e = expr.args[1]
        if e == sp.Rational(1, 2):
            return ca.sqrt(a[0])
        return ca.constpow(a[0], a[1]) if e.is_Number else ca.power(a[0], a[1])
    ops = {"StrictGreaterThan": lambda x, y: x > y, "GreaterThan": lambda x, y: x >= y,
           "StrictLessThan": lambda x, y: x < y, "LessThan": lambda x, y: x <= y,
           "Equality": lambda x, y: x == y, "Unequality": lambda x, y: x != y,
           "And": lambda *x: _fold(ca.logic_and, x), "Or": lambda *x: _fold(ca.logic_or, x),
           "Not": lambda x: ca.logic_not(x), "Abs": ca.fabs, "sign": ca.sign,
           "Max": lambda *x: _fold(ca.fmax, x), "Min": lambda *x: _fold(ca.fmin, x),
           "Heaviside": lambda x, *_: ca.if_else(x > 0, 1, ca.if_else(x == 0, 0.5, 0)),
           "PosPow": lambda x, g: ca.if_else(x > 0, ca.power(x, g), 0),
           "atan2": ca.atan2}
    if name in ops:
        return ops[name](*a)
    fn = getattr(ca, name, None)
    if fn is None:
        raise NotImplementedError(f"no CasADi form for {name}")
    return fn(*a)


def _fold(f, xs):
    out = xs[0]
    for x in xs[1:]:
        out = f(out, x)
    return out


# -- CasADi IDAS on the same DAE ------------------------------------------------------
class CasadiIDAS:
    """The breaker's reduced DAE in CasADi IDAS with grid-located events."""

    def __init__(self, cm, rtol, atol, jit, grid=40):
        import casadi as ca
        dae = cm.dae
        n, ns = len(dae.y), dae.n_states
        self.cm, self.n, self.ns = cm, n, ns
        x = ca.SX.sym("x", ns)
        za = ca.SX.sym("za", n - ns)
        w = ca.SX.sym("w", ns)
        npd = len(cm.param_syms) + len(cm.disc_syms)
        pd = ca.SX.sym("pd", npd)
        t0, dt, tau = ca.SX.sym("t0"), ca.SX.sym("dt"), ca.SX.sym("tau")
        tt = t0 + tau * dt
        y = ca.vertcat(x, za)
        env = {s: y[i] for i, s in enumerate(dae.y)}
        env.update({s: w[i] for i, s in enumerate(dae.yp[:ns])})
        env.update({s: pd[i] for i, s in enumerate(list(cm.param_syms) + list(cm.disc_syms))})
        env[t_sym] = tt
        memo = {}
        F = ca.vertcat(*[to_casadi(r, env, memo) for r in dae.residuals])
        roots = [cm.resolve(e.expr) for e in cm.events] + \
            [cm.resolve(a.expr) for a in cm.assertions]
        G = ca.vertcat(*[to_casadi(g, env, memo) for g in roots])
        z = ca.vertcat(za, w)
        p = ca.vertcat(pd, t0, dt)
        opts = dict(reltol=rtol, abstol=1e-10, calc_ic=True, max_num_steps=100000)
        if np.ndim(atol):
            opts["abstolv"] = list(np.asarray(atol)[:ns]) + list(np.asarray(atol)[ns:]) + \
                [1e-2] * ns
            del opts["abstol"]
        if jit:
            opts.update(jit=True, compiler="shell", jit_options=dict(flags=["-O2"]))
        ode = dict(x=x, z=z, p=p, t=tau, ode=dt * w, alg=F)
        taus = list(np.linspace(0.0, 1.0, grid + 1)[1:])
        self.grid = np.linspace(0.0, 1.0, grid + 1)
        self.I_grid = ca.integrator("Ig", "idas", ode, 0.0, taus, opts)
        self.I_end = ca.integrator("Ie", "idas", ode, 0.0, 1.0, opts)
        self.gf = ca.Function("g", [x, z, pd, t0, dt, tau], [G])
        self.gmap = self.gf.map(grid + 1)
        self.dirs = [e.direction for e in cm.events] + [-1] * len(cm.assertions)
        self.terminal = [not e.observer for e in cm.events] + [True] * len(cm.assertions)

    def _g(self, X, Z, pd, t0, dt, taus):
        G = self.gmap(X, Z, pd, t0, dt, taus.reshape(1, -1))
        return np.array(G)

    def simulate(self, p, d, t, y, yp, t_end, chunk):
        """Integrate from the consistent point to the terminal root; the
        event times, in order."""
        cm, ns = self.cm, self.ns
        x, z = y[:ns].copy(), np.concatenate([y[ns:], yp[:ns]])
        d, events = list(d), []
        while t < t_end:
            pd = np.concatenate([p, d])
            dt = min(chunk, t_end - t)
            r = self.I_grid(x0=x, z0=z, p=np.concatenate([pd, [t, dt]]))
            X = np.hstack([x[:, None], np.array(r["xf"])])
            Z = np.hstack([z[:, None], np.array(r["zf"])])
            G = self._g(X, Z, pd, t, dt, self.grid)
            hit = self._first_crossing(G)
            if hit is None:
                t, x, z = t + dt, X[:, -1], Z[:, -1]
                continue
            k, i = hit
            te, x, z = self._refine(X[:, k - 1], Z[:, k - 1], pd, t + self.grid[k - 1] * dt,
                                    (self.grid[k] - self.grid[k - 1]) * dt, i)
            t = te
            events.append((te, cm.events[i].name if i < len(cm.events) else "assert"))
            if self.terminal[i] and i < len(cm.events) and cm.events[i].terminal:
                break
            d = self._act(p, d, te, x, z, i)
        return events

    def _act(self, p, d, te, x, z, i):
        """Event ``i``'s action at the point (x, z) of the CasADi state: the
        discrete values after it."""
        cm, ns = self.cm, self.ns
        yy = np.concatenate([x, z[:len(z) - ns]])
        yyp = np.zeros(len(yy))
        yyp[:ns] = z[len(z) - ns:]
        st = EventState(cm, p, d, te, cm.callbacks(p, d)[4](te, yy, yyp))
        cm.events[i].action(st)
        return st.d

    def replay(self, p, d, t, y, yp, events):
        """The lower bound of the CasADi side: integrate from event to event
        at the given times (one integrator call per mode, nothing located),
        applying the same event actions."""
        cm, ns = self.cm, self.ns
        x, z = y[:ns].copy(), np.concatenate([y[ns:], yp[:ns]])
        d = list(d)
        for te, name in events:
            pd = np.concatenate([p, d])
            r = self.I_end(x0=x, z0=z, p=np.concatenate([pd, [t, te - t]]))
            x, z, t = np.array(r["xf"]).ravel(), np.array(r["zf"]).ravel(), te
            i = [e.name for e in cm.events].index(name)
            if cm.events[i].terminal:
                break
            d = self._act(p, d, te, x, z, i)
        return x

    def _first_crossing(self, G):
        best = None
        for i, direc in enumerate(self.dirs):
            if not self.terminal[i]:
                continue    # observers do not change the trajectory
            g = G[i]
            for k in range(1, len(g)):
                up, down = g[k - 1] < 0 <= g[k], g[k - 1] > 0 >= g[k]
                if (direc >= 0 and up) or (direc <= 0 and down):
                    if best is None or k < best[0]:
                        best = (k, i)
                    break
        return best

    def _refine(self, x, z, pd, ta, span, i, tol=1e-11):
        """Illinois on the end time of an integration from (ta, x, z)."""
        def g_at(h):
            r = self.I_end(x0=x, z0=z, p=np.concatenate([pd, [ta, h]]))
            xf, zf = np.array(r["xf"]).ravel(), np.array(r["zf"]).ravel()
            return float(self.gf(xf, zf, pd, ta, h, 1.0)[i]), xf, zf
        a, b = 0.0, span
        ga = float(self.gf(x, z, pd, ta, span, 0.0)[i])
        gb, xb, zb = g_at(b)
        side, c_last = 0, np.inf
        for _ in range(60):
            c = (a * gb - b * ga) / (gb - ga)
            if abs(c - c_last) <= tol * max(abs(ta), span):
                break     # converged (to the noise of a restarted integration)
            c_last = c
            gc, xc, zc = g_at(c)
            if gc * gb > 0:
                b, gb, xb, zb = c, gc, xc, zc
                if side == -1:
                    ga *= 0.5
                side = -1
            else:
                a, ga = c, gc
                if side == 1:
                    gb *= 0.5
                side = 1
            if b - a <= tol * max(abs(ta), span):
                break
        return ta + b, xb, zb


def _thrt(events):
    onset = next(t for t, n in events if n.endswith("onset"))
    return next(t for t, n in events if n == "release") - onset


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=10)
    ap.add_argument("--no-jit", action="store_true")
    ap.add_argument("--cpu", action="store_true", help="CPU time instead of wall time")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    mf, cm = compile_file(os.path.join(ROOT, "models", "breaker_24kv.py"))
    print(f"acausal compile (once): {time.perf_counter() - t0:.2f} s; "
          f"states/unknowns {cm.dae.n_states}/{len(cm.dae.y)}")
    bench = mf.experiment.run_options()
    bench.update(output_step=0, atol=ATOL)
    own = mf.experiment.run_options()
    runs, results = [], {}
    for backend in ["sundae", "compiled"]:
        for label, opts in [("benchmark options", bench), ("the file's options", own)]:
            res = cm.simulate(params=PARAMS, backend=backend, **opts)   # builds/loads once
            results[(backend, label)] = res
            runs.append((f"acausal {res.stats['backend']}, {label}",
                         lambda b=backend, o=opts: cm.simulate(params=PARAMS, backend=b, **o),
                         evaluate_measures(mf, res)["thrt"]))
    why = compiled_available()
    if why:
        print(f"note: the compiled backend is unavailable here ({why}); it fell back")
    p = cm.param_vector(PARAMS)
    d = cm.discrete_start()
    y, yp = initial_point(cm, p, d, cm.callbacks(p, d), 0.0)
    from acausal.simulate import _atol_vector
    atol = _atol_vector(cm, ATOL, None)
    t_end = bench["t_end"]
    for jit in ([False] if args.no_jit else [False, True]):
        t0 = time.perf_counter()
        cas = CasadiIDAS(cm, bench["rtol"], atol, jit, grid=100)
        label = "CasADi IDAS, " + ("compiled (jit)" if jit else "SX virtual machine")
        print(f"{label}: set-up {time.perf_counter() - t0:.2f} s")
        events = cas.simulate(p, d, 0.0, y, yp, t_end, 5e-4)
        runs.append((label, lambda c=cas: c.simulate(p, d, 0.0, y, yp, t_end, 5e-4),
                     _thrt(events)))
        runs.append((label + ", events given", lambda c=cas, e=events:
                     c.replay(p, d, 0.0, y, yp, e), _thrt(events)))
    load0 = os.getloadavg()[0]
    times = best_interleaved([fn for _, fn, _ in runs], args.repeat,
                             time.process_time if args.cpu else time.perf_counter)
    anchor = min(tm for (lab, _, _), tm in zip(runs, times)
                 if lab.startswith("CasADi") and "given" not in lab)
    bound = min(tm for (lab, _, _), tm in zip(runs, times) if "given" in lab)
    ref = runs[0][2]
    print(f"\nbest of {args.repeat}, interleaved, {'CPU' if args.cpu else 'wall'} time (load "
          f"{load0:.1f} before, {os.getloadavg()[0]:.1f} after); THRT difference against "
          "acausal sundae (benchmark options)")
    print(f"{'engine':58s} {'ms/sim':>8s} {'x CasADi':>9s} {'THRT [ms]':>12s} {'dTHRT [s]':>10s}")
    for (lab, _, thrt), tm in zip(runs, times):
        print(f"{lab:58s} {tm * 1e3:8.2f} {tm / anchor:9.2f} {thrt * 1e3:12.7f} "
              f"{thrt - ref:10.1e}")
    fastest = min(tm for (lab, _, _), tm in zip(runs, times) if lab.startswith("acausal"))
    print(f"\nfastest acausal / fastest CasADi IDAS locating its events = "
          f"{fastest / anchor:.2f} (target <= 2)")
    print(f"fastest acausal / CasADi IDAS with the event times given (a lower bound "
          f"of any CasADi IDAS run) = {fastest / bound:.2f}")


if __name__ == "__main__":
    main()
