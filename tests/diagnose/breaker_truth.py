"""Truth generator for blind cases on the breaker (models/breaker_24kv.py).

NOT an independent simulator: an independent scipy truth of the breaker
(armature, contact events, hook, four-bar and main shaft) was not written
this session. The truth is the project's model file plus hidden effects
written here, in the test folder, as laws of the mechanics library's
generic sources (``Torque``/``Force`` with a law written in this file),
never with the diagnosis library's hypothesis code
(acausal/diagnose/hypotheses.py); the Hunt-Crossley case switches the
model's contact from its Lankarani-Nikravesh damping to the Hunt-Crossley
law. It therefore shares the compiler and the component library with the
model it tests, and a bug there would not be caught by these cases.

Hidden effects (several at once as a dict {effect: value}):

* ``hook_drag``: tau = -c w|w| on the hook (quadratic drag);
* ``hook_coulomb``: tau = -T tanh(w/1e-3) on the hook (dry friction);
* ``coil_slope``: the solenoid's force grows with the stroke: f = k (s - s0)
  on the armature along +s (the armature moves along -s, so k > 0 adds force
  along the motion);
* ``hook_threshold``: tau = -T_t tanh(w/1e-3) min(max(|w| - W_T, 0) / W_T, 1) on
  the hook, a torque that sets in above the speed W_T (no library law);
* ``hunt_crossley``: the contact's damping follows Hunt-Crossley
  (chi = 3 (1 - e) / 2) instead of the model's Lankarani-Nikravesh (value:
  the restitution e of the truth's law).

The hook angle and the armature's position are sampled at RATE Hz from the
first contact to the release, Gaussian noise added and rounded to the
sensors' resolution: a finer instrument than tests/diagnose/test_diagnose.py's
breaker set-up, so that effects within the library's bounds reach 50 floors.
"""
import os

import numpy as np
import sympy as sp

from acausal.compile import compile_model
from acausal.data import Dataset, Experiment, Instrument, Trace, write_dataset
from acausal.mechanics.rotational import Torque
from acausal.mechanics.translational import Force
from acausal.modelfile import compile_file, load_model_file

HERE = os.path.dirname(os.path.abspath(__file__))
BREAKER = os.path.abspath(os.path.join(HERE, "..", "..", "models", "breaker_24kv.py"))
V_IMPACT = (3.3, 3.5, 3.8, 4.0, 4.2, 4.5)
RATE = 50e3
# a 17-bit encoder on the hook (4.8e-5 rad counts) and a 1 um travel sensor
NOISE = {"hook.phi": 5e-5, "armature.mass.s": 2e-6}
RESOLUTION = {"hook.phi": 4.8e-5, "armature.mass.s": 1e-6}
SIGNALS = ("hook.phi", "armature.mass.s")
W_T = 40.0          # hook speed at which the threshold torque sets in [rad/s]
GAP0 = 1e-6         # the armature's start position (models/breaker_24kv.py)
_CACHE = {}


def _effects(effect, value):
    if isinstance(effect, dict):
        return effect
    return {} if effect is None else {effect: value}


def _threshold(w, T):
    ramp = sp.Min(sp.Max(sp.Abs(w) - W_T, 0) / W_T, 1)
    return -T * sp.tanh(w / 1e-3) * ramp


def _add(m, eff):
    """Add the hidden effects to the breaker model ``m`` in place."""
    w = m.hook.body.w
    tau = 0
    if "hook_drag" in eff:
        tau += -eff["hook_drag"] * w * sp.Abs(w)
    if "hook_coulomb" in eff:
        tau += -eff["hook_coulomb"] * sp.tanh(w / 1e-3)
    if "hook_threshold" in eff:
        tau += _threshold(w, eff["hook_threshold"])
    if tau != 0:
        m.truth_torque = Torque(tau=tau)
        m.connect(m.truth_torque.flange, m.hook.body.flange)
    if "coil_slope" in eff:
        m.truth_force = Force(f=eff["coil_slope"] * (m.armature.mass.s - GAP0))
        m.connect(m.truth_force.flange, m.armature.mass.flange)
    if "hunt_crossley" in eff:
        m.contact.set(law="hunt_crossley", e=eff["hunt_crossley"])


def truth_model(effect=None, value=None):
    """(ModelFile, CompiledModel) of the breaker with the hidden effects."""
    eff = _effects(effect, value)
    if not eff:               # the model file as every command compiles it (shared)
        return compile_file(BREAKER)
    key = repr(sorted(eff.items()))
    if key not in _CACHE:
        mf = load_model_file(BREAKER)
        _add(mf.model, eff)
        mf.model.event(mf.experiment.stop.event(mf.model))
        _CACHE[key] = (mf, compile_model(mf.model))
    return _CACHE[key]


def simulate(v, effect=None, value=None, backend=None):
    mf, cm = truth_model(effect, value)
    opts = mf.experiment.run_options(dense=True)
    opts.update(rtol=1e-10, atol=1e-13)
    return cm.simulate(params={"v_impact": float(v)}, backend=backend, **opts)


def _grid(res):
    return np.arange(0.0, res.t[-1] + 1e-15, 1.0 / RATE)


def write(folder, effect=None, value=None, seed=0, speeds=V_IMPACT):
    """Write a dataset: one experiment per impact speed, both signals traced."""
    rng = np.random.default_rng(seed)
    exps = []
    for i, v in enumerate(speeds):
        res = simulate(v, effect, value)
        t = _grid(res)
        cols = {}
        for s in SIGNALS:
            z = np.interp(t, res.t, res[s]) + rng.normal(0.0, NOISE[s], t.shape)
            cols[s] = RESOLUTION[s] * np.round(z / RESOLUTION[s])
        exps.append(Experiment(f"B{i + 1}", {"v_impact": float(v)}, {}, Trace(t, cols)))
    inst = {s: Instrument(s, RESOLUTION[s], NOISE[s]) for s in SIGNALS}
    write_dataset(folder, Dataset(None, exps, inst),
                  {"time": "ms", "hook.phi": "deg", "armature.mass.s": "mm"})
    return folder


def effect_floors(effect, value, speeds=V_IMPACT):
    """RMS change the hidden effect makes to the sampled signals (on the
    truth's grid; the nominal run held at its release state past its
    release), in noise floors."""
    acc = []
    for v in speeds:
        res, ref = simulate(v, effect, value), simulate(v)
        t = _grid(res)
        for s in SIGNALS:
            floor = np.sqrt(NOISE[s] ** 2 + RESOLUTION[s] ** 2 / 12)
            acc.append((np.interp(t, res.t, res[s]) - np.interp(t, ref.t, ref[s])) / floor)
    return float(np.sqrt(np.mean(np.concatenate(acc) ** 2)))
