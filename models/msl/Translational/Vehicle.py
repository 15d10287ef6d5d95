"""Modelica.Mechanics.Translational.Examples.Vehicle (MSL 4.0.0), with the
library alone: a 100 kg vehicle driven along a drive cycle (a time table
of normalised torque and inclination), and the same vehicle pulling a
trailer with twice the torque through a multi-sensor.

As in MSL, the model's rho = 1.18 enters only the torque gain: the
vehicles keep their own default air density, 1.2 kg/m^3.

Compared with the reference: vehicle.s, vehicle.v, vehicle1.s,
vehicle1.v, trailer.s, trailer.v (tests/msl/test_parts_examples.py).
"""
import math

from acausal import Experiment, Model
from acausal.blocks import CombiTimeTable, Gain
from acausal.mechanics.rotational import Torque
from acausal.mechanics.translational import MultiSensor, Vehicle
from acausal.mechanics.translational.components import G_N

m = 100.0            # mass of vehicle [kg]
R = 0.25             # radius of wheel [m]
A = 1.0              # cross section of vehicle [m2]
Cd = 0.5             # drag resistance coefficient
rho = 1.18           # density of air [kg/m3]
vWind = 0.0          # constant wind velocity [m/s]
Cr = 0.01            # rolling resistance coefficient
inclination = 0.0    # constant inclination = tan(angle)
vNom = 25 / 3.5      # nominal velocity [m/s]
fDrag = Cd * A * rho * (vNom - vWind) ** 2 / 2      # drag resistance [N]
alpha = math.atan(inclination)                      # inclination angle [rad]
fRoll = Cr * m * G_N * math.cos(alpha)              # roll resistance [N]
fGrav = m * G_N * math.sin(alpha)                   # grav resistance [N]

model = Model()
model.vehicle = Vehicle(m=m, J=0, R=R, A=A, Cd=Cd, CrConstant=Cr, vWindConstant=vWind,
                        useInclinationInput=True, s=0, v=0)
model.vehicle1 = Vehicle(m=m, J=0, R=R, A=A, Cd=Cd, CrConstant=Cr, vWindConstant=vWind,
                         useInclinationInput=True, s=0, v=0)
model.trailer = Vehicle(m=m, J=0, R=R, A=A, Cd=Cd, CrConstant=Cr, vWindConstant=vWind,
                        useInclinationInput=True)
model.multiSensor = MultiSensor()
model.timeTableTorqueInclination = CombiTimeTable(
    table=[[0, 0, 0], [5, 0, 0], [5, 5.6, 0], [10.8, 5.6, 0], [10.8, 1, 0], [20, 1, 0],
           [20, 2.8, 0.05], [25, 2.8, 0.05], [25, 1, 0], [50, 1, 0], [50, -5, 0],
           [55, -5, 0], [55, 0, 0], [60, 0, 0]],
    extrapolation="HoldLastPoint")
model.torque = Torque()
model.torque1 = Torque()
model.gain = Gain(k=(fDrag + fRoll + fGrav) * R)
model.gain1 = Gain(k=2)

model.connect(model.timeTableTorqueInclination.y1, model.gain.u)
model.connect(model.timeTableTorqueInclination.y2, model.vehicle.inclination)
model.connect(model.gain.y, model.torque.tau)
model.connect(model.torque.flange, model.vehicle.flangeR)
model.connect(model.torque1.flange, model.vehicle1.flangeR)
model.connect(model.vehicle.inclination, model.vehicle1.inclination)
model.connect(model.vehicle1.inclination, model.trailer.inclination)
model.connect(model.gain.y, model.gain1.u)
model.connect(model.gain1.y, model.torque1.tau)
model.connect(model.vehicle1.flangeT, model.multiSensor.flange_a)
model.connect(model.multiSensor.flange_b, model.trailer.flangeT)

experiment = Experiment(t_end=60.0, rtol=1e-6, output_step=5e-3)
