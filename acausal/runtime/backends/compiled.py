"""The compiled backend: SUNDIALS IDA calling generated C, with no Python
call per residual, Jacobian or root evaluation.

The model's residual, iteration matrix and root functions are generated as
C (:mod:`acausal.compiler.codegen_c`), compiled with the system's C compiler
together with a small segment driver (``ida_driver.c``) and the
re-initialisation Newton (``reinit.c``), and linked against the SUNDIALS 7
libraries that the scikit-sundae wheel ships, so nothing but pip and a C
compiler is needed. The library is kept in the on-disk store (namespace
``c-build``, :mod:`acausal.infra.store`), keyed by a hash of its sources, the
compiler and the SUNDIALS libraries. Python sees one call per segment (and
one per located root or full output buffer).

IDA is set up as :mod:`.sundae` sets it up, so both backends run the same
integrator; the hybrid loop is shared.

When there is no C compiler or no SUNDIALS library to link against,
:class:`Unavailable` says why and :func:`acausal.runtime.backends.make_solver`
falls back to the reference backend (``res.stats["backend_fallback"]``).
"""
import ctypes
import glob
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile
import weakref
from dataclasses import dataclass

import numpy as np
from sympy.printing.codeprinter import PrintMethodNotImplementedError

from ...compiler.codegen import Callbacks
from ...compiler.codegen_c import generate_c
from ...infra import store
from . import Root, Segment, SegmentSolver

_HERE = os.path.dirname(os.path.abspath(__file__))
_DRIVER = os.path.join(_HERE, "ida_driver.c")
_REINIT = os.path.join(_HERE, "reinit.c")     # the re-initialisation Newton in C
_SWEEP = os.path.join(_HERE, "sweep.c")       # staggered sensitivities along a run
_LIBS = ("sundials_core", "sundials_nvecserial", "sundials_sunmatrixdense",
         "sundials_sunlinsoldense", "sundials_ida")
_ROOT, _FULL = 2, 99
CAP = 1024   # rows of a solver call's output buffer: a call returns to Python (the
             # watch's guard) each time it fills
_MESSAGES = {
    -1: "the maximum number of steps was taken before reaching the output time",
    -2: "the requested accuracy could not be achieved",
    -3: "Error tests failed too many times, or reached min step size.",
    -4: "the corrector (Newton) iteration failed to converge too many times",
    -5: "the linear solver's setup failed",
    -6: "the linear solver's solve failed",
    -8: "the residual function failed",
    -10: "the root function failed",
}
_loaded = weakref.WeakKeyDictionary()   # compiled model -> _Library (the runtime's cache)


class Unavailable(Exception):
    """The compiled backend cannot run here (the message says why)."""


def c_compiler():
    """The C compiler command (``$CC``, else cc, gcc or clang); Unavailable
    when there is none."""
    cc = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc") or \
        shutil.which("clang")
    if not cc or not shutil.which(cc.split()[0]):
        raise Unavailable(f"no C compiler found ({cc or 'cc, gcc, clang'})")
    return cc


def sundials_libraries():
    """Full paths of the SUNDIALS shared libraries of the scikit-sundae wheel."""
    try:
        import sksundae
    except ImportError as exc:   # pragma: no cover - a core dependency
        raise Unavailable(f"scikit-sundae cannot be imported: {exc}") from None
    base = os.path.dirname(os.path.dirname(os.path.abspath(sksundae.__file__)))
    paths = []
    for lib in _LIBS:
        hits = sorted(glob.glob(os.path.join(base, "scikit_sundae.libs", f"lib{lib}-*.so*")))
        if not hits:
            raise Unavailable(f"no {lib} library in the scikit-sundae installation "
                              f"({sys.platform}); the compiled backend needs the Linux wheel")
        paths.append(hits[0])
    return paths


def _build_dir():
    """The store's ``c-build`` namespace (created): a library has to live
    somewhere, so with the store off it is the default location's."""
    d = str(store.namespace("c-build", required=True))
    os.makedirs(d, exist_ok=True)
    return d


def _key(cm, cc, libs):
    """Cache key of a model's library: the model's identity (a digest that
    fixes its DAE, roots and symbols), the C generator, the driver,
    the compiler and the SUNDIALS libraries; so a cached library is found
    without generating C again."""
    import acausal.compiler.codegen_c as gen
    parts = [cm.identity(), cc] + libs
    for path in (_DRIVER, _REINIT, _SWEEP, gen.__file__):
        with open(path) as fh:
            parts.append(fh.read())
    return hashlib.sha256("\0".join(parts).encode()).hexdigest()[:24]


def _build(cm):
    """Path of the shared library of ``cm`` (compiled once per store) and
    whether it was compiled now."""
    cc, libs = c_compiler(), sundials_libraries()
    try:
        out = os.path.join(_build_dir(), f"acs_{_key(cm, cc, libs)}.so")
        if not store.make_once(out, lambda: _compile(cm, cc, libs, out)):
            return out, False
    except OSError as exc:
        raise Unavailable(f"cannot write the compiled-library store: {exc} "
                          f"(set {store.ENV} to a writable folder)") from None
    return out, True


def _compile(cm, cc, libs, out):
    try:
        csrc = generate_c(cm)
    except PrintMethodNotImplementedError as exc:
        raise Unavailable("an expression of the model has no C form: "
                          + str(exc).splitlines()[0]
                          + " (give its sympy Function a _ccode method)") from None
    tmpdir = tempfile.mkdtemp(dir=os.path.dirname(out))
    try:
        model_c = os.path.join(tmpdir, "model.c")
        with open(model_c, "w") as fh:
            fh.write(csrc.text)
        libdir = os.path.dirname(libs[0])
        objs = [_driver_object(cc, src) for src in (_DRIVER, _REINIT, _SWEEP)]
        with store.atomic(out) as tmp_so:      # a reader never sees a partial file
            _run_cc(cc.split() + ["-O1", "-shared", "-fPIC", "-o", tmp_so, model_c, *objs]
                    + libs + [f"-Wl,-rpath,{libdir}", "-lm"], "the generated code")
    finally:
        shutil.rmtree(tmpdir, ignore_errors=True)


def _run_cc(cmd, what):
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        raise Unavailable(f"the C compiler failed on {what}: "
                          f"{cc_error(proc.stderr, proc.returncode)}")


def cc_error(stderr, status=None):
    """The first error line of a C compiler's output, with the source's
    folder left out (``model.c:348:1: error: 'true' undeclared ...``); its
    last line was often only the caret under the code ("| ^~~~"). With no
    output: its exit status."""
    lines = [ln.strip() for ln in stderr.splitlines() if ln.strip()]
    hit = next((ln for ln in lines if "error" in ln and ":" in ln), None) or \
        (lines[-1] if lines else f"exit status {status}, no message")
    head, sep, rest = hit.partition(": ")
    return (os.path.basename(head) + sep + rest) if sep and os.sep in head else hit


def _driver_object(cc, src):
    """The object file of one of the driver's C sources (the same for every
    model: compiled once per store, keyed by the compiler and the source
    text), so that a model's build compiles only its own generated code."""
    with open(src) as fh:
        key = hashlib.sha256("\0".join([cc, fh.read()]).encode()).hexdigest()[:24]
    out = os.path.join(_build_dir(), f"{os.path.basename(src)[:-2]}_{key}.o")

    def make():
        with store.atomic(out) as tmp:      # a reader never sees a partial file
            _run_cc(cc.split() + ["-O1", "-fPIC", "-c", src, "-o", tmp],
                    os.path.basename(src))
    store.make_once(out, make)
    return out


@dataclass(frozen=True)
class _Static:
    """The run-independent settings of a model's IDA handle: unknowns,
    root functions, which unknowns are differential (IDASetId), the roots'
    directions and which of them end a segment (not an observer's)."""

    n: int
    nr: int
    ident: np.ndarray
    dirs: np.ndarray
    terminal: tuple

    @classmethod
    def of(cls, cm):
        n = len(cm.dae.y)
        ident = np.zeros(n)
        ident[:cm.dae.n_states] = 1.0
        dirs = np.array([e.direction for e in cm.events] + [-1] * len(cm.assertions)
                        or [0], dtype=np.intc)
        terminal = tuple([not e.observer for e in cm.events] + [True] * len(cm.assertions))
        return cls(n, cm.n_roots, ident, dirs, terminal)


class _SweepArgs(ctypes.Structure):
    """sweep.c's ``acs_sweep_args`` (the same fields in the same order)."""

    _fields_ = [("N", ctypes.c_int), ("n", ctypes.c_int), ("ns", ctypes.c_int), ("k", ctypes.c_int),
                ("q", ctypes.c_int), ("t", ctypes.c_void_p), ("Y", ctypes.c_void_p),
                ("YP", ctypes.c_void_p), ("pd", ctypes.c_void_p), ("pidx", ctypes.c_void_p),
                ("step", ctypes.c_void_p), ("central", ctypes.c_void_p),
                ("S0", ctypes.c_void_p), ("SP0", ctypes.c_void_p),
                ("nout", ctypes.c_int), ("tout", ctypes.c_void_p), ("Sout", ctypes.c_void_p),
                ("SPout", ctypes.c_void_p)]


@dataclass(frozen=True)
class Sweep:
    """What :func:`sweep` integrates: a run's accepted steps ``t`` (strictly
    increasing), ``Y``, ``YP`` (steps x n), its parameters and discrete values
    ``pd``; the columns' positions ``pidx`` in ``pd``, their difference
    steps ``step`` and whether the residuals are linear in each (``linear``:
    forward differences, else central); the consistent ``S0``, ``SP0`` (n x
    k) at ``t[0]``; the output times ``tout`` (sorted); the highest BDF
    order ``order``."""

    t: np.ndarray
    Y: np.ndarray
    YP: np.ndarray
    pd: np.ndarray
    pidx: np.ndarray
    step: np.ndarray
    linear: np.ndarray
    S0: np.ndarray
    SP0: np.ndarray
    tout: np.ndarray
    order: int = 3


SWEEP_ERRORS = {-1: "the iteration matrix is singular at a step",
                -2: "the run's times do not increase strictly (a restart)",
                -3: "out of memory"}


def sweep(cm, s: Sweep):
    """(S, S') at ``s.tout`` (outputs x n x k) of compiled model ``cm``:
    sweep.c's staggered sensitivities along a finished run
    (:mod:`acausal.runtime.staggered`). Raises :class:`Unavailable` when
    there is no compiled library, and ``RuntimeError`` with
    :data:`SWEEP_ERRORS`' reason when the sweep fails."""
    L = library(cm)
    n, k = s.Y.shape[1], s.pidx.size
    if not 1 <= s.order <= 5:
        raise ValueError(f"the sweep's BDF order is 1 to 5, not {s.order}")  # internal
    arr = dict(t=_f64(s.t), Y=_f64(s.Y), YP=_f64(s.YP), pd=np.array(s.pd, float),
               pidx=np.ascontiguousarray(s.pidx, dtype=np.intc), step=_f64(s.step),
               central=np.ascontiguousarray(~np.asarray(s.linear, bool), dtype=np.intc),
               S0=_f64(s.S0), SP0=_f64(s.SP0), tout=_f64(s.tout))
    Sout = np.zeros((s.tout.size, n, k))
    SPout = np.zeros((s.tout.size, n, k))
    args = _SweepArgs(N=s.t.size, n=n, ns=cm.dae.n_states, k=k, q=int(s.order),
                      nout=s.tout.size,
                      Sout=Sout.ctypes.data, SPout=SPout.ctypes.data,
                      **{name: a.ctypes.data for name, a in arr.items()})
    flag = L.lib.acs_sweep(ctypes.byref(args))
    if flag != 0:
        raise RuntimeError(SWEEP_ERRORS.get(flag, f"flag {flag}"))  # internal
    return Sout, SPout


def parameter_derivatives(cm, point, pd, pidx, step):
    """(d residuals / d p_j (k x n), d observed variables / d p_j (k x
    observed)) of compiled model ``cm`` at ``point`` = (t, y, y'), with the
    parameters and discrete values ``pd``: central differences of the
    library's residual and observe in each position ``pidx[j]`` of ``pd``
    by ``step[j]``. Raises :class:`Unavailable` without a compiled library
    or a C observe."""
    L = library(cm)
    if L.n_obs is None:
        raise Unavailable("an observed expression of the model has no C form")
    t, y, yp = float(point[0]), _f64(point[1]), _f64(point[2])
    pd = np.array(pd, float)
    n = y.size
    Fp, op = np.empty((len(pidx), n)), np.empty((len(pidx), L.n_obs))
    r = [np.empty(n), np.empty(n)]
    o = [np.empty(L.n_obs), np.empty(L.n_obs)]
    for j, (i, h) in enumerate(zip(pidx, step)):
        v = pd[i]
        for side, sign in enumerate((1.0, -1.0)):
            pd[i] = v + sign * h
            L.lib.acs_res(t, y.ctypes.data, yp.ctypes.data, pd.ctypes.data, r[side].ctypes.data)
            L.lib.acs_observe(t, y.ctypes.data, yp.ctypes.data, pd.ctypes.data,
                              o[side].ctypes.data)
        pd[i] = v
        Fp[j] = (r[0] - r[1]) / (2 * h)
        op[j] = (o[0] - o[1]) / (2 * h)
    return Fp, op


class _Library:
    """The loaded shared library of one compiled model."""

    def __init__(self, cm):
        self.n_pd = len(cm.param_syms) + len(cm.disc_syms)
        self.path, self.built = _build(cm)
        lib = self.lib = ctypes.CDLL(self.path)
        dp, ip = ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_int)
        vp = ctypes.c_void_p
        lib.acs_new.restype = vp
        lib.acs_new.argtypes = [ctypes.c_int, ctypes.c_int, ctypes.c_int, ctypes.c_double, dp,
                                dp, ip, ctypes.c_double, ctypes.c_long]
        lib.acs_free.argtypes = [vp]
        # arrays go in as raw addresses (``a.ctypes.data``: cheaper per call)
        lib.acs_start.argtypes = [vp, ctypes.c_double, vp, vp, vp, ctypes.c_double]
        lib.acs_advance.argtypes = [vp, vp, ctypes.c_int, ip, ctypes.c_int, vp, vp, vp,
                                    ctypes.c_int, ip, vp, vp, vp, vp]
        lib.acs_counters.argtypes = [vp, vp]
        lib.acs_flag_name.restype = ctypes.c_char_p
        lib.acs_flag_name.argtypes = [ctypes.c_long]
        lib.acs_eval.argtypes = [ctypes.c_int, ctypes.c_double, dp, dp, dp, ctypes.c_double,
                                 dp]
        # the generated functions and the re-initialisation, called from
        # Python with raw addresses (see c_callbacks)
        lib.acs_res.argtypes = [ctypes.c_double, vp, vp, vp, vp]
        lib.acs_roots.argtypes = [ctypes.c_double, vp, vp, vp, vp]
        lib.acs_jacs.argtypes = [ctypes.c_double, vp, vp, vp, vp, vp]
        lib.acs_reinit.argtypes = [ctypes.c_int, ctypes.c_int, ctypes.c_double, vp, vp, vp]
        lib.acs_observe.argtypes = [ctypes.c_double, vp, vp, vp, vp]
        lib.acs_init_newton.argtypes = [ctypes.c_int, ctypes.c_int, ctypes.c_double, vp, vp,
                                        ctypes.c_int, vp, vp, ctypes.c_int, vp, ctypes.c_int]
        lib.acs_init_check.argtypes = [ctypes.c_int, ctypes.c_int, ctypes.c_double, vp, vp,
                                       ctypes.c_int, vp, vp]
        lib.acs_sweep.argtypes = [ctypes.POINTER(_SweepArgs)]
        self.n_fixed = sum(1 for nm in cm.var_names if cm.flat.variables[nm].start.fixed)
        # the C observe serves the model's observe callback when it gives the
        # same values (a sensitivity model observes their sensitivities too,
        # which its C does not: its Python observe then serves)
        n_obs = getattr(cm, "n_observed", len(cm.var_names))
        self.n_obs = n_obs if lib.acs_has_observe() and lib.acs_n_observed() == n_obs else None
        self.idle = {}
        self.static = _Static.of(cm)
        weakref.finalize(self, _free_idle, lib, self.idle)


    # IDA handles of finished runs, by settings: every segment starts with
    # IDAReInit (acs_start), so a later run of the model takes one over
    # instead of creating SUNDIALS objects again
    IDLE = 2   # kept per setting

    def take(self, key):
        idle = self.idle.get(key)
        return idle.pop() if idle else None

    def give(self, key, h):
        idle = self.idle.setdefault(key, [])
        if len(idle) < self.IDLE:
            idle.append(h)
        else:
            self.lib.acs_free(ctypes.c_void_p(h))


def _free_idle(lib, idle):
    for handles in idle.values():
        for h in handles:
            lib.acs_free(ctypes.c_void_p(h))


def library(cm):
    """The compiled library of ``cm``, generated, built and loaded once."""
    lib = _loaded.get(cm)
    if lib is None:
        lib = _loaded[cm] = _Library(cm)
    return lib


def _ptr(a, kind=ctypes.c_double):
    return a.ctypes.data_as(ctypes.POINTER(kind))


class CompiledSolver(SegmentSolver):
    """A segment solver on the compiled library of ``cm``: one IDA handle
    per run, re-initialised at each segment with that mode's discrete
    values (``pd`` = parameters then discrete values)."""
    name = "compiled"

    def __init__(self, cm, p, opts):
        self.cm, self.p = cm, np.asarray(p, float)
        L = self.L = library(cm)
        self.detail = "SUNDIALS IDA calling generated C" + (" (compiled now)" if L.built
                                                              else " (from the cache)")
        L.built = False
        st = L.static
        n = self.n = st.n
        self.nr, self.dirs, self.terminal = st.nr, st.dirs, st.terminal
        atol = np.asarray(opts["atol"], float)
        if atol.shape != (n,) or not atol.flags.c_contiguous:
            atol = np.ascontiguousarray(np.broadcast_to(atol, (n,)))
        rtol, hmax = float(opts["rtol"]), float(opts.get("max_step") or 0.0)
        key = (rtol, atol.tobytes(), hmax, int(opts["max_num_steps"]))
        self.h = L.take(key) or L.lib.acs_new(n, self.nr, L.n_pd, rtol, _ptr(atol),
                                              _ptr(st.ident), _ptr(self.dirs, ctypes.c_int),
                                              hmax, key[3])
        if not self.h:
            raise Unavailable("SUNDIALS refused the solver settings")
        self._free = weakref.finalize(self, L.give, key, self.h)
        self.troot = np.zeros(1)
        self.yroot, self.yproot = np.zeros(n), np.zeros(n)
        self.rootinfo = np.zeros(max(self.nr, 1), dtype=np.intc)
        self.counters = np.zeros(3, dtype=np.int_)
        self._cnt = self.counters.ctypes.data
        self._buffers = None   # the output buffers (made at the first segment)

    def _buffer(self):
        """The output buffers (:data:`CAP` rows of t, y and y'), their row
        count and acs_advance's pointer arguments after ``every_step``: made
        once per run, reused by its segments (their rows are copied out)."""
        got = self._buffers
        if got is None:
            n, cap = self.n, CAP
            bt, by, byp = np.empty(cap), np.empty((cap, n)), np.empty((cap, n))
            nrows = ctypes.c_int(0)
            ptrs = (bt.ctypes.data, by.ctypes.data, byp.ctypes.data, cap, ctypes.byref(nrows),
                    self.troot.ctypes.data, self.yroot.ctypes.data, self.yproot.ctypes.data,
                    self.rootinfo.ctypes.data)
            got = self._buffers = (bt, by, byp, nrows, ptrs)
        return got

    def solve(self, cb, d, t, y, yp, tout, every_step):
        L = self.L.lib
        tout = np.ascontiguousarray(tout, dtype=float)
        y0, yp0 = np.array(y, float), np.array(yp, float)
        pd = np.concatenate([self.p, np.asarray(d, float)])
        flag = L.acs_start(self.h, float(t), y0.ctypes.data, yp0.ctypes.data, pd.ctypes.data,
                           float(tout[-1]))
        if flag < 0:
            return Segment(np.array([t]), y0[None], yp0[None], flag, self._message(flag))
        # (a dense grid's buffer fills every CAP rows too: the guard then
        # sees a limit or a stop request within a bounded time)
        bt, by, byp, nrows, ptrs = self._buffer()
        T, Y, YP = [np.array([t])], [y0[None]], [yp0[None]]
        roots, iout = [], ctypes.c_int(0)
        tp, nt, every = tout.ctypes.data, len(tout), int(bool(every_step))
        while True:
            flag = L.acs_advance(self.h, tp, nt, ctypes.byref(iout), every, *ptrs)
            k = nrows.value
            if k:
                T.append(bt[:k].copy()), Y.append(by[:k].copy()), YP.append(byp[:k].copy())
            if flag == _FULL:
                if self.guard is not None:
                    L.acs_counters(self.h, self._cnt)
                    if self.guard(int(self.counters[0]), float(bt[k - 1]) if k else None):
                        flag = 0      # stopped: the rows so far are the segment
                        break
                continue
            if flag != _ROOT:
                break
            fired = [i for i in range(self.nr) if self.rootinfo[i] != 0]
            roots.append(Root(float(self.troot[0]), self.yroot.copy(), self.yproot.copy(),
                              fired))
            if any(self.terminal[i] for i in fired):
                T.append(self.troot.copy()), Y.append(self.yroot[None].copy())
                YP.append(self.yproot[None].copy())
                break
        L.acs_counters(self.h, self._cnt)
        steps, nfev, njev = self.counters.tolist()
        return Segment(np.concatenate(T), np.concatenate(Y), np.concatenate(YP),
                       int(flag) if flag < 0 else (_ROOT if flag == _ROOT else 0),
                       self._message(flag), roots, nfev, njev, steps)

    def _message(self, flag):
        if flag >= 0:
            return "ok"
        name = self.L.lib.acs_flag_name(flag)
        return _MESSAGES.get(flag, "IDA failed") + (f" ({name.decode()})" if name else "")

    def serve(self, model, p, d):
        """Mode ``d``'s callbacks of ``model`` calling the compiled library;
        its generated Python callbacks are made only if one of theirs is
        called (the dense and sparse Jacobians, which IDA here takes from C)."""
        return c_callbacks(library(model), model, p, d, lambda: model.callbacks(p, d))


def _f64(a):
    """``a`` as a C-contiguous float64 array (``a`` itself when it is one)."""
    if type(a) is np.ndarray and a.dtype == np.float64 and a.flags.c_contiguous:
        return a
    return np.ascontiguousarray(a, dtype=float)


def _into(fn, out, *args):
    """Call ``fn(*args, address of out)``, through a temporary when ``out``
    is not a C-contiguous float64 array."""
    buf = _f64(out)
    fn(*args, buf.ctypes.data)
    if buf is not out:
        out[...] = buf.reshape(np.shape(out))


def _fixed_arrays(fixed):
    """(indices, values) of the fixed starts ``fixed`` ((index, value, name)
    triples) as the C initialisation takes them (one dummy entry when none)."""
    return (np.array([k for k, _, _ in fixed] or [0], dtype=np.intc),
            np.array([v for _, v, _ in fixed] or [0.0], dtype=float))


class _CMode:
    """The compiled library's functions bound to one mode: ``pd`` (the
    parameters, then the discrete values) passed by its address, the array
    kept alive with the functions that use it."""

    def __init__(self, L, cm, p, d):
        self.L, self.lib = L, L.lib
        self.n, self.ns = len(cm.dae.y), cm.dae.n_states
        self.pd = np.ascontiguousarray(np.concatenate([np.asarray(p, float),
                                                       np.asarray(d, float)]))
        self.pdp = self.pd.ctypes.data or 0
        self._fixed_of = None

    def res(self, t, y, yp, r):
        y, yp = _f64(y), _f64(yp)
        _into(self.lib.acs_res, r, t, y.ctypes.data, yp.ctypes.data, self.pdp)

    def roots(self, t, y, yp, g):
        y, yp = _f64(y), _f64(yp)
        _into(self.lib.acs_roots, g, t, y.ctypes.data, yp.ctypes.data, self.pdp)

    def jacs(self, t, y, yp, Jy, Jyp):
        y, yp = _f64(y), _f64(yp)
        jy = _f64(Jy)
        _into(self.lib.acs_jacs, Jyp, t, y.ctypes.data, yp.ctypes.data, self.pdp,
              jy.ctypes.data)
        if jy is not Jy:
            Jy[...] = jy.reshape(np.shape(Jy))

    def observe(self, t, y, yp):
        y, yp = _f64(y), _f64(yp)
        o = np.empty(self.L.n_obs)
        self.lib.acs_observe(t, y.ctypes.data, yp.ctypes.data, self.pdp, o.ctypes.data)
        return o

    def _fixed(self, fixed):
        """:func:`_fixed_arrays` of ``fixed``, made once per list (the
        initialisation passes its one list to every call)."""
        got = self._fixed_of
        if got is None or got[0] is not fixed:
            got = self._fixed_of = (fixed, *_fixed_arrays(fixed))
        return got[1], got[2]

    def init_newton(self, t, z0, guess_rows, fixed, max_iter=50):
        if self.L.n_obs is None or len(fixed) != self.L.n_fixed:
            return NotImplemented
        z = np.array(z0, dtype=float)
        fk, fv = self._fixed(fixed)
        gk = np.array(list(guess_rows) or [0], dtype=np.intc)
        flag = self.lib.acs_init_newton(self.n, self.ns, float(t), z.ctypes.data, self.pdp,
                                        len(fixed), fk.ctypes.data, fv.ctypes.data,
                                        len(guess_rows), gk.ctypes.data, max_iter)
        return z if flag == 0 else (None if flag == 1 else NotImplemented)

    def init_check(self, t, z, fixed):
        if self.L.n_obs is None or len(fixed) != self.L.n_fixed:
            return NotImplemented
        z = _f64(z)
        fk, fv = self._fixed(fixed)
        ok = self.lib.acs_init_check(self.n, self.ns, float(t), z.ctypes.data, self.pdp,
                                     len(fixed), fk.ctypes.data, fv.ctypes.data)
        return NotImplemented if ok < 0 else bool(ok)

    def reinit(self, t, y, yp):
        y2, yp2 = np.array(y, dtype=float), np.array(yp, dtype=float)
        flag = self.lib.acs_reinit(self.n, self.ns, float(t), y2.ctypes.data,
                                   yp2.ctypes.data, self.pdp)
        return (y2, yp2) if flag == 0 else None


def c_callbacks(L, cm, p, d, make):
    """The :class:`~acausal.compiler.codegen.Callbacks` of one mode of ``cm``
    (parameters ``p``, discrete values ``d``; library ``L``) with the
    residual, the root functions and the two Jacobians ``jacs`` calling the
    compiled C instead of the generated Python (the same expressions), for
    what the hybrid loop computes in Python between segments: the
    initialisation, event actions and re-initialisation. ``reinit(t, y,
    yp)`` is the re-initialisation in C (``reinit.c``;
    :func:`acausal.runtime.initialize.reinitialize` calls it), or None where
    the Python version must run; ``init_newton(t, z0, guess_rows, fixed)``
    the initialisation's Gauss-Newton in C (the same return as
    :func:`acausal.runtime.linalg.newton`, or NotImplemented where the Python
    version must run); ``init_check(t, z, fixed)`` the initialisation's
    consistency test in C (True, False, or NotImplemented where the Python
    test must run). The observed variables (``observe``, an array here) are
    C too unless one has no C form. ``make()`` returns the mode's generated
    Python callbacks; it is called only when one of those runs (the dense
    and sparse Jacobians, which IDA here takes from C)."""
    mode = _CMode(L, cm, p, d)
    made = []

    def python(name):   # the generated Python callback ``name``, made on first use
        def call(*args):
            if not made:
                made.append(make())
            return getattr(made[0], name)(*args)
        return call

    # count: the step attempts the Python residual sees (none here)
    return Callbacks(mode.res, python("jac"), mode.roots, mode.jacs,
                     python("observe") if L.n_obs is None else mode.observe, [0, None],
                     python("jac_csc"), reinit=mode.reinit, init_newton=mode.init_newton,
                     init_check=mode.init_check)
