"""Adaptors from a planar frame to the 1-D flanges (the mapping is written
in :mod:`acausal.connectors`). Each is massless and lossless: the power
into the frame side equals the power out of the flange side."""

from acausal.lang import Eq, Flange, Parameter, RotFlange

from acausal.errors import ParameterError

from .partials import PartialOneFrame

__all__ = ["ShaftAdaptor", "AxisAdaptor"]


class ShaftAdaptor(PartialOneFrame):
    """The frame's rotation as a 1-D shaft: ``flange.phi = frame.phi``,
    ``frame.tau = -flange.tau``; it takes no force (``frame.fx = fy = 0``).

    Connectors: ``frame`` (planar), ``flange`` (RotFlange, world z axis).
    """

    flange = RotFlange("shaft with the frame's angle")

    def equations(self):
        fr = self.frame
        return [Eq(self.flange.phi, fr.phi), Eq(fr.tau, -self.flange.tau),
                Eq(fr.fx, 0), Eq(fr.fy, 0)]


class AxisAdaptor(PartialOneFrame):
    """The frame's motion along a fixed world axis ``(ex, ey)`` as a 1-D
    flange: ``flange.s = ex*x + ey*y``, ``frame.(fx, fy) = -flange.f (ex, ey)``;
    no force across the axis and no torque are taken.

    Parameters: ``ex``, ``ey`` [1] axis direction in the world (made unit
    length). Connectors: ``frame`` (planar), ``flange`` (Flange).
    """

    flange = Flange("position along the axis")
    ex = Parameter(1.0, "1", "axis direction, world x")
    ey = Parameter(0.0, "1", "axis direction, world y")

    def __init__(self, **kw):
        super().__init__(**kw)
        ex, ey = self.value("ex"), self.value("ey")
        if all(isinstance(c, (int, float)) for c in (ex, ey)) and ex * ex + ey * ey == 0:
            raise ParameterError(f"AxisAdaptor {self.path or ''}: the axis (ex, ey) is zero")

    def equations(self):
        fr = self.frame
        n = (self.ex**2 + self.ey**2) ** 0.5
        ux, uy = self.ex / n, self.ey / n
        return [Eq(self.flange.s, ux * fr.x + uy * fr.y),
                Eq(fr.fx, -self.flange.f * ux), Eq(fr.fy, -self.flange.f * uy),
                Eq(fr.tau, 0)]
