"""Analyses of a compiled model that are not simulations: linearisation
and trim (static equilibrium), :mod:`.linearize`.

The layer sits above :mod:`acausal.runtime`: it reads the compiled model's
DAE and generated Jacobians (:mod:`acausal.compiler`), and takes its
operating points from the runtime (the consistent start after the event
iteration, a simulated state, the re-initialisation of the algebraic
unknowns). :mod:`acausal.cli` and :mod:`acausal.studies` may import it; it
imports neither.
"""
from .linearize import Equilibrium, Linearization, RunSettings, linearize, trim

__all__ = ["linearize", "trim", "Linearization", "Equilibrium", "RunSettings"]
