"""Linearisation and trim (static equilibrium) of a compiled model.

Why a module of its own, above :mod:`acausal.runtime`: a linearisation is
not a simulation, but it needs the runtime's operating points -- the
consistent start after the event iteration (the modes of contacts and
friction), a state reached by simulating, the algebraic unknowns
re-solved for given states -- and the compiler's DAE and generated
Jacobians. Putting it in the runtime would make the hybrid loop's package
carry analyses it never runs; putting it in :mod:`acausal.studies` (many
simulations of one model) would make the CLI's and the FMU's lighter
needs import the studies. So: ``acausal.analysis`` imports the compiler and
the runtime, and only :mod:`acausal.cli` imports it.

The model
---------
The compiler leaves the DAE ``F(t, y, y', p, d) = 0`` with ``y = (x, z)``:
``x`` the states it chose (index reduction, dummy derivatives: for a
pendulum the body's angle and its rate, whatever the joint's variables are
called), ``z`` the algebraic unknowns of its implicit blocks; ``y'`` exists
for the states only; ``p`` the free parameters (inputs are some of them),
``d`` the discrete values (modes, held fixed: a linearisation is of one mode).

Linearisation at a consistent point (t, x, z, x', u)
----------------------------------------------------
Differentiating ``F = 0`` along ``(dx, du)``::

    F_x' dx' + F_z dz = -(F_x dx + F_u du)

The matrix ``E = [F_z  F_x']`` is square and regular exactly when the DAE
has index 1 at the point (the compiler's index reduction guarantees it away
from singular configurations), so the algebraic part is eliminated by one
solve: ``[dz; dx'] = -E^-1 [F_x  F_u] [dx; du]``. Its lower block rows give
``A = dx'/dx`` and ``B = dx'/du``: with the rows ordered so that ``F_z``'s
upper part ``Z1`` is square and regular, ``A = -S^-1 (X2 - Z2 Z1^-1 X1)``,
``S = P2 - Z2 Z1^-1 P1`` the Schur complement of the algebraic block (``X``,
``P`` the matching parts of ``F_x``, ``F_x'``); one LU solve of ``E`` gives
the same without forming it, whatever the rows' order. An output
``h(t, x, z, x', u)`` (any variable of the model, resolved to the DAE's
unknowns) gives ``C = h_x + h_z dz/dx + h_x' A``, ``D = h_u + h_z dz/du +
h_x' B``.

``F_x``, ``F_z``, ``F_x'`` are the generated Jacobian code that IDA uses
(:mod:`acausal.compiler.codegen`, exact); ``F_u`` and the outputs'
derivatives are differentiated symbolically here from the same residuals
(:func:`acausal.lang.fastdiff.diff`) and evaluated at the point. No finite
difference is taken.

Trim
----
A static equilibrium is a consistent point with ``x' = 0``:
``F(t, x, z, 0, u) = 0`` for the unknowns ``(x, z)`` -- and, for a trim
with held states, the inputs named ``free`` instead of those states. The
unknowns that a state's row equates to a derivative (``v`` in ``x' = v``)
are zero at rest and taken out. The rest is solved by trust-region least
squares (scipy's ``trf``, the exact Jacobian, each unknown scaled by its
size) from the model's start or given guesses. A start between equilibria
-- where the unbalance does not change to first order along some states,
a pendulum released horizontal -- is also left both ways along those
directions, and the stable equilibrium found is kept (the largest real part
of its eigenvalues smallest): a pendulum at rest hangs. The modes are the
start's (after its event iteration); a point where one of the model's
events would change the mode is refused, naming the event.
"""
import weakref
from dataclasses import dataclass, field

import numpy as np
import sympy as sp
from scipy.optimize import least_squares

from ..compiler.codegen import Names
from ..errors import AcausalError, AnalysisError, UsageError
from ..lang.fastdiff import diff
from ..lang.symbols import time
from ..runtime.initialize import ask_components, reinitialize

__all__ = ["linearize", "trim", "Linearization", "Equilibrium"]

_memo = weakref.WeakKeyDictionary()     # compiled model -> {what: made once per model}


# ---------------------------------------------------------------------------
# operating points
# ---------------------------------------------------------------------------

@dataclass(frozen=True)
class RunSettings:
    """How the operating point is computed: the integrator ``backend``
    (None: the default) and the tolerances of a simulation to a time
    (``rtol``, ``atol``); ``tol`` and ``max_iter``: the equilibrium search's
    residual tolerance (relative to each equation's terms) and its limit of
    evaluations."""

    backend: str | None = None
    rtol: float = 1e-8
    atol: float = 1e-10
    tol: float = 1e-10
    max_iter: int = 100


@dataclass
class _Point:
    """A consistent point of the DAE: time, unknowns, derivatives, modes,
    parameter vector."""
    t: float
    y: np.ndarray
    yp: np.ndarray
    d: list
    p: np.ndarray


class Equilibrium:
    """A static equilibrium found by :func:`trim`: ``eq["rev.phi"]`` is any
    variable's value there; ``eq.inputs`` the inputs' values (the free ones
    solved for), ``eq.params`` every parameter override that holds it (give
    them to ``simulate(params=...)``, with the states' start values, to
    start a run there); ``linearize(cm, at=eq)`` linearises about it."""

    def __init__(self, cm, point, inputs, params):
        self.model, self._pt = cm, point
        self.inputs, self.params = dict(inputs), dict(params)
        self.t = point.t
        cb = cm.callbacks(point.p, point.d)
        self._values = dict(zip(cm.var_names, map(float, cb[4](point.t, point.y, point.yp))))

    def __getitem__(self, name):
        if name in self._values:
            return self._values[name]
        if name in self.inputs:
            return self.inputs[name]
        raise AnalysisError(f"no variable {name!r} in the equilibrium")

    @property
    def states(self):
        """{state name: value} at the equilibrium (:func:`state_names`)."""
        ns = self.model.dae.n_states
        return dict(zip(state_names(self.model), map(float, self._pt.y[:ns])))

    def __repr__(self):
        shown = ", ".join(f"{k} = {v:.6g}" for k, v in self.states.items())
        return f"<Equilibrium t = {self.t:g} s: {shown}>"


def state_names(cm):
    """A readable name for each state the compiler chose: the variable that
    is exactly that unknown (a declared variable rather than a connector's,
    in the model's order), else the unknown's own name (``der(body.phi)``)."""
    ns = cm.dae.n_states
    slots = {s: i for i, s in enumerate(cm.dae.y[:ns])}
    best = [None] * ns
    for name in cm.var_names:
        e = cm.resolve(sp.Symbol(name))
        i = slots.get(e)
        if i is None:
            continue
        port = cm.flat.variables[name].port
        if best[i] is None or (best[i][1] and not port):
            best[i] = (name, port)
    return [b[0] if b else cm.dae.y[i].name for i, b in enumerate(best)]


def _state_setter(cm, name, p):
    """(slot, function value -> slot value) for a variable that is an affine
    function of one state (``rev.phi`` for the state ``body.phi``); an
    AnalysisError otherwise."""
    if name not in cm.flat.variables:
        raise AnalysisError(f"{name!r} is not a variable of the model; its states are: "
                            + ", ".join(state_names(cm)), variable=name)
    e = cm.resolve(sp.Symbol(name))
    ns = cm.dae.n_states
    states = [s for s in cm.dae.y[:ns] if s in e.free_symbols]
    pvals = dict(zip(cm.param_syms, map(float, p)))
    others = [s for s in e.free_symbols if s not in pvals and s not in states]
    if len(states) == 1 and not others:
        s = states[0]
        c = sp.sympify(diff(e, s)).xreplace(pvals)
        rest = sp.sympify(e.xreplace({s: 0})).xreplace(pvals)
        if c.is_number and rest.is_number and float(c) != 0:
            c, rest = float(c), float(rest)
            return cm.dae.y.index(s), (lambda v: (v - rest) / c)
    raise AnalysisError(f"{name} is not a state of the model (nor a state plus a constant): "
                        "it follows from the states, so it cannot be set at the point; the "
                        "states are: " + ", ".join(state_names(cm)), variable=name)


def _set_states(cm, pt, values, what):
    """``pt.y`` with the states named in ``values`` set; the slots set."""
    y, slots = np.array(pt.y, dtype=float), {}
    for name, v in values.items():
        try:
            v = float(v)
        except (TypeError, ValueError):
            raise AnalysisError(f"{what}: {name} = {v!r} is not a number", variable=name) from None
        k, fn = _state_setter(cm, name, pt.p)
        val = fn(v)
        if k in slots and abs(slots[k][2] - val) > 1e-12 * (1 + abs(val)):
            raise AnalysisError(
                f"inconsistent {what}: {slots[k][0]} = {slots[k][1]:g} and {name} = "
                f"{v:g} name the same state ({state_names(cm)[k]}) with different values",
                variable=name)
        slots[k] = (name, v, val)
        y[k] = val
    return y, {k for k in slots}


def _start(cm, params, t0, backend):
    """The consistent start at ``t0`` after the event iteration (its modes)."""
    res = cm.simulate(t0=t0, t_end=t0, params=params, output_step=0, backend=backend)
    return _Point(float(res.t[-1]), np.array(res.y[-1]), np.array(res.yp[-1]),
                  list(map(float, res.d[-1])), np.array(res.p))


def _residual_check(cm, pt, what):
    """An AnalysisError naming the equation that ``pt`` violates, if any."""
    n = len(cm.dae.y)
    cb = cm.callbacks(pt.p, pt.d)
    r = np.zeros(n)
    cb[0](pt.t, pt.y, pt.yp, r)
    Jy, Jyp = np.zeros((n, n)), np.zeros((n, n))
    cb[3](pt.t, pt.y, pt.yp, Jy, Jyp)
    scale = np.abs(Jy) @ (np.abs(pt.y) + 1e-12) + np.abs(Jyp) @ (np.abs(pt.yp) + 1e-12) + 1e-12
    bad = ~(np.abs(r) <= 1e-7 * scale + 1e-10)
    if bad.any():
        k = int(np.argmax(np.where(bad, np.abs(r) / scale, -1)))
        origin = cm.dae.origins[k]
        text = _equation(origin)
        paths = [getattr(cm.dae.origins[i], "origin", None) for i in np.flatnonzero(bad)]
        own = ask_components(cm.model, "initialization_failure", [q for q in paths if q],
                             f" ({text} is violated by {r[k]:.3g})")
        if own is not None:       # a component's own words (a loop that cannot close)
            raise AnalysisError(f"inconsistent {what}: {own}", component=own.component)
        raise AnalysisError(f"inconsistent {what}: {text} is violated by {r[k]:.3g}",
                            component=getattr(origin, "origin", None))


def _point(cm, at, params, t, run):
    """The consistent :class:`_Point` that ``at`` describes (see :func:`linearize`)."""
    from ..runtime.result import Result
    backend = run.backend
    t0 = 0.0 if t is None else float(t)
    if isinstance(at, Equilibrium):
        if at.model is not cm:
            raise AnalysisError("at: the equilibrium is of another compiled model")
        return at._pt
    if isinstance(at, str) and at == "equilibrium":
        return trim(cm, params=params, t=t0, run=run)._pt
    if isinstance(at, Result):
        if at.model is not cm:
            raise AnalysisError("at: the result is of another compiled model")
        if len(at.t) == 0:
            raise AnalysisError("at: the result has no time point")
        k = -1 if t is None else int(np.argmin(np.abs(at.t - t0)))
        if t is not None and abs(at.t[k] - t0) > 1e-12 * max(1.0, abs(t0)):
            raise AnalysisError(f"at: the result has no point at t = {t0:g} s")
        return _Point(float(at.t[k]), np.array(at.y[k]), np.array(at.yp[k]),
                      list(map(float, at.d[k])), np.array(at.p))
    if at is None or (isinstance(at, str) and at == "start"):
        return _start(cm, params, t0, backend)
    if isinstance(at, (int, float)) and not isinstance(at, bool):
        res = cm.simulate(t_end=float(at), params=params, output_step=0, rtol=run.rtol,
                          atol=run.atol, backend=backend)
        if res.t[-1] < float(at) * (1 - 1e-12) - 1e-12:
            raise AnalysisError(f"at = {at:g} s: the run stopped at t = {res.t[-1]:g} s "
                                f"({[n for _, n in res.events][-1:] or 'no event'})")
        return _Point(float(res.t[-1]), np.array(res.y[-1]), np.array(res.yp[-1]),
                      list(map(float, res.d[-1])), np.array(res.p))
    if isinstance(at, dict):
        pt = _start(cm, params, t0, backend)
        y, _ = _set_states(cm, pt, at, "linearisation point")
        cb = cm.callbacks(pt.p, pt.d)
        try:
            with np.errstate(all="ignore"):
                y, yp = reinitialize(cm, cb, pt.t, y, np.array(pt.yp))
        except (ArithmeticError, ValueError, np.linalg.LinAlgError) as exc:
            raise AnalysisError(f"inconsistent linearisation point {at}: the algebraic "
                                f"unknowns cannot be solved there ({exc})") from None
        new = _Point(pt.t, np.asarray(y, float), np.asarray(yp, float), pt.d, pt.p)
        _residual_check(cm, new, f"linearisation point {_show(at)}")
        return new
    raise AnalysisError(f"at: expected 'start', 'equilibrium', a time [s], a dict of state "
                        f"values, a Result or an Equilibrium, got {at!r}")


def _equation(origin, longest=100):
    """An equation named for a one-line message: its label and component,
    and its text when that is short."""
    if not hasattr(origin, "describe"):
        return str(origin)
    text = origin.describe()
    if len(text) <= longest + 40:
        return text
    return f"{origin.label or 'equation'} of {origin.origin or 'the model'}"


def _show(values):
    return ", ".join(f"{k} = {v:g}" if isinstance(v, (int, float)) else f"{k} = {v!r}"
                     for k, v in values.items())


# ---------------------------------------------------------------------------
# inputs, outputs and their derivatives
# ---------------------------------------------------------------------------

@dataclass
class _Input:
    """An input: ``name`` as the user gave it, the free parameter ``param``
    it moves, and ``value = a * param + b`` (a parameter itself: a = 1, b =
    0; a signal fed by a constant source, ``force.f`` from ``u.k``: its
    resolved expression, affine in that one parameter)."""
    name: str
    param: str
    a: object
    b: object

    def coefficients(self, cm, p):
        """(a, b) as numbers at the parameter vector ``p``."""
        vals = dict(zip(cm.param_syms, map(float, p)))
        return float(sp.sympify(self.a).xreplace(vals)), float(sp.sympify(self.b).xreplace(vals))


def _split(names):
    if isinstance(names, str):
        names = [s for s in names.split(",") if s.strip()]
    return names


def _inputs(cm, inputs, what="inputs"):
    """(list of :class:`_Input`, {name: value given}) of ``inputs``: a list
    of names or a dict name -> value. A name is a free parameter (a
    declared input, ``model.parameter("u", ...)``; a source's level, a
    force's ``f_const``) or a variable -- a causal signal, ``force.f`` --
    that the model makes an affine function of one free parameter (a
    ``Constant`` block's ``k`` wired into it)."""
    inputs = _split(inputs)
    values = dict(inputs) if isinstance(inputs, dict) else {}
    names = [str(n).strip() for n in inputs]
    if len(set(names)) != len(names):
        raise AnalysisError(f"{what}: a name is given twice in {names}")
    free = {e.name for e in cm.params}
    out = []
    for n in names:
        if n in free:
            out.append(_Input(n, n, 1, 0))
            continue
        if n in cm.flat.variables:
            e = cm.resolve(sp.Symbol(n))
            ps = [q for q in e.free_symbols if q.name in free]
            if len(ps) == 1 and all(q.name in free for q in e.free_symbols):
                a = diff(e, ps[0])
                if not a.has(ps[0]) and a != 0:
                    out.append(_Input(n, ps[0].name, a, e.xreplace({ps[0]: 0})))
                    continue
            raise AnalysisError(
                f"{what}: {n} is a variable that the model computes (from "
                f"{', '.join(sorted(q.name for q in e.free_symbols)) or 'constants'}), not an "
                "input: wire a Constant source (acausal.blocks) into it, or name a free "
                "parameter", variable=n)
        why = ""
        try:
            cm.param_index(n)
        except AcausalError as exc:
            why = f" ({exc})"
        shown = ", ".join(sorted(free)[:10]) + (" ..." if len(free) > 10 else "")
        raise AnalysisError(
            f"{what}: {n!r} is not an input of the model{why}; an input is a free parameter "
            "(a declared model.parameter, a source's level such as a force's f_const) or a "
            f"signal fed by a Constant source; the model's parameters: {shown}", variable=n)
    return out, values


def _input_params(cm, ins, values, params):
    """``params`` with the inputs' given ``values`` turned into values of
    the parameters they move."""
    params = dict(params)
    given = [u for u in ins if u.name in values]
    if given:
        p = cm.param_vector({k: v for k, v in params.items() if k in
                             {e.name for e in cm.params}})
        for u in given:
            try:
                v = float(values[u.name])
            except (TypeError, ValueError):
                raise AnalysisError(f"input {u.name} = {values[u.name]!r} is not a number",
                                    variable=u.name) from None
            a, b = u.coefficients(cm, p)
            params[u.param] = (v - b) / a
    return params


def _output_names(cm, outputs):
    outputs = _split(outputs)
    names = [str(n).strip() for n in outputs]
    for n in names:
        if n not in cm.flat.variables:
            raise AnalysisError(f"outputs: {n!r} is not a variable of the model (try `acausal "
                                "variables MODEL`)", variable=n)
    return names


class _Derivatives:
    """The residuals' derivatives with respect to the inputs, and the
    outputs' with respect to (y, y', inputs): symbolic, evaluated at a
    point (module docstring). Entries are kept where they are not zero."""

    def __init__(self, cm, inputs, outputs):
        dae = cm.dae
        self.n, self.ns, self.m, self.k = len(dae.y), dae.n_states, len(inputs), len(outputs)
        P = [cm.param_syms[cm.param_index(u)] for u in inputs]
        entries, exprs = [], []
        for i, r in enumerate(dae.residuals):
            for j, s in enumerate(P):
                if r.has(s):
                    entries.append(("Fu", i, j))
                    exprs.append(diff(r, s))
        cols = {s: ("Hy", j) for j, s in enumerate(dae.y)}
        cols.update({s: ("Hyp", j) for j, s in enumerate(dae.yp) if s is not None})
        cols.update({s: ("Hu", j) for j, s in enumerate(P)})
        for i, name in enumerate(outputs):
            h = cm.resolve(sp.Symbol(name))
            for s in sorted(h.free_symbols, key=lambda q: q.name):
                hit = cols.get(s)
                if hit is not None:
                    entries.append((hit[0], i, hit[1]))
                    exprs.append(diff(h, s))
        self.entries = entries
        names = Names(dae.y, dae.yp, cm.param_syms, cm.disc_syms)
        args = ([names.map[time]] + [names.map[s] for s in dae.y]
                + [names.map.get(s) or sp.Dummy() for s in dae.yp]
                + [names.map[s] for s in cm.param_syms] + [names.map[s] for s in cm.disc_syms])
        self._fn = sp.lambdify(args, names.rename(exprs, "a derivative"), "numpy") \
            if exprs else None

    def at(self, pt):
        """(F_u, H_y, H_y', H_u) at the point."""
        out = {"Fu": np.zeros((self.n, self.m)), "Hy": np.zeros((self.k, self.n)),
               "Hyp": np.zeros((self.k, self.n)), "Hu": np.zeros((self.k, self.m))}
        if self._fn is not None:
            with np.errstate(all="ignore"):
                vals = self._fn(pt.t, *pt.y, *pt.yp, *pt.p, *pt.d)
            for (what, i, j), v in zip(self.entries, vals):
                out[what][i, j] = float(v)
        return out["Fu"], out["Hy"], out["Hyp"], out["Hu"]


# ---------------------------------------------------------------------------
# linearisation
# ---------------------------------------------------------------------------

@dataclass
class Linearization:
    """``x' = A x + B u``, ``y = C x + D u`` about an operating point, in
    deviations from it. ``states``, ``inputs``, ``outputs``: the names of
    the columns/rows; ``t``, ``x0``, ``u0``, ``y0``: the point."""
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    states: list
    inputs: list
    outputs: list
    t: float
    x0: np.ndarray
    u0: np.ndarray
    y0: np.ndarray
    units: dict = field(default_factory=dict)

    @property
    def eigenvalues(self):
        """The eigenvalues of A (poles), sorted by real part then imaginary."""
        ev = np.linalg.eigvals(self.A) if self.A.size else np.zeros(0, complex)
        return ev[np.lexsort((ev.imag, ev.real))]

    def to_statespace(self):
        """The python-control ``StateSpace`` (``pip install control``) with
        the state, input and output names (python-control refuses dots in
        signal names: ``rev.phi`` is labelled ``rev_phi``)."""
        try:
            import control
        except ImportError:
            raise UsageError("to_statespace needs python-control: pip install control "
                             "(or acausal[control])") from None
        label = (lambda names: [n.replace(".", "_") for n in names])
        return control.ss(self.A, self.B, self.C, self.D, states=label(self.states),
                          inputs=label(self.inputs), outputs=label(self.outputs))

    def as_dict(self):
        """Plain lists (JSON): the matrices, names, point and eigenvalues."""
        ev = self.eigenvalues
        return {"t": self.t, "states": self.states, "inputs": self.inputs,
                "outputs": self.outputs, "units": self.units,
                "x0": self.x0.tolist(), "u0": self.u0.tolist(), "y0": self.y0.tolist(),
                "A": self.A.tolist(), "B": self.B.tolist(), "C": self.C.tolist(),
                "D": self.D.tolist(),
                "eigenvalues": [[float(e.real), float(e.imag)] for e in ev]}

    def save(self, path):
        """Write the linearisation: ``.npz`` (numpy arrays) or ``.json``."""
        path = str(path)
        if path.endswith(".npz"):
            np.savez(path, A=self.A, B=self.B, C=self.C, D=self.D, t=self.t, x0=self.x0,
                     u0=self.u0, y0=self.y0, eigenvalues=self.eigenvalues,
                     states=np.array(self.states, dtype=str),
                     inputs=np.array(self.inputs, dtype=str),
                     outputs=np.array(self.outputs, dtype=str))
        elif path.endswith(".json"):
            import json
            with open(path, "w") as fh:
                json.dump(self.as_dict(), fh, indent=1)
        else:
            raise UsageError(f"{path}: write a linearisation to .npz or .json")
        return path

    def __str__(self):
        def mat(name, M, rows, cols):
            if M.size == 0:
                return f"{name} = [] ({M.shape[0]} x {M.shape[1]})"
            w = max([len(c) for c in cols] + [12])
            head = " " * (max(len(r) for r in rows) + 2) + "".join(f"{c:>{w + 1}s}" for c in cols)
            lines = [f"{name} =", head]
            for r, row in zip(rows, M):
                lines.append(f"  {r:<{max(len(q) for q in rows)}s}"
                             + "".join(f" {v + 0.0:>{w}.6g}" for v in row))
            return "\n".join(lines)
        out = [f"linearisation at t = {self.t:g} s",
               "  x0: " + ", ".join(f"{s} = {v:.6g}" for s, v in zip(self.states, self.x0))]
        if self.inputs:
            out.append("  u0: " + ", ".join(f"{s} = {v:.6g}" for s, v in zip(self.inputs,
                                                                            self.u0)))
        out += [mat("A", self.A, self.states, self.states),
                mat("B", self.B, self.states, self.inputs),
                mat("C", self.C, self.outputs, self.states),
                mat("D", self.D, self.outputs, self.inputs), "eigenvalues:"]
        for e in self.eigenvalues:
            out.append(f"  {e.real + 0.0:.6g} {'+' if e.imag >= 0 else '-'} {abs(e.imag):.6g}j")
        return "\n".join(out)


def linearize(cm, at=None, inputs=(), outputs=(), *, params=None, t=None,
              run: RunSettings = RunSettings()):
    """The linearisation of compiled model ``cm`` (module docstring):
    a :class:`Linearization` with ``A``, ``B``, ``C``, ``D`` as numpy arrays
    (``.to_statespace()``: python-control's ``StateSpace``).

    ``at``: the operating point --

    * ``None`` or ``"start"``: the consistent start (fixed start values,
      ``params``; at time ``t``, default 0);
    * a number: the state reached by simulating from the start to that time;
    * ``"equilibrium"``: the static equilibrium :func:`trim` finds;
    * a dict ``{state: value}``: the start with those states set (by any
      variable that is a state, or a state plus a constant: ``rev.phi`` for
      the state ``body.phi``), the algebraic unknowns and derivatives solved
      for them (an :class:`~acausal.errors.AnalysisError` when they cannot
      be: an inconsistent point);
    * an :class:`Equilibrium` from :func:`trim`, or a ``Result`` (its last
      point, or its point at ``t``).

    ``inputs``: names of free parameters (a list, or a dict giving their
    values at the point); ``outputs``: names of variables (default: the
    states, ``C = I``). ``params``: other parameter and fixed-start
    overrides. ``run``: :class:`RunSettings` of the simulation to ``at``.
    Discrete modes are the point's (held fixed)."""
    from ..runtime.result import Result
    ins, in_values = _inputs(cm, inputs)
    out_names = _output_names(cm, outputs)
    if isinstance(at, (Result, Equilibrium)) and (params or in_values):
        raise AnalysisError("linearize: the point's parameters and inputs are those of the "
                            f"{type(at).__name__.lower()} given as at; name the inputs "
                            "without values and give no params")
    params = _input_params(cm, ins, in_values, params or {})
    pt = _point(cm, at, params, t, run)
    return _linearize_at(cm, pt, ins, out_names)


def _linearize_at(cm, pt, ins, out_names):
    dae = cm.dae
    n, ns = len(dae.y), dae.n_states
    states = state_names(cm)
    default_out = not out_names
    if default_out:
        out_names = list(states)
    der = _derivatives(cm, [u.param for u in ins], [] if default_out else out_names)
    cb = cm.callbacks(pt.p, pt.d)
    Jy, Jyp = np.zeros((n, n)), np.zeros((n, n))
    cb[3](pt.t, pt.y, pt.yp, Jy, Jyp)
    Fu, Hy, Hyp, Hu = der.at(pt)
    E = np.hstack([Jy[:, ns:], Jyp[:, :ns]])
    rhs = -np.hstack([Jy[:, :ns], Fu])
    W = _solve(cm, E, rhs, pt)
    dz, dxp = W[:n - ns], W[n - ns:]
    ab = [u.coefficients(cm, pt.p) for u in ins]
    per = np.array([1.0 / a for a, _ in ab]) if ins else np.zeros(0)   # d(param)/d(input)
    A, B = dxp[:, :ns], dxp[:, ns:] * per
    if default_out:
        C, D = np.eye(ns), np.zeros((ns, len(ins)))
        y0 = np.array(pt.y[:ns])
    else:
        C = Hy[:, :ns] + Hy[:, ns:] @ dz[:, :ns] + Hyp[:, :ns] @ A
        D = Hu * per + Hy[:, ns:] @ dz[:, ns:] * per + Hyp[:, :ns] @ B
        obs = dict(zip(cm.var_names, cb[4](pt.t, pt.y, pt.yp)))
        y0 = np.array([obs[o] for o in out_names], dtype=float)
    u0 = np.array([a * pt.p[cm.param_index(u.param)] + b for u, (a, b) in zip(ins, ab)],
                  dtype=float)
    units = {name: cm.flat.variables[name].unit for name in list(states) + out_names
             if name in cm.flat.variables}
    units.update({u.name: (cm.flat.variables[u.name].unit if u.name in cm.flat.variables
                           else cm.params[cm.param_index(u.param)].unit) for u in ins})
    return Linearization(A, B, C, D, states, [u.name for u in ins], list(out_names),
                         float(pt.t),
                         np.array(pt.y[:ns], dtype=float), u0, y0, units)


def _derivatives(cm, inputs, outputs):
    """:class:`_Derivatives` made once per model, inputs and outputs."""
    memo = _memo.setdefault(cm, {})
    key = ("derivatives", tuple(inputs), tuple(outputs))
    if key not in memo:
        memo[key] = _Derivatives(cm, inputs, outputs)
    return memo[key]


def _solve(cm, E, rhs, pt):
    """``E^-1 rhs``; an AnalysisError when ``E`` is singular at the point
    (the DAE has no index 1 there: a dead centre of a linkage)."""
    if E.size == 0:
        return np.zeros((0, rhs.shape[1]))
    scale = np.linalg.norm(E, axis=0)
    scale[scale == 0] = 1.0
    Es = E / scale
    s = np.linalg.svd(Es, compute_uv=False)
    if not np.all(np.isfinite(s)) or s[-1] <= 1e-13 * s[0]:
        raise AnalysisError(f"the model cannot be linearised at t = {pt.t:g} s: its "
                            "algebraic equations are singular there (a dead centre or a "
                            "locked configuration)")
    return np.linalg.solve(Es, rhs) / scale[:, None]


# ---------------------------------------------------------------------------
# trim
# ---------------------------------------------------------------------------

def trim(cm, inputs=None, *, hold=None, free=(), start=None, params=None, t=0.0,
         run: RunSettings = RunSettings()):
    """The static equilibrium of ``cm`` (module docstring): a consistent
    point with every state's derivative zero, under the loads of the model
    and the fixed ``inputs`` (dict name -> value, free parameters).

    ``hold``: states (dict name -> value) to keep where they are, with the
    inputs named in ``free`` solved for instead (the torque that holds a
    pendulum at 30 deg); ``start``: guesses of states for the search (dict
    name -> value; default the model's start), which decide between several
    equilibria (a pendulum hanging or upright); ``params``: other parameter
    and fixed-start overrides; ``t``: the time (for loads that depend on it).
    Returns an :class:`Equilibrium`; an :class:`~acausal.errors.AnalysisError`
    in one line when there is none (the equation left unbalanced, and its
    component), or when it lies where an event changes the mode."""
    ins, in_values = _inputs(cm, inputs or {})
    frees, _ = _inputs(cm, free, "free")
    both = {u.param for u in ins} & {u.param for u in frees}
    if both:
        raise AnalysisError(f"trim: {sorted(both)[0]} is both a fixed input and a free one")
    params = _input_params(cm, ins, in_values, params or {})
    pt = _start(cm, params, float(t), run.backend)
    tol, max_iter = run.tol, run.max_iter
    dae = cm.dae
    n, ns = len(dae.y), dae.n_states
    y = np.array(pt.y, dtype=float)
    if start:
        y, _ = _set_states(cm, _Point(pt.t, y, pt.yp, pt.d, pt.p), start, "trim start")
    held = set()
    if hold:
        y, held = _set_states(cm, _Point(pt.t, y, pt.yp, pt.d, pt.p), hold, "trim hold")
    if len(frees) > len(held):
        raise AnalysisError(f"trim: {len(frees)} free inputs for {len(held)} held "
                            "states: each free input needs a held state to determine it")
    rest = _zero_at_rest(cm) - held
    y[list(rest)] = 0.0
    cols = [k for k in range(n) if k not in held and k not in rest]
    fidx = [cm.param_index(u.param) for u in frees]
    der = _derivatives(cm, [u.param for u in frees], [])
    p = np.array(pt.p, dtype=float)
    yp = np.zeros(n)
    d = pt.d
    cb = cm.callbacks(p, d)

    def F(y, p):
        r = np.zeros(n)
        with np.errstate(all="ignore"):
            (cb if not fidx else cm.callbacks(p, d))[0](pt.t, y, yp, r)
        return r

    def J(y, p):
        Jy, Jyp = np.zeros((n, n)), np.zeros((n, n))
        cm.callbacks(p, d)[3](pt.t, y, yp, Jy, Jyp)
        Fu = der.at(_Point(pt.t, y, yp, d, p))[0]
        return np.hstack([Jy[:, cols], Fu])

    def unpack(w):
        y2 = y.copy()
        y2[cols] = w[:len(cols)]
        p2 = p.copy()
        p2[fidx] = w[len(cols):]
        return y2, p2

    def search(w):
        """(w, r, converged): a trust-region least-squares search from ``w``
        (scipy's ``trf`` with the exact Jacobian), each unknown scaled by
        its size (at least 1 in its unit), so that no step from near a
        stall leaps to a far equilibrium (a pendulum by several turns)."""
        fun = (lambda v: F(*unpack(v)))
        with np.errstate(all="ignore"):
            try:
                sol = least_squares(fun, w, jac=lambda v: J(*unpack(v)), method="trf",
                                    x_scale=1.0 + np.abs(w), xtol=1e-15, ftol=1e-15,
                                    gtol=1e-15, max_nfev=max_iter)
            except ValueError:           # a residual that is not finite at w
                return w, fun(w), False
        v, r = sol.x, sol.fun
        return v, r, bool(np.all(np.isfinite(r)) and _converged(r, J(*unpack(v)), v, tol))

    w0 = np.concatenate([y[cols], p[fidx]])
    states = [k for k, c in enumerate(cols) if c < ns]
    w, r, ok = search(w0)
    found = [w] if ok else []
    # a start (or a stall) where the unbalance does not change to first
    # order along some states (a pendulum released horizontal: the gravity
    # torque is largest there) lies between equilibria: search both ways
    # along those directions too, and keep the stable equilibrium
    for origin in ([w0] if np.all(np.isfinite(F(*unpack(w0)))) else []) + ([] if ok else [w]):
        for start_w in _escapes(J(*unpack(origin)), origin, states)[1 if origin is w0 else 0:]:
            w2, r2, ok2 = search(start_w)
            if ok2 and not any(np.allclose(w2, f, rtol=1e-8, atol=1e-10) for f in found):
                found.append(w2)
            elif not ok2 and np.all(np.isfinite(r2)) and (
                    not np.all(np.isfinite(r)) or np.linalg.norm(r2) < np.linalg.norm(r)):
                w, r = w2, r2
        if found:
            break
    if not found:
        y_eq, p_eq = unpack(w)
        raise AnalysisError(_no_equilibrium(cm, r, J(y_eq, p_eq) if np.all(np.isfinite(r))
                                            else None, w, in_values))
    points = [_Point(pt.t, unpack(f)[0], yp, d, unpack(f)[1]) for f in found]
    best = _most_stable(cm, points)
    y_eq, p_eq = best.y, best.p
    eq_pt = _Point(pt.t, y_eq, yp, d, p_eq)
    _check_modes(cm, pt, eq_pt)
    out_params = dict(params)
    out_params.update({u.param: float(p_eq[k]) for u, k in zip(frees, fidx)})
    solved = {}
    for u, k in zip(frees, fidx):
        a, b = u.coefficients(cm, p_eq)
        solved[u.name] = a * float(p_eq[k]) + b
    return Equilibrium(cm, eq_pt, {**in_values, **solved}, out_params)


def _zero_at_rest(cm):
    """The unknowns that are zero in every static equilibrium: those a
    state's row equates to its derivative (``x' = v``: ``v = 0`` at rest),
    found as rows that are ``c * y_j`` once the derivatives are 0."""
    memo = _memo.setdefault(cm, {}).get("zero at rest")
    if memo is None:
        dae = cm.dae
        zero = {s: 0 for s in dae.yp if s is not None}
        index = {s: j for j, s in enumerate(dae.y)}
        memo = set()
        for r in dae.residuals[:dae.n_states]:
            e = sp.sympify(r).xreplace(zero)
            syms = [q for q in e.free_symbols if q in index]
            if len(syms) == 1 and e.free_symbols == set(syms):
                c = diff(e, syms[0])
                if c.is_number and c != 0 and sp.simplify(e - c * syms[0]) == 0:
                    memo.add(index[syms[0]])
        _memo[cm]["zero at rest"] = memo
    return set(memo)


def _escapes(J, w, states, size=0.1):
    """Starting points: ``w`` itself first, then ``w + size (1 + |w|)
    (+-v1 +- v2 ...)`` for every sign combination of the right singular
    vectors ``v`` of the column-scaled ``J`` that ``J`` does not pin
    (singular value below 1e-8 of the largest), at most three; each
    restricted to the states (indices ``states`` of ``w``: the other
    unknowns follow them) and scaled to a largest component of 1."""
    import itertools
    s, live = _column_scale(J)
    _, sv, vt = np.linalg.svd(J * s * live)
    full = np.zeros(J.shape[1])
    full[:len(sv)] = sv
    weak = [k for k in np.argsort(full) if full[k] <= 1e-8 * max(full.max(), 1e-300)][:3]
    dirs = []
    for k in weak:
        v = np.zeros(len(w))
        v[states] = (s * vt[k])[states]
        if np.max(np.abs(v)) > 0:
            dirs.append(v / np.max(np.abs(v)))
    out = [w]
    if not dirs:
        return out
    for signs in itertools.product((1.0, -1.0), repeat=len(dirs)):
        step = sum(c * v for c, v in zip(signs, dirs))
        out.append(w + size * (1 + np.abs(w)) * step)
    return out


def _most_stable(cm, points):
    """The first of ``points`` whose linearisation's largest eigenvalue real
    part is smallest (by more than round-off: equal ones keep the order)."""
    if len(points) == 1:
        return points[0]
    rank = [_instability(cm, q) for q in points]
    best = 0
    for k in range(1, len(points)):
        if rank[k] < rank[best] - 1e-9 * (1 + abs(rank[best])):
            best = k
    return points[best]


def _instability(cm, pt):
    """The largest real part of the linearisation's eigenvalues at ``pt``."""
    try:
        ev = _linearize_at(cm, pt, [], []).eigenvalues
    except AnalysisError:
        return np.inf
    return float(ev.real.max()) if ev.size else 0.0


def _converged(r, J, w, tol):
    """Each residual within ``tol`` of what its terms amount to (its
    Jacobian row times the unknowns' sizes, at least 1 in their units)."""
    scale = np.abs(J) @ (np.abs(w) + 1.0)
    return bool(np.all(np.abs(r) <= tol * scale + 1e-300))


def _column_scale(J):
    """Factors that give the columns of ``J`` unit norm; a column below
    1e-12 of the largest counts as zero (a pendulum's angle where the
    gravity torque is largest: rounding leaves 1e-27) and keeps factor 1."""
    norms = np.linalg.norm(J, axis=0)
    live = norms > 1e-12 * max(norms.max(initial=0.0), 1e-300)
    return np.where(live, 1.0 / np.where(live, norms, 1.0), 1.0), live


def _no_equilibrium(cm, r, J, w, inputs):
    """The one line of a trim that found no equilibrium."""
    loads = f" under {_show(inputs)}" if inputs else ""
    if J is None:
        return f"no static equilibrium{loads}: the search left the model's domain (a residual " \
               "is not finite)"
    scale = np.abs(J) @ (np.abs(w) + 1.0) + 1e-300
    k = int(np.argmax(np.abs(r) / scale))
    text = _equation(cm.dae.origins[k])
    return (f"no static equilibrium{loads}: with every state at rest, {text} stays "
            f"unbalanced by {r[k]:.4g} at the closest point found")


def _check_modes(cm, start, eq):
    """An AnalysisError when an event of the model would change a mode
    between the start (whose modes the trim kept) and the equilibrium."""
    if not cm.events:
        return
    g0, g1 = np.zeros(cm.n_roots), np.zeros(cm.n_roots)
    cb = cm.callbacks(start.p, start.d)
    with np.errstate(all="ignore"):
        cb[2](start.t, start.y, start.yp, g0)
        cm.callbacks(eq.p, eq.d)[2](eq.t, eq.y, eq.yp, g1)
    for k, ev in enumerate(cm.events):
        if ev.observer or not (np.isfinite(g0[k]) and np.isfinite(g1[k])):
            continue
        if g0[k] * g1[k] < 0 and (ev.direction == 0 or np.sign(g1[k] - g0[k]) == ev.direction):
            raise AnalysisError(
                f"the equilibrium found lies past event {ev.name} of {ev.owner or 'the model'}"
                ", which would change the mode the search kept (the start's): start nearer "
                "to it (trim(start=...)) or in that mode", component=ev.owner)
