"""Causal blocks (MSL ``Modelica.Blocks``): signal connectors, partial
blocks (:mod:`.interfaces`) and signal sources (:mod:`.sources`)."""
from .interfaces import SI, SISO, SO, RealInput, RealOutput, SignalSource

__all__ = ["RealInput", "RealOutput", "SO", "SI", "SISO", "SignalSource"]
