"""The 24 kV breaker (models/breaker_24kv.py) with its trigger cam and
roller built from planar bodies and joints instead of the closed-form
``FourBar``: the same armature, contact, trigger hook and main shaft (1-D,
from the base file), joined by a planar four-bar whose two revolutes carry
the hook shaft and the main shaft as 1-D flanges.

The planar linkage is drawn in the report's Fig. 5 frame mirrored about the
x axis (y down), so that the report's clockwise angles theta1 (hook shaft)
and theta3 (main shaft) are the counter-clockwise joint angles of the
revolutes (acausal.connectors: angles counter-clockwise positive)::

    A (main shaft, origin) ----- f ----- O (hook shaft, frame turned by pi)
     cam.pin_b: theta3                    cam.pin_a: theta1
       rocker r1 -> C  cam.pin_c  coupler r2 + r3  cam.pin_d  D <- crank e

(the shared sub-assembly :class:`acausal.mechanics.planar.linkages.FourBarLinkage`).

The links are massless (as the closed form): the hook and main-shaft
inertias stay on the 1-D side. Same run and measures as the base file.
"""
from breaker_24kv import (BH_CAL, FREE_PARAMETERS, K_CAL, MEASURES, THETA1_0, Armature,
                          MainShaft, TriggerHook, release_experiment)

import math

from acausal import Model
from acausal.mechanics.contact import Contact
from acausal.mechanics.fourbar import fourbar_angles
from acausal.mechanics.planar.linkages import FourBarLinkage


TABLE1 = dict(e=0.0002, f=0.125, r1=0.116, r2=0.036, r3=0.0533)   # [m] the report's


class PlanarCamRoller(FourBarLinkage):
    """The report's cam-and-roller four-bar (Table 1: e, f, r1, r2 + r3) as
    a :class:`~acausal.mechanics.planar.linkages.FourBarLinkage`: crank
    ``a = e`` on the hook shaft O at (f, 0) with its zero direction towards
    A (``phia = pi``), rocker ``b = r1`` on the main shaft A at the origin,
    coupler ``c = r2 + r3`` (roller centre C to cam-circle centre D).
    Connectors: ``flange_a`` (hook shaft, theta1), ``flange_b`` (main shaft,
    theta3), both rotational, absolute angles."""

    def __init__(self, theta1=0.0, geometry=TABLE1):
        g = geometry
        super().__init__(theta_a0=theta1, mode=1, xa=g["f"], ya=0.0, phia=math.pi, xb=0.0,
                         yb=0.0, phib=0.0, a=g["e"], b=g["r1"], c=g["r2"] + g["r3"])


def build(v_impact=3.8, K=8.3e9, bh=0.219):
    """The planar breaker (same defaults and parameters as the base build)."""
    m = Model()
    v = m.parameter("v_impact", v_impact, "m/s", "armature speed at first contact",
                    min=0.0, min_open=True)
    Ra = m.parameter("Ra", math.radians(5.0), "rad", "release angle of the trigger hook",
                     min=0.0, min_open=True)
    m.armature = Armature(v)
    m.hook = TriggerHook()
    m.hook.set(bh=bh)
    m.contact = Contact(K=K, e=0.74, gamma=1.5, law="lankarani_nikravesh")
    m.cam = PlanarCamRoller(THETA1_0)
    m.main_shaft = MainShaft(fourbar_angles(THETA1_0)[1])
    m.connect(m.hook.point, m.contact.flange_a)
    m.connect(m.contact.flange_b, m.armature.flange)
    m.connect(m.hook.shaft, m.cam.flange_a)
    m.connect(m.cam.flange_b, m.main_shaft.shaft)
    m.Ra_sym = Ra
    return m


model = build(K=K_CAL, bh=BH_CAL)
free_parameters = dict(FREE_PARAMETERS)
experiment = release_experiment(model)
measures = dict(MEASURES)
