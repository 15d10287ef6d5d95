"""Staggered sensitivities through mode changes (prototype): the base run's rows are
split where the discrete values change (pre/post rows at the same t); each segment is
swept as in proto.py from the state sensitivities carried over; at a boundary
(Galan, Feehery & Barton 1999; as acausal.runtime.sensitivity):
    dtau/dp = -(g_y S- + g_y' S'- + g_p) / (dg/dt-)      (g: the root that fired first)
    S+_states = S-_states + (y'-_states - y'+_states) dtau/dp
then the algebraic S and the states' S' re-solved in the new mode; BDF restarts at order 1.
Discrete values set from continuous ones (sd) are NOT handled (none change here)."""
import numpy as np
import proto


class Sub:
    def __init__(self, res, a, b, vars_):
        self.t, self.y, self.yp = res.t[a:b], res.y[a:b], res.yp[a:b]
        self.cols = {v: np.asarray(res[v], float)[a:b] for v in vars_}

    def __getitem__(self, v):
        return self.cols[v]


def sweep_events(cm, res, vals, cond, names, part_vars, order=3, jumps=True):
    ns = cm.dae.n_states
    k = len(names)
    cut = list(np.where(np.any(np.diff(res.d, axis=0) != 0, axis=1))[0])   # row i pre, i+1 post
    bounds = [0] + [i + 1 for i in cut] + [res.t.size]
    St, SPt = np.zeros((res.t.size, len(cm.dae.y), k)), np.zeros((res.t.size, len(cm.dae.y), k))
    S0 = None
    evnames = [e.name for e in cm.events]
    for si in range(len(bounds) - 1):
        a, b = bounds[si], bounds[si + 1]
        st = proto.Setup(cm, vals, cond, names, part_vars, d=res.d[a])
        S, SP = proto.sweep(st, Sub(res, a, b, part_vars.values()), order, S0=S0)
        St[a:b], SPt[a:b] = S, SP
        if b == res.t.size:
            break
        # --- the event between row b-1 (pre) and row b (post) ---
        tau = res.t[b - 1]
        ev = [nm for (te, nm) in res.events if abs(te - tau) <= 1e-12 * max(1, tau)]
        gi = evnames.index(ev[0])
        y, yp = res.y[b - 1], res.yp[b - 1]
        cb = st.cb_py
        def g(cbk, t, yy, yyp):
            out = np.zeros(cm.n_roots)
            cbk.roots(t, yy, yyp, out)
            return out[gi]
        g0 = g(cb, tau, y, yp)
        n = len(y)
        gy = np.zeros(n); gyp = np.zeros(n)
        for j in range(n):
            h = 1e-7 * max(1.0, abs(y[j])); yy = y.copy(); yy[j] += h
            gy[j] = (g(cb, tau, yy, yp) - g0) / h
            h = 1e-7 * max(1.0, abs(yp[j])); yy = yp.copy(); yy[j] += h
            gyp[j] = (g(cb, tau, y, yy) - g0) / h
        gp = np.zeros(k)
        p0 = st.p0
        for c, nm in enumerate(names):
            j = cm.param_index(nm); h = 1e-6 * max(abs(p0[j]), 1e-3)
            pp, pm = p0.copy(), p0.copy(); pp[j] += h; pm[j] -= h
            gp[c] = (g(cm.callbacks(pp, st.d), tau, y, yp) - g(cm.callbacks(pm, st.d), tau, y, yp)) / (2 * h)
        # dg/dt along the left segment: quadratic through the last three rows
        tt = res.t[b - 3:b]; gg = np.array([g(cb, res.t[m], res.y[m], res.yp[m]) for m in range(b - 3, b)])
        dgdt = float(np.polyfit(tt - tau, gg, 2)[1])     # derivative at tau of the fitted quadratic
        dtau = -(gy @ S[-1] + gyp @ SP[-1] + gp) / dgdt
        S0 = S[-1].copy()
        if jumps:
            S0[:ns] += np.outer(res.yp[b - 1, :ns] - res.yp[b, :ns], dtau)
    return St, SPt
