"""Spring and damper between two frames, along the line joining their
origins. Sign convention: :mod:`acausal.connectors` (:class:`Frame`);
force law: :class:`.partials.PartialLineForce` (tension positive)."""

from acausal.lang import Eq, Parameter, der

from .partials import PartialLineForce

__all__ = ["Spring", "Damper", "SpringDamper"]


class Spring(PartialLineForce):
    """Linear spring between two frame origins: ``f = c (s - s0) + f0``.

    Parameters: ``c`` [N/m] stiffness (>= 0), ``s0`` [m] free length,
    ``f0`` [N] preload at ``s = s0``. States: ``s`` [m], ``f`` [N].
    Connectors: ``frame_a``, ``frame_b``.
    """

    c = Parameter(1.0, "N/m", "stiffness", min=0.0)
    s0 = Parameter(0.0, "m", "free length", min=0.0)
    f0 = Parameter(0.0, "N", "tension at s = s0 (preload)")

    def equations(self):
        return [Eq(self.f, self.c * (self.s - self.s0) + self.f0)]


class Damper(PartialLineForce):
    """Linear damper between two frame origins: ``f = d der(s)``.

    Parameters: ``d`` [N*s/m] damping (>= 0). States: ``s`` [m], ``f`` [N].
    Connectors: ``frame_a``, ``frame_b``.
    """

    d = Parameter(1.0, "N*s/m", "damping constant", min=0.0)

    def equations(self):
        return [Eq(self.f, self.d * der(self.s))]


class SpringDamper(PartialLineForce):
    """Spring and damper in parallel: ``f = c (s - s0) + d der(s)``.

    Parameters: ``c`` [N/m], ``s0`` [m], ``d`` [N*s/m]. States: ``s`` [m],
    ``f`` [N]. Connectors: ``frame_a``, ``frame_b``.
    """

    c = Parameter(1.0, "N/m", "stiffness", min=0.0)
    s0 = Parameter(0.0, "m", "free length", min=0.0)
    d = Parameter(1.0, "N*s/m", "damping constant", min=0.0)

    def equations(self):
        return [Eq(self.f, self.c * (self.s - self.s0) + self.d * der(self.s))]
