"""A torsion rig, written as a user would with the library: an inertia on a
torsion spring with a viscous damper, released at rest from the angle
``phi_start`` and ringing down (about 16 cycles at 10 Hz). The spring's
stiffness and the damper's coefficient are the free parameters a user
would calibrate. Used by the blind tests with data from an independent
scipy simulator (tests/diagnose/rig_truth.py)."""
from acausal import Experiment, Model
from acausal.mechanics.rotational import Fixed, Inertia, RotationalDamper, TorsionSpring

model = Model()
phi_start = model.parameter("phi_start", 0.4, "rad", "release angle")
model.frame = Fixed()
model.rotor = Inertia(J=1e-3, phi=phi_start, w=0.0)
model.spring = TorsionSpring(c=4.0)
model.damper = RotationalDamper(d=1.5e-3)
model.connect(model.frame.flange, model.spring.flange_a, model.damper.flange_a)
model.connect(model.spring.flange_b, model.damper.flange_b, model.rotor.flange)

free_parameters = {"spring.c": (2.0, 8.0), "damper.d": (0.0, 1e-2)}

experiment = Experiment(t_end=1.6, rtol=1e-7, atol=1e-9, output_step=5e-4)
