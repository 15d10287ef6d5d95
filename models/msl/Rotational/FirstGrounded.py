"""Modelica.Mechanics.Rotational.Examples.FirstGrounded (MSL 4.0.0), with
the library alone: First with the torque source and the gear grounded
internally (useSupport=False) instead of through their support flanges.

Compared with the reference: damper.phi_rel, damper.w_rel, inertia3.phi,
inertia3.w (tests/msl/test_parts_examples.py).
"""
from acausal import Experiment, Model
from acausal.blocks import Sine
from acausal.mechanics.rotational import Damper, Fixed, IdealGear, Inertia, Spring, Torque

amplitude = 10.0   # amplitude of driving torque [N.m]
f = 5.0            # frequency of driving torque [Hz]
Jmotor = 0.1       # motor inertia [kg.m2]
Jload = 2.0        # load inertia [kg.m2]
ratio = 10.0       # gear ratio
damping = 10.0     # damping in bearing of gear [N.m.s/rad]

model = Model()
model.fixed = Fixed()
model.torque = Torque(useSupport=False)
model.inertia1 = Inertia(J=Jmotor)
model.idealGear = IdealGear(ratio=ratio, useSupport=False)
model.inertia2 = Inertia(J=2, phi=0, w=0)
model.spring = Spring(c=1e4, phi_rel=0)
model.inertia3 = Inertia(J=Jload, w=0)
model.damper = Damper(d=damping)
model.sine = Sine(amplitude=amplitude, f=f)

model.connect(model.inertia1.flange_b, model.idealGear.flange_a)
model.connect(model.idealGear.flange_b, model.inertia2.flange_a)
model.connect(model.inertia2.flange_b, model.spring.flange_a)
model.connect(model.spring.flange_b, model.inertia3.flange_a)
model.connect(model.damper.flange_a, model.inertia2.flange_b)
model.connect(model.damper.flange_b, model.fixed.flange)
model.connect(model.sine.y, model.torque.tau)
model.connect(model.torque.flange, model.inertia1.flange_a)

experiment = Experiment(t_end=1.0, rtol=1e-6, output_step=5e-4)
