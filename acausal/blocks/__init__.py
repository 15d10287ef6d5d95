"""Causal blocks (MSL ``Modelica.Blocks``): signal connectors, partial
blocks (:mod:`.interfaces`), signal sources (:mod:`.sources`), time
tables (:mod:`.tables`) and mathematical blocks (:mod:`.math`)."""
from .interfaces import SI, SISO, SO, RealInput, RealOutput, SignalSource
from .sources import (Constant, Cosine, Exponentials, ExpSine, Pulse, Ramp, RealExpression,
                      SawTooth, Sine, Step, Trapezoid)
from .tables import CombiTimeTable
from .math import Abs, Add, Atan, Cos, Division, Feedback, Gain, Product, Sin

__all__ = ["RealInput", "RealOutput", "SO", "SI", "SISO", "SignalSource", "Constant", "Step",
           "Ramp", "Sine", "Cosine", "ExpSine", "Exponentials", "Pulse", "SawTooth",
           "Trapezoid", "RealExpression", "CombiTimeTable", "Gain", "Add", "Feedback", "Product",
           "Division", "Abs", "Sin", "Cos", "Atan"]
