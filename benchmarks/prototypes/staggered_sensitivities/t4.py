"""C recursion kernel alone (precomputed alphas and arrays), per step."""
from params import *
import proto
tot = 0; steps = 0
for e in ds.experiments:
    res = proto.base_run(cm, mf, e, vals)
    st = proto.Setup(cm, vals, e, NAMES, PART_VARS)
    N, n, k, q = res.t.size, st.n, len(NAMES), 3
    # arrays as the sweep builds them (values irrelevant for timing, but use the real ones)
    Jy = np.zeros((N, n, n)); Jyp = np.zeros((N, n, n)); Fp = np.random.default_rng(0).standard_normal((N, n, k)) * 1e-3
    for m in range(N): st.cb.jacs(res.t[m], res.y[m], res.yp[m], Jy[m], Jyp[m])
    al = proto.alphas(res.t, q)
    S = np.zeros((N, n, k)); SP = np.zeros((N, n, k))
    best = 1e9
    for rep in range(5):
        t0 = time.perf_counter(); proto._c_sweep(N, n, k, q, al, Jy, Jyp, Fp, S, SP); best = min(best, time.perf_counter() - t0)
    ta = time.perf_counter(); proto.alphas(res.t, q); ta = time.perf_counter() - ta
    print(e.name, N - 1, "steps: kernel", f"{best*1e3:.2f} ms = {best/(N-1)*1e9:.0f} ns/step; alphas (numpy) {ta*1e3:.2f} ms")
    tot += best; steps += N - 1
fl = 2 * n**3 / 3 + k * (2 * q * n + 4 * n * n + 2 * n)
print(f"total kernel {tot*1e3:.1f} ms for {steps} steps; ~{fl:.0f} flop/step -> {fl*steps/tot/1e9:.2f} GFlop/s")
