"""Variant of the 24 kV breaker (models/breaker_24kv.py): a toggle latch.
The cam and roller (a 0.2 mm eccentric on the hook shaft, Table 1) is
replaced by a real two-link toggle: a link ``l2`` on the hook shaft and a
coupler ``l1`` to the main shaft's roller lever ``r1``, nearly in line (the
knee just over its dead centre). The armature, contact, hook and main shaft
are the base design's; only the linkage between hook and main shaft
changes. The 1-D library could not express this: the closed-form FourBar is
the report's cam only, and the toggle's torque on the hook changes sign as
the knee passes the dead centre.

Geometry, in the planar breaker's frame (models/breaker_24kv_planar.py: the
report's Fig. 5 mirrored, y down, A the main shaft at the origin, O the hook
shaft at (f, 0))::

                    C (roller lever end, latched: the base's C0)
       rocker r1   /  \\  coupler l1
                  /    o K (knee)
                 /      \\ l2 (on the hook)
     A o------------------o O        at the dead centre O, K, C are in line:
                                     l1 + l2 = |O C0|

* the hook link starts ``over_centre`` (default 1 deg) past the line O-C0
  on the locking side (the knee's angle, :func:`knee_angle`, is then
  (1 + l2/l1) over_centre = 1.39 deg): the main-shaft load (14.6 kN preload) then pushes the hook
  against the trip (a resisting torque of about F l2 sin(over_centre), 5 N*m),
  until the hook has turned by ``over_centre``; past the dead centre the
  same load drives the hook towards release (about 20 N*m at 5 deg);
* the main shaft starts where the loop closes at the latched hook angle
  (within 0.003 deg of the base's), with the base's preloads there.

Default values: l2 = 25 mm, l1 = |O C0| - l2 = 64.4 mm, over_centre =
1 deg. The loop is a :class:`~acausal.mechanics.planar.linkages.FourBarLinkage`
(``cam``): crank ``a = l2`` on the hook shaft, rocker ``b = r1`` on the main
shaft, coupler ``c = l1``. Sign convention, run and measures: the base
file's (the hook angle decreases to -Ra at release).
Run: ``acausal simulate models/breaker_24kv_toggle.py --plot FILE``.
"""
import math

from breaker_24kv import (BH_CAL, CONDITIONS, FREE_PARAMETERS, K_CAL, MEASURES, THETA1_0,
                          Armature, MainShaft, TriggerHook, release_experiment,
                          t_first_contact, t_release)
from breaker_24kv_planar import TABLE1

from acausal import Measure, Model
from acausal.mechanics import contact as ct
from acausal.mechanics.contact import Contact
from acausal.mechanics.fourbar import fourbar_angles
from acausal.mechanics.planar.linkages import FourBarLinkage, fourbar_assembly

L2 = 0.025                         # [m] toggle link on the hook shaft
OVER_CENTRE = math.radians(1.0)    # [rad] the knee past its dead centre when latched


def toggle_geometry(l2=L2, over_centre=OVER_CENTRE, g=TABLE1):
    """The toggle's FourBarLinkage geometry (a dict of its parameters): the
    base's pivots, rocker and latched roller centre C0; l1 = |O C0| - l2;
    the hook link's zero direction over the dead centre by ``over_centre``
    (positive: the hook's trip direction, decreasing angle, brings the knee
    back through the dead centre)."""
    th3 = fourbar_angles(THETA1_0)[1]
    c0 = (g["r1"] * math.cos(th3), g["r1"] * math.sin(th3))
    oc = (c0[0] - g["f"], c0[1])
    dead = math.atan2(oc[1], oc[0])               # direction O -> C0 (the line of the toggle)
    return dict(xa=g["f"], ya=0.0, phia=dead + over_centre, xb=0.0, yb=0.0, phib=0.0, a=l2,
                b=g["r1"], c=math.hypot(*oc) - l2)


def build(v_impact=3.8, K=K_CAL, bh=BH_CAL, l2=L2, over_centre=OVER_CENTRE):
    """The base breaker with the toggle latch between hook and main shaft."""
    m = Model()
    v = m.parameter("v_impact", v_impact, "m/s", "armature speed at first contact",
                    min=0.0, min_open=True)
    Ra = m.parameter("Ra", math.radians(5.0), "rad", "release angle of the trigger hook",
                     min=0.0, min_open=True)
    geo = toggle_geometry(l2, over_centre)
    th3_latched = fourbar_assembly(THETA1_0, 1, **geo)[0]
    m.armature = Armature(v)
    m.hook = TriggerHook()
    m.hook.set(bh=bh)
    m.contact = Contact(K=K, e=0.74, gamma=1.5, law="lankarani_nikravesh")
    m.cam = FourBarLinkage(theta_a0=THETA1_0, mode=1, **geo)
    m.main_shaft = MainShaft(th3_latched)
    m.connect(m.hook.point, m.contact.flange_a)
    m.connect(m.contact.flange_b, m.armature.flange)
    m.connect(m.hook.shaft, m.cam.flange_a)
    m.connect(m.cam.flange_b, m.main_shaft.shaft)
    m.Ra_sym = Ra
    return m


def knee_angle(res):
    """The knee's angle past its dead centre [rad] along a result: the angle
    between hook link and coupler at the knee K, less pi; positive on the
    locking side (about (1 + l2/l1) over_centre when latched)."""
    import numpy as np
    bend = res["cam.pin_d.phi"] + math.pi          # 0 (mod 2 pi) when straight
    return -(np.mod(bend + math.pi, 2 * math.pi) - math.pi)


def toggle_torque(res):
    """Torque of the toggle on the hook [N*m] along a result (positive:
    against the trip, which turns the hook to negative angles)."""
    return -res["cam.pin_a.axis.tau"]


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
    """Contact force, hook angle, the toggle's torque on the hook (positive:
    against the trip) and the hook speed; contact end and release marked."""
    import numpy as np
    from acausal.viz.plot import plot_result
    t0 = t_first_contact(res)
    imp = ct.impacts(res, "contact")[0]
    t_rel = t_release(res)
    return plot_result(
        res, ["contact.fc", "hook.phi", "cam.pin_a.axis.tau", "hook.body.w"], path,
        title=f"toggle latch, v_impact = {ct.impact_velocity(res, 'contact'):.2f} m/s: contact "
              f"{(imp.t_release - t0) * 1e3:.3f} ms, THRT {(t_rel - t0) * 1e3:.3f} ms",
        scales={"hook.phi": 180 / np.pi, "cam.pin_a.axis.tau": -1.0},
        labels={"contact.fc": "contact force\n(>= 0) [N]", "hook.phi": "hook angle [deg]",
                "cam.pin_a.axis.tau": "toggle torque\non hook [N*m]",
                "hook.body.w": "hook speed\n[rad/s]"},
        marks=[(imp.t_release, "contact end"), (t_rel, "release (THRT)")])
