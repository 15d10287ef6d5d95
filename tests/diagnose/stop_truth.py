"""An independent simulator of the stop rig (tests/diagnose/stop_rig.py),
written directly with scipy (no code of the project's model), with hidden
effects the diagnosis must find:

    m s'' = -c s - d s' - f_stop(s, s') - f_extra(s, s')

f_stop = max(0, D^1.5 (K + beta s')), D = max(s - S_LIMIT, 0) (the stop
above the slider, a Hertz law with hysteretic damping that never pulls);

* ``coulomb``: f_extra = F tanh(s'/1e-4) (dry friction in the guide);
* ``drag``: f_extra = c2 s'|s'| (quadratic air drag);
* ``hardening``: the spring's force is c s + k3 s^3;
* ``threshold``: f_extra = F_t sign(s') max(|s'| - v_t, 0) / v_t capped at
  F_t (a force that sets in above a speed: not a library law);

several at once as a dict {effect: value}. Each contact onset and release
is an event of the integration (DOP853 at rtol 1e-10 between them).

The position is sampled at ``RATE`` Hz, Gaussian noise added, rounded to
the sensor's resolution, and written in the dataset format.
"""
import numpy as np
from scipy.integrate import solve_ivp

from acausal.data import Dataset, MeasuredExperiment, Instrument, Trace, write_dataset

M, C, D = 0.1, 400.0, 0.04          # slider mass, spring, damper (nominal)
S_LIMIT, K, BETA = 0.008, 1e7, 5e6  # stop position, Hertz stiffness, damping
T_END, RATE = 1.5, 2000.0
NOISE, RESOLUTION = 2e-5, 5e-6      # m
V_T = 0.3                           # speed at which the threshold force sets in [m/s]


def _effects(effect, value):
    if isinstance(effect, dict):
        return effect
    return {} if effect is None else {effect: value}


def _force(s, v, c, d, eff):
    f = c * s + eff.get("hardening", 0.0) * s ** 3 + d * v
    f += eff.get("coulomb", 0.0) * np.tanh(v / 1e-4)
    f += eff.get("drag", 0.0) * v * abs(v)
    if "threshold" in eff:
        f += eff["threshold"] * np.sign(v) * min(max(abs(v) - V_T, 0.0) / V_T, 1.0)
    pen = max(s - S_LIMIT, 0.0)
    return f + max(0.0, pen ** 1.5 * (K + BETA * v))


def simulate(s0, effect=None, value=0.0, c=C, d=D, t=None):
    t = np.arange(0.0, T_END + 1e-12, 1.0 / RATE) if t is None else t
    eff = _effects(effect, value)

    def rhs(_, y):
        return [y[1], -_force(y[0], y[1], c, d, eff) / M]

    def touch(_, y):
        return y[0] - S_LIMIT

    touch.terminal = True

    out, t0, y0 = [], 0.0, [s0, 0.0]
    while t0 < t[-1]:
        sol = solve_ivp(rhs, (t0, t[-1]), y0, method="DOP853", rtol=1e-10, atol=1e-13,
                        events=touch, dense_output=True, max_step=1e-3)
        t1 = sol.t[-1]
        out.append((t0, t1, sol.sol))
        if sol.status != 1:
            break
        t0, y0 = t1, sol.y[:, -1]
        # step just past the crossing so that the event is not found again at t0
        nxt = solve_ivp(rhs, (t0, t0 + 1e-7), y0, method="DOP853", rtol=1e-12, atol=1e-15)
        t0, y0 = nxt.t[-1], nxt.y[:, -1]
    y = np.empty_like(t)
    for a, b, f in out:
        m = (t >= a) & (t <= b)
        y[m] = f(t[m])[0]
    return t, y


def write(folder, effect=None, value=0.0, starts=(-0.012, -0.016, -0.020), seed=0, c=C,
          d=D):
    """Write a dataset of the slider released from each of ``starts``."""
    rng = np.random.default_rng(seed)
    exps = []
    for i, s0 in enumerate(starts):
        t, s = simulate(s0, effect, value, c, d)
        y = s + rng.normal(0.0, NOISE, s.shape)
        y = RESOLUTION * np.round(y / RESOLUTION)
        exps.append(MeasuredExperiment(f"S{i + 1}", {"s_start": float(s0)}, {},
                               Trace(t, {"slider.s": y})))
    inst = {"slider.s": Instrument("slider.s", RESOLUTION, NOISE)}
    write_dataset(folder, Dataset(None, exps, inst), {"time": "ms", "slider.s": "mm"})
    return folder


def effect_floors(effect, value, starts=(-0.012, -0.016, -0.020)):
    """RMS change the hidden effect makes to the position, in noise floors."""
    floor = np.sqrt(NOISE ** 2 + RESOLUTION ** 2 / 12)
    diffs = [simulate(p, effect, value)[1] - simulate(p)[1] for p in starts]
    return float(np.sqrt(np.mean(np.concatenate(diffs) ** 2)) / floor)
