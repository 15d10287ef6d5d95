"""Forward sensitivities along a finished run, staggered: a fit's Jacobian
for the price of about one simulation.

The augmented model of :mod:`.sensitivity` integrates the sensitivities
with the states under IDA's error control: n (1 + k) unknowns, and for the
located term's 50-100 weights slower than k + 1 simulations. Here the base
DAE ``F(t, y, y', p) = 0`` is integrated once by the compiled backend
(every accepted step kept), then the linear sensitivity DAE

    F_y S + F_y' S' + F_p = 0

is integrated for all k parameters at once on the same step sequence by
the variable-coefficient BDF of order :data:`ORDER` (Lagrange form on the
run's own time points), one LU of ``F_y + a_0 F_y'`` a step, in C
(``backends/sweep.c``; the staggered direct method of Caracotsios and
Stewart 1985, "Sensitivity analysis of initial value problems with mixed
ODEs and algebraic equations", Comput. Chem. Eng. 9, without its corrector
iteration since the equations are linear). ``F_p`` by central differences
of the residual (relative step :data:`REL_STEP`; forward ones in a
parameter the residuals are linear in: :func:`linear_in`); the start by the implicit
function theorem on the initial system
(:func:`.sensitivity_run.initial_state_sensitivities`); outputs by cubic
Hermite interpolation of (S, S'), observed variables through their
expressions' gradients.

Accuracy: the sensitivities' error is not controlled, it follows the base
run's steps (on the geared drive's located term, 84 parameters, within
2-3e-4 of central differences of rtol 1e-10 runs, where forward differences
of the fits' step were 1 % off; benchmarks/prototypes/staggered_sensitivities/).

Limits (:class:`SweepUnavailable`, a caller falls back to differences): the
compiled backend only; a run with events or restarts (mode changes would
need the jumps of Galan, Feehery and Barton 1999, which the augmented model
carries); measures (functions of a whole result).
"""
import weakref

import numpy as np

from ..errors import SolverError, UsageError
from ..lang.fastdiff import diff
from .linalg import jacobians, lstsq_scaled
from .result import Result, Rows
from .sensitivity_run import ParameterDerivatives, initial_state_sensitivities

ORDER = 3        # the sweep's BDF order (1-5): 3 agreed with the tight reference to 2-3e-4
                 # on the geared drive, within the reference's own spread
REL_STEP = 1e-6  # F_p's central-difference step, of each parameter's size (its value or
                 # its typical magnitude, the larger: a weight near 0 took steps of 1e-16
                 # of a unit, all rounding)
_GRADIENTS = weakref.WeakKeyDictionary()   # compiled model -> {(var, names): row function}
_LINEAR = weakref.WeakKeyDictionary()      # compiled model -> {names: linear mask}


class SweepUnavailable(SolverError):
    """The staggered sweep cannot serve this run (events, restarts, no
    compiled library, measures): a caller takes differences instead."""


def simulate(cm, params, names, scales=None, **options) -> Result:
    """Simulate compiled model ``cm`` with ``params`` (as ``cm.simulate``)
    and the sensitivities of every variable with respect to the parameters
    ``names``, staggered (module doc). ``scales``: each parameter's typical
    magnitude (the difference steps' size where its value is smaller; None:
    1 in its unit). ``options``: ``cm.simulate``'s; the
    result's rows are at ``output_times`` when given, else at every
    accepted step. ``res.sensitivity(var, name)`` reads them.

    Raises :class:`SweepUnavailable` (module doc's limits),
    :class:`~acausal.errors.ParameterError` for a name that is not a free
    parameter, and what ``cm.simulate`` raises."""
    from .backends import compiled
    names = list(names)
    pidx = [cm.param_index(nm) for nm in names]      # ParameterError names a stranger
    if options.get("backend") not in (None, "compiled"):
        raise SweepUnavailable(f"the staggered sweep runs on the compiled backend, "
                               f"not {options['backend']!r}")
    try:
        compiled.library(cm)
    except compiled.Unavailable as exc:
        raise SweepUnavailable(str(exc)) from None
    tout = options.get("output_times")
    run = {**options, "backend": "compiled", "output_step": 0, "output_times": None}
    base = cm.simulate(params=params, **run)
    _check(base)
    p, d0 = base.p, base.d[0]
    pd = np.concatenate([p, d0])
    linear = linear_in(cm, tuple(names))
    typical = np.ones(len(names)) if scales is None else np.abs(np.asarray(scales, float))
    size = np.maximum(np.abs(p[pidx]), np.where(typical > 0, typical, 1.0))
    S0, SP0 = _start(cm, base, pd, pidx, REL_STEP * size, options.get("starts"))
    # (a linear column's difference is exact for any step: a large one, so
    # that rounding in the residual stays small against it)
    step = np.where(linear, 1.0, REL_STEP) * size
    tout = base.t if tout is None else _within(np.asarray(tout, float), base.t)
    try:
        S, SP = compiled.sweep(cm, compiled.Sweep(
            base.t, base.y, base.yp, pd, np.asarray(pidx), step, linear, S0, SP0, tout,
            ORDER))
    except RuntimeError as exc:
        raise SweepUnavailable(f"the sensitivity sweep failed: {exc}") from None
    Y, YP = _interpolate(base, tout, cm.dae.n_states)
    rows = Rows(tout, Y, YP, np.tile(d0, (tout.size, 1)))
    sens = StaggeredSensitivities(cm, p, rows, names, (S, SP))
    return Result(cm, p, rows, [], base.stats, base.status, base.message, sens)


def linear_in(cm, names):
    """Whether the residuals of compiled model ``cm`` are linear in each
    parameter of ``names`` (the derivative of every residual that reads it
    is free of it: a generic term's weights, a damper's coefficient), made
    once per model and names; the sweep takes forward differences there."""
    table = _LINEAR.setdefault(cm, {})
    got = table.get(names)
    if got is None:
        a = cm.artefact
        psyms = list(a.parameters.symbols)
        got = np.zeros(len(names), bool)
        for j, nm in enumerate(names):
            s = psyms[cm.param_index(nm)]
            reads = [r for r in a.dae.residuals if s in r.free_symbols]
            got[j] = all(s not in diff(r, s).free_symbols for r in reads)
        table[names] = got
    return got


def _check(base):
    if base.events:
        raise SweepUnavailable(f"the run has {len(base.events)} events (the staggered sweep "
                               f"carries no jumps)")
    if base.d.size and not np.all(base.d == base.d[0]):
        raise SweepUnavailable("the run's discrete values change")
    if base.t.size < 2 or not np.all(np.diff(base.t) > 0):
        raise SweepUnavailable("the run restarts (repeated times)")


def _within(tout, t):
    """The output times inside the run (the run ends at the last one asked,
    or stopped early: then only those it reached)."""
    return tout[(tout >= t[0]) & (tout <= t[-1])]


def _start(cm, base, pd, pidx, step, starts):
    """(S0, S'0), n x k, at the run's consistent start (``pd``: its
    parameters, then discrete values): the states' by the implicit function
    theorem on the initial system, then the algebraic unknowns' S and the
    states' S' from the linearised equations."""
    from .backends import compiled
    point = (base.t[0], base.y[0], base.yp[0])
    p, d0 = base.p, base.d[0]
    n, ns = base.y.shape[1], cm.dae.n_states
    Fp, op = compiled.parameter_derivatives(cm, point, pd, pidx, step)
    cb = compiled.c_callbacks(compiled.library(cm), cm, p, d0, lambda: cm.callbacks(p, d0))
    Ss = initial_state_sensitivities(cm, cb, p, point, d0, starts,
                                     ParameterDerivatives(tuple(pidx), Fp, op))
    Jy, Jyp = jacobians(cb, point[0], point[1], point[2], n)
    A = np.hstack([Jyp[:, :ns], Jy[:, ns:]])
    rhs = -(Fp.T + Jy[:, :ns] @ Ss.T)
    try:
        z = np.linalg.solve(A, rhs)
    except np.linalg.LinAlgError:
        z = lstsq_scaled(A, rhs)
    S0, SP0 = np.zeros((n, len(pidx))), np.zeros((n, len(pidx)))
    S0[:ns], S0[ns:], SP0[:ns] = Ss.T, z[ns:], z[:ns]
    return S0, SP0


def _interpolate(base, tout, ns):
    """(y, y') at ``tout`` from the run's steps: cubic Hermite of y with the
    slopes y' (the states' y' its derivative; the algebraic unknowns' y'
    linear)."""
    t, Y, YP = base.t, base.y, base.yp
    i = np.clip(np.searchsorted(t, tout, side="right") - 1, 0, t.size - 2)
    h = (t[i + 1] - t[i])[:, None]
    u = (tout[:, None] - t[i][:, None]) / h
    y = ((1 + 2 * u) * (1 - u) ** 2 * Y[i] + u * (1 - u) ** 2 * h * YP[i]
         + u * u * (3 - 2 * u) * Y[i + 1] + u * u * (u - 1) * h * YP[i + 1])
    dy = (6 * u * (u - 1) / h * (Y[i] - Y[i + 1]) + (1 - u) * (1 - 3 * u) * YP[i]
          + u * (3 * u - 2) * YP[i + 1])
    yp = YP[i] + u * (YP[i + 1] - YP[i])
    yp[:, :ns] = dy[:, :ns]
    return y, yp


class StaggeredSensitivities:
    """The sensitivities of a staggered run (``Result.sensitivity`` reads
    them): the unknowns' ``S`` and ``S'`` at the result's rows (rows x n x
    parameters); an observed variable's through its expression's gradient
    in the unknowns, their rates and the parameters."""

    def __init__(self, cm, p, rows, names, sens):
        self.cm, self.p, self.rows, self._names = cm, p, rows, list(names)
        self.S, self.SP = sens
        self._of = {}

    def names(self):
        return list(self._names)

    def of(self, var, param):
        if param not in self._names:
            raise UsageError(f"no sensitivity with respect to {param!r}: the run computed "
                             f"them for {', '.join(self._names)}")
        j = self._names.index(param)
        cm = self.cm
        if var not in cm.var_names:
            discretes = [s.name for s in cm.disc_syms]
            if var in discretes:
                return np.zeros(len(self.rows.t))
            if var in self._names or var in [e.name for e in cm.params]:
                return np.full(len(self.rows.t), 1.0 if var == param else 0.0)
            from ..errors import UnknownNameError
            raise UnknownNameError(f"no variable {var!r} in the result", variable=var)
        if var not in self._of:
            self._of[var] = self._observed(cm.var_names.index(var))
        return self._of[var][:, j]

    def _observed(self, k):
        """rows x parameters: d(observed variable k)/d(each parameter)."""
        fn, ys, yps = _gradient(self.cm, k, tuple(self._names))
        r = self.rows
        G = np.zeros((len(ys) + len(yps) + len(self._names), len(r.t)))
        d = r.d[0] if r.d.size else np.zeros(0)
        fn(r.t, r.y.T, r.yp.T, self.p, d, G)
        out = G[len(ys) + len(yps):].T.copy()
        for a, i in enumerate(ys):
            out += G[a][:, None] * self.S[:, i, :]
        for a, i in enumerate(yps):
            out += G[len(ys) + a][:, None] * self.SP[:, i, :]
        return out

    def event(self, param):
        return np.zeros(0)      # a staggered run has no events (SweepUnavailable)

    def measure(self, result, fn, param, rel_step=1e-6):
        raise SweepUnavailable("a measure's sensitivity needs the augmented model "
                               "(simulate(sensitivities=...))")


def _gradient(cm, k, names):
    """(row function, unknowns, unknowns whose rate) of observed variable
    ``k``'s gradient: the rows it fills are d/d y_i for the unknowns its
    expression reads, d/d y'_i for the rates it reads, then d/d p_j for
    ``names`` (:func:`acausal.compiler.codegen.generate_observe_rows`),
    made once per model, variable and names."""
    from ..compiler.codegen import generate_observe_rows
    table = _GRADIENTS.setdefault(cm, {})
    got = table.get((k, names))
    if got is None:
        a = cm.artefact
        e = a.observed_exprs()[k]
        free = e.free_symbols
        ys = [i for i, s in enumerate(a.dae.y) if s in free]
        yps = [i for i, s in enumerate(a.dae.yp) if s is not None and s in free]
        psyms = list(a.parameters.symbols)
        exprs = ([diff(e, a.dae.y[i]) for i in ys] + [diff(e, a.dae.yp[i]) for i in yps]
                 + [diff(e, psyms[cm.param_index(nm)]) for nm in names])
        fn = generate_observe_rows(exprs, a.dae.y, a.dae.yp, psyms, list(cm.disc_syms))
        got = table[(k, names)] = (fn, ys, yps)
    return got
