"""An independent simulator of the two-mass chain (tests/diagnose/two_mass.py),
written directly with scipy (no code of the project's model), with hidden
effects the diagnosis must find::

    m1 x1'' = -k1 x1 - d1 x1' + f12 - f1(x1')
    m2 x2'' = -f12 - f2(x2')
    f12 = k2 (x2 - x1) + d2 (x2' - x1') + k3 (x2 - x1)^3

* ``m2_coulomb``: f2 = F tanh(x2'/1e-4) (dry friction of m2 on its guide);
* ``m2_viscous``: f2 += b x2' (a viscous loss in m2's guide, linear in its speed);
* ``m1_drag``: f1 += c x1'|x1'| (quadratic drag on m1);
* ``k2_cubic``: k3 (a hardening coupling spring);
* ``m1_threshold``: f1 += F_t sign(x1') min(max(|x1'| - 0.1, 0)/0.1, 1), a
  force that sets in above 0.1 m/s (no library law);
several at once as a dict {effect: value}. Both positions are sampled at
RATE Hz, Gaussian noise added and rounded to a 1 um sensor's resolution."""
import numpy as np
from scipy.integrate import solve_ivp
from acausal.data import Dataset, MeasuredExperiment, Instrument, Trace, write_dataset

M1, M2, K1, D1, K2, D2 = 0.5, 0.2, 2000.0, 1.0, 800.0, 0.2
T_END, RATE, NOISE, RES = 1.5, 2000.0, 2e-6, 1e-6
STARTS = (0.008, 0.012, 0.016)
SIG = ("m1.s", "m2.s")


def _eff(effect, value):
    return dict(effect) if isinstance(effect, dict) else ({} if effect is None else {effect: value})


def simulate(x20, effect=None, value=0.0):
    e = _eff(effect, value)
    t = np.arange(0.0, T_END + 1e-12, 1.0 / RATE)

    def rhs(_, y):
        x1, v1, x2, v2 = y
        f12 = K2 * (x2 - x1) + D2 * (v2 - v1) + e.get("k2_cubic", 0.0) * (x2 - x1) ** 3
        f1 = e.get("m1_drag", 0.0) * v1 * abs(v1)
        if "m1_threshold" in e:   # a force that sets in above 0.1 m/s: no library law
            f1 += e["m1_threshold"] * np.sign(v1) * min(max(abs(v1) - 0.1, 0.0) / 0.1, 1.0)
        f2 = e.get("m2_coulomb", 0.0) * np.tanh(v2 / 1e-4) + e.get("m2_viscous", 0.0) * v2
        return [v1, (-K1 * x1 - D1 * v1 + f12 - f1) / M1, v2, (-f12 - f2) / M2]
    sol = solve_ivp(rhs, (0, T_END), [0.0, 0.0, x20, 0.0], t_eval=t, method="LSODA",
                    rtol=1e-11, atol=1e-14, max_step=2e-4)
    return t, sol.y[0], sol.y[2]


def write(folder, effect=None, value=0.0, seed=0):
    rng = np.random.default_rng(seed)
    exps = []
    for i, x20 in enumerate(STARTS):
        t, x1, x2 = simulate(x20, effect, value)
        cols = {}
        for s, x in zip(SIG, (x1, x2)):
            y = x + rng.normal(0.0, NOISE, x.shape)
            cols[s] = RES * np.round(y / RES)
        exps.append(MeasuredExperiment(f"T{i + 1}", {"x2_start": x20}, {}, Trace(t, cols)))
    inst = {s: Instrument(s, RES, NOISE) for s in SIG}
    write_dataset(folder, Dataset(None, exps, inst), {"time": "ms", "m1.s": "mm", "m2.s": "mm"})
    return folder


def effect_floors(effect, value):
    floor = np.sqrt(NOISE ** 2 + RES ** 2 / 12)
    d = []
    for x20 in STARTS:
        a, b = simulate(x20, effect, value), simulate(x20)
        d += [a[1] - b[1], a[2] - b[2]]
    return float(np.sqrt(np.mean(np.concatenate(d) ** 2)) / floor)
