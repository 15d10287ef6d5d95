"""Translational (1-D) mechanics: components, sources and sensors.

Sign convention: :mod:`acausal.connectors` (through variables positive INTO
the component; positions along one +s axis). Two-flange elements report
``f`` = ``flange_b.f``, positive when the element is in tension (pulled
apart), and ``s_rel = flange_b.s - flange_a.s``.

Several components may be connected to one flange (a mass has a single
flange; the forces of everything connected to it add up there).
"""
from .components import Fixed, Mass, Spring, Damper, SpringDamper
from .sources import Force, RelativeForce, Position
from .sensors import PositionSensor, SpeedSensor, AccSensor, ForceSensor, RelPositionSensor, RelSpeedSensor

__all__ = ["Fixed", "Mass", "Spring", "Damper", "SpringDamper", "Force", "RelativeForce", "Position", "PositionSensor", "SpeedSensor", "AccSensor", "ForceSensor", "RelPositionSensor", "RelSpeedSensor"]
