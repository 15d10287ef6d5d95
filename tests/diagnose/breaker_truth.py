"""The breaker (models/breaker_24kv.py) with the blind cases' hidden
effects, compiled by acausal: the reference the independent simulator
(tests/diagnose/breaker_scipy.py, which writes the blind cases' data) is
checked against in tests/diagnose/test_breaker_scipy.py. Until 2026-11-23
it also wrote those data; it is not independent: the effects are laws of
the mechanics library's generic sources (``Torque``/``Force`` with a law
written in this file, never the diagnosis library's hypothesis code), so
it shares the compiler and the component library with the model.

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
"""
import os

import sympy as sp

from acausal.compiler.pipeline import compile_model
from acausal.mechanics.rotational import Torque
from acausal.mechanics.translational import Force
from acausal.modelfile import compile_file, load_model_file

HERE = os.path.dirname(os.path.abspath(__file__))
BREAKER = os.path.abspath(os.path.join(HERE, "..", "..", "models", "breaker_24kv.py"))
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
