"""The breaker's trigger cam and roller as an equivalent four-bar linkage
(research report, section 2.4, eqs. 5 to 16; Table 1).

Geometry and angle conventions (report, Fig. 5)
-----------------------------------------------
Take A, the main-shaft centre, as origin and the x axis from A towards O, the
hook-shaft centre, at distance ``f``; y perpendicular (the report's frame).

* crank ``e``: the eccentricity of the trigger cam, from O to the cam-circle
  centre D = (f - e cos(theta1), e sin(theta1))          (eqs. 7, 8);
* rocker ``r1``: the roller lever, from A to the roller centre
  C = (r1 cos(theta3), -r1 sin(theta3));
* coupler ``r2 + r3`` (roller radius + cam-circle radius), from C to D, at
  angle theta2: D - C = (r2 + r3) (cos(theta2), sin(theta2)).

With these, the report's eqs. 9 to 13 are mutually consistent:
the loop D - C gives exactly eqs. 11 (y) and 12 (x),
``theta3 = lambda - phi`` (eq. 10) is the closure with C on the clockwise
side of AD (``mode = +1``; the other closure is ``theta3 = -lambda - phi``,
``mode = -1``) and differentiating eqs. 11-12 (eqs. 14, 15) gives the
velocity ratio (eq. 16, garbled in the text extraction, re-derived here)::

    dtheta3/dtheta1 = -e sin(theta1 + theta2) / (r1 sin(theta2 + theta3))

theta1 and theta3 both turn in the same sense (clockwise in a frame whose y
axis points up); theta2 turns the other way. The dead centre of the output
(coupler aligned with the roller lever, ``sin(theta2 + theta3) = 0``) is the
same configuration as ``|cos(lambda)| = 1`` in eq. 9: where the linkage stops
closing. Along a closed linkage
``(r2 + r3) sin(theta2 + theta3) = mode * d * sin(lambda)``.
"""
import functools
import math

import sympy as sp
from sympy import Max, Min, cos, sin, sqrt

from acausal.lang import Assertion, Component, Eq, Parameter, RotFlange, Start, Variable
from acausal.errors import ParameterError


def _closed_form(th1, e, f, r1, r2, r3, mode, lib):
    """(theta2, theta3, cos_lambda) from eqs. 5 to 13; ``lib`` is math-like."""
    xd = f - e * lib.cos(th1)                       # eq. 7
    yd = e * lib.sin(th1)                           # eq. 8
    d = lib.sqrt(xd**2 + yd**2)                     # eq. 5
    phi = lib.atan2(yd, xd)                         # eq. 6
    c = (d**2 + r1**2 - (r2 + r3)**2) / (2 * r1 * d)   # eq. 9
    lam = lib.acos(lib.clip(c))
    th3 = mode * lam - phi                          # eq. 10
    th2 = lib.atan2(r1 * lib.sin(th3) + e * lib.sin(th1),
                    f - r1 * lib.cos(th3) - e * lib.cos(th1))   # eq. 13
    return th2, th3, c


_CLIP = 1e-6


class _Math:
    cos, sin, sqrt, atan2, acos = math.cos, math.sin, math.sqrt, math.atan2, math.acos

    @staticmethod
    def clip(c):
        return min(max(c, -1.0), 1.0)


class _Sym:
    cos, sin, sqrt, atan2, acos = sp.cos, sp.sin, sp.sqrt, sp.atan2, sp.acos

    @staticmethod
    def clip(c):
        # guesses stay off the exact dead centre (where the state selection
        # would see a singular Jacobian) so that a start that cannot close is
        # reported by the initialisation with the component's message
        return Min(Max(c, -1 + _CLIP), 1 - _CLIP)


@functools.lru_cache(maxsize=64)
def _guess_exprs(th1, e, f, r1, r2, r3, mode):
    """(theta2, theta3) of :func:`_closed_form` in sympy, once per process for
    the same symbols (building it costs about 0.1 s, and a diagnosis flattens
    the same linkage in every hypothesis model it compiles)."""
    th2, th3, _ = _closed_form(th1, e, f, r1, r2, r3, mode, _Sym)
    return th2, th3


def fourbar_angles(theta1, e=0.0002, f=0.125, r1=0.116, r2=0.036, r3=0.0533, mode=1):
    """Closed form (report eqs. 5 to 13): ``(theta2, theta3)`` [rad] for the
    input angle ``theta1`` [rad]. Raises ``ValueError`` if the linkage cannot
    close there. Use it to set start values, e.g. an offset that makes the
    main shaft start at 0."""
    th2, th3, c = _closed_form(float(theta1), e, f, r1, r2, r3, mode, _Math)
    if abs(c) > 1.0:
        raise ParameterError(f"four-bar cannot close at theta1 = {theta1:g} rad: "
                         f"cos(lambda) = {c:.6g}")
    return th2, th3


def fourbar_ratio(theta1, e=0.0002, f=0.125, r1=0.116, r2=0.036, r3=0.0533, mode=1):
    """Velocity ratio dtheta3/dtheta1 [1] at ``theta1`` (eq. 16, re-derived)."""
    th2, th3 = fourbar_angles(theta1, e, f, r1, r2, r3, mode)
    return -e * math.sin(theta1 + th2) / (r1 * math.sin(th2 + th3))


class FourBar(Component):
    """Trigger cam and roller as a massless four-bar linkage (report eqs. 5-16).

    Position-level closure (eqs. 11, 12 as residuals, theta2 internal)::

        (r2 + r3) sin(theta2) = r1 sin(theta3) + e sin(theta1)
        (r2 + r3) cos(theta2) = f - r1 cos(theta3) - e cos(theta1)

    Torques (Lagrange multipliers lambda = Fc (sin theta2, cos theta2) on the
    two closure residuals; the third condition lambda . dg/dtheta2 = 0 is
    built into that form)::

        flange_a.tau = -Fc e  sin(theta1 + theta2)
        flange_b.tau = -Fc r1 sin(theta2 + theta3)

    so ``flange_a.tau * w1 + flange_b.tau * w3 = 0`` exactly wherever the
    differentiated closure holds (massless, lossless). ``Fc`` is the force in
    the coupler, i.e. the cam-roller contact force, positive in compression
    (the cam pushes the roller); a real cam can only push: ``Fc < 0`` means
    the roller would lift off, which this linkage model does not represent.
    ``ratio = dtheta3/dtheta1 = -e sin(theta1+theta2) / (r1 sin(theta2+theta3))``
    (eq. 16). theta1 = flange_a.phi + theta1_offset, theta3 = flange_b.phi +
    theta3_offset (the report's theta1, theta3; see the module docstring).

    Initialisation: the input angle is fixed by the user (on the hook inertia
    or here: ``FourBar(theta1=0.1)``); theta2 and theta3 are solved from the
    closure by a Newton iteration that goes to the solution nearest to their
    guesses. The guesses are the closed form (eqs. 10, 13 for ``mode``) at the
    start given to ``theta1`` here, by default ``theta1_offset`` (the input
    flange starting at 0). With a large ``e`` and an input starting far from
    there, give the four-bar the start as well (``theta1=guess(x)`` when it
    is fixed elsewhere). Start angles at which the linkage cannot close, or
    that land in the other assembly mode, stop the initialisation with an
    error naming the component; so does reaching a dead centre (within
    ``sin_min``) while simulating. Explicit ``theta2``/``theta3`` starts
    replace the closed-form guesses.

    Parameters: ``e`` [m] cam eccentricity (crank), ``f`` [m] distance
    hook shaft - main shaft (frame), ``r1`` [m] roller lever (rocker),
    ``r2`` [m] roller radius, ``r3`` [m] cam-circle radius (coupler is
    r2 + r3), ``theta1_offset``, ``theta3_offset`` [rad] flange angle ->
    report angle, ``sin_min`` [1] smallest allowed ``mode*sin(theta2+theta3)``
    (transmission, dead-centre guard), ``mode`` (structural, +1: eq. 10
    ``theta3 = lambda - phi``, -1: ``theta3 = -lambda - phi``).
    States: ``theta1``, ``theta2``, ``theta3`` [rad], ``Fc`` [N] coupler
    force, ``ratio`` [1] dtheta3/dtheta1.
    Connectors: ``flange_a`` (hook shaft, theta1), ``flange_b`` (main shaft,
    theta3).
    """

    flange_a = RotFlange("hook shaft (input, theta1)")
    flange_b = RotFlange("main shaft (output, theta3)")

    e = Parameter(0.0002, "m", "eccentric distance of the trigger cam (crank)",
                  min=0.0, min_open=True)
    f = Parameter(0.125, "m", "distance between hook-shaft and main-shaft centres",
                  min=0.0, min_open=True)
    r1 = Parameter(0.116, "m", "arm length of the roller lever (rocker)",
                   min=0.0, min_open=True)
    r2 = Parameter(0.036, "m", "radius of the roller", min=0.0)
    r3 = Parameter(0.0533, "m", "radius of the trigger cam circle (cam lever)", min=0.0)
    theta1_offset = Parameter(0.0, "rad", "theta1 - flange_a.phi")
    theta3_offset = Parameter(0.0, "rad", "theta3 - flange_b.phi")
    sin_min = Parameter(0.01, "1", "smallest allowed mode*sin(theta2 + theta3) "
                        "(dead-centre guard)", min=0.0, max=1.0, min_open=True,
                        max_open=True)
    mode = Parameter(1, "1", "assembly mode: +1 theta3 = lambda - phi (eq. 10), "
                     "-1 theta3 = -lambda - phi", structural=True, choices=(1, -1))

    theta1 = Variable(0.0, "rad", "input angle (report's theta1)")
    theta2 = Variable(0.0, "rad", "coupler angle (report's theta2)")
    theta3 = Variable(0.0, "rad", "output angle (report's theta3)")
    Fc = Variable(0.0, "N", "coupler (cam-roller contact) force, compression positive")
    ratio = Variable(0.0, "1", "velocity ratio dtheta3/dtheta1 (eq. 16)")

    # -- start values: closed-form guesses of theta2, theta3 ---------------------
    def start(self, name):
        st = super().start(name)
        if name == "theta1" and st is type(self).__dict__[name].start:
            return Start(self.theta1_offset, False)      # flange_a.phi starts near 0
        if name in ("theta2", "theta3") and st is type(self).__dict__[name].start:
            th1 = self.start("theta1").value
            g = self._guess_expr(th1)
            return Start(g[0] if name == "theta2" else g[1], False)
        return st

    def _guess_expr(self, th1):
        """theta2, theta3 (sympy expressions of the parameters) at ``th1``."""
        return _guess_exprs(sp.sympify(th1), self.e, self.f, self.r1, self.r2, self.r3,
                            self.mode)

    # -- law ---------------------------------------------------------------------
    def equations(self):
        th1, th2, th3 = self.theta1, self.theta2, self.theta3
        e, f, r1, L = self.e, self.f, self.r1, self.r2 + self.r3
        return [
            Eq(th1, self.flange_a.phi + self.theta1_offset),
            Eq(th3, self.flange_b.phi + self.theta3_offset),
            Eq(L * sin(th2), r1 * sin(th3) + e * sin(th1)),               # eq. 11
            Eq(L * cos(th2), f - r1 * cos(th3) - e * cos(th1)),           # eq. 12
            Eq(self.flange_a.tau, -self.Fc * e * sin(th1 + th2)),
            Eq(self.flange_b.tau, -self.Fc * r1 * sin(th2 + th3)),
            Eq(self.ratio * r1 * sin(th2 + th3), -e * sin(th1 + th2)),    # eq. 16
        ]

    def cos_lambda(self):
        """cos(lambda) of eq. 9 as a function of theta1 (sympy)."""
        th1 = self.theta1
        xd = self.f - self.e * cos(th1)
        yd = self.e * sin(th1)
        d = sqrt(xd**2 + yd**2)
        L = self.r2 + self.r3
        return (d**2 + self.r1**2 - L**2) / (2 * self.r1 * d)

    def assertions(self):
        c = self.cos_lambda()
        return [
            Assertion(1 - c**2,
                      "the four-bar cannot close: |cos(lambda)| of eq. 9 exceeds 1, i.e. "
                      "d = |AD| is outside [|r1 - (r2+r3)|, r1 + r2 + r3] at this theta1"),
            Assertion(self.mode * sin(self.theta2 + self.theta3) - self.sin_min,
                      "four-bar dead centre or wrong assembly mode: mode*sin(theta2 + "
                      "theta3) fell below sin_min, i.e. the coupler (r2+r3) and the roller "
                      "lever r1 are (nearly) aligned, where dtheta3/dtheta1 diverges and "
                      "the linkage locks or switches assembly mode; at the start it means "
                      "theta2, theta3 are in the other assembly mode than 'mode' or too "
                      "close to a dead centre"),
        ]
