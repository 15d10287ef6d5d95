"""Laws shared by the translational and rotational libraries (MSL's
``Blocks.Types.Regularization`` of a sign, the critically damped Bessel
filter of the kinematic sources), so that neither domain imports the other."""
import sympy as sp
from sympy import Piecewise

from acausal.lang import Eq

BESSEL_AF = 1.3617   # s coefficient of MSL's second-order Bessel filter
BESSEL_BF = 0.6180   # s^2 coefficient


def bessel_filter(a, ref, x, v, f_crit):
    """MSL's second-order Bessel filter of ``ref`` realised on the states
    ``x``, ``v = der(x)``: ``a = ((ref - x)*w_crit - af*v)*(w_crit/bf)``,
    ``w_crit = 2*pi*f_crit``."""
    w = 2 * sp.pi * f_crit
    return Eq(a, ((ref - x) * w - BESSEL_AF * v) * (w / BESSEL_BF))


REGULARIZATIONS = ("Exp", "Sine", "Linear", "CoSine")


def regularized_sign(x, x0, reg):
    """MSL's ``Blocks.Types.Regularization`` of ``sign(x)`` below ``x0``
    (a sympy expression, continuous in ``x``; no events)::

        Exp:    2 / (1 + exp(-x / (0.01 x0))) - 1
        Sine:   sign(x) if |x| >= x0 else sin(pi/2 x/x0)
        Linear: sign(x) if |x| >= x0 else x/x0
        CoSine: sign(x) if |x| >= x0 else sign(x) (1 - cos(pi/2 x/x0))
    """
    if reg == "Exp":
        return 2 / (1 + sp.exp(-x / (sp.Rational(1, 100) * x0))) - 1
    sgn = Piecewise((1, x >= 0), (-1, True))     # sign(x) without a DiracDelta derivative
    inside = {"Sine": sp.sin(sp.pi / 2 * x / x0),
              "Linear": x / x0,
              "CoSine": sgn * (1 - sp.cos(sp.pi / 2 * x / x0))}[reg]
    return Piecewise((1, x >= x0), (-1, x <= -x0), (inside, True))
