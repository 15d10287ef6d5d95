"""The report's trigger cam and roller (section 2.4, Table 1) as a planar
four-bar built from bodies and joints, not from the closed form of
:mod:`acausal.mechanics.fourbar` (whose picture and angles it follows).

World frame = the report's: A (main shaft) at the origin, O (hook shaft) at
(f, 0)::

          C (roller centre)  coupler r2 + r3   D (cam-circle centre)
           o-----------------------------------o
          /  rocker r1                crank e  |
         /                                     |
    A   o  main shaft (Js, spring)        O    o  hook shaft (Jh)
    (0, 0)                                 (f, 0)

The loop is the shared sub-assembly
:class:`~acausal.mechanics.planar.linkages.FourBarLinkage` (``linkage``):

* hook: its Revolute at O (``linkage.pin_a``), angle psi1 = pi - theta1
  (theta1 the report's crank angle, clockwise), a Body with the hook
  inertia Jh on it and the crank e to D;
* main shaft: its Revolute at A (``linkage.pin_b``), angle psi3 = -theta3,
  a Body with Js, the rocker r1 to C;
* coupler: a Revolute at C (``linkage.pin_c``, angle theta2 + theta3), the
  link r2 + r3 and a Revolute at D (``linkage.pin_d``, angle
  theta1 + theta2 - pi) that closes the loop.

The main shaft carries the open and wipe springs as one preloaded torsion
spring on ``linkage.pin_b.axis`` (as models/examples/fourbar.py). Geometry and
starts are model parameters (``e``, ``f``, ``r1``, ``r2``, ``r3``,
``theta1_0``, ``w1_0``); the joint angles' start guesses follow them.
"""
import math

import sympy as sp

from acausal import Experiment, Model, Start, Stop
from acausal.mechanics import rotational as rot
from acausal.mechanics.planar.linkages import FourBarLinkage
from acausal.mechanics.planar.parts import Body

TABLE1 = dict(e=0.0002, f=0.125, r1=0.116, r2=0.036, r3=0.0533)   # [m]
JH, JS = 0.00044, 0.02              # hook (Table 1), main shaft (assumption) [kg m^2]
C_SHAFT = 7.0e4 * 0.091**2 + 2.4e5 * 0.091**2   # ko s1^2 + kw s2^2 [N m/rad]
PRELOAD = 0.035                     # [rad], as models/examples/fourbar.py
W_HOOK = 3.0                        # hook speed after the impact [rad/s]
RA = math.radians(5.0)              # release angle (Table 1)


def loop_angles(th1, e, f, r1, L, mode=1, lib=sp):
    """(theta2, theta3) closing the loop at ``th1`` (law of cosines in
    triangle A-C-D; ``mode`` +1: C on the clockwise side of AD). With sympy
    the cosine is clipped to [-1, 1], so that a loop that cannot close still
    gets start guesses (and the initialisation names the loop)."""
    dx, dy = f - e * lib.cos(th1), e * lib.sin(th1)
    d2 = dx**2 + dy**2
    cl = (d2 + r1**2 - L**2) / (2 * r1 * lib.sqrt(d2))
    lam = lib.acos(sp.Min(sp.Max(cl, -1), 1) if lib is sp else cl)
    th3 = mode * lam - lib.atan2(dy, dx)
    th2 = lib.atan2(dy + r1 * lib.sin(th3), dx - r1 * lib.cos(th3))
    return th2, th3


def build(geometry=TABLE1, theta1_0=0.0, w1_0=W_HOOK, jh=JH, js=JS, c=C_SHAFT,
          preload=PRELOAD, mode=1):
    """The four-bar with the hook at ``theta1_0`` [rad] turning at ``w1_0``
    [rad/s] (report's sense), the main shaft spring preloaded by ``preload``
    [rad] from the latched position (``c = 0``: free spin)."""
    m = Model()
    g = {k: m.parameter(k, v, "m", f"Table 1 {k}", min=0.0, min_open=True)
         for k, v in geometry.items()}
    th1 = m.parameter("theta1_0", theta1_0, "rad", "hook (crank) start angle")
    w1 = m.parameter("w1_0", w1_0, "rad/s", "hook start speed (theta1 sense)")
    L = g["r2"] + g["r3"]
    th3_latched = loop_angles(0.0, *(geometry[k] for k in ("e", "f", "r1")),
                              geometry["r2"] + geometry["r3"], mode, math)[1]
    # the shared sub-assembly: crank e at O = (f, 0), rocker r1 at A, its
    # assembly mode -mode in its own convention (C on the other side of B-D)
    m.linkage = FourBarLinkage(theta_a0=sp.pi - th1, mode=-mode, xa=g["f"], ya=0.0,
                               phia=0.0, xb=0.0, yb=0.0, phib=0.0, a=g["e"], b=g["r1"], c=L)
    m.linkage.pin_a.set(phi=sp.pi - th1, w=-w1)
    m.hook = Body(m=1.0, I=jh, phi=Start(sp.pi - th1, False))
    th3 = loop_angles(th1, g["e"], g["f"], g["r1"], L, mode)[1]
    m.shaft = Body(m=1.0, I=js, phi=Start(-th3, False))
    m.spring = rot.TorsionSpring(c=c, phi_rel0=-th3_latched + preload)
    m.spring_support = rot.Fixed()
    m.connect(m.linkage.crank, m.hook.frame)
    m.connect(m.linkage.rocker, m.shaft.frame)
    m.connect(m.spring_support.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.linkage.flange_b)
    return m


def report_angles(res):
    """theta1, theta2, theta3 [rad] (the report's) along a result."""
    th1 = math.pi - res["linkage.pin_a.phi"]
    th3 = -res["linkage.pin_b.phi"]
    return th1, res["linkage.pin_c.phi"] - th3, th3


model = build()
experiment = Experiment(t_end=0.1, rtol=1e-10, atol=1e-12, output_step=1e-4,
                        stop=Stop("linkage.pin_a.phi", "<=", math.pi - RA, name="released"))


def _released_at(res):
    names = [n for _, n in res.events]
    return res.events[names.index("released")][0] if "released" in names else float("nan")


measures = {
    "t_release_s": _released_at,
    # as models/examples/fourbar.py: the main shaft's turn from its start
    "theta3_at_release_rad": lambda res: float(report_angles(res)[2][-1]
                                               - report_angles(res)[2][0]),
}
