"""Modelica.Mechanics.Rotational.Examples.Friction (MSL 4.0.0), with the
library alone: a drive train with a clutch and a brake. The motor torque
(200 sin(100 t) N*m) is switched off and the brake applied at 0.5 s.

    torque -> inertia3 -> clutch -> inertia2 -> spring (damper) -> brake -> inertia1

The clutch (fn_max = 160 N, tau0 = 80 N*m) starts sliding backward
(w_rel = 90 - 100 rad/s); the brake is free until 0.5 s, then slides
forward and sticks at 0.64 s.

Compared with the reference: clutch.phi_rel, clutch.w_rel, inertia3.phi,
inertia3.w, spring.phi_rel, spring.w_rel and the modes and start flags of
brake and clutch (tests/msl/test_friction_examples.py).
"""
import math

from acausal import Experiment, Model
from acausal.blocks.math import Product
from acausal.blocks.sources import Constant, Sine, Step
from acausal.mechanics.rotational import Brake, Clutch, Fixed, Inertia, SpringDamper, Torque

model = Model()
startTime = model.parameter("startTime", 0.5, "s", "start time of the steps")
model.torque = Torque(useSupport=True)
model.inertia3 = Inertia(J=1, phi=0, w=100)
model.clutch = Clutch(fn_max=160)
model.inertia2 = Inertia(J=0.05, phi=0, w=90)
model.spring = SpringDamper(c=160, d=1)
model.inertia1 = Inertia(J=1, phi=0, w=90)
model.brake = Brake(fn_max=1600, useSupport=True)
model.const = Constant(k=1)
model.step = Step(startTime=startTime)
model.step2 = Step(height=-1, offset=1, startTime=startTime)
model.sine = Sine(amplitude=200, f=50 / math.pi)
model.product = Product()
model.fixed = Fixed()

model.connect(model.torque.flange, model.inertia3.flange_a)
model.connect(model.inertia3.flange_b, model.clutch.flange_a)
model.connect(model.clutch.flange_b, model.inertia2.flange_a)
model.connect(model.inertia2.flange_b, model.spring.flange_a)
model.connect(model.spring.flange_b, model.brake.flange_a)
model.connect(model.brake.flange_b, model.inertia1.flange_a)
model.connect(model.sine.y, model.product.u1)
model.connect(model.step2.y, model.product.u2)
model.connect(model.product.y, model.torque.tau)
model.connect(model.const.y, model.clutch.f_normalized)
model.connect(model.step.y, model.brake.f_normalized)
model.connect(model.torque.support, model.fixed.flange)
model.connect(model.brake.support, model.fixed.flange)

experiment = Experiment(t_end=3.0, rtol=1e-6, output_step=5e-4)
