"""Independent truth of the geared drive (``geared_drive.py``), written by
hand with scipy (``truth_core``): no code of acausal. The generalised
coordinate is the load angle q; the motor turns N q (gear ratio N), so

    M = J_L + N^2 J_m,    Q = N tau_m - c q - d q'

Sites where a hidden law can act: ``load`` (x = q, r = 1: the output
bearing) and ``motor`` (x = N q, r = N: the motor's bearing, where a
cogging torque of the motor's poles acts).
"""
import numpy as np

try:
    from . import truth_core
except ImportError:
    import truth_core

J_M, J_L, N = 2e-4, 5e-3, 5.0
C, D = 2.0, 2e-3
T_END, RATE = 3.0, 500.0
CONDITIONS = [{"tau_m": 0.05}, {"tau_m": 0.1}, {"tau_m": 0.2}]
SIGNALS = ("load.phi",)
NOISE = {"load.phi": 1e-3}
RESOLUTION = {"load.phi": 2 * np.pi / 8192}
MODEL = "geared_drive.py"
FREE = {"spring.c": C, "bearing.d": D}
NODES = {"load": ("load", "motor"), "motor": ("motor", "load")}   # tied by the gear


def mechanism(tau_m, free=None):
    c, d = (free or {}).get("spring.c", C), (free or {}).get("bearing.d", D)

    def inertia(q):
        return J_L + N * N * J_M, 0.0

    def nominal(q, w, t):
        return N * tau_m - c * q - d * w

    sites = {"load": (lambda q: q, lambda q: 1.0),
             "motor": (lambda q: N * q, lambda q: N)}
    return truth_core.Mechanism(inertia, nominal, sites)


def times():
    return np.arange(0.0, T_END + 1e-12, 1.0 / RATE)


def run(cond, laws=(), free=None, t=None):
    t = times() if t is None else t
    q, w, events = truth_core.simulate(mechanism(cond["tau_m"], free), 0.0, 0.0, t, laws)
    return {"time": t, "load.phi": q, "motor.phi": N * q, "load.w": w}, events
