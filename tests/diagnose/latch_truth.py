"""An independent simulator of the latch striker (models/latch_striker.py),
written directly from the physics with scipy (it imports nothing of the
project's model or component code), with hidden effects the diagnosis must
find.

Bodies: the plunger (mass M_P, position x, start 0 at rest) and the latch
(mass M_L, position y, start GAP at rest), both along +s::

    M_P x'' = F_coil + P0 - C_RET x - f_c - f_plunger(x, x')
    M_L y'' = f_c - C_L (y - GAP) - D_L y' - f_latch(y, y')

``P0`` is the return spring's installed force (3 N, compression at x = 0).
Contact (Hunt-Crossley damping): indentation delta = x - y, and while in
contact f_c = K delta^1.5 max(0, 1 + CHI delta'/v_i), CHI = 3 (1 - E) / 2,
v_i = max(delta' at the onset of this impact, 1e-4). Each contact onset and
release is an event of the integration (DOP853 between events), and the run
stops when the latch has moved TRIP (y = GAP + TRIP).

Hidden effects (several at once as a dict {effect: value}):

* ``plunger_drag``: f_plunger += c x'|x'| (quadratic drag on the plunger);
* ``latch_drag``: f_latch += c y'|y'| (quadratic drag on the latch);
* ``coil_slope``: the coil's force grows with the stroke, F_coil + k x;
* ``plunger_stribeck``: (F_c, dF, v_s): f_plunger += (F_c + dF exp(-(x'/v_s)^2))
  tanh(x'/1e-4) (Stribeck friction in the plunger's guide);
* ``plunger_threshold``: f_plunger += F_t min(max(x' - V_T, 0) / V_T, 1) sign(x')
  (a force that sets in above the speed V_T, e.g. an air cushion
  that vents above a flow rate: no library law).

Both positions are sampled at RATE Hz from 0 to the trip, Gaussian noise
added, rounded to the sensor's resolution, and written in the dataset format.
"""
import numpy as np
from scipy.integrate import solve_ivp

from acausal.data import Dataset, MeasuredExperiment, Instrument, Trace, write_dataset

M_P, M_L = 0.04, 0.02              # plunger and latch masses [kg]
C_RET, P0 = 300.0, 3.0             # return spring [N/m], its force at x = 0 [N]
C_L, D_L = 2000.0, 4.0             # latch spring [N/m], latch damper [N s/m]
K, E = 5e8, 0.6                    # contact stiffness [N/m^1.5], restitution
GAP, TRIP = 1e-3, 2e-3             # [m]
V_MIN = 1e-4
RATE, NOISE, RESOLUTION = 50e3, 1e-6, 1e-6    # a 1 um sensor at 50 kHz
V_T = 0.8                          # speed at which the threshold force sets in [m/s]
COILS = (20.0, 26.0, 32.0, 38.0, 45.0)
SIGNALS = ("plunger.s", "latch.s")


def _effects(effect, value):
    if isinstance(effect, dict):
        return effect
    return {} if effect is None else {effect: value}


def _plunger_extra(v, eff):
    f = eff.get("plunger_drag", 0.0) * v * abs(v)
    if "plunger_stribeck" in eff:
        fc, df, vs = eff["plunger_stribeck"]
        f += (fc + df * np.exp(-(v / vs) ** 2)) * np.tanh(v / 1e-4)
    if "plunger_threshold" in eff:
        f += eff["plunger_threshold"] * np.sign(v) * min(max(abs(v) - V_T, 0.0) / V_T, 1.0)
    return f


def _rhs(coil, eff, k, d, state):
    """Right-hand side in contact mode ``state`` = (in contact, v_i)."""
    contact, v_i = state
    chi = 1.5 * (1.0 - E)

    def rhs(_, z):
        x, v, y, w = z
        fc = 0.0
        if contact:
            delta, rate = x - y, v - w
            fc = k * max(delta, 0.0) ** 1.5 * max(0.0, 1.0 + chi * rate / v_i)
        f_coil = coil + eff.get("coil_slope", 0.0) * x
        a_p = (f_coil + P0 - C_RET * x - fc - _plunger_extra(v, eff)) / M_P
        a_l = (fc - C_L * (y - GAP) - d * w - eff.get("latch_drag", 0.0) * w * abs(w)) / M_L
        return [v, a_p, w, a_l]
    return rhs


def _events(contact):
    def touch(_, z):
        return z[0] - z[2]
    touch.terminal, touch.direction = True, (-1 if contact else 1)

    def trip(_, z):
        return z[2] - (GAP + TRIP)
    trip.terminal, trip.direction = True, 1
    return [touch, trip]


def simulate(coil, effect=None, value=None, k=K, d=D_L, t_end=0.05):
    """(segments, trip time): dense solutions [(t0, t1, sol)] up to the trip."""
    eff = _effects(effect, value)
    z, t0, state, segs = [0.0, 0.0, GAP, 0.0], 0.0, (False, 1.0), []
    while t0 < t_end:
        sol = solve_ivp(_rhs(coil, eff, k, d, state), (t0, t_end), z, method="DOP853",
                        rtol=1e-11, atol=1e-14, events=_events(state[0]), dense_output=True,
                        max_step=2e-5)
        segs.append((t0, sol.t[-1], sol.sol))
        if sol.status != 1 or sol.t_events[1].size:
            return segs, sol.t[-1]
        t0, z = sol.t[-1], sol.y[:, -1]
        if state[0]:
            state = (False, 1.0)
        else:
            state = (True, max(z[1] - z[3], V_MIN))
    return segs, t_end


def sample(segs, t):
    """(x, y) of the piecewise solution at the times t."""
    out = np.empty((2, len(t)))
    for a, b, f in segs:
        m = (t >= a) & (t <= b)
        if m.any():
            out[:, m] = f(t[m])[[0, 2]]
    return out


def _grid(t_trip):
    return np.arange(0.0, t_trip + 1e-15, 1.0 / RATE)


def write(folder, effect=None, value=None, coils=COILS, seed=0, k=K, d=D_L):
    """Write a dataset: one experiment per coil force, both positions traced."""
    rng = np.random.default_rng(seed)
    exps = []
    for i, coil in enumerate(coils):
        segs, t_trip = simulate(coil, effect, value, k, d)
        t = _grid(t_trip)
        xy = sample(segs, t)
        cols = {}
        for name, z in zip(SIGNALS, xy):
            z = z + rng.normal(0.0, NOISE, z.shape)
            cols[name] = RESOLUTION * np.round(z / RESOLUTION)
        exps.append(MeasuredExperiment(f"L{i + 1}", {"F_coil": float(coil)}, {}, Trace(t, cols)))
    inst = {s: Instrument(s, RESOLUTION, NOISE) for s in SIGNALS}
    write_dataset(folder, Dataset(None, exps, inst),
                  {"time": "ms", "plunger.s": "mm", "latch.s": "mm"})
    return folder


def effect_floors(effect, value, coils=COILS):
    """RMS change the hidden effect makes to the sampled positions (on the
    truth's own sampling grid, the nominal run held at its trip state past
    its trip), in noise floors."""
    floor = np.sqrt(NOISE ** 2 + RESOLUTION ** 2 / 12)
    diffs = []
    for coil in coils:
        segs, t_trip = simulate(coil, effect, value)
        segs0, t0 = simulate(coil)
        t = _grid(t_trip)
        diffs.append((sample(segs, t) - sample(segs0, np.minimum(t, t0))).ravel())
    return float(np.sqrt(np.mean(np.concatenate(diffs) ** 2)) / floor)
