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
     shaft_pin: theta3                    hook_pin: theta1
       rocker r1 -> C  roller_pin  coupler r2 + r3  cam_pin  D <- crank e

The links are massless (as the closed form): the hook and main-shaft
inertias stay on the 1-D side. Same run and measures as the base file.
"""
from breaker_24kv import (BH_CAL, FREE_PARAMETERS, K_CAL, MEASURES, THETA1_0, Armature,
                          MainShaft, TriggerHook, release_experiment)

from acausal import Model, guess
from acausal.mechanics.contact import Contact
from acausal.mechanics.fourbar import fourbar_angles
from acausal.mechanics.planar.joints import Revolute
from acausal.mechanics.planar.parts import Fixed, FixedTranslation

import math


class PlanarCamRoller(Model):
    """The report's cam-and-roller four-bar (Table 1: e, f, r1, r2 + r3) from
    planar parts. Connectors: ``flange_a`` (hook shaft, theta1),
    ``flange_b`` (main shaft, theta3), both rotational, absolute angles
    (their joints' frame_a are fixed)."""

    def __init__(self, theta1=0.0, **kw):
        super().__init__(**kw)
        e = self.parameter("e", 0.0002, "m", "cam eccentricity (crank)", min=0.0, min_open=True)
        f = self.parameter("f", 0.125, "m", "hook shaft - main shaft distance", min=0.0,
                           min_open=True)
        r1 = self.parameter("r1", 0.116, "m", "roller lever (rocker)", min=0.0, min_open=True)
        r2 = self.parameter("r2", 0.036, "m", "roller radius", min=0.0)
        r3 = self.parameter("r3", 0.0533, "m", "cam-circle radius", min=0.0)
        th2, th3 = fourbar_angles(theta1)          # start guesses (Table 1 geometry)
        self.ground_A = Fixed()
        self.ground_O = Fixed(x0=f, phi0=math.pi)
        self.hook_pin = Revolute(phi=guess(theta1))
        self.crank = FixedTranslation(rx=e, ry=0.0)
        self.shaft_pin = Revolute(phi=guess(th3))
        self.rocker = FixedTranslation(rx=r1, ry=0.0)
        self.roller_pin = Revolute(phi=guess(-th2 - th3))
        self.coupler = FixedTranslation(rx=r2 + r3, ry=0.0)
        self.cam_pin = Revolute(phi=guess(-th2 - math.pi - theta1))
        self.connect(self.ground_O.frame, self.hook_pin.frame_a)
        self.connect(self.hook_pin.frame_b, self.crank.frame_a)
        self.connect(self.ground_A.frame, self.shaft_pin.frame_a)
        self.connect(self.shaft_pin.frame_b, self.rocker.frame_a)
        self.connect(self.rocker.frame_b, self.roller_pin.frame_a)
        self.connect(self.roller_pin.frame_b, self.coupler.frame_a)
        self.connect(self.coupler.frame_b, self.cam_pin.frame_b)
        self.connect(self.crank.frame_b, self.cam_pin.frame_a)
        self.flange_a = self.hook_pin.axis
        self.flange_b = self.shaft_pin.axis


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
