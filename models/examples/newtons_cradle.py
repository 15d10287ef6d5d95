"""Newton's cradle: N equal steel balls in a row joined by undamped Hertz
contacts; the first ball hits the resting chain at 1 m/s.

``N`` (default 5) is read from the environment variable ``CRADLE_N``;
``build(n, spacing=0.0)`` builds any variant. Ball k is ``ball{k}``
(k = 0 .. n-1), the contact between ball k and ball k+1 is ``c{k}``.
The resting balls touch (``spacing = 0``: those contacts start closed with
zero force); ball 0 starts 1 mm away.

Exact: the total momentum m * v0 and (restitution 1) the kinetic energy are
conserved. With touching balls most of the momentum ends in the last ball
and the others keep small velocities (Hertz dispersion); with a spacing much
larger than the indentation (about 20 um here) the impacts are separate
binary exchanges and the last ball leaves with exactly v0.
"""
import math
import os

from acausal import Experiment, Measure, Model
from acausal.mechanics.contact import Contact, hertz_stiffness
from acausal.mechanics.translational import Mass

N = int(os.environ.get("CRADLE_N", "5"))
R = 0.01            # ball radius [m]
RHO = 7850.0        # steel density [kg/m^3]
E, NU = 2.1e11, 0.3  # Young's modulus [Pa], Poisson ratio
V0 = 1.0            # impact velocity of ball 0 [m/s]
M = RHO * 4.0 / 3.0 * math.pi * R ** 3   # 0.0329 kg
K = hertz_stiffness(R, R, E, E, NU, NU)   # 1.09e10 N/m^1.5


def build(n=N, spacing=0.0, e=1.0):
    """The cradle with ``n`` balls, ``spacing`` [m] between resting balls."""
    if n < 2:
        raise ValueError(f"newtons_cradle: n = {n} must be at least 2")
    model = Model()
    for k in range(n):
        s0 = -2 * R - 1e-3 if k == 0 else (k - 1) * (2 * R + spacing)
        model.add(f"ball{k}", Mass(m=M, s=s0, v=V0 if k == 0 else 0.0))
    for k in range(n - 1):
        c = model.add(f"c{k}", Contact(K=K, gamma=1.5, e=e, gap=2 * R))
        model.connect(getattr(model, f"ball{k}").flange, c.flange_a)
        model.connect(c.flange_b, getattr(model, f"ball{k + 1}").flange)
    return model


def momentum(res, n=N):
    """Total momentum [kg m/s] over the result."""
    return sum(M * res[f"ball{k}.v"] for k in range(n))


def energy(res, n=N):
    """Kinetic energy [J] over the result (the contact energy is excluded)."""
    return sum(0.5 * M * res[f"ball{k}.v"] ** 2 for k in range(n))


model = build(N)

experiment = Experiment(t_end=3e-3, rtol=1e-10, atol=1e-13, output_step=1e-5)

measures = {
    "momentum_error": Measure(lambda res: float(abs(momentum(res) - M * V0).max() / (M * V0)),
                              "1"),
    "energy_error": Measure(lambda res: float(abs(energy(res)[-1] - 0.5 * M * V0 ** 2)
                                              / (0.5 * M * V0 ** 2)), "1"),
    "v_last": Measure(lambda res: res.final()[f"ball{N - 1}.v"], "m/s"),
    "v_first": Measure(lambda res: res.final()["ball0.v"], "m/s"),
}
