"""Rotational (1-D) mechanics: components, sources and sensors (MSL
``Modelica.Mechanics.Rotational``).

Sign convention: :mod:`acausal.connectors` (torques positive INTO the
component; angles about one positive axis). Two-flange elements report
``tau`` = ``flange_b.tau`` (positive when the element is twisted
positively, ``phi_rel > phi_rel0`` for a spring) and
``phi_rel = flange_b.phi - flange_a.phi``.

Several components may be connected to one flange (the torques of
everything connected to it add up there).
"""
from .components import (Fixed, Inertia, Disc, TorsionSpring, RotationalDamper, SpringDamper,
                         Spring, Damper, ElastoBacklash, ElastoBacklash2, IdealGear,
                         IdealGearR2T, IdealRollingWheel, RelativeStates)
from .sources import (Torque, Torque2, RelativeTorque, ConstantTorque, SignTorque,
                      QuadraticSpeedDependentTorque, LinearSpeedDependentTorque, TorqueStep, Angle,
                      Position, Speed, Accelerate, Move)
from .sensors import (AngleSensor, SpeedSensor, AccSensor, TorqueSensor, PowerSensor, MultiSensor,
                      RelAngleSensor, RelSpeedSensor, RelAccSensor)

__all__ = ["Fixed", "Inertia", "Disc", "RelativeStates", "TorsionSpring", "RotationalDamper",
           "SpringDamper", "Spring", "Damper", "ElastoBacklash", "ElastoBacklash2", "IdealGear",
           "IdealGearR2T", "IdealRollingWheel", "Torque", "Torque2", "RelativeTorque",
           "ConstantTorque", "SignTorque", "QuadraticSpeedDependentTorque",
           "LinearSpeedDependentTorque", "TorqueStep", "Angle", "Position", "Speed", "Accelerate",
           "Move", "AngleSensor", "SpeedSensor", "AccSensor", "TorqueSensor", "PowerSensor",
           "MultiSensor", "RelAngleSensor", "RelSpeedSensor", "RelAccSensor"]

# friction elements on the shared mode machine (acausal.mechanics.frictionmodes)
from .friction import BearingFriction, Brake, Clutch, OneWayClutch, LossyGear  # noqa: E402
from .planetary import IdealPlanetary  # noqa: E402

__all__ += ["BearingFriction", "Brake", "Clutch", "OneWayClutch", "LossyGear", "IdealPlanetary"]
