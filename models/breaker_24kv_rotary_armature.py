"""Variant of the 24 kV breaker (models/breaker_24kv.py): a rotary (clapper)
armature that strikes the trigger hook through a lever arm, instead of the
base design's plunger armature (a linear Mass).

Design change: the trip magnet pulls a clapper plate on a pivot (moment of
inertia ``Ja`` about the pivot, magnetic torque ``Te``, reset torsion spring
``kr``); a striking pin on the clapper at arm ``la`` hits the hook's contact
point. The pin moves on a circle: the lever is exact, ``s = la*sin(phi)``,
force ratio ``la*cos(phi)`` (acausal.mechanics.levers.IdealLever(exact=True)), with
``phi`` = 0 (the arm perpendicular to the strike line) 1 um before first
contact. Default values: a steel clapper of about 0.1 kg and 50 mm swinging
about one end (Ja = 1.0e-4 kg*m^2), pin at la = 25 mm, i.e. an effective mass
Ja/la^2 = 0.16 kg at the pin (the plunger: 0.22 kg), and Te = 4.0 N*m, the
plunger's 160 N at the pin. The hook, contact, four-bar and main shaft are the
base design's sub-models and values.

``v_impact`` is the pin's speed at first contact (the base file's armature
speed), so sweeps compare both designs at equal striking speed. With
``Ja = ma*la^2``, ``Te = Fe*la`` and the small-angle lever the model is the
base model exactly (tests/models/test_breaker_variants.py checks it).

Sign convention as the base file: the pin moves along -s (``phi``
decreases). Measures as the base file, plus ``n_impacts``.
Run: ``acausal simulate models/breaker_24kv_rotary_armature.py --plot FILE``.
"""
import math

import sympy as sp
from breaker_24kv import CONDITIONS
from breaker_24kv import (BH_CAL, FREE_PARAMETERS, GAP0, K_CAL, MEASURES, MainShaft,
                         THETA1_0, TriggerHook, release_experiment, t_first_contact,
                         t_release)

from acausal import Measure, Model, guess
from acausal.mechanics import contact as ct
from acausal.mechanics.contact import Contact
from acausal.mechanics.fourbar import FourBar, fourbar_angles
from acausal.mechanics.levers import IdealLever
from acausal.mechanics.rotational import Fixed as RotFixed
from acausal.mechanics.rotational import Inertia, Torque, TorsionSpring


class RotaryArmature(Model):
    """Clapper armature on a fixed pivot: inertia ``Ja`` [kg*m^2], constant
    magnetic torque ``Te`` [N*m] turning it towards the hook (about -phi),
    reset torsion spring ``kr`` [N*m/rad] (unstretched at the start), striking
    pin at arm ``la`` [m] (``exact``: ``s = la*sin(phi)``, else ``la*phi``).
    At t = 0 the pin is at ``s = GAP0`` moving at ``-v0``.
    Connector: ``flange`` (translational, the pin). Variable ``v`` [m/s] the
    pin's speed along s."""

    def __init__(self, v0, exact=True, **kw):
        super().__init__(**kw)
        Ja = self.parameter("Ja", 1.0e-4, "kg*m^2", "clapper moment of inertia about its pivot",
                            min=0.0, min_open=True)
        la = self.parameter("la", 0.025, "m", "arm of the striking pin", min=0.0,
                            min_open=True)
        Te = self.parameter("Te", 4.0, "N*m", "magnetic torque during the impact", min=0.0)
        kr = self.parameter("kr", 0.01, "N*m/rad", "clapper reset-spring stiffness", min=0.0)
        if exact:
            phi0 = sp.asin(GAP0 / la)
            w0 = -v0 / (la * sp.cos(phi0))
        else:
            phi0, w0 = GAP0 / la, -v0 / la
        self.body = Inertia(J=Ja, phi=phi0, w=w0)
        self.coil = Torque(tau=-Te)
        self.reset = TorsionSpring(c=kr, phi_rel0=phi0)
        self.frame = RotFixed()
        self.lever = IdealLever(arm=la, exact=exact)
        self.connect(self.frame.flange, self.reset.flange_a)
        self.connect(self.reset.flange_b, self.body.flange, self.coil.flange,
                     self.lever.flange_r)
        self.flange = self.lever.flange_t
        v = self.variable("v", 0.0, "m/s", "pin speed along s")
        k = la * sp.cos(self.body.phi) if exact else la
        self.equation(v - k * self.body.w)


def build(v_impact=3.8, K=K_CAL, bh=BH_CAL, exact=True):
    """The base breaker with the clapper armature (base's K and bh)."""
    m = Model()
    v = m.parameter("v_impact", v_impact, "m/s", "pin speed at first contact",
                    min=0.0, min_open=True)
    Ra = m.parameter("Ra", math.radians(5.0), "rad", "release angle of the trigger hook",
                     min=0.0, min_open=True)
    m.armature = RotaryArmature(v, exact=exact)
    m.hook = TriggerHook()
    m.hook.set(bh=bh)
    m.contact = Contact(K=K, e=0.74, gamma=1.5, law="lankarani_nikravesh")
    m.cam = FourBar(theta1=guess(THETA1_0))
    m.main_shaft = MainShaft(fourbar_angles(THETA1_0)[1])
    m.connect(m.hook.point, m.contact.flange_a)
    m.connect(m.contact.flange_b, m.armature.flange)
    m.connect(m.hook.shaft, m.cam.flange_a)
    m.connect(m.cam.flange_b, m.main_shaft.shaft)
    m.Ra_sym = Ra
    return m


model = build()
free_parameters = dict(FREE_PARAMETERS)

experiment = release_experiment(model)

measures = {
    **MEASURES,
    "n_impacts": Measure(lambda res: ct.n_impacts(res, "contact"), "1",
                         desc="impacts between armature and hook"),
}
conditions = dict(CONDITIONS)


def plot(res, path):
    """Impact force, hook angle, hook velocity at s3, pin velocity and
    clapper angle; contact ends and release marked."""
    import numpy as np
    from acausal.viz.plot import plot_result
    t0 = t_first_contact(res)
    imp = ct.impacts(res, "contact")
    t_rel = t_release(res)
    s3 = float(res["hook.s3"][0])
    marks = [(i.t_release, f"contact {k + 1} end") for k, i in enumerate(imp)
             if i.t_release == i.t_release]
    return plot_result(
        res, ["contact.fc", "hook.phi", "hook.body.w", "armature.v", "armature.body.phi"],
        path,
        title=f"rotary armature (Ja {res['armature.Ja'][0]:.2e}, la "
              f"{res['armature.la'][0] * 1e3:.0f} mm), "
              f"v_impact = {ct.impact_velocity(res, 'contact'):.2f} m/s: {len(imp)} impact(s), "
              f"THRT {(t_rel - t0) * 1e3:.3f} ms",
        scales={"hook.phi": 180 / np.pi, "hook.body.w": s3,
                "armature.body.phi": 180 / np.pi},
        labels={"contact.fc": "contact force\n(>= 0) [N]", "hook.phi": "hook angle [deg]",
                "hook.body.w": "hook velocity\nat s3 [m/s]",
                "armature.v": "pin velocity [m/s]",
                "armature.body.phi": "clapper angle [deg]"},
        marks=marks + [(t_rel, "release")])
