"""Independent truth of the cam follower (``cam_follower.py``), written by
hand with scipy (``truth_core``): no code of acausal. The generalised
coordinate is the cam angle q; the follower's lift is s = e (1 - cos q),
so with the cam's inertia J and the follower's mass m

    M(q) = J + m e^2 sin^2 q,
    Q    = -d q' - e sin q * c (s + PRELOAD / c)    (bearing, spring)

Sites where a hidden law can act: ``cam`` (x = q, r = 1: the cam's
bearing) and ``follower`` (x = s, r = e sin q: the follower's guide).
"""
import numpy as np

try:
    from . import truth_core
except ImportError:                      # imported as a top-level module by the tests
    import truth_core

J, M_F, E = 1e-3, 0.2, 5e-3          # cam inertia, follower mass, eccentricity
C, D = 2000.0, 2e-5                  # spring rate [N/m], bearing viscous [N m s/rad]
PRELOAD = 20.0                       # spring force at zero lift [N] (s_rel0 = -0.01 m)
T_END, RATE = 2.0, 500.0
CONDITIONS = [{"w0": 12.0}, {"w0": 20.0}, {"w0": 35.0}]
SIGNALS = ("cam.phi", "follower.s")
NOISE = {"cam.phi": 2e-3, "follower.s": 5e-6}
RESOLUTION = {"cam.phi": 2 * np.pi / 4096, "follower.s": 1e-6}
MODEL = "cam_follower.py"
FREE = {"spring.c": C, "bearing.d": D}
NODES = {"cam": ("cam",), "follower": ("follower",)}   # site -> the diagnosis's nodes there


def lift(q):
    return E * (1.0 - np.cos(q))


def mechanism(free=None):
    c, d = (free or {}).get("spring.c", C), (free or {}).get("bearing.d", D)

    def inertia(q):
        s = np.sin(q)
        return J + M_F * E * E * s * s, 2.0 * M_F * E * E * s * np.cos(q)

    def nominal(q, w, t):
        return -d * w - E * np.sin(q) * (c * lift(q) + PRELOAD * c / C)

    sites = {"cam": (lambda q: q, lambda q: 1.0),
             "follower": (lift, lambda q: E * np.sin(q))}
    return truth_core.Mechanism(inertia, nominal, sites)


def times():
    return np.arange(0.0, T_END + 1e-12, 1.0 / RATE)


def run(cond, laws=(), free=None, t=None):
    """{signal: samples} of one experiment at the times ``t``, and its events."""
    t = times() if t is None else t
    q, w, events = truth_core.simulate(mechanism(free), 0.0, cond["w0"], t, laws)
    return {"time": t, "cam.phi": q, "follower.s": lift(q), "cam.w": w}, events


def contact_margin(cond, laws=(), free=None):
    """The smallest contact force between cam and follower over the run [N]
    (the model assumes permanent contact: it must stay positive).
    N = spring force + m s'' + the follower site's laws' reaction."""
    t = np.linspace(0.0, T_END, 20001)
    out, _ = run(cond, laws, free, t)
    s = out["follower.s"]
    sdd = np.gradient(np.gradient(s, t), t)
    c = (free or {}).get("spring.c", C)
    return float(np.min(c * s + PRELOAD * c / C + M_F * sdd))
