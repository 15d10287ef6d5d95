"""A rigid pendulum from planar parts: a pin (Revolute) at the origin, a
massless rod (FixedTranslation) of length L and a bob (Body, mass m,
inertia I about its centre) under gravity g along -y.

    ground o  pin
            \\   rod L (angle phi from world x; hanging: phi = -pi/2)
             \\
              O bob (m, I)

With theta = phi + pi/2 (angle from the downward vertical):
``(I + m L^2) theta'' = -m g L sin(theta)``; small-angle period
``T0 = 2 pi sqrt((I + m L^2) / (m g L))``, exact period
``4 sqrt((I + m L^2) / (m g L)) K(sin(theta0 / 2)^2)`` (K the complete
elliptic integral of the first kind, parameter m = k^2).
"""
import math

import numpy as np

from acausal import Experiment, Model
from acausal.mechanics.planar.joints import Revolute
from acausal.mechanics.planar.parts import Body, Fixed, FixedTranslation

L, M, I, G = 0.4, 1.2, 2e-3, 9.81      # [m], [kg], [kg m^2], [m/s^2]
THETA0 = 1.2                           # release angle from the vertical [rad]


def small_angle_period(l=L, m=M, i=I, g=G):
    """T0 [s] of the compound pendulum."""
    return 2 * math.pi * math.sqrt((i + m * l**2) / (m * g * l))


def build(theta0=THETA0, l=L, m=M, i=I, g=G):
    """The pendulum released at rest ``theta0`` [rad] from the vertical (a
    run-time parameter of the model: ``params={"theta0": ...}``)."""
    model = Model()
    th0 = model.parameter("theta0", theta0, "rad", "release angle from the vertical")
    model.ground = Fixed()
    model.pin = Revolute(phi=th0 - math.pi / 2, w=0.0)
    model.rod = FixedTranslation(rx=l, ry=0.0)
    model.bob = Body(m=m, I=i, g=g)
    model.connect(model.ground.frame, model.pin.frame_a)
    model.connect(model.pin.frame_b, model.rod.frame_a)
    model.connect(model.rod.frame_b, model.bob.frame)
    return model


def period(res):
    """Mean period [s] from the upward zero crossings of theta (linear
    interpolation between output points: theta'' = 0 there)."""
    th = np.asarray(res["pin.phi"]) + math.pi / 2
    t = np.asarray(res.t)
    k = np.flatnonzero((th[:-1] < 0) & (th[1:] >= 0))
    tc = t[k] - th[k] * (t[k + 1] - t[k]) / (th[k + 1] - th[k])
    return float((tc[-1] - tc[0]) / (len(tc) - 1)) if len(tc) > 1 else float("nan")


model = build()
experiment = Experiment(t_end=3.0, rtol=1e-10, atol=1e-12, output_step=1e-3)
measures = {"period_s": period,
            "small_angle_period_s": lambda res: small_angle_period()}
