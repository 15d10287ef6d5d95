"""An independent simulator of the stick rig (tests/diagnose/stick_rig.py),
written directly with scipy (no code of the project), with dry friction in
the guide that sticks and slips, integrated event by event::

    sliding (sign sg):  m s'' = -c s - d s' - sg F_k - f_extra(s')
    stuck (s' = 0):     s'' = 0 while |c s| <= F_s  (no other force at rest)

A sliding phase ends where s' returns to zero (a solve_ivp event, DOP853 at
rtol 1e-12). There the force on the slider at rest is -c s: if its size is
at most the static level F_s the slider stays where it is for the rest of
the run (nothing else acts on it), else it slides the other way. The start
(at rest) is judged the same way.

Effects (``effect``, ``value``; or several as a dict):

* ``stick``: F_k = F_s = value (dry friction with stiction, static level =
  sliding level, as the library's friction elements with peak 1);
* ``viscous``: f_extra = value * s' (a viscous loss in the guide, on top of
  the model's damper; no stick: F = 0).

The position is sampled at ``RATE`` Hz, Gaussian noise added, rounded to
the sensor's resolution, and written in the dataset format.
"""
import numpy as np
from scipy.integrate import solve_ivp

from acausal.data import Dataset, Instrument, MeasuredExperiment, Trace, write_dataset

M, C, D = 0.5, 200.0, 0.05          # slider mass, spring rate, damper (nominal)
T_END, RATE = 1.0, 1000.0
NOISE, RESOLUTION = 2e-5, 5e-6      # m
STARTS = (0.03, 0.04, 0.05)


def _effects(effect, value):
    if isinstance(effect, dict):
        return dict(effect)
    return {} if effect is None else {effect: value}


def simulate(s0, effect=None, value=0.0, c=C, d=D, t=None):
    """(t, s, stops): the slider released at rest from ``s0``; ``stops`` the
    times at which it came to rest and stayed."""
    t = np.arange(0.0, T_END + 1e-12, 1.0 / RATE) if t is None else np.asarray(t)
    eff = _effects(effect, value)
    F = eff.get("stick", 0.0)
    b = eff.get("viscous", 0.0)
    s = np.empty_like(t)
    t0, y0 = 0.0, np.array([s0, 0.0])
    stops = []
    while True:
        pull = -c * y0[0]                  # the force on the slider at rest
        if abs(pull) <= F or (pull == 0.0 and y0[1] == 0.0):
            s[t >= t0] = y0[0]             # stuck for good
            stops.append(t0)
            break
        sg = np.sign(pull)                 # it slides the way it is pulled

        def rhs(_, y, sg=sg):
            return [y[1], (-c * y[0] - (d + b) * y[1] - sg * F) / M]

        def rest(_, y, sg=sg):
            return y[1]
        rest.terminal, rest.direction = True, -sg
        mask = t >= t0
        sol = solve_ivp(rhs, (t0, T_END), y0, method="DOP853", rtol=1e-12, atol=1e-15,
                        events=rest, dense_output=True, max_step=1e-3)
        t1 = sol.t_events[0][0] if sol.t_events[0].size else T_END
        seg = mask & (t <= t1)
        s[seg] = sol.sol(t[seg])[0]
        if not sol.t_events[0].size:
            break
        t0, y0 = t1, np.array([sol.y_events[0][0][0], 0.0])
        if F == 0.0:                       # no stick: a viscous ring-down never rests
            y0 = sol.y_events[0][0].copy()
            y0[1] = 0.0
    return t, s, stops


def write(folder, effect=None, value=0.0, starts=STARTS, seed=0):
    """Write a dataset of the slider released from each of ``starts``."""
    rng = np.random.default_rng(seed)
    exps = []
    for i, s0 in enumerate(starts):
        t, s, _ = simulate(s0, effect, value)
        y = s + rng.normal(0.0, NOISE, s.shape)
        y = RESOLUTION * np.round(y / RESOLUTION)
        exps.append(MeasuredExperiment(f"S{i + 1}", {"s_start": float(s0)}, {},
                                       Trace(t, {"slider.s": y})))
    inst = {"slider.s": Instrument("slider.s", RESOLUTION, NOISE)}
    write_dataset(folder, Dataset(None, exps, inst), {"time": "s", "slider.s": "m"})
    return folder


def effect_floors(effect, value, starts=STARTS):
    """RMS change the hidden effect makes to the position, in noise floors."""
    floor = np.sqrt(NOISE ** 2 + RESOLUTION ** 2 / 12)
    diffs = [simulate(p, effect, value)[1] - simulate(p)[1] for p in starts]
    return float(np.sqrt(np.mean(np.concatenate(diffs) ** 2)) / floor)
