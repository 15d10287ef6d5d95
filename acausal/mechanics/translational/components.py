"""Translational components. Sign convention: :mod:`acausal.lang.connectors`."""

from acausal.lang import Component, Eq, Flange, Parameter, der


from ..partials import (PartialCompliant, PartialRigid)

__all__ = ["Fixed", "Mass", "Spring", "Damper", "SpringDamper"]


class Fixed(Component):
    """A flange fixed at position ``s0``: ``flange.s = s0`` (it takes any force).

    Parameters: ``s0`` [m] position. Connectors: ``flange``.
    """

    diagnosis_site = "ground"   # what acausal.diagnose may extend here

    flange = Flange("fixed flange")
    s0 = Parameter(0.0, "m", "fixed position")

    def equations(self):
        return [Eq(self.flange.s, self.s0)]


class Mass(PartialRigid):
    """A point mass: ``m * der(v) = flange.f`` (the sum of the forces of
    everything connected to its flange).

    Parameters: ``m`` [kg] mass (> 0). States: ``s`` [m], ``v`` [m/s]
    (start values: ``Mass(m=1, s=0.1, v=0)``; ``guess(x)`` for a guess).
    Connectors: ``flange``.
    """

    m = Parameter(1.0, "kg", "mass", min=0.0, min_open=True)

    def equations(self):
        return [Eq(self.m * der(self.v), self.flange.f)]


class Spring(PartialCompliant):
    """Linear spring: ``f = c * (s_rel - s_rel0) + f0`` (tension positive).

    With ``f0 = 0`` (default), ``s_rel0`` is the free length. To give a
    preloaded spring the way a designer knows it, set ``s_rel0`` to the
    *installed* length and ``f0`` to the installed force there; the free
    length is then ``s_rel0 - f0 / c``. ``f0`` follows the tension-positive
    convention: a compression spring installed pushing its flanges apart
    with 2 kN has ``f0 = -2000``.

    Parameters: ``c`` [N/m] stiffness (>= 0), ``s_rel0`` [m] reference
    length, ``f0`` [N] force at ``s_rel0`` (preload). States: ``s_rel`` [m],
    ``f`` [N]. Connectors: ``flange_a``, ``flange_b``.
    """

    c = Parameter(1.0, "N/m", "spring constant", min=0.0)
    s_rel0 = Parameter(0.0, "m", "reference length (free length when f0 = 0)")
    f0 = Parameter(0.0, "N", "force at s_rel = s_rel0 (preload, tension positive)")

    def equations(self):
        return [Eq(self.f, self.c * (self.s_rel - self.s_rel0) + self.f0)]


class Damper(PartialCompliant):
    """Linear damper: ``f = d * der(s_rel)`` (tension positive).

    Parameters: ``d`` [N*s/m] damping constant (>= 0). States: ``s_rel``
    [m], ``f`` [N]. Connectors: ``flange_a``, ``flange_b``.
    """

    d = Parameter(0.0, "N*s/m", "damping constant", min=0.0)

    def equations(self):
        return [Eq(self.f, self.d * der(self.s_rel))]


class SpringDamper(PartialCompliant):
    """Spring and damper in parallel:
    ``f = c * (s_rel - s_rel0) + f0 + d * der(s_rel)`` (tension positive;
    ``s_rel0``/``f0`` as in :class:`Spring`).

    Parameters: ``c`` [N/m] stiffness (>= 0), ``s_rel0`` [m] reference
    length, ``f0`` [N] spring force at ``s_rel0``, ``d`` [N*s/m] damping
    (>= 0). States: ``s_rel`` [m], ``f`` [N]. Connectors: ``flange_a``,
    ``flange_b``.
    """

    c = Parameter(1.0, "N/m", "spring constant", min=0.0)
    s_rel0 = Parameter(0.0, "m", "reference length (free length when f0 = 0)")
    f0 = Parameter(0.0, "N", "spring force at s_rel = s_rel0 (preload, tension positive)")
    d = Parameter(0.0, "N*s/m", "damping constant", min=0.0)

    def equations(self):
        return [Eq(self.f, self.c * (self.s_rel - self.s_rel0) + self.f0
                   + self.d * der(self.s_rel))]
