"""Causal blocks (MSL ``Modelica.Blocks``): signal connectors, partial
blocks (:mod:`.interfaces`), signal sources (:mod:`.sources`) and time
tables (:mod:`.tables`)."""
from .interfaces import SI, SISO, SO, RealInput, RealOutput, SignalSource
from .sources import (Constant, Cosine, Exponentials, ExpSine, Pulse, Ramp, RealExpression,
                      SawTooth, Sine, Step, Trapezoid)
from .tables import CombiTimeTable

__all__ = ["RealInput", "RealOutput", "SO", "SI", "SISO", "SignalSource", "Constant", "Step",
           "Ramp", "Sine", "Cosine", "ExpSine", "Exponentials", "Pulse", "SawTooth",
           "Trapezoid", "RealExpression", "CombiTimeTable"]
