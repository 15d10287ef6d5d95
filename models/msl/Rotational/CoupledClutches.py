"""Modelica.Mechanics.Rotational.Examples.CoupledClutches (MSL 4.0.0), with
the library alone: a drive train of four inertias and three clutches
switched by their normal-force inputs (2^3 configurations, 3^3 modes).

    torque(10 sin(2 pi 5 t)) -> J1 -> clutch1 -> J2 -> clutch2 -> J3 -> clutch3 -> J4

clutch1's normal force is sin(2 pi 0.2 t + pi/2) (released at 1.25 s),
clutch2 closes at T2 = 0.4 s, clutch3 at T3 = 0.9 s; J1 starts at 10 rad/s.

Compared with the reference: J1.phi, J1.w, the clutches' phi_rel, w_rel,
mode, startForward and startBackward (tests/msl/test_unlisted_examples.py).
"""
from acausal import Experiment, Model
from acausal.blocks.sources import Sine, Step
from acausal.mechanics.rotational import Clutch, Fixed, Inertia, Torque

model = Model()
f = model.parameter("f", 0.2, "Hz", "frequency of sine function to invoke clutch1")
T2 = model.parameter("T2", 0.4, "s", "time when clutch2 is invoked")
T3 = model.parameter("T3", 0.9, "s", "time when clutch3 is invoked")
model.J1 = Inertia(J=1, phi=0, w=10)
model.torque = Torque(useSupport=True)
model.clutch1 = Clutch(peak=1.1, fn_max=20)
model.sin1 = Sine(amplitude=10, f=5)
model.step1 = Step(startTime=T2)
model.J2 = Inertia(J=1, phi=0, w=0)
model.clutch2 = Clutch(peak=1.1, fn_max=20)
model.J3 = Inertia(J=1, phi=0, w=0)
model.clutch3 = Clutch(peak=1.1, fn_max=20)
model.J4 = Inertia(J=1, phi=0, w=0)
model.sin2 = Sine(amplitude=1, f=f, phase=1.570796326794897)
model.step2 = Step(startTime=T3)
model.fixed = Fixed()

model.connect(model.torque.flange, model.J1.flange_a)
model.connect(model.J1.flange_b, model.clutch1.flange_a)
model.connect(model.clutch1.flange_b, model.J2.flange_a)
model.connect(model.J2.flange_b, model.clutch2.flange_a)
model.connect(model.clutch2.flange_b, model.J3.flange_a)
model.connect(model.J3.flange_b, model.clutch3.flange_a)
model.connect(model.clutch3.flange_b, model.J4.flange_a)
model.connect(model.sin1.y, model.torque.tau)
model.connect(model.sin2.y, model.clutch1.f_normalized)
model.connect(model.step1.y, model.clutch2.f_normalized)
model.connect(model.step2.y, model.clutch3.f_normalized)
model.connect(model.fixed.flange, model.torque.support)

experiment = Experiment(t_end=1.5, rtol=1e-6, output_step=5e-4)
