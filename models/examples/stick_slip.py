"""Stick-slip: a block on a table, pulled through a spring whose far end
moves at constant speed V (the classic model of squeal, chatter and jerky
sliding in slow mechanisms).

    driver (s = V t) --/\\/\\/\\-- [block m] on the table (Coulomb friction)

The friction levels are given in normal-force form, F_c = mu_k N and
F_s = mu_s N with N = m g (model parameters, so a sweep can vary them;
N does not follow block.m: set both).

Closed form (omega = sqrt(k/m)): the block sticks until the spring force
reaches F_s, at t = F_s/(k V) for the first time. It then slides, harmonic
about the kinetic equilibrium stretch F_c/k, until its velocity returns to
zero: slip time ``(2 pi - 2 atan(omega (F_s - F_c) / (k V))) / omega``. The
stretch has then dropped to (2 F_c - F_s)/k, so the block dwells stuck for
``2 (F_s - F_c) / (k V)``; period = slip + dwell. :func:`closed_form`
returns these; the measures take them from the simulated events.
"""
import math

import numpy as np

from acausal import Experiment, Measure, Model, time
from acausal.mechanics.friction import GroundFriction
from acausal.mechanics.translational import Mass, Position, Spring

M, K, V, MU_K, MU_S, G = 1.0, 200.0, 0.05, 0.4, 0.6, 9.81

model = Model()
speed = model.parameter("V", V, "m/s", "driver speed", min=0.0, min_open=True)
mu_k = model.parameter("mu_k", MU_K, "1", "kinetic friction coefficient", min=0.0)
mu_s = model.parameter("mu_s", MU_S, "1", "static friction coefficient", min=0.0)
normal = model.parameter("N", M * G, "N", "normal force (block weight)", min=0.0)
model.block = Mass(m=M, s=0.0, v=0.0)
model.spring = Spring(c=K)
model.driver = Position(s=speed * time)
model.friction = GroundFriction(F_c=mu_k * normal, F_s=mu_s * normal)
model.connect(model.driver.flange, model.spring.flange_b)
model.connect(model.spring.flange_a, model.block.flange, model.friction.flange)

experiment = Experiment(t_end=3.0, rtol=1e-9, atol=1e-11, output_step=1e-3)


def closed_form(m=M, k=K, v=V, mu_k=MU_K, mu_s=MU_S, n=M * G):
    """First break-away time, slip time, stick dwell and period [s]."""
    fc, fs = mu_k * n, mu_s * n
    w = math.sqrt(k / m)
    slip = (2 * math.pi - 2 * math.atan(w * (fs - fc) / (k * v))) / w
    dwell = 2 * (fs - fc) / (k * v)
    return dict(first_break=fs / (k * v), slip=slip, dwell=dwell, period=slip + dwell)


def _times(res, name):
    return np.array([t for t, n in res.events if n == f"friction.{name}"])


def _period(res):
    brk = _times(res, "break_forward")
    return float(np.mean(np.diff(brk))) if len(brk) >= 2 else float("nan")


def _dwell(res):
    brk, stp = _times(res, "break_forward"), _times(res, "slide_stop")
    gaps = [b - s for s in stp for b in brk[brk > s][:1]]
    return float(np.mean(gaps)) if gaps else float("nan")


def _slip(res):
    brk, stp = _times(res, "break_forward"), _times(res, "slide_stop")
    runs = [s - b for b in brk for s in stp[stp > b][:1]]
    return float(np.mean(runs)) if runs else float("nan")


measures = {
    "period": Measure(_period, "s", desc="stick-slip period"),
    "dwell": Measure(_dwell, "s", desc="time stuck per cycle"),
    "slip_time": Measure(_slip, "s", desc="time sliding per cycle"),
    "first_break": Measure(lambda res: float(_times(res, "break_forward")[0]), "s"),
    "max_speed": Measure(lambda res: float(np.max(res["block.v"])), "m/s"),
}
