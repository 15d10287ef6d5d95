"""An independent simulator of the 24 kV breaker (models/breaker_24kv.py),
written from the research report's equations (docs/breaker_model.md
section 2) with scipy. It imports nothing of the project's compiler, model
file or component library, so a bug there shows as a disagreement with
this file (tests/diagnose/test_breaker_scipy.py) and cannot hide in the
blind cases' data. The hidden effects are those of breaker_truth.py; it
offers what tests/diagnose/blind.py's runner needs (``write``,
``effect_floors``) and ``simulate``.

Sign convention: docs/breaker_model.md section 1 (the report's own). The
armature's position s starts at GAP0 and moves along -s at v_impact; the
hook angle theta1 starts at 0 and falls to -Ra at release; the main shaft's
angle theta3 follows theta1 through the four-bar (cam and roller)::

    armature (s, v) --contact--> hook (theta1, w) ==four-bar==> main shaft (theta3)
    indentation delta = s3 theta1 - s   (> 0 in contact)

State y = [s, v, theta1, w]. The four-bar is massless and rigid, so the
main shaft is reduced onto the hook by virtual work (R = dtheta3/dtheta1,
R' = dR/dtheta1)::

    ma v' = -Fe + F - ka (s - GAP0) + f_armature(s)
    (Jh + Js R^2) w' + Js R R' w^2 = -s3 F - kh s4^2 theta1 - bh w + R Ts + tau_hook(w)
    Ts = -[s1 Fo0 + s2 Fw0 + (ko s1^2 + kw s2^2)(theta3 - theta3_0)]

theta3(theta1) is the report's closed form (eqs. 5 to 10, assembly mode
"+", theta3 = lambda - phi); R is its derivative by a complex step,
R' a central difference of R. Contact (report eqs. 1-2): while delta > 0,
F = K delta^1.5 (1 + chi delta'/v_i), chi = 3 (1 - e^2)/4 (Lankarani-
Nikravesh) or 3 (1 - e)/2 (Hunt-Crossley), v_i = max(delta' at the
impact's onset, 1e-4). Onset (delta rising through 0), separation (delta
falling through 0) and pull-off (the damping factor falling through 0) are
events of the integration; each contact mode is integrated on its own
(Radau between events), and the run stops when theta1 reaches -Ra.

Hidden effects (several at once as a dict {effect: value}):

* ``hook_drag``: tau_hook += -c w|w|;
* ``hook_coulomb``: tau_hook += -T tanh(w/1e-3);
* ``hook_threshold``: tau_hook += -T tanh(w/1e-3) min(max(|w| - W_T, 0)/W_T, 1);
* ``coil_slope``: f_armature += k (s - GAP0) (grows with the stroke, along
  the motion for k > 0);
* ``hunt_crossley``: the contact's damping follows Hunt-Crossley with the
  restitution ``value`` instead of Lankarani-Nikravesh with 0.74.
"""
import math

import numpy as np
from scipy.integrate import solve_ivp

# Table 1 of the report and the model file's assumed values
MA, KA, FE = 0.22, 0.013, 160.0                 # armature [kg, N/m, N]
JH, BH, S3, S4, KH = 0.00044, 0.219, 0.055, 0.058, 714.0   # hook
JS, KO, KW, S1, S2, FO0, FW0 = 0.05, 7.0e4, 2.4e5, 0.091, 0.091, 5600.0, 9000.0  # main shaft
E_CAM, F_AO, R1, R2, R3 = 0.0002, 0.125, 0.116, 0.036, 0.0533    # four-bar [m]
K_CAL, E_REST, GAMMA, V_MIN = 6.17e8, 0.74, 1.5, 1e-4             # contact
RA = math.radians(5.0)
GAP0 = 1e-6
W_T = 40.0
V_IMPACT = (3.3, 3.5, 3.8, 4.0, 4.2, 4.5)
RATE = 50e3
NOISE = {"hook.phi": 5e-5, "armature.mass.s": 2e-6}
RESOLUTION = {"hook.phi": 4.8e-5, "armature.mass.s": 1e-6}
SIGNALS = ("hook.phi", "armature.mass.s")
STATE = {"armature.mass.s": 0, "armature.mass.v": 1, "hook.phi": 2, "hook.body.w": 3}  # y's order


def _theta3(t1):
    """theta3(theta1), the report's closed form (eqs. 5-10, mode "+"); it
    takes complex angles (atan written for x_D > 0, which holds: f >> e)."""
    xd, yd = F_AO - E_CAM * np.cos(t1), E_CAM * np.sin(t1)
    d = np.sqrt(xd ** 2 + yd ** 2)
    return np.arccos((d ** 2 + R1 ** 2 - (R2 + R3) ** 2) / (2 * R1 * d)) - np.arctan(yd / xd)


def _ratio(t1):
    """R = dtheta3/dtheta1 by a complex step (exact to round-off)."""
    return float(np.imag(_theta3(complex(t1, 1e-30)))) / 1e-30


def _fourbar():
    """theta3(theta1), R and R' = dR/dtheta1 (a central difference of the
    exact R; its error, about 1e-10 relative, is far below the tests')."""
    h = 1e-5
    return (lambda t: float(_theta3(t)), _ratio,
            lambda t: (_ratio(t + h) - _ratio(t - h)) / (2 * h))


def _effects(effect, value):
    if isinstance(effect, dict):
        return dict(effect)
    return {} if effect is None else {effect: value}


def _hook_torque(w, eff):
    tau = 0.0
    if "hook_drag" in eff:
        tau -= eff["hook_drag"] * w * abs(w)
    if "hook_coulomb" in eff:
        tau -= eff["hook_coulomb"] * math.tanh(w / 1e-3)
    if "hook_threshold" in eff:
        ramp = min(max(abs(w) - W_T, 0.0) / W_T, 1.0)
        tau -= eff["hook_threshold"] * math.tanh(w / 1e-3) * ramp
    return tau


class _Breaker:
    """The right-hand side for one contact mode (``v_i`` None: no force)."""

    def __init__(self, eff, K, bh):
        self.eff, self.K, self.bh = eff, K, bh
        law_e = eff.get("hunt_crossley")
        self.chi = (3 * (1 - law_e) / 2 if law_e is not None
                    else 3 * (1 - E_REST ** 2) / 4)
        self.th3, self.R, self.dR = _fourbar()
        self.th3_0 = self.th3(0.0)

    def force(self, y, v_i):
        s, v, th1, w = y
        delta, ddelta = S3 * th1 - s, S3 * w - v
        if v_i is None or delta <= 0.0:
            return 0.0
        return self.K * delta ** GAMMA * (1.0 + self.chi * ddelta / v_i)

    def rhs(self, t, y, v_i):
        s, v, th1, w = y
        F = self.force(y, v_i)
        fa = self.eff.get("coil_slope", 0.0) * (s - GAP0)
        a = (-FE + F - KA * (s - GAP0) + fa) / MA
        R, dR = self.R(th1), self.dR(th1)
        Ts = -(S1 * FO0 + S2 * FW0 + (KO * S1 ** 2 + KW * S2 ** 2) * (self.th3(th1) - self.th3_0))
        tau = -S3 * F - KH * S4 ** 2 * th1 - self.bh * w + R * Ts + _hook_torque(w, self.eff)
        return [v, a, w, (tau - JS * R * dR * w * w) / (JH + JS * R * R)]


def _event(fn, direction, terminal=True):
    fn.direction, fn.terminal = direction, terminal
    return fn


def _segment(b, t0, y0, v_i, t_end, rtol):
    """Integrate one mode from (t0, y0) until its first event; returns the
    solution and which event ended it (None: t_end)."""
    delta = _event(lambda t, y, *a: S3 * y[2] - y[0], 1.0 if v_i is None else -1.0)
    release = _event(lambda t, y, *a: y[2] + RA, -1.0)
    events = [delta, release]
    if v_i is not None:
        events.append(_event(lambda t, y, *a: 1.0 + b.chi * (S3 * y[3] - y[1]) / v_i, -1.0))
    sol = solve_ivp(b.rhs, (t0, t_end), y0, method="Radau", args=(v_i,), events=events,
                    rtol=rtol, atol=[1e-14, 1e-11, 1e-13, 1e-10], dense_output=True)
    names = ("delta", "release", "pull_off")
    hit = [(ev[0], names[i]) for i, ev in enumerate(sol.t_events) if len(ev)]
    return sol, (min(hit) if hit else (None, None))


class Run:
    """A simulated run: ``t``, and the signals by name (``run["hook.phi"]``)."""

    def __init__(self, pieces):
        self.pieces = pieces
        self.t = np.concatenate([p.t for p in pieces])
        self.y = np.concatenate([p.y for p in pieces], axis=1)
        self.t_release = self.t[-1]

    def __getitem__(self, name):
        return self.y[STATE[name]]

    def at(self, times, name):
        """``name`` at ``times`` from each segment's dense output."""
        idx = STATE[name]
        out = np.empty(len(times))
        for i, t in enumerate(times):
            p = next((q for q in self.pieces if t <= q.t[-1]), self.pieces[-1])
            out[i] = p.sol(min(t, p.t[-1]))[idx]
        return out


def simulate(v, effect=None, value=None, K=K_CAL, bh=BH, rtol=1e-10, t_end=0.02):
    """The run at impact speed ``v`` [m/s] with the hidden effects, from
    1 um before the first contact to the release."""
    b = _Breaker(_effects(effect, value), K, bh)
    t, y, v_i, pieces = 0.0, np.array([GAP0, -float(v), 0.0, 0.0]), None, []
    while t < t_end:
        sol, (t_ev, what) = _segment(b, t, y, v_i, t_end, rtol)
        pieces.append(sol)
        if what is None or what == "release":
            break
        t, y = t_ev, sol.sol(t_ev)
        if what == "delta" and v_i is None:
            v_i = max(S3 * y[3] - y[1], V_MIN)      # onset: the approach speed
        else:
            v_i = None                              # separation or pull-off
    return Run(pieces)


def _grid(run):
    return np.arange(0.0, run.t_release + 1e-15, 1.0 / RATE)


def write(folder, effect=None, value=None, seed=0, speeds=V_IMPACT):
    """Write a dataset: one experiment per impact speed, both signals traced
    (acausal's dataset format; the writer is the project's, the data are not)."""
    from acausal.data import Dataset, MeasuredExperiment, Instrument, Trace, write_dataset
    rng = np.random.default_rng(seed)
    exps = []
    for i, v in enumerate(speeds):
        run = simulate(v, effect, value)
        t = _grid(run)
        cols = {}
        for s in SIGNALS:
            z = run.at(t, s) + rng.normal(0.0, NOISE[s], t.shape)
            cols[s] = RESOLUTION[s] * np.round(z / RESOLUTION[s])
        exps.append(MeasuredExperiment(f"B{i + 1}", {"v_impact": float(v)}, {}, Trace(t, cols)))
    inst = {s: Instrument(s, RESOLUTION[s], NOISE[s]) for s in SIGNALS}
    write_dataset(folder, Dataset(None, exps, inst),
                  {"time": "ms", "hook.phi": "deg", "armature.mass.s": "mm"})
    return folder


def effect_floors(effect, value, speeds=V_IMPACT):
    """RMS change the hidden effect makes to the sampled signals, in noise
    floors (on the truth's grid; the nominal run held at its release state)."""
    acc = []
    for v in speeds:
        run, ref = simulate(v, effect, value), simulate(v)
        t = _grid(run)
        tr = np.minimum(t, ref.t_release)
        for s in SIGNALS:
            floor = np.sqrt(NOISE[s] ** 2 + RESOLUTION[s] ** 2 / 12)
            acc.append((run.at(t, s) - ref.at(tr, s)) / floor)
    return float(np.sqrt(np.mean(np.concatenate(acc) ** 2)))
