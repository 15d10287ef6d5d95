"""Staggered direct forward sensitivities along a finished base run (prototype).

Base: the index-1 DAE F(t, y, y', p) = 0 integrated once by IDA (compiled
backend, output_step=0: every accepted step). Then, on the SAME step
sequence, the linear sensitivity DAE

    F_y S + F_y' S' + F_p = 0          (S = dy/dp, n x k, all k columns at once)

is integrated by a variable-coefficient BDF of order q (Lagrange form on the
base's own time points; order ramps 1..q over the first steps):

    S'_{m} ~= sum_j alpha_j S_{m-j},  (F_y + alpha_0 F_y') S_m = -(F_p + F_y' sum_{j>=1} alpha_j S_{m-j})

one n x n LU per accepted step, k right-hand sides. F_y, F_y' from the generated
callbacks (cb.jacs) at the base's accepted (t, y, y'); F_p:
  * the generic term's weights: F is linear in them and a weight's column is
    c(t) * hat_i(z(t)) (z the body position or velocity); c(t)*sum_i hat_i(z) from
    ONE residual difference with every weight of the part raised by delta (exact:
    linear); hats from acausal.diagnose.library.generic.hats;
  * other parameters (the free ones): central difference of the residual in p.
Outputs at the data's sample times by cubic Hermite interpolation of (S, S'),
mapped to the observed variable by g_y S + g_p (g from differences of cb.observe).
"""
import os
import time
import numpy as np
from acausal.diagnose.library import generic as gen
from acausal.diagnose.stages.fitting import run_options


def base_run(cm, mf, e, vals, rtol=None, atol=None, backend="compiled"):
    opts = run_options(mf, e)
    opts.update(output_step=0, output_times=None)
    if rtol is not None:
        opts.update(rtol=rtol, atol=atol)
    return cm.simulate(params={**vals, **e.conditions}, backend=backend, **opts)


def bdf_coeffs(tt):
    """alpha_j: derivative at tt[0] of the Lagrange basis on points tt[0..q]."""
    q = len(tt) - 1
    a = np.empty(q + 1)
    a[0] = sum(1.0 / (tt[0] - tt[m]) for m in range(1, q + 1))
    for j in range(1, q + 1):
        num = 1.0
        for m in range(1, q + 1):
            if m != j:
                num *= tt[0] - tt[m]
        den = 1.0
        for m in range(q + 1):
            if m != j:
                den *= tt[j] - tt[m]
        a[j] = num / den
    return a


class Setup:
    """Per experiment: callbacks for the base and perturbed parameter vectors."""

    def __init__(self, cm, vals, e, names, part_vars, delta_rel=1e-6, use_c=False, d=None):
        self.cm, self.names = cm, list(names)
        if use_c:
            from acausal.runtime.backends.compiled import _CMode, library
            L = library(cm)
            mk = lambda p, d: _CMode(L, cm, p, d)
        else:
            mk = cm.callbacks
        allp = {**vals, **(e.conditions if hasattr(e, 'conditions') else e)}
        self.p0 = cm.param_vector(allp)
        self.d = cm.discrete_start() if d is None else np.asarray(d, float)
        self.cb = mk(self.p0, self.d)
        self.cb_py = cm.callbacks(self.p0, self.d)
        self.n = len(cm.dae.y)
        # groups: hat parts  (prefix letter -> (column indices, knots, variable, ranges))
        pv = lambda nm: float(self.p0[cm.param_index(nm)])
        lo_hi = {"a": (pv("gen.x_lo"), pv("gen.x_hi")), "b": (pv("gen.v_lo"), pv("gen.v_hi"))}
        self.parts = []
        for c in ("a", "b"):
            cols = [i for i, nm in enumerate(self.names) if nm.startswith(f"gen.{c}") and nm[5:].isdigit()]
            if not cols:
                continue
            every = [str(sy) for sy in cm.param_syms if str(sy).startswith(f"gen.{c}") and str(sy)[5:].isdigit()]
            p1 = self.p0.copy()
            dlt = 1.0      # F is linear in the weights: any step is exact up to rounding
            p1[[cm.param_index(nm) for nm in every]] += dlt       # every weight of the part: sum of hats
            self.parts.append(dict(cols=cols, knots=len(every), which=[int(self.names[i][5:]) for i in cols],
                                   var=part_vars[c], lohi=lo_hi[c], cb=mk(p1, self.d), dlt=dlt))
        hatcols = {i for pt in self.parts for i in pt["cols"]}
        self.other = []
        for i, nm in enumerate(self.names):
            if i in hatcols:
                continue
            j = cm.param_index(nm)
            h = delta_rel * max(abs(self.p0[j]), 1e-3)
            pp, pm = self.p0.copy(), self.p0.copy()
            pp[j] += h
            pm[j] -= h
            self.other.append(dict(col=i, h=h, cbp=mk(pp, self.d), cbm=mk(pm, self.d), pyp=cm.callbacks(pp, self.d), pym=cm.callbacks(pm, self.d)))


def sweep(st, res, order=2, timing=None, kernel=None, S0=None):
    """S (N x n x k) and S' at every accepted step of ``res``."""
    t0w = time.perf_counter()
    t, Y, YP = res.t, res.y, res.yp
    N, n, k = t.size, st.n, len(st.names)
    # --- callbacks along the steps (F_y, F_y', F_p) ---
    Jy = np.zeros((N, n, n)); Jyp = np.zeros((N, n, n)); Fp = np.zeros((N, n, k))
    r0 = np.zeros(n); r1 = np.zeros(n); r2 = np.zeros(n)
    cb = st.cb
    for m in range(N):
        cb.jacs(t[m], Y[m], YP[m], Jy[m], Jyp[m])
        cb.res(t[m], Y[m], YP[m], r0)
        for pt in st.parts:
            pt["cb"].res(t[m], Y[m], YP[m], r1)
            pt.setdefault("c", np.zeros((N, n)))[m] = (r1 - r0) / pt["dlt"]
        for o in st.other:
            o["cbp"].res(t[m], Y[m], YP[m], r1)
            o["cbm"].res(t[m], Y[m], YP[m], r2)
            Fp[m, :, o["col"]] = (r1 - r2) / (2 * o["h"])
    for pt in st.parts:
        z = np.asarray(res[pt["var"]], float)
        H = gen.hats(z, pt["lohi"][0], pt["lohi"][1], pt["knots"])          # N x nk
        ssum = H.sum(axis=1)
        c = np.where(ssum[:, None] > 0, pt["c"] / np.where(ssum > 0, ssum, 1.0)[:, None], 0.0)
        Fp[:, :, pt["cols"]] = c[:, :, None] * H[:, None, pt["which"]]
    t1w = time.perf_counter()
    # --- initial sensitivities: states' S fixed (starts independent of p), the
    # states' S' and the algebraic S from the linearised equations ---
    ns = st.cm.dae.n_states
    S = np.zeros((N, n, k)); SP = np.zeros((N, n, k))
    if S0 is not None:
        S[0, :ns] = S0[:ns]
    A0 = np.concatenate([Jyp[0][:, :ns], Jy[0][:, ns:]], axis=1)
    z0 = np.linalg.solve(A0, -(Fp[0] + Jy[0][:, :ns] @ S[0, :ns]))
    SP[0, :ns] = z0[:ns]
    S[0, ns:] = z0[ns:]
    # --- BDF sweep, one LU per step (batched), then the sequential recursion ---
    al = alphas(t, order)                                   # N x (order+1), row m: S'_m coefficients
    if kernel == "c":
        _c_sweep(N, n, k, order, al, Jy, Jyp, Fp, S, SP)
        t2w = time.perf_counter()
        if timing is not None:
            timing["callbacks"] = timing.get("callbacks", 0) + (t1w - t0w)
            timing["sweep"] = timing.get("sweep", 0) + (t2w - t1w)
        return S, SP
    A = Jy + al[:, 0, None, None] * Jyp
    Ainv = np.linalg.inv(A[1:])                             # one LU per step
    B = -Ainv @ Jyp[1:]
    G = -Ainv @ Fp[1:]
    q = order
    for m in range(1, N):
        qq = min(q, m)
        hist = al[m, 1] * S[m - 1]
        for j in range(2, qq + 1):
            hist = hist + al[m, j] * S[m - j]
        S[m] = G[m - 1] + B[m - 1] @ hist
    SP[1:] += al[1:, 0, None, None] * S[1:]       # S'_m = sum_j alpha_j S_{m-j}
    for j in range(1, q + 1):
        SP[j:] += al[j:, j, None, None] * S[:N - j]
    t2w = time.perf_counter()
    if timing is not None:
        timing["callbacks"] = timing.get("callbacks", 0) + (t1w - t0w)
        timing["sweep"] = timing.get("sweep", 0) + (t2w - t1w)
    return S, SP


def hermite(t, S, SP, tq):
    """Cubic Hermite interpolation of S (N x ...) with slopes SP at times tq."""
    i = np.clip(np.searchsorted(t, tq, side="right") - 1, 0, t.size - 2)
    h = t[i + 1] - t[i]
    u = ((tq - t[i]) / h)
    sh = (slice(None),) + (None,) * (S.ndim - 1)
    u = u[sh]; hh = h[sh]
    h00 = 2 * u**3 - 3 * u**2 + 1; h10 = u**3 - 2 * u**2 + u
    h01 = -2 * u**3 + 3 * u**2; h11 = u**3 - u**2
    return h00 * S[i] + h10 * hh * SP[i] + h01 * S[i + 1] + h11 * hh * SP[i + 1]


def observed_rows(st, var, tq, yq, ypq, Sq):
    """d var / d p at the sample times: g_y S + g_p (g by differences of observe)."""
    cm, cb = st.cm, st.cb_py
    iv = cm.var_names.index(var)
    k = len(st.names)
    out = np.zeros((tq.size, k))
    for m in range(tq.size):
        y, yp = yq[m], ypq[m]
        o0 = cb.observe(tq[m], y, yp)[iv]
        g = np.zeros(st.n)
        for j in range(st.n):
            h = 1e-7 * max(1.0, abs(y[j]))
            yy = y.copy(); yy[j] += h
            g[j] = (cb.observe(tq[m], yy, yp)[iv] - o0) / h
        out[m] = g @ Sq[m]
        for o in st.other:
            out[m, o["col"]] += (o["pyp"].observe(tq[m], y, yp)[iv]
                                 - o["pym"].observe(tq[m], y, yp)[iv]) / (2 * o["h"])
    return out


def jacobian(cm, mf, ds, vals, names, part_vars, order=2, timing=None, base_kw=None, kernel=None):
    """(d observed / d p rows of every experiment's traced signals, stacked in the
    order of weighted_residuals (unweighted, parameter units); per-experiment stats)."""
    rows, stats = [], []
    for e in ds.experiments:
        tb = time.perf_counter()
        res = base_run(cm, mf, e, vals, **(base_kw or {}))
        if timing is not None:
            timing["base"] = timing.get("base", 0) + time.perf_counter() - tb
        st = Setup(cm, vals, e, names, part_vars)
        S, SP = sweep(st, res, order, timing, kernel)
        tq = e.trace.time
        tq_ = np.clip(tq, res.t[0], res.t[-1])
        to = time.perf_counter()
        Sq = hermite(res.t, S, SP, tq_)
        yq = hermite(res.t, res.y, res.yp, tq_)
        ypq = np.array([np.interp(tq_, res.t, res.yp[:, j]) for j in range(st.n)]).T
        for var in e.trace.signals:
            rows.append(observed_rows(st, var, tq_, yq, ypq, Sq))
        if timing is not None:
            timing["output"] = timing.get("output", 0) + time.perf_counter() - to
        stats.append(dict(exp=e.name, steps=res.t.size - 1, **{k: res.stats.get(k) for k in ("nfev", "njev")}))
    return np.vstack(rows), stats


def alphas(t, q):
    """Row m: the variable-step BDF coefficients of order min(q, m) on t[m], t[m-1], ..."""
    N = t.size
    al = np.zeros((N, q + 1))
    for m in range(1, min(q, N)):
        al[m, :m + 1] = bdf_coeffs(t[m::-1][:m + 1])
    if N > q:
        tt = np.stack([t[q - j:N - j] for j in range(q + 1)], axis=1)   # rows m = q..N-1
        d0 = tt[:, :1] - tt[:, 1:]
        al[q:, 0] = (1.0 / d0).sum(axis=1)
        for j in range(1, q + 1):
            num = np.ones(N - q); den = np.ones(N - q)
            for m in range(1, q + 1):
                if m != j:
                    num *= tt[:, 0] - tt[:, m]
            for m in range(q + 1):
                if m != j:
                    den *= tt[:, j] - tt[:, m]
            al[q:, j] = num / den
    return al


_LIB = None


def _c_sweep(N, n, k, q, al, Jy, Jyp, Fp, S, SP):
    """The recursion in C (sweep.c, built with gcc -O2)."""
    global _LIB
    import ctypes, os
    if _LIB is None:
        _LIB = ctypes.CDLL(os.path.join(os.path.dirname(os.path.abspath(__file__)), "sweep.so"))
        _LIB.sweep.argtypes = [ctypes.c_int] * 4 + [ctypes.c_void_p] * 7
    work = np.zeros(n * n + 2 * n * k)
    arrs = [np.ascontiguousarray(a) for a in (al, Jy, Jyp, Fp)]
    _LIB.sweep(N, n, k, q, *[a.ctypes.data for a in arrs], S.ctypes.data, SP.ctypes.data, work.ctypes.data)


def reference_table(cm, vals, cond, names, tq, sig, mine):
    """Central differences of tight runs (rtol 1e-10, atol 1e-12; relative steps
    1e-4 and 1e-3 of each value, at least 1e-3) of the signals ``sig`` at ``tq``,
    against each Jacobian of ``mine`` (label -> matrix, columns as ``names``): one
    printed row per parameter (column norm, relative errors, the reference's own
    spread between its two steps)."""
    p0 = cm.param_vector({**vals, **cond})

    def obs(pp):
        r = cm.simulate(params={**vals, **cond, **pp}, backend="compiled", t_end=tq[-1],
                        rtol=1e-10, atol=1e-12, output_times=tq)
        return np.concatenate([np.interp(tq, r.t, r[v]) for v in sig])
    print("param      |col|     " + "  ".join(f"{k}-vs-ref" for k in mine)
          + "  ref(1e-4 vs 1e-3 rel step)")
    for i, n in enumerate(names):
        v = float(p0[cm.param_index(n)])
        refs = {}
        for rel in (1e-4, 1e-3):
            h = rel * max(abs(v), 1e-3)
            refs[rel] = (obs({n: v + h}) - obs({n: v - h})) / (2 * h)
        a = refs[1e-4]
        na = np.linalg.norm(a)
        errs = "  ".join(f"{np.linalg.norm(J[:, i] - a) / na:.1e}" for J in mine.values())
        print(f"{n:12s} {na:.3e}  {errs}  {np.linalg.norm(refs[1e-3] - a) / na:.1e}")


def cam_case(w0):
    """The cam DAE of cam_test.py / cam_events_test.py: the generic term (17 x 9
    knots) at the cam beside stick-slip friction (tau 2e-3), small random weights
    (seed 1), the cam started at ``w0``: (mf, cm, values, conditions)."""
    from acausal.diagnose.library.hypotheses import HYPOTHESES
    here = os.path.dirname(os.path.abspath(__file__))
    path = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(here))), "tests",
                        "diagnose", "independent", "cam_follower.py")
    mf, cm = gen.build_at(path, "cam", 17, 9, beside=("stick_slip_friction", "cam"),
                          hypotheses=HYPOTHESES)
    rng = np.random.default_rng(1)
    vals = {f"gen.a{i}": float(v) for i, v in enumerate(1e-3 * rng.standard_normal(17))}
    vals.update({f"gen.b{i}": float(v) for i, v in enumerate(1e-3 * rng.standard_normal(9))})
    vals["hyp_ssf.tau"] = 2e-3
    return mf, cm, vals, {"w0": float(w0)}
