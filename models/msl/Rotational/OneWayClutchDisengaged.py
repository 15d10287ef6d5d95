"""Modelica.Mechanics.Rotational.Examples.OneWayClutchDisengaged (MSL
4.0.0), with the library alone: a one-way clutch that is never engaged
(normal force 0): it freewheels while the input turns backward relative to
the output and locks when the relative speed reaches zero; a small
forward torque (1e-4 of the engaged break-away) starts it slipping again.

    torque(0.3 + 10 sin(2 pi 2 t)) -> inertiaIn -> oneWayClutch -> inertiaOut <- load -0.3 N*m

inertiaIn starts at -0.5 rad/s, inertiaOut at rest; the clutch starts
slipping (MSL's startForward and stuck fixed at false).

Compared with the reference: inertiaIn.phi, inertiaIn.w,
oneWayClutch.phi_rel, oneWayClutch.w_rel (tests/msl/test_unlisted_examples.py).
"""
from acausal import Experiment, Model
from acausal.blocks.sources import Constant, Sine
from acausal.mechanics.rotational import ConstantTorque, Inertia, OneWayClutch, Torque

model = Model()
model.inertiaIn = Inertia(J=1, phi=0, w=-0.5)
model.inertiaOut = Inertia(J=1, phi=0, w=0)
model.oneWayClutch = OneWayClutch(peak=25, fn_max=3)
model.torque = Torque()
model.torqueLoad = ConstantTorque(tau_constant=-0.3)
model.signalTorque = Sine(amplitude=10, offset=0.3, f=2)
model.signalEngagement = Constant(k=0)

model.connect(model.torque.flange, model.inertiaIn.flange_a)
model.connect(model.signalTorque.y, model.torque.tau)
model.connect(model.inertiaIn.flange_b, model.oneWayClutch.flange_a)
model.connect(model.oneWayClutch.flange_b, model.inertiaOut.flange_a)
model.connect(model.signalEngagement.y, model.oneWayClutch.f_normalized)
model.connect(model.inertiaOut.flange_b, model.torqueLoad.flange)

experiment = Experiment(t_end=2.0, rtol=1e-6, output_step=5e-4)
