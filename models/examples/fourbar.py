"""The breaker's trigger cam and roller (report section 2.4) as a four-bar
linkage between the trigger-hook shaft and the main shaft, up to the hook's
release angle.

* hook: inertia Jh = 0.00044 kg m^2 (Table 1), starting at the latched
  position with the speed it got from the armature's impact (assumed
  3 rad/s; reset spring and friction left out to show the linkage alone);
* linkage: e, f, r1, r2, r3 from Table 1; theta1 = hook.phi (theta1 = 0 at
  the latch is an assumption: the report does not give it); the main shaft
  angle is measured from its latched position (theta3_offset = eq. 10 at
  theta1 = 0);
* main shaft: inertia Js = 0.02 kg m^2 (an assumption: not in Table 1) and
  the open and wipe springs as one torsion spring, c = ko s1^2 + kw s2^2 =
  2567 N m/rad, preloaded (assumed 0.035 rad, about 90 N m) so that it
  presses the roller on the cam (coupler force Fc > 0, compression).

The report's eccentricity e = 0.2 mm makes the velocity ratio tiny
(|dtheta3/dtheta1| about 0.0015): the spring's torque reaches the hook as a
torque of about Fc * e, and the main shaft turns by about 1e-4 rad while the
hook turns to the release angle Ra = 5 deg.
"""
import math

from acausal import Experiment, Measure, Model, Stop
from acausal.mechanics.fourbar import FourBar, fourbar_angles
from acausal.mechanics.rotational import Fixed, Inertia, TorsionSpring

TABLE1 = dict(e=0.0002, f=0.125, r1=0.116, r2=0.036, r3=0.0533)
JH = 0.00044                       # hook inertia [kg m^2], Table 1
JS = 0.02                          # main-shaft inertia [kg m^2], assumption
C_SHAFT = 7.0e4 * 0.091**2 + 2.4e5 * 0.091**2   # ko s1^2 + kw s2^2 [N m/rad]
PRELOAD = 0.035                    # spring preload angle [rad], assumption
W_HOOK = 3.0                       # hook speed after the impact [rad/s], assumption
RA = math.radians(5.0)             # release angle of the trigger hook (Table 1)

theta3_latched = fourbar_angles(0.0, **TABLE1)[1]

model = Model()
model.hook = Inertia(J=JH, phi=0.0, w=W_HOOK)
model.cam = FourBar(theta1_offset=0.0, theta3_offset=theta3_latched, **TABLE1)
model.shaft = Inertia(J=JS)
model.springs = TorsionSpring(c=C_SHAFT, phi_rel0=-PRELOAD)
model.ground = Fixed()
model.connect(model.hook.flange, model.cam.flange_a)
model.connect(model.cam.flange_b, model.shaft.flange, model.springs.flange_b)
model.connect(model.ground.flange, model.springs.flange_a)

experiment = Experiment(t_end=0.1, rtol=1e-9, atol=1e-12, output_step=1e-4,
                        stop=Stop("hook.phi", ">=", RA, name="released"))


def _released_at(res):
    names = [n for _, n in res.events]
    return res.events[names.index("released")][0] if "released" in names else float("nan")


measures = {
    "t_release_s": Measure(_released_at, "s", display="ms"),
    "theta3_at_release_rad": Measure(lambda res: res.final()["shaft.phi"], "rad"),
    "max_abs_ratio": Measure(lambda res: max(abs(res["cam.ratio"])), "1"),
    "Fc_start_N": Measure(lambda res: res["cam.Fc"][0], "N"),
    "hook_w_at_release": Measure(lambda res: res.final()["hook.w"], "rad/s"),
}
