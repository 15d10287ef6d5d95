"""Modelica.Mechanics.Rotational.Examples.OneWayClutch (MSL 4.0.0), with
the library alone: a drive train with a one-way clutch, engaged by a pulse
(1 for 0.65 s of every 1.3 s from 0.3 s on) while a sine torque (10 N*m,
3 Hz) drives the input inertia.

    torque -> inertiaIn -> oneWayClutch -> inertiaOut

The freewheel never lets w_rel = w_out - w_in become negative; engaged,
the clutch also drags the output along when it overruns.

Compared with the reference: inertiaIn.phi, inertiaIn.w,
oneWayClutch.phi_rel, oneWayClutch.w_rel
(tests/msl/test_friction_examples.py).
"""
from acausal import Experiment, Model
from acausal.blocks.sources import Pulse, Sine
from acausal.mechanics.rotational import Inertia, OneWayClutch, Torque

model = Model()
model.inertiaIn = Inertia(J=1, phi=0, w=-0.5)
model.inertiaOut = Inertia(J=1, phi=0, w=0)
model.oneWayClutch = OneWayClutch(peak=25, fn_max=3)
model.torque = Torque()
model.signalTorque = Sine(amplitude=10, f=3)
model.signalEngagement = Pulse(amplitude=1, width=50, period=1.3, startTime=0.3)

model.connect(model.torque.flange, model.inertiaIn.flange_a)
model.connect(model.signalTorque.y, model.torque.tau)
model.connect(model.inertiaIn.flange_b, model.oneWayClutch.flange_a)
model.connect(model.oneWayClutch.flange_b, model.inertiaOut.flange_a)
model.connect(model.signalEngagement.y, model.oneWayClutch.f_normalized)

experiment = Experiment(t_end=2.0, rtol=1e-6, output_step=5e-4)
