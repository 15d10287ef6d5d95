"""Modelica.Mechanics.Translational.Examples.Sensors (MSL 4.0.0), with the
library alone: a sine force drives a mass of length 1 through a force
sensor and a multi-sensor; position, speed and acceleration sensors
watch the mass's flanges.

Compared with the reference: mass.s, mass.v (the sensors' outputs are
not compared; tests/msl/test_parts_examples.py checks them against the
mass).
"""
from acausal import Experiment, Model
from acausal.blocks import Sine
from acausal.mechanics.translational import (AccSensor, Force, ForceSensor, Mass, MultiSensor,
                                             PositionSensor, SpeedSensor)

model = Model()
model.forceSensor = ForceSensor()
model.multiSensor = MultiSensor()
model.speedSensor1 = SpeedSensor()
model.positionSensor1 = PositionSensor()
model.accSensor1 = AccSensor()
model.positionSensor2 = PositionSensor()
model.mass = Mass(L=1, s=0, v=0, m=1)
model.force = Force()
model.sineForce = Sine(amplitude=10, f=4)

model.connect(model.sineForce.y, model.force.f)
model.connect(model.forceSensor.flange_a, model.force.flange)
model.connect(model.mass.flange_a, model.positionSensor1.flange)
model.connect(model.mass.flange_a, model.speedSensor1.flange)
model.connect(model.mass.flange_a, model.accSensor1.flange)
model.connect(model.mass.flange_b, model.positionSensor2.flange)
model.connect(model.forceSensor.flange_b, model.multiSensor.flange_a)
model.connect(model.multiSensor.flange_b, model.mass.flange_a)

experiment = Experiment(t_end=1.0, rtol=1e-6, output_step=5e-4)
