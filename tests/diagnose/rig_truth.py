"""An independent simulator of the torsion rig (tests/diagnose/torsion_rig.py),
written directly with scipy (no code of the project's model), with hidden
effects the diagnosis must find:

    J phi'' = -tau_spring(phi) - d phi' - tau_extra(phi, phi')

* ``hardening``: tau_spring = c phi + k3 phi^3 (the library's
  hardening_spring law, amplitude-dependent frequency);
* ``dead_band``: the spring's attachment has a play of +-b, tau_spring =
  c * sign(phi) * max(|phi| - b, 0) (no library hypothesis acts there);
* ``coulomb``: tau_extra = F sign(phi') (dry friction at the bearing,
  regularised over 1e-4 rad/s);
* ``drag``: tau_extra = c2 phi'|phi'| (quadratic drag);
* ``threshold``: tau_extra = F_t sign(phi') min(max(|phi'| - W_T, 0) / W_T, 1)
  (a torque that sets in above the speed W_T: no library law);

several at once as a dict {effect: value}.

The angle is sampled at ``rate`` Hz, Gaussian noise added, rounded to the
encoder's resolution, and written in the dataset format.
"""
import numpy as np
from scipy.integrate import solve_ivp

from acausal.data import Dataset, MeasuredExperiment, Instrument, Trace, write_dataset

J, C, D = 1e-3, 4.0, 1.5e-3     # the rig's nominal inertia, stiffness and damping
T_END, RATE = 1.6, 2000.0
NOISE, RESOLUTION = 5e-4, 2e-4  # rad
W_T = 10.0                      # speed at which the threshold torque sets in [rad/s]


def _effects(effect, value):
    """{name: value}: one effect by name, or several as a dict."""
    if isinstance(effect, dict):
        return effect
    return {} if effect is None else {effect: value}


def spring_torque(phi, c, eff):
    if "dead_band" in eff:
        tau = c * np.sign(phi) * np.maximum(np.abs(phi) - eff["dead_band"], 0.0)
    else:
        tau = c * phi
    return tau + eff.get("hardening", 0.0) * phi ** 3


def extra_torque(w, eff):
    tau = eff.get("coulomb", 0.0) * np.tanh(w / 1e-4) + eff.get("drag", 0.0) * w * abs(w)
    if "threshold" in eff:
        tau += eff["threshold"] * np.sign(w) * min(max(abs(w) - W_T, 0.0) / W_T, 1.0)
    return tau


def simulate(phi0, effect=None, value=0.0, c=C, d=D, t=None):
    t = np.arange(0.0, T_END + 1e-12, 1.0 / RATE) if t is None else t
    eff = _effects(effect, value)

    def rhs(_, y):
        phi, w = y
        return [w, -(spring_torque(phi, c, eff) + d * w + extra_torque(w, eff)) / J]

    sol = solve_ivp(rhs, (0.0, t[-1]), [phi0, 0.0], t_eval=t, method="DOP853",
                    rtol=1e-11, atol=1e-13, max_step=2e-4)
    return t, sol.y[0]


def write(folder, effect=None, value=0.0, starts=(0.3, 0.4, 0.5), seed=0, c=C, d=D):
    """Write a dataset of the rig released from each of ``starts``."""
    rng = np.random.default_rng(seed)
    exps = []
    for i, phi0 in enumerate(starts):
        t, phi = simulate(phi0, effect, value, c, d)
        y = phi + rng.normal(0.0, NOISE, phi.shape)
        y = RESOLUTION * np.round(y / RESOLUTION)
        exps.append(MeasuredExperiment(f"R{i + 1}", {"phi_start": float(phi0)}, {},
                               Trace(t, {"rotor.phi": y})))
    inst = {"rotor.phi": Instrument("rotor.phi", RESOLUTION, NOISE)}
    write_dataset(folder, Dataset(None, exps, inst), {"time": "ms", "rotor.phi": "deg"})
    return folder


def effect_floors(effect, value, starts=(0.3, 0.4, 0.5)):
    """RMS change the hidden effect makes to the angle, in noise floors."""
    floor = np.sqrt(NOISE ** 2 + RESOLUTION ** 2 / 12)
    diffs = [simulate(p, effect, value)[1] - simulate(p)[1] for p in starts]
    return float(np.sqrt(np.mean(np.concatenate(diffs) ** 2)) / floor)
