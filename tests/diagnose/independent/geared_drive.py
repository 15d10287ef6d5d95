"""A geared drive, written as a user would with the library: a motor
(rotor inertia ``Jm``) delivers a constant torque ``tau_m`` (the
experiment's condition), switched on at t = 0, through a reduction gear
(ratio 5) to a load inertia that a return spring holds at zero; a viscous
loss at the load's bearing damps the swing. Released at rest, the load
swings about the angle ``5 tau_m / c`` where motor torque and spring
balance, and rings down.

The return spring's rate and the load bearing's viscous coefficient are
the free parameters a user would calibrate. Measured: the load angle (an
encoder on the output shaft). Used by the independent blind cases
(``tests/diagnose/independent/``) with data from a scipy simulator that
shares no code with the library (``gear_truth.py``)."""
from acausal import Experiment, Model
from acausal.mechanics.rotational import (Fixed, IdealGear, Inertia, RotationalDamper, Torque,
                                          TorsionSpring)

model = Model()
tau_m = model.parameter("tau_m", 0.1, "N*m", "motor torque, switched on at t = 0")
model.frame = Fixed()
# (a ConstantTorque here stops the diagnosis on today's main: its hypothesis
# position_dependent_force reads the source's `quantity`, which ConstantTorque lacks)
model.drive = Torque(tau_m)
model.motor = Inertia(J=2e-4, phi=0.0, w=0.0)
model.gear = IdealGear(ratio=5.0)
model.load = Inertia(J=5e-3)
model.spring = TorsionSpring(c=2.0)
model.bearing = RotationalDamper(d=2e-3)
model.connect(model.drive.flange, model.motor.flange_a)
model.connect(model.motor.flange_b, model.gear.flange_a)
model.connect(model.gear.flange_b, model.load.flange_a)
model.connect(model.frame.flange, model.spring.flange_a, model.bearing.flange_a)
model.connect(model.spring.flange_b, model.bearing.flange_b, model.load.flange_b)

free_parameters = {"spring.c": (1.0, 4.0), "bearing.d": (0.0, 2e-2)}
conditions = {"tau_m": (0.02, 0.2, "N*m")}

experiment = Experiment(t_end=3.0, rtol=1e-8, atol=1e-10, output_step=1e-3)
