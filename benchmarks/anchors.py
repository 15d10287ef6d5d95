"""Anchors: the breaker (models/breaker_24kv.py, from its start just before
first contact to the hook's release, rtol 1e-8) in the best outside engines
on the same equations, against each acausal backend, in one interleaved run:
CasADi IDAS and CVODES, scipy's solve_ivp and diffrax. Prints the time per
simulation, the ratios and the THRT agreement. Target (issue 10): the
fastest acausal backend <= 2x CasADi IDAS.

The outside engines are benchmark-only extras (``pip install
'acausal[bench]'``: CasADi, JAX and diffrax); one that is not installed is
skipped with a line saying so. Every engine starts from acausal's
consistent initial point (computed once, outside the timing), integrates
acausal's reduced DAE converted from sympy, and applies acausal's own event
actions (a few Python operations per event); each is what a competent user
of that engine would write for this hybrid system:

* CasADi IDAS: the semi-explicit DAE x' = w, 0 = F(t, x, z, w) in SX;
  parameters and discrete values are integrator parameters, so one
  integrator serves every mode. CasADi 3.8's IDAS plugin does not locate
  zero crossings (casadi#3682, casadi#4393: its ``zero``/``transition``
  events are ignored by IDAS), so each mode is integrated over a grid of
  output times, the first sign change of the mode's root functions (with
  their directions) is found on the grid and refined by Illinois iterations
  on the end time of an integration from the last grid point before it.
* CasADi CVODES: the explicit ODE x' = w(t, x, z(x)) (:func:`explicit_form`:
  the breaker's reduced DAE is explicit in the accelerations; its algebraic
  unknowns, the four-bar's coupler and main-shaft angles, are fixed by the
  nonlinear position closure, solved by Newton steps unrolled in the SX
  graph). CVODES's own events in CasADi 3.8 fire on falling crossings only
  (casadi#4393; checked with 3.8.2: x' = 1 through x = 0.5 never calls the
  transition), act through a CasADi transition function rather than
  acausal's actions, and do not stop the integration at a terminal event,
  so CVODES shares IDAS's grid-located mode loop. Adams with functional iteration (the
  default, ``--cvodes``) was faster here than BDF (7.4 against 9.3 ms).
  Each CasADi engine has an "events given" row: one integration per mode
  to the known event times, the lower bound of any run of that engine.
* scipy ``solve_ivp`` (LSODA, DOP853; ``--scipy``), its own event location
  (terminal events with directions), the same explicit ODE in plain Python.
* diffrax (JAX on the CPU, float64): the explicit ODE in jax.numpy, one
  ``jax.jit``-compiled ``diffeqsolve`` per mode segment with a
  ``diffrax.Event`` of the root functions (directions, optimistix Newton
  for the root time); Tsit5 by default (``--diffrax``): Dopri5 took about
  as long, Dopri8 7x as long, Kvaerno5 (implicit) 30x (measured when the
  Newton steps still used ``jnp.linalg.solve``). Timed warm; its compile
  time (13-45 s on 2 loaded cores) is the "first run" line printed before
  the table.

The ODE engines reach the same THRT to a few 1e-10 s (the same rtol and
per-state absolute tolerances; CVODES takes one absolute tolerance, so its
states are scaled by theirs, which gives the same error weights).

    python benchmarks/anchors.py [--repeat N] [--no-jit] [--cpu] [--blocks]
        [--scipy LSODA,DOP853] [--diffrax Tsit5] [--cvodes adams|bdf]

``--cpu`` times CPU seconds of this process instead of wall time (the engines
are single-threaded; JAX's CPU time equalled its wall time here): steadier
on a shared machine. The load average is printed with the table. The runs
are interleaved (a, b, c, a, b, c, ...) so that a change of load hits every
engine alike, but then each run starts with caches the others have used:
``--blocks`` adds a column with each engine's runs back to back, what a loop
of simulations on one engine sees (acausal's compiled backend and diffrax
took about half their interleaved time that way).
"""
import argparse
import os
import sys
import time
from types import SimpleNamespace

import numpy as np
import sympy as sp

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.join(ROOT, "benchmarks"))

from timing import best_interleaved  # noqa: E402

from acausal.runtime.backends import compiled_available  # noqa: E402
from acausal.runtime.initialize import initial_point  # noqa: E402
from acausal.modelfile import compile_file, evaluate_measures  # noqa: E402
from acausal.runtime.hybrid import EventState  # noqa: E402
from acausal.lang.symbols import time as t_sym  # noqa: E402

PARAMS = {"contact.K": 6.25e8, "hook.bh": 0.219}
# the hand-written reference's absolute tolerances (benchmarks/breaker_speed.py)
ATOL = {"armature.mass.s": 1e-11, "armature.mass.v": 1e-8, "hook.phi": 1e-10,
        "hook.body.w": 1e-7, "*": 1e-10}


# -- sympy -> CasADi SX or JAX ------------------------------------------------------
def _casadi_lib():
    import casadi as ca
    return SimpleNamespace(
        mod=ca, if_else=ca.if_else, sqrt=ca.sqrt, constpow=ca.constpow, power=ca.power,
        And=ca.logic_and, Or=ca.logic_or, Not=ca.logic_not, Abs=ca.fabs, sign=ca.sign,
        Max=ca.fmax, Min=ca.fmin, atan2=ca.atan2,
        PosPow=lambda x, g: ca.if_else(x > 0, ca.power(x, g), 0))


def _jax_lib():
    import jax.numpy as jnp

    def pospow(x, g):    # no NaN in the branch not taken: its derivative would be NaN
        return jnp.where(x > 0, jnp.where(x > 0, x, 1.0) ** g, 0.0)
    return SimpleNamespace(
        mod=jnp, if_else=jnp.where, sqrt=jnp.sqrt, constpow=lambda x, e: x ** e,
        power=jnp.power, And=jnp.logical_and, Or=jnp.logical_or, Not=jnp.logical_not,
        Abs=jnp.abs, sign=jnp.sign, Max=jnp.maximum, Min=jnp.minimum, atan2=jnp.arctan2,
        PosPow=pospow)


def convert(expr, env, memo, lib):
    """A sympy expression in ``lib`` (:func:`_casadi_lib` or :func:`_jax_lib`);
    ``env`` maps symbols to that library's values."""
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
            v = convert(val, env, memo, lib)
            out = v if cond == sp.true else lib.if_else(convert(cond, env, memo, lib), v, out)
    else:
        out = _apply(expr, [convert(x, env, memo, lib) for x in expr.args], lib)
    memo[expr] = out
    return out


def to_casadi(expr, env, memo):
    """CasADi SX of a sympy expression; ``env`` maps symbols to SX."""
    return convert(expr, env, memo, _casadi_lib())


_RELATIONS = {"StrictGreaterThan": lambda x, y: x > y, "GreaterThan": lambda x, y: x >= y,
              "StrictLessThan": lambda x, y: x < y, "LessThan": lambda x, y: x <= y,
              "Equality": lambda x, y: x == y, "Unequality": lambda x, y: x != y}


def _apply(expr, a, lib):
    name = type(expr).__name__
    if expr.is_Add:
        return sum(a[1:], a[0])
    if expr.is_Mul:
        return _fold(lambda x, y: x * y, a)
    if expr.is_Pow:
        e = expr.args[1]
        if e == sp.Rational(1, 2):
            return lib.sqrt(a[0])
        return lib.constpow(a[0], a[1]) if e.is_Number else lib.power(a[0], a[1])
    if name in _RELATIONS:
        return _RELATIONS[name](*a)
    if name in ("And", "Or", "Max", "Min"):
        return _fold(getattr(lib, name), a)
    if name == "Heaviside":
        return lib.if_else(a[0] > 0, 1.0, lib.if_else(a[0] == 0, 0.5, 0.0))
    fn = getattr(lib, name, None) or getattr(lib.mod, name, None)
    if fn is None:
        raise NotImplementedError(f"no {lib.mod.__name__} form for {name}")
    return fn(*a)


def _fold(f, xs):
    out = xs[0]
    for x in xs[1:]:
        out = f(out, x)
    return out


# -- the reduced DAE, its roots, its explicit form ------------------------------------
def root_functions(cm):
    """(expressions, directions, acts) of the root functions in acausal's order
    (events, then assertions); ``acts``: False for observers, which do not
    change the trajectory."""
    exprs = [cm.resolve(e.expr) for e in cm.events] + [cm.resolve(a.expr) for a in cm.assertions]
    dirs = [e.direction for e in cm.events] + [-1] * len(cm.assertions)
    acts = [not e.observer for e in cm.events] + [True] * len(cm.assertions)
    return exprs, dirs, acts


def explicit_form(cm):
    """The reduced DAE F(t, x, z, w) = 0 (x' = w) split for an ODE integrator:
    (w as expressions of (t, x, z), the constraint rows g(t, x, z) = 0 that fix
    the algebraic unknowns z). Checked, not assumed: F must be linear in w
    with constant coefficients (for the breaker it is explicit, w = f(x, z):
    acausal has already eliminated the contact and joint forces); z (the
    four-bar's coupler and main-shaft angles) enters nonlinearly through the
    position closure, so the ODE engines solve g = 0 by Newton."""
    dae = cm.dae
    ns = dae.n_states
    w = list(dae.yp[:ns])
    A = sp.Matrix([[r.diff(s) for s in w] for r in dae.residuals])
    if not all(a.is_Number for a in A):
        raise NotImplementedError("the reduced DAE is not linear in x' with constant coefficients")
    b = [r.subs({s: 0 for s in w}) for r in dae.residuals]
    rows = [i for i in range(len(b)) if any(A[i, j] != 0 for j in range(ns))]
    if len(rows) != ns:
        raise NotImplementedError("x' is not fixed by the differential rows alone")
    Ainv = A.extract(rows, list(range(ns))).inv()
    w_expr = [-sum(Ainv[j, k] * b[rows[k]] for k in range(ns)) for j in range(ns)]
    return w_expr, [b[i] for i in range(len(b)) if i not in rows]


def _act(cm, p, d, te, x, z, i):
    """Event ``i``'s action at the point (x, z = (algebraic unknowns, x')): the
    discrete values after it."""
    ns = cm.dae.n_states
    yy = np.concatenate([x, z[:len(z) - ns]])
    yyp = np.zeros(len(yy))
    yyp[:ns] = z[len(z) - ns:]
    st = EventState(cm, p, d, te, cm.callbacks(p, d)[4](te, yy, yyp))
    cm.events[i].action(st)
    return st.d


def _ended(cm, i):
    return i < len(cm.events) and cm.events[i].terminal


# -- CasADi: IDAS and CVODES, events located on a grid ----------------------------------
class _CasadiHybrid:
    """The breaker's reduced DAE in CasADi with grid-located events: the mode
    loop shared by the IDAS and CVODES rows. A subclass integrates with
    ``_grid(x, z, pd, t, dt)`` (the state at the grid's points, the start
    included) and ``_end(x, z, pd, ta, h)`` (the state at ta + h); z is
    (algebraic unknowns, x') in both."""

    def __init__(self, cm, grid):
        import casadi as ca
        dae = cm.dae
        n, ns = len(dae.y), dae.n_states
        self.cm, self.n, self.ns = cm, n, ns
        self.x, self.za, self.w = ca.SX.sym("x", ns), ca.SX.sym("za", n - ns), ca.SX.sym("w", ns)
        self.pd = ca.SX.sym("pd", len(cm.param_syms) + len(cm.disc_syms))
        self.t0, self.dt, self.tau = ca.SX.sym("t0"), ca.SX.sym("dt"), ca.SX.sym("tau")
        self.tt = self.t0 + self.tau * self.dt
        self.env = _sym_env(cm, ca.vertcat(self.x, self.za), self.w, self.pd, self.tt)
        self.memo = {}
        exprs, self.dirs, self.acts = root_functions(cm)
        G = ca.vertcat(*[self.sx(g) for g in exprs])
        self.z = ca.vertcat(self.za, self.w)
        self.gf = ca.Function("g", [self.x, self.z, self.pd, self.t0, self.dt, self.tau], [G])
        self.gmap = self.gf.map(grid + 1)
        self.grid = np.linspace(0.0, 1.0, grid + 1)

    def sx(self, expr):
        return to_casadi(expr, self.env, self.memo)

    def simulate(self, p, d, t, y, yp, t_end, chunk):
        """Integrate from the consistent point to the terminal root; the
        event times, in order."""
        cm, ns = self.cm, self.ns
        x, z = y[:ns].copy(), np.concatenate([y[ns:], yp[:ns]])
        d, events = list(d), []
        while t < t_end:
            pd = np.concatenate([p, d])
            dt = min(chunk, t_end - t)
            X, Z = self._grid(x, z, pd, t, dt)
            hit = self._first_crossing(np.array(self.gmap(X, Z, pd, t, dt, self.grid[None, :])))
            if hit is None:
                t, x, z = t + dt, X[:, -1], Z[:, -1]
                continue
            k, i = hit
            t, x, z = self._refine(X[:, k - 1], Z[:, k - 1], pd, t + self.grid[k - 1] * dt,
                                   (self.grid[k] - self.grid[k - 1]) * dt, i)
            events.append((t, cm.events[i].name if i < len(cm.events) else "assert"))
            if _ended(cm, i):
                break
            d = _act(cm, p, d, t, x, z, i)
        return events

    def replay(self, p, d, t, y, yp, events):
        """The lower bound of the CasADi side: integrate from event to event
        at the given times (one integrator call per mode, nothing located),
        applying the same event actions."""
        cm, ns = self.cm, self.ns
        x, z = y[:ns].copy(), np.concatenate([y[ns:], yp[:ns]])
        d = list(d)
        for te, name in events:
            x, z = self._end(x, z, np.concatenate([p, d]), t, te - t)
            t = te
            i = [e.name for e in cm.events].index(name)
            if _ended(cm, i):
                break
            d = _act(cm, p, d, te, x, z, i)
        return x

    def _first_crossing(self, G):
        best = None
        for i, direc in enumerate(self.dirs):
            if not self.acts[i]:
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
            xf, zf = self._end(x, z, pd, ta, h)
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


def _sym_env(cm, y, w, pd, t):
    """Symbol -> value map of acausal's unknowns, x', parameters, discrete
    values and time (CasADi SX or JAX arrays alike)."""
    dae = cm.dae
    env = {s: y[i] for i, s in enumerate(dae.y)}
    env.update({s: w[i] for i, s in enumerate(dae.yp[:dae.n_states])})
    env.update({s: pd[i] for i, s in enumerate(list(cm.param_syms) + list(cm.disc_syms))})
    env[t_sym] = t
    return env


def _casadi_opts(rtol, atol, jit):
    opts = dict(reltol=rtol, abstol=1e-10, max_num_steps=100000)
    if np.ndim(atol):
        opts["abstolv"] = [float(a) for a in atol]
        del opts["abstol"]
    if jit:
        opts.update(jit=True, compiler="shell", jit_options=dict(flags=["-O2"]))
    return opts


class CasadiIDAS(_CasadiHybrid):
    """IDAS on the semi-explicit DAE x' = w, 0 = F(t, x, z, w); parameters and
    discrete values are integrator parameters, so one integrator serves
    every mode."""

    def __init__(self, cm, rtol, atol, jit, grid=40):
        import casadi as ca
        super().__init__(cm, grid)
        F = ca.vertcat(*[self.sx(r) for r in cm.dae.residuals])
        ode = dict(x=self.x, z=self.z, p=ca.vertcat(self.pd, self.t0, self.dt), t=self.tau,
                   ode=self.dt * self.w, alg=F)
        atol = list(atol) + [1e-2] * self.ns if np.ndim(atol) else atol
        opts = _casadi_opts(rtol, atol, jit)
        opts["calc_ic"] = True
        self.I_grid = ca.integrator("Ig", "idas", ode, 0.0, list(self.grid[1:]), opts)
        self.I_end = ca.integrator("Ie", "idas", ode, 0.0, 1.0, opts)

    def _grid(self, x, z, pd, t, dt):
        r = self.I_grid(x0=x, z0=z, p=np.concatenate([pd, [t, dt]]))
        return (np.hstack([x[:, None], np.array(r["xf"])]),
                np.hstack([z[:, None], np.array(r["zf"])]))

    def _end(self, x, z, pd, ta, h):
        r = self.I_end(x0=x, z0=z, p=np.concatenate([pd, [ta, h]]))
        return np.array(r["xf"]).ravel(), np.array(r["zf"]).ravel()


class CasadiCVODES(_CasadiHybrid):
    """CVODES on the explicit ODE x' = w(t, x, z(x)) of :func:`explicit_form`:
    z(x) is ``newton`` Newton steps on the position closure g(t, x, z) = 0
    inside the SX graph (unrolled, so CVODES's Jacobian is CasADi's AD of it),
    from the algebraic unknowns at the start of the integrator call (an
    integrator parameter). CVODES's own zero crossings (experimental in
    CasADi 3.8) fire on falling crossings only and need the event actions as
    CasADi functions (casadi#4393), so the events are located as for IDAS."""

    def __init__(self, cm, rtol, atol, jit, grid=40, newton=3, method="adams"):
        import casadi as ca
        super().__init__(cm, grid)
        w_expr, cons = explicit_form(cm)
        zg = ca.SX.sym("zg", self.n - self.ns)
        za = casadi_newton(ca.vertcat(*[self.sx(g) for g in cons]), self.za, zg, newton)
        w = ca.substitute(ca.vertcat(*[self.sx(e) for e in w_expr]), self.za, za)
        self.zw = ca.Function("zw", [self.x, self.pd, zg, self.t0, self.dt, self.tau],
                              [ca.vertcat(za, w)])
        self.zw_grid = self.zw.map(grid + 1)
        # CVODES takes one absolute tolerance: the states scaled by their own
        # (x = atol_x * xs, abstol 1) give the same error weights
        self.scale = np.broadcast_to(np.asarray(atol, float), (self.n,))[:self.ns].copy()
        xs = ca.SX.sym("xs", self.ns)
        ode = dict(x=xs, p=ca.vertcat(self.pd, zg, self.t0, self.dt), t=self.tau,
                   ode=ca.substitute(self.dt * w / self.scale, self.x, self.scale * xs))
        opts = _casadi_opts(rtol, 1.0, jit)
        opts["linear_multistep_method"] = method
        if method == "adams":
            opts["nonlinear_solver_iteration"] = "functional"
        self.I_grid = ca.integrator("Cg", "cvodes", ode, 0.0, list(self.grid[1:]), opts)
        self.I_end = ca.integrator("Ce", "cvodes", ode, 0.0, 1.0, opts)

    def _grid(self, x, z, pd, t, dt):
        zg = z[:self.n - self.ns]
        r = self.I_grid(x0=x / self.scale, p=np.concatenate([pd, zg, [t, dt]]))
        X = np.hstack([x[:, None], np.array(r["xf"]) * self.scale[:, None]])
        return X, np.array(self.zw_grid(X, pd, zg, t, dt, self.grid[None, :]))

    def _end(self, x, z, pd, ta, h):
        zg = z[:self.n - self.ns]
        r = self.I_end(x0=x / self.scale, p=np.concatenate([pd, zg, [ta, h]]))
        xf = np.array(r["xf"]).ravel() * self.scale
        return xf, np.array(self.zw(xf, pd, zg, ta, h, 1.0)).ravel()


def casadi_newton(g, z, z0, steps):
    """``steps`` Newton steps on g(z) = 0 from ``z0``, unrolled in SX."""
    import casadi as ca
    step = z - ca.solve(ca.jacobian(g, z), g)
    out = z0
    for _ in range(steps):
        out = ca.substitute(step, z, out)
    return out


# -- ODE integrators that locate their own roots: scipy, diffrax ----------------------
class _OdeHybrid:
    """The mode loop around an ODE integrator with its own root finding: each
    segment runs to the first root (with its direction) of the root
    functions that change the trajectory, in the current mode's discrete
    values; acausal's event action then gives the next mode. A subclass
    gives ``_segment(x, pd, zg, t, t_end)`` -> (t, x, z = (algebraic unknowns,
    x') at t, index into ``self.active`` or None)."""

    def __init__(self, cm):
        self.cm, self.ns = cm, cm.dae.n_states
        self.exprs, self.dirs, acts = root_functions(cm)
        self.active = [i for i, a in enumerate(acts) if a]

    def simulate(self, p, d, t, y, yp, t_end):
        cm, ns = self.cm, self.ns
        x, zg, d, events = np.array(y[:ns]), np.array(y[ns:]), list(d), []
        while t < t_end:
            pd = np.concatenate([p, d])
            t, x, z, k = self._segment(x, pd, zg, t, t_end)
            if k is None:
                break
            i = self.active[k]
            zg = z[:len(zg)]
            events.append((t, cm.events[i].name if i < len(cm.events) else "assert"))
            if _ended(cm, i):
                break
            d = _act(cm, p, d, t, x, z, i)
        return events


def python_form(cm, roots):
    """The explicit form as plain-Python ``math`` functions of (t, x, z, p):
    a Newton step on the position closure (its 2x2 solve written out by
    sympy), x', and the root functions ``roots`` (with x' as a last
    argument)."""
    dae, ns = cm.dae, cm.dae.n_states
    w_expr, cons = explicit_form(cm)
    za = list(dae.y[ns:])
    g = sp.Matrix(cons)
    step = sp.Matrix(za) - g.jacobian(za).LUsolve(g)
    args = [t_sym, list(dae.y[:ns]), za, list(cm.param_syms) + list(cm.disc_syms)]
    mods = [{"PosPow": lambda x, e: x ** e if x > 0 else 0.0}, "math"]
    return (sp.lambdify(args, list(step), modules=mods, cse=True),
            sp.lambdify(args, w_expr, modules=mods, cse=True),
            sp.lambdify(args + [list(dae.yp[:ns])], roots, modules=mods, cse=True))


class ScipyODE(_OdeHybrid):
    """scipy.integrate.solve_ivp on x' = w(t, x, z(x)) in plain Python: the
    same sympy equations as scalar ``math`` code (``sympy.lambdify``, cse),
    z(x) by ``newton`` Newton steps (2x2 linear solve written out by sympy)
    from the algebraic unknowns at the segment's start; one solve_ivp event
    per acting root function (terminal, with its direction), the events
    sharing one evaluation per (t, x). No Jacobian is given: the explicit
    methods need none (a CasADi-evaluated right-hand side was 3-4x slower
    per call here, 40 us against 11 us, and Radau and BDF 2-4x slower than
    LSODA)."""

    def __init__(self, cm, rtol, atol, method, newton=3):
        super().__init__(cm)
        self.rtol, self.atol, self.method = rtol, np.asarray(atol)[:self.ns], method
        self.step, self.w, self.g = python_form(cm, [self.exprs[i] for i in self.active])
        self.newton = newton
        self._key, self._gval = None, None

    def _za(self, t, x, pd, zg):
        za = zg
        for _ in range(self.newton):
            za = self.step(t, x, za, pd)
        return za

    def _segment(self, x, pd, zg, t, t_end):
        from scipy.integrate import solve_ivp
        pd, zg = pd.tolist(), zg.tolist()

        def rhs(t, x):
            x = x.tolist()
            return self.w(t, x, self._za(t, x, pd, zg), pd)
        events = [self._event(k, pd, zg) for k in range(len(self.active))]
        sol = solve_ivp(rhs, (t, t_end), x, method=self.method, rtol=self.rtol,
                        atol=self.atol, events=events)
        hit = [k for k, te in enumerate(sol.t_events) if len(te)]
        if not hit:
            return sol.t[-1], sol.y[:, -1], None, None
        k = hit[0]
        te, xe = sol.t_events[k][0], sol.y_events[k][0]
        return te, xe, self._zw(xe, pd, zg, te), k

    def _event(self, k, pd, zg):
        def g(t, x):
            key = (t, x.tobytes())
            if key != self._key:
                x = x.tolist()
                za = self._za(t, x, pd, zg)
                self._key, self._gval = key, self.g(t, x, za, pd, self.w(t, x, za, pd))
            return self._gval[k]
        g.terminal, g.direction = True, self.dirs[self.active[k]]
        return g

    def _zw(self, x, pd, zg, t):
        x = x.tolist()
        za = self._za(t, x, pd, zg)
        return np.array(list(za) + list(self.w(t, x, za, pd)), float)


class JaxForm:
    """The explicit form in jax.numpy: ``zw(t, x, pd, zg)`` -> (algebraic
    unknowns by ``newton`` Newton steps from ``zg``, x'), and a root
    function's diffrax condition (the Newton steps only where the root needs
    the algebraic unknowns or x')."""

    def __init__(self, cm, newton):
        import jax.numpy as jnp
        self.cm, self.ns, self.newton, self.lib = cm, cm.dae.n_states, newton, _jax_lib()
        w_expr, cons = explicit_form(cm)
        self.g, self.w = self.fn(cons), self.fn(w_expr)
        self.w0 = jnp.zeros(self.ns)

    def fn(self, exprs):
        import jax.numpy as jnp

        def f(t, x, za, w, pd):
            env = _sym_env(self.cm, jnp.concatenate([x, za]), w, pd, t)
            memo = {}
            return jnp.stack([jnp.asarray(convert(e, env, memo, self.lib), float)
                              for e in exprs])
        return f

    def zw(self, t, x, pd, zg):
        import jax
        import jax.numpy as jnp
        za, w0 = zg, self.w0
        for _ in range(self.newton):
            jac = jax.jacfwd(self.g, argnums=2)(t, x, za, w0, pd)
            za = za - _small_solve(jac, self.g(t, x, za, w0, pd))
        return za, self.w(t, x, za, w0, pd)

    def rhs(self, t, x, args):
        return self.zw(t, x, *args)[1]

    def cond(self, expr):
        dae, root = self.cm.dae, self.fn([expr])
        if expr.free_symbols & (set(dae.y[self.ns:]) | set(dae.yp[:self.ns])):
            return lambda t, y, args, **kw: root(t, y, *self.zw(t, y, *args), args[0])[0]
        return lambda t, y, args, **kw: root(t, y, args[1], self.w0, args[0])[0]


def _small_solve(A, b):
    """A^-1 b in jax.numpy; 2x2 by Cramer's rule: XLA's LAPACK call on the
    CPU took two thirds of the diffrax run (1.5 against 0.56 ms) when the
    closure's 2x2 Newton steps used ``jnp.linalg.solve``."""
    import jax.numpy as jnp
    if A.shape != (2, 2):
        return jnp.linalg.solve(A, b)
    det = A[0, 0] * A[1, 1] - A[0, 1] * A[1, 0]
    return jnp.stack([A[1, 1] * b[0] - A[0, 1] * b[1], A[0, 0] * b[1] - A[1, 0] * b[0]]) / det


class DiffraxODE(_OdeHybrid):
    """diffrax (JAX, CPU, float64) on x' = w(t, x, z(x)) (:class:`JaxForm`):
    one ``jax.jit``-compiled ``diffeqsolve`` per segment with a PID step-size
    controller and a ``diffrax.Event`` of the acting root functions (with
    their directions, optimistix Newton on the dense output for the root
    time). Parameters, discrete values and the Newton steps' start are
    arguments, so the one compiled function serves every mode."""

    def __init__(self, cm, rtol, atol, solver="Tsit5", newton=3):
        import jax
        jax.config.update("jax_enable_x64", True)
        import diffrax as dfx
        import jax.numpy as jnp
        import optimistix as optx
        super().__init__(cm)
        form = JaxForm(cm, newton)
        event = dfx.Event([form.cond(self.exprs[i]) for i in self.active],
                          root_finder=optx.Newton(rtol=1e-12, atol=1e-15),
                          direction=[None if self.dirs[i] == 0 else self.dirs[i] > 0
                                     for i in self.active])
        ctrl = dfx.PIDController(rtol=rtol, atol=jnp.asarray(np.asarray(atol)[:self.ns]))
        term, solv = dfx.ODETerm(form.rhs), getattr(dfx, solver)()

        @jax.jit
        def segment(x, pd, zg, t, t_end):
            sol = dfx.diffeqsolve(term, solv, t, t_end, None, x, args=(pd, zg),
                                  stepsize_controller=ctrl, event=event, max_steps=100000)
            te, xe = sol.ts[-1], sol.ys[-1]
            return te, xe, jnp.concatenate(form.zw(te, xe, pd, zg)), jnp.stack(sol.event_mask)
        self.segment_jit = segment

    def _segment(self, x, pd, zg, t, t_end):
        te, xe, z, mask = self.segment_jit(x, pd, zg, t, t_end)
        mask = np.asarray(mask)
        return (float(te), np.asarray(xe), np.asarray(z),
                int(np.argmax(mask)) if mask.any() else None)


def _thrt(events):
    onset = next(t for t, n in events if n.endswith("onset"))
    return next(t for t, n in events if n == "release") - onset


class Case:
    """The breaker run every engine repeats: acausal's consistent initial point,
    parameters, discrete values, tolerances."""

    def __init__(self, cm, bench):
        from acausal.runtime.hybrid import _atol_vector
        self.cm = cm
        self.p = cm.param_vector(PARAMS)
        self.d = cm.discrete_start()
        self.y, self.yp = initial_point(cm, self.p, self.d, cm.callbacks(self.p, self.d), 0.0)
        self.atol = _atol_vector(cm, ATOL, None)
        self.rtol, self.t_end = bench["rtol"], bench["t_end"]

    def row(self, label, run):
        """(label, timed function, THRT) of an engine's ``run(p, d, t, y, yp)``
        -> events; runs it once (set-up and, for JAX, compilation)."""
        t0 = time.perf_counter()
        events = run(self.p, self.d, 0.0, self.y, self.yp)
        print(f"{label}: first run {time.perf_counter() - t0:.2f} s")
        return (label, lambda: run(self.p, self.d, 0.0, self.y, self.yp), _thrt(events))


def _missing(*modules):
    """The first module of ``modules`` that does not import, or None."""
    import importlib
    for m in modules:
        try:
            importlib.import_module(m)
        except ImportError:
            return m
    return None


def acausal_rows(mf, cm, bench):
    own = mf.experiment.run_options()
    rows = []
    for backend in ["sundae", "compiled"]:
        for label, opts in [("benchmark options", bench), ("the file's options", own)]:
            res = cm.simulate(params=PARAMS, backend=backend, **opts)   # builds/loads once
            rows.append((f"acausal {res.stats['backend']}, {label}",
                         lambda b=backend, o=opts: cm.simulate(params=PARAMS, backend=b, **o),
                         evaluate_measures(mf, res)["thrt"]))
    why = compiled_available()
    if why:
        print(f"note: the compiled backend is unavailable here ({why}); it fell back")
    return rows


def casadi_rows(case, jits, cvodes_method, chunk=5e-4):
    """IDAS and CVODES, each locating its events and with the event times
    given, per jit setting."""
    rows = []
    for jit in jits:
        how = "compiled (jit)" if jit else "SX virtual machine"
        t0 = time.perf_counter()
        engines = [("CasADi IDAS", CasadiIDAS(case.cm, case.rtol, case.atol, jit, grid=100)),
                   (f"CasADi CVODES ({cvodes_method.upper()})",
                    CasadiCVODES(case.cm, case.rtol, case.atol, jit, grid=100,
                                 method=cvodes_method))]
        print(f"CasADi IDAS and CVODES ({how}): set-up {time.perf_counter() - t0:.2f} s")
        for name, eng in engines:
            rows += _casadi_pair(case, f"{name}, {how}", eng, chunk)
    return rows


def _casadi_pair(case, label, eng, chunk):
    """The rows of one CasADi engine: locating its events, and given them."""
    row = case.row(label, lambda *a: eng.simulate(*a, case.t_end, chunk))
    events = eng.simulate(case.p, case.d, 0.0, case.y, case.yp, case.t_end, chunk)
    return [row, (label + ", events given", lambda:
                  eng.replay(case.p, case.d, 0.0, case.y, case.yp, events), row[2])]


def ode_rows(case, engine, methods, label):
    """One row per method of an ODE engine (:class:`ScipyODE`, :class:`DiffraxODE`)."""
    rows = []
    for method in methods:
        eng = engine(case.cm, case.rtol, case.atol, method)
        rows.append(case.row(label.format(method),
                             lambda *a, e=eng: e.simulate(*a, case.t_end)))
    return rows


def outside_rows(case, args):
    """Every outside engine that is installed; one line for each that is not."""
    rows = []
    if _missing("casadi"):
        print("skipped: CasADi IDAS and CVODES: casadi is not installed "
              "(pip install 'acausal[bench]')")
    else:
        rows += casadi_rows(case, [False] if args.no_jit else [False, True], args.cvodes)
    rows += ode_rows(case, ScipyODE, args.scipy.split(","),
                     "scipy {}, plain-Python right-hand side")
    gone = _missing("jax", "diffrax", "optimistix")
    if gone:
        print(f"skipped: diffrax: {gone} is not installed (pip install 'acausal[bench]')")
    else:
        rows += ode_rows(case, DiffraxODE, args.diffrax.split(","),
                         "diffrax {} (JAX, CPU, jit), event root")
    return rows


def print_table(runs, times, args, load0, blocks=None):
    """The table; ``blocks``: each engine's best time with its runs back to
    back, when measured."""
    names = [lab for lab, _, _ in runs]
    idas = [tm for lab, tm in zip(names, times) if lab.startswith("CasADi IDAS")
            and "given" not in lab]
    anchor = min(idas) if idas else min(times)
    ref = runs[0][2]
    print(f"\nbest of {args.repeat}, interleaved, {'CPU' if args.cpu else 'wall'} time (load "
          f"{load0:.1f} before, {os.getloadavg()[0]:.1f} after); THRT difference against "
          "acausal sundae (benchmark options)")
    per = "x IDAS" if idas else "x best"      # per CasADi IDAS, else per the fastest row
    print(f"{'engine':58s} {'ms/sim':>8s} {per:>7s} {'THRT [ms]':>12s} {'dTHRT [s]':>10s}"
          + (f" {'blocks':>7s}" if blocks else ""))
    for k, ((lab, _, thrt), tm) in enumerate(zip(runs, times)):
        print(f"{lab:58s} {tm * 1e3:8.2f} {tm / anchor:7.2f} {thrt * 1e3:12.7f} "
              f"{thrt - ref:10.1e}" + (f" {blocks[k] * 1e3:7.2f}" if blocks else ""))
    if blocks:
        print("blocks: ms/sim with each engine's runs back to back (measured after the "
              "interleaved runs)")
    fastest = min(tm for lab, tm in zip(names, times) if lab.startswith("acausal"))
    if idas:
        bound = min(tm for lab, tm in zip(names, times) if "given" in lab and "IDAS" in lab)
        print(f"\n'x IDAS': per fastest CasADi IDAS locating its events. Fastest acausal / "
              f"that = {fastest / anchor:.2f} (target <= 2)")
        print(f"fastest acausal / CasADi IDAS with the event times given (a lower bound "
              f"of any CasADi IDAS run) = {fastest / bound:.2f}")
    for lab, tm in zip(names, times):
        if not lab.startswith(("acausal", "CasADi IDAS")) and "given" not in lab:
            print(f"fastest acausal / {lab} = {fastest / tm:.2f}")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=10)
    ap.add_argument("--no-jit", action="store_true")
    ap.add_argument("--cpu", action="store_true", help="CPU time instead of wall time")
    ap.add_argument("--scipy", default="LSODA,DOP853", help="solve_ivp methods, comma-separated")
    ap.add_argument("--diffrax", default="Tsit5", help="diffrax solvers, comma-separated")
    ap.add_argument("--blocks", action="store_true",
                    help="also time each engine's runs back to back (warm caches)")
    ap.add_argument("--cvodes", default="adams", choices=["adams", "bdf"],
                    help="CVODES's multistep method (Adams with functional iteration, "
                         "or BDF with Newton)")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    mf, cm = compile_file(os.path.join(ROOT, "models", "breaker_24kv.py"))
    print(f"acausal compile (once): {time.perf_counter() - t0:.2f} s; "
          f"states/unknowns {cm.dae.n_states}/{len(cm.dae.y)}")
    bench = mf.experiment.run_options()
    bench.update(output_step=0, atol=ATOL)
    runs = acausal_rows(mf, cm, bench) + outside_rows(Case(cm, bench), args)
    load0 = os.getloadavg()[0]
    clock = time.process_time if args.cpu else time.perf_counter
    times = best_interleaved([fn for _, fn, _ in runs], args.repeat, clock)
    blocks = [best_interleaved([fn], args.repeat, clock)[0] for _, fn, _ in runs] \
        if args.blocks else None
    print_table(runs, times, args, load0, blocks)


if __name__ == "__main__":
    main()
