"""The ideal planetary gear (MSL ``Rotational.Components.IdealPlanetary``).
Sign convention: :mod:`acausal.lang.connectors`."""
from acausal.lang import Component, Eq, Parameter, RotFlange

__all__ = ["IdealPlanetary"]


class IdealPlanetary(Component):
    """An ideal planetary gear box: sun, carrier and ring shafts, massless
    and without losses (MSL ``IdealPlanetary``)::

        (1 + ratio)*carrier.phi = sun.phi + ratio*ring.phi
        ring.tau = ratio*sun.tau,   carrier.tau = -(1 + ratio)*sun.tau

    ``ratio`` is the number of ring teeth over the number of sun teeth,
    so it is positive (a zero or negative ratio describes no planetary
    gear and is rejected). With the ring held, the carrier turns at
    ``sun.phi / (1 + ratio)``; with sun and ring locked together, the whole
    gear turns as one.

    Parameters: ``ratio`` [1] ring teeth / sun teeth (> 0). Connectors:
    ``sun``, ``carrier``, ``ring``.
    """

    ratio = Parameter(2.0, "1", "number of ring teeth / number of sun teeth", min=0.0,
                      min_open=True)
    sun = RotFlange("flange of the sun shaft")
    carrier = RotFlange("flange of the carrier shaft")
    ring = RotFlange("flange of the ring shaft")

    def equations(self):
        r = self.ratio
        return [Eq((1 + r) * self.carrier.phi, self.sun.phi + r * self.ring.phi),
                Eq(self.ring.tau, r * self.sun.tau),
                Eq(self.carrier.tau, -(1 + r) * self.sun.tau)]
