"""Planar sub-assemblies built from the parts and joints of this package.

:class:`FourBarLinkage`: a four-bar on two ground pivots, the shared loop of
the breaker's cam and roller (models/breaker_24kv_planar.py), its toggle-
latch variant (models/breaker_24kv_toggle.py) and any crank-rocker::

                 C  coupler c   D
                  o-------------o
       rocker b  /               \\  crank a
                /                 \\
   pivot B    o                    o   pivot A
   (xb, yb), zero direction phib   (xa, ya), zero direction phia

* ``pin_a`` (Revolute at A): the crank's angle ``theta_a`` from the
  direction ``phia`` (counter-clockwise, :mod:`acausal.connectors`), so D =
  A + a (cos(phia + theta_a), sin(phia + theta_a)); ``pin_b`` likewise for
  the rocker at B; ``pin_c`` joins the rocker to the coupler at C, ``pin_d``
  closes the loop at D.
* Connectors: ``flange_a`` (``pin_a.axis``) and ``flange_b`` (``pin_b.axis``),
  rotational, the joint angles (absolute: the pivots are fixed); ``crank``
  and ``rocker`` (planar, ``pin_a.frame_b`` / ``pin_b.frame_b``: the frames
  turning with each, at the pivots) to hang bodies on.

The links are massless (put a ``Body`` on ``crank`` / ``rocker`` or 1-D
inertias on the flanges). The start guesses of the four joint angles are the
closed-form assembly (two circles' intersection) at ``theta_a0`` for the
assembly ``mode`` (+1: C to the left of the line from B to D, -1: to the
right), as expressions of the linkage's parameters (so a run with other
lengths starts from their assembly); the initialisation then closes the
loop (and names it when it cannot). The geometry may be given as numbers or
as expressions of the enclosing model's parameters.
"""
import math

import sympy as sp

from acausal.lang import Model, guess
from acausal.lang.symbols import FastMax, FastMin
from acausal.errors import ParameterError

from .joints import Revolute
from .parts import Fixed, FixedTranslation

__all__ = ["FourBarLinkage", "fourbar_assembly"]

GEOMETRY = (("xa", "m", "pivot A, world x"), ("ya", "m", "pivot A, world y"),
            ("phia", "rad", "zero direction of the crank angle at A"),
            ("xb", "m", "pivot B, world x"), ("yb", "m", "pivot B, world y"),
            ("phib", "rad", "zero direction of the rocker angle at B"),
            ("a", "m", "crank length A-D"), ("b", "m", "rocker length B-C"),
            ("c", "m", "coupler length C-D"))


def fourbar_assembly(theta_a, mode=1, lib=math, **g):
    """(theta_b, pin_c, pin_d) [rad]: the rocker's angle and the two coupler
    joints' angles that close the loop at crank angle ``theta_a``, for the
    geometry ``g`` (the names of :data:`GEOMETRY`). With ``lib=math`` (numbers)
    None when the loop cannot close there; with ``lib=sympy`` expressions
    (the cosine clipped to [-1, 1], so that a loop that cannot close still
    gets start guesses and the initialisation names it)."""
    ua = g["phia"] + theta_a
    dx = g["xa"] + g["a"] * lib.cos(ua) - g["xb"]
    dy = g["ya"] + g["a"] * lib.sin(ua) - g["yb"]
    d = lib.sqrt(dx**2 + dy**2)
    if lib is math:
        cos_l = (d * d + g["b"] ** 2 - g["c"] ** 2) / (2 * g["b"] * d) if d > 0 else 2.0
        if abs(cos_l) > 1:
            return None
    else:
        # built as written (FastMax/FastMin): sympy's Min/Max reduce their
        # arguments again at every xreplace of these start guesses
        cos_l = FastMin(FastMax((d**2 + g["b"]**2 - g["c"]**2) / (2 * g["b"] * d), -1), 1)
    ub = lib.atan2(dy, dx) + mode * lib.acos(cos_l)            # rocker direction (world)
    cx, cy = g["b"] * lib.cos(ub), g["b"] * lib.sin(ub)         # C - B
    uc = lib.atan2(dy - cy, dx - cx)                            # coupler direction C -> D
    return ub - g["phib"], uc - ub, uc - ua


class FourBarLinkage(Model):
    """A four-bar on two ground pivots (picture, angles and connectors: the
    module docstring).

    Parameters: ``xa``, ``ya`` [m] pivot A, ``phia`` [rad] zero direction of
    the crank angle, ``xb``, ``yb`` [m] pivot B, ``phib`` [rad] zero
    direction of the rocker angle, ``a`` [m] crank, ``b`` [m] rocker,
    ``c`` [m] coupler (lengths > 0). Constructor: ``theta_a0`` [rad] the
    crank angle the start guesses assemble at, ``mode`` (+1 / -1) the
    assembly mode. States: the joints' (``pin_a.phi``, ``pin_a.w``...).
    Connectors: ``flange_a``, ``flange_b`` (rotational), ``crank``,
    ``rocker`` (planar).
    """

    def __init__(self, theta_a0=0.0, mode=1, xa=0.1, ya=0.0, phia=0.0, xb=0.0, yb=0.0,
                 phib=0.0, a=0.02, b=0.06, c=0.1):
        super().__init__()
        given = dict(xa=xa, ya=ya, phia=phia, xb=xb, yb=yb, phib=phib, a=a, b=b, c=c)
        s = {}
        for name, unit, desc in GEOMETRY:
            bounds = dict(min=0.0, min_open=True) if name in "abc" else {}
            s[name] = self.parameter(name, given[name], unit, desc, **bounds)
        numbers = all(isinstance(v, (int, float)) for v in (theta_a0, *given.values()))
        if numbers and fourbar_assembly(theta_a0, mode, **given) is None:
            raise ParameterError(
                f"FourBarLinkage: the loop cannot close at theta_a0 = {theta_a0:g} rad with "
                f"a = {a:g}, b = {b:g}, c = {c:g} m and the pivots "
                f"{math.hypot(xa - xb, ya - yb):g} m apart")
        # the guesses follow the parameters of the run (a sweep of a length or angle)
        th_b, th_c, th_d = fourbar_assembly(theta_a0, mode, lib=sp, **s)
        self.ground_a = Fixed(x0=s["xa"], y0=s["ya"], phi0=s["phia"])
        self.ground_b = Fixed(x0=s["xb"], y0=s["yb"], phi0=s["phib"])
        self.pin_a = Revolute(phi=guess(theta_a0))
        self.pin_b = Revolute(phi=guess(th_b))
        self.pin_c = Revolute(phi=guess(th_c))
        self.pin_d = Revolute(phi=guess(th_d))
        self.link_a = FixedTranslation(rx=s["a"], ry=0.0)
        self.link_b = FixedTranslation(rx=s["b"], ry=0.0)
        self.link_c = FixedTranslation(rx=s["c"], ry=0.0)
        self.connect(self.ground_a.frame, self.pin_a.frame_a)
        self.connect(self.pin_a.frame_b, self.link_a.frame_a)
        self.connect(self.ground_b.frame, self.pin_b.frame_a)
        self.connect(self.pin_b.frame_b, self.link_b.frame_a)
        self.connect(self.link_b.frame_b, self.pin_c.frame_a)
        self.connect(self.pin_c.frame_b, self.link_c.frame_a)
        self.connect(self.link_c.frame_b, self.pin_d.frame_b)
        self.connect(self.link_a.frame_b, self.pin_d.frame_a)
        self.flange_a = self.pin_a.axis
        self.flange_b = self.pin_b.axis
        self.crank = self.pin_a.frame_b
        self.rocker = self.pin_b.frame_b
