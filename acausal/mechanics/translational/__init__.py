"""Translational (1-D) mechanics: components, sources and sensors (MSL
``Modelica.Mechanics.Translational``).

Sign convention: :mod:`acausal.connectors` (through variables positive INTO
the component; positions along one +s axis). Two-flange elements report
``f`` = ``flange_b.f``, positive when the element is in tension (pulled
apart), and ``s_rel = flange_b.s - flange_a.s``.

Several components may be connected to one flange (the forces of everything
connected to it add up there).
"""
from .components import (Fixed, Mass, Rod, Spring, Damper, SpringDamper, ElastoGap,
                         RollingResistance, Vehicle, RelativeStates)
from ..rotational.components import IdealGearR2T, IdealRollingWheel
from .sources import (Force, Force2, RelativeForce, ConstantForce, SignForce,
                      QuadraticSpeedDependentForce, LinearSpeedDependentForce, ForceStep,
                      Position, Speed, Accelerate, Move)
from .sensors import (PositionSensor, SpeedSensor, AccSensor, ForceSensor, PowerSensor,
                      MultiSensor, RelPositionSensor, RelSpeedSensor, RelAccSensor)

__all__ = ["Fixed", "Mass", "Rod", "Spring", "Damper", "SpringDamper", "ElastoGap",
           "RollingResistance", "Vehicle", "RelativeStates", "IdealGearR2T", "IdealRollingWheel", "Force",
           "Force2", "RelativeForce", "ConstantForce", "SignForce",
           "QuadraticSpeedDependentForce", "LinearSpeedDependentForce", "ForceStep", "Position",
           "Speed", "Accelerate", "Move", "PositionSensor", "SpeedSensor", "AccSensor",
           "ForceSensor", "PowerSensor", "MultiSensor", "RelPositionSensor", "RelSpeedSensor",
           "RelAccSensor"]

# friction elements on the shared mode machine (acausal.mechanics.frictionmodes)
from .friction import SupportFriction, Brake, MassWithStopAndFriction, stribeck_table  # noqa: E402

__all__ += ["SupportFriction", "Brake", "MassWithStopAndFriction", "stribeck_table"]
