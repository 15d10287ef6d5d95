"""The independent blind cases of issue 24 (item 7): each a mechanism
outside ``models/`` (its model file, written as a user would, and its
hand-written truth), the hidden laws (``truth_core.Law``, at reference
magnitudes that ``datawriter.scaled`` scales to the effect asked for) and
what a right diagnosis says:

* ``named``: these causes named (hypothesis ids any of ``ids``, at
  ``site``), the parameter ``param`` of each within 10 % of the truth's
  ``value`` (the law's magnitude, after scaling);
* ``unexplained``: "not explained by the library" at one of ``nodes``,
  and no confident name of a cause the truth lacks;
* ``null``: no cause named and nothing unexplained.

``stick`` cases are not scaled: their friction is fixed strong enough that
the mechanism stops and sticks within the record (``events`` say where).
"""
from dataclasses import dataclass

try:
    from . import cam_truth, gear_truth
    from .truth_core import Law
except ImportError:
    import cam_truth
    import gear_truth
    from truth_core import Law

FRICTION = ("coulomb_friction", "stribeck_friction", "coulomb_viscous_friction",
            "stick_slip_friction")
# a plain viscous law at a joint: whatever member carries a viscous coefficient
VISCOUS = ("viscous_damping", "coulomb_viscous_friction")
DRAG = ("quadratic_damping", "power_drag")
MAG = ("tau", "F", "T")      # the friction level, as each friction member names it
VIS = ("b", "d")             # a viscous coefficient


@dataclass(frozen=True)
class Expect:
    """One expected cause: any hypothesis of ``ids`` at ``site``, its
    parameter (any of the names ``param`` after the sub-model prefix, e.g.
    ``tau``) within 10 %
    of the law ``law`` (index into the case's laws) magnitude ``key``."""

    ids: tuple
    site: str
    param: str
    law: int
    key: str


@dataclass(frozen=True)
class Case:
    name: str
    truth: object          # the truth module
    shape: str             # the failure shape of issue 24 it tests
    laws: tuple = ()
    kind: str = "named"    # named | unexplained | null | either
    expect: tuple = ()     # Expect per named cause
    nodes: tuple = ()      # where "not explained" must point
    scale: bool = True

    @property
    def model(self):
        import os
        return os.path.join(os.path.dirname(os.path.abspath(__file__)), self.truth.MODEL)


CASES = {c.name: c for c in [
    # -- the cam follower ------------------------------------------------
    Case("cam_null", cam_truth, "null", (), "null"),
    Case("cam_coulomb_follower", cam_truth, "one law two members mimic",
         (Law("coulomb", "follower", {"F": 0.5}),),
         expect=(Expect(FRICTION, "follower", MAG, 0, "F"),)),
    Case("cam_friction_drag", cam_truth, "dry friction + drag in a free decay",
         (Law("coulomb", "cam", {"F": 1e-3}), Law("drag", "cam", {"c": 1e-6})),
         expect=(Expect(FRICTION, "cam", MAG, 0, "F"), Expect(DRAG, "cam", ("c",), 1, "c"))),
    Case("cam_viscous_follower", cam_truth, "viscous loss at a joint",
         (Law("viscous", "follower", {"b": 5.0}),),
         expect=(Expect(VISCOUS, "follower", VIS, 0, "b"),)),
    Case("cam_detent", cam_truth, "a localised force (out of library)",
         (Law("detent", "follower", {"A": 1.0, "x_d": 2.5e-3, "w": 3e-4}),),
         "unexplained", nodes=cam_truth.NODES["follower"]),
    Case("cam_friction_detent", cam_truth, "friction + a force off the library's form",
         (Law("coulomb", "cam", {"F": 1e-3}),
          Law("detent", "follower", {"A": 1.0, "x_d": 2.5e-3, "w": 3e-4})),
         "either", expect=(Expect(FRICTION, "cam", MAG, 0, "F"),),
         nodes=cam_truth.NODES["follower"]),
    Case("cam_stick", cam_truth, "friction that makes a body stop and stick",
         (Law("coulomb", "cam", {"F": 0.02}),), scale=False,
         expect=(Expect(FRICTION, "cam", MAG, 0, "F"),)),
    # -- the geared drive -------------------------------------------------
    Case("gear_null", gear_truth, "null", (), "null"),
    Case("gear_coulomb_load", gear_truth, "one law two members mimic",
         (Law("coulomb", "load", {"F": 5e-3}),),
         expect=(Expect(FRICTION, "load", MAG, 0, "F"),)),
    Case("gear_friction_drag", gear_truth, "dry friction + drag in a free decay",
         (Law("coulomb", "load", {"F": 3e-3}), Law("drag", "load", {"c": 3e-4})),
         expect=(Expect(FRICTION, "load", MAG, 0, "F"), Expect(DRAG, "load", ("c",), 1, "c"))),
    Case("gear_cogging", gear_truth, "a position-periodic force (out of library)",
         (Law("periodic", "motor", {"A": 2e-3, "P": 1.0471975511965976}),),
         "unexplained", nodes=gear_truth.NODES["motor"]),
    Case("gear_friction_cogging", gear_truth, "friction + a force off the library's form",
         (Law("coulomb", "load", {"F": 3e-3}),
          Law("periodic", "motor", {"A": 2e-3, "P": 1.0471975511965976})),
         "either", expect=(Expect(FRICTION, "load", MAG, 0, "F"),),
         nodes=gear_truth.NODES["motor"]),
    Case("gear_stick", gear_truth, "friction that makes a body stop and stick",
         (Law("coulomb", "load", {"F": 0.03}),), scale=False,
         expect=(Expect(FRICTION, "load", MAG, 0, "F"),)),
]}
