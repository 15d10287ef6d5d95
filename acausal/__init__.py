"""acausal: equation-based (Modelica-style) simulation of mechanisms.

The public face. The layers, bottom up (docs/architecture.md):
:mod:`.errors`; :mod:`.infra` (store, checkpoints, executors); :mod:`.data`
(measured data); :mod:`.lang` (the modelling language); :mod:`.mechanics`
(the component library); :mod:`.compiler` (flatten -> aliases -> structure
-> causalize -> codegen); :mod:`.runtime` (the hybrid loop around IDA);
:mod:`.viz`; :mod:`.modelfile`; :mod:`.studies` (calibrate, profile,
design, sweep); :mod:`.diagnose`; :mod:`.cli`.
"""
from .infra import startup as _startup

if _startup.is_command():   # first thing: a signal while the command imports is one line
    _startup.guard()

from sympy import Piecewise, cos, exp, sin, sqrt  # noqa: E402,F401  (for model files)

from .lang.component import Component, Model
from .runtime.model import CompiledModel, compile_model
from .lang.connectors import Flange, Frame, Port, RotFlange
from .lang.declare import Assertion, Discrete, Event, Parameter, Start, Variable, guess
from .lang.experiment import Experiment, Measure, Stop
from .errors import (AcausalError, ChatteringError, InitializationError, LimitError, ModelError,
                     ParameterError, SolverError, StructuralError)
from .lang.symbols import Eq, der, time

__all__ = [
    "Component", "Model", "CompiledModel", "compile_model", "Flange", "RotFlange", "Frame", "Port",
    "Parameter", "Variable", "Discrete", "Event", "Assertion", "Start", "guess", "der",
    "time", "Eq", "Experiment", "Measure", "Stop", "AcausalError", "ModelError",
    "ParameterError", "StructuralError",
    "InitializationError", "SolverError", "ChatteringError", "LimitError",
]


# ---------------------------------------------------------------------------
# Old module paths (before the layered layout) keep working, with a
# DeprecationWarning: ``import acausal.simulate`` gives acausal.runtime.hybrid.
# ---------------------------------------------------------------------------
_MOVED = {
    "component": "lang.component",
    "connectors": "lang.connectors",
    "declare": "lang.declare",
    "symbols": "lang.symbols",
    "fastdiff": "lang.fastdiff",
    "experiment": "lang.experiment",
    "flatten": "compiler.flatten",
    "aliases": "compiler.aliases",
    "structure": "compiler.structure",
    "causalize": "compiler.causalize",
    "codegen": "compiler.codegen",
    "codegen_c": "compiler.codegen_c",
    "compile": "runtime.model",
    "simulate": "runtime.hybrid",
    "initialize": "runtime.initialize",
    "events": "runtime.events",
    "result": "runtime.result",
    "batch": "runtime.batch",
    "sensitivity": "runtime.sensitivity",
    "backends": "runtime.backends",
    "backends.compiled": "runtime.backends.compiled",
    "backends.sundae": "runtime.backends.sundae",
    "calibrate": "studies.calibrate",
    "profile": "studies.profile",
    "design": "studies.design",
    "sweep": "studies.sweep",
    "differences": "studies.differences",
    "executor": "infra.executor",
    "checkpoint": "infra.checkpoint",
    "blas": "infra.blas",
    "cache": "infra.store",
    "plot": "viz.plot",
    "animate": "viz.animate",
    "diagnose.domain": "diagnose.library.domain",
    "diagnose.elements": "diagnose.library.elements",
    "diagnose.generic": "diagnose.library.generic",
    "diagnose.graph": "diagnose.library.graph",
    "diagnose.hypotheses": "diagnose.library.hypotheses",
    "diagnose.nominal": "diagnose.library.nominal",
    "diagnose.families": "diagnose.stages.families",
    "diagnose.fitting": "diagnose.stages.fitting",
    "diagnose.fingerprints": "diagnose.stages.fingerprints",
    "diagnose.intervals": "diagnose.stages.intervals",
    "diagnose.kinematics": "diagnose.stages.kinematics",
    "diagnose.locate": "diagnose.stages.locate",
    "diagnose.nextexp": "diagnose.stages.nextexp",
    "diagnose.pairsearch": "diagnose.stages.pairsearch",
    "diagnose.screen": "diagnose.stages.screen",
    "diagnose.stats": "diagnose.stages.stats",
    "diagnose.tasks": "diagnose.stages.tasks",
    "diagnose.views": "diagnose.stages.views",
    "diagnose.resume": "diagnose.stages.resume",
    "diagnose.plots": "diagnose.report.plots",
    "diagnose.result": "diagnose.report.result",
}


def _install_moved_finder():
    import importlib
    import importlib.abc
    import importlib.util
    import sys
    import warnings

    class _Alias(importlib.abc.MetaPathFinder, importlib.abc.Loader):
        def find_spec(self, fullname, path=None, target=None):
            if not fullname.startswith(__name__ + "."):
                return None
            old = fullname[len(__name__) + 1:]
            if old not in _MOVED:
                return None
            return importlib.util.spec_from_loader(fullname, self)

        def create_module(self, spec):
            new = f"{__name__}.{_MOVED[spec.name[len(__name__) + 1:]]}"
            warnings.warn(f"{spec.name} moved to {new}; import it from there",
                          DeprecationWarning, stacklevel=2)
            return importlib.import_module(new)

        def exec_module(self, module):
            pass

    if not any(isinstance(f, _Alias) for f in sys.meta_path):
        sys.meta_path.insert(0, _Alias())


_install_moved_finder()
