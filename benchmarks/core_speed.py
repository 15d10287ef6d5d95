"""Generated model vs hand-written scikit-sundae residual, same equations,
same tolerances, measured in the same run (ratios, because the machine is
shared and noisy). Target: ratio <= 1.5.

    python benchmarks/core_speed.py [--repeat N]
"""
import argparse
import os
import sys
import time

import numpy as np
import sksundae as sun

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, ROOT)
sys.path.insert(0, os.path.join(ROOT, "benchmarks"))

from acausal.modelfile import compile_file  # noqa: E402
from timing import best_interleaved  # noqa: E402


# -- oscillator ------------------------------------------------------------------
def oscillator_handwritten(rtol=1e-8, atol=1e-10):
    def res(t, y, yp, r):
        r[0] = yp[0] - y[1]
        r[1] = 1.0 * yp[1] + 100.0 * y[0]

    def jac(t, y, yp, r, cj, J):
        J[0, 0] = cj
        J[0, 1] = -1.0
        J[1, 0] = 100.0
        J[1, 1] = cj

    s = sun.ida.IDA(res, jacfn=jac, rtol=rtol, atol=atol)
    out = s.solve(np.linspace(0, 1, 1001), [0.1, 0.0], [0.0, -10.0])
    return out.y[-1, 0], out.nfev


# -- Hertz impact: mass into a wall, contact switched on/off by events -------------
T_END, S0, OUT = 6e-4, -1e-4, np.linspace(0.0, 6e-4, 601)


def hertz_handwritten(rtol=1e-8, atol=1e-12, m=0.1, K=1e9, v0=1.0):
    """y = [s, v]; wall at s = 0; in contact m v' = -K s^1.5. Onset when s
    rises through 0, release when it falls through 0; each mode is one IDA
    solve over the output times, restarted at the event (as the generated
    model does)."""
    on = [False]

    def res(t, y, yp, r):
        r[0] = yp[0] - y[1]
        r[1] = m * yp[1] + (K * y[0] ** 1.5 if on[0] and y[0] > 0.0 else 0.0)

    def jac(t, y, yp, r, cj, J):
        J[0, 0] = cj
        J[0, 1] = -1.0
        J[1, 0] = 1.5 * K * y[0] ** 0.5 if on[0] and y[0] > 0.0 else 0.0
        J[1, 1] = m * cj

    def ev(t, y, yp, g):
        g[0] = y[0]
    ev.terminal = [True]
    ev.direction = [0]
    t, y, yp, nfev = 0.0, np.array([S0, v0]), np.array([v0, 0.0]), 0
    while t < T_END:
        s = sun.ida.IDA(res, jacfn=jac, eventsfn=ev, num_events=1, rtol=rtol, atol=atol)
        sol = s.solve(np.concatenate([[t], OUT[OUT > t]]), y, yp)
        nfev += sol.nfev
        t, y = sol.t[-1], sol.y[-1]
        if sol.status != 2:
            break
        on[0] = not on[0]
        f = K * max(y[0], 0.0) ** 1.5 if on[0] else 0.0
        yp = np.array([y[1], -f / m])
    return y[1], nfev


def hertz_generated(peak_event):
    from acausal import Model, compile_model
    from acausal.mechanics.contact import Contact
    from acausal.mechanics.translational import Fixed, Mass
    model = Model()
    model.mass = Mass(m=0.1, s=S0, v=1.0)
    model.wall = Fixed(s0=0.0)
    model.contact = Contact(K=1e9, gamma=1.5, e=1.0, peak_event=peak_event)
    model.connect(model.mass.flange, model.contact.flange_a)
    model.connect(model.contact.flange_b, model.wall.flange)
    cm = compile_model(model)
    return lambda: cm.simulate(t_end=T_END, rtol=1e-8, atol=1e-12, output_times=OUT)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--repeat", type=int, default=20)
    args = ap.parse_args(argv)
    rows = []
    _, osc = compile_file(os.path.join(ROOT, "models/examples/oscillator.py"))
    out = np.linspace(0, 1, 1001)

    def gen_osc():
        return osc.simulate(t_end=1.0, rtol=1e-8, atol=1e-10, output_times=out)
    rows.append(("oscillator", gen_osc, oscillator_handwritten,
                 gen_osc().stats["nfev"], oscillator_handwritten()[1]))
    for peak in (False, True):
        gen_hz = hertz_generated(peak)
        rows.append((f"hertz{'+peak' if peak else ''}", gen_hz, hertz_handwritten,
                     gen_hz().stats["nfev"], hertz_handwritten()[1]))
    print(f"{'model':16s} {'generated [ms]':>15s} {'hand [ms]':>10s} {'ratio':>6s} "
          f"{'nfev gen/hand':>14s}")
    for name, gen, hand, nf_g, nf_h in rows:
        tg, th = best_interleaved([gen, hand], args.repeat)
        print(f"{name:16s} {tg * 1e3:15.2f} {th * 1e3:10.2f} {tg / th:6.2f} "
              f"{nf_g:>7d}/{nf_h:<6d}")


if __name__ == "__main__":
    main()
