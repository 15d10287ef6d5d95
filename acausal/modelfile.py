"""Model files: plain Python scripts that build a model.

A model file binds a :class:`~acausal.Model` to the module-level name
``model``; it may define ``experiment`` (an :class:`~acausal.Experiment`),
``measures``, a dict of name -> function(result) -> float (a scalar
computed from a result, such as a response time), ``measure_units``, a dict
of measure -> SI unit (``{"thrt": "s"}``; a measure function may instead
carry a ``unit`` attribute), ``conditions``, the parameters an experiment
sets (``["v_impact"]``: a dataset must give at least one of them),
``free_parameters``, a dict of parameter -> (low, high) that calibration
and diagnosis may fit, and ``plot(result, path)``. A model file can import
another one (``from breaker_24kv import build``): its folder is on the path.
"""
import os
import runpy
import sys
import traceback
from dataclasses import dataclass, field

from .compile import compile_model
from .component import Model
from .errors import AcausalError, ModelFileError
from .experiment import Experiment


@dataclass
class ModelFile:
    path: str
    model: Model
    experiment: Experiment
    measures: dict = field(default_factory=dict)
    namespace: dict = field(default_factory=dict)
    free: dict = field(default_factory=dict)   # parameter -> (low, high) bounds
    measure_units: dict = field(default_factory=dict)  # measure -> SI unit (None: unknown)
    conditions: tuple = ()                     # parameters an experiment sets

    def measure_unit(self, name):
        """The SI unit of measure ``name``, or None if the file declares none."""
        return self.measure_units.get(name)


def _where(exc, path):
    """'file:line' of the deepest frame of ``exc`` inside ``path``."""
    line = None
    for fr in traceback.extract_tb(exc.__traceback__):
        if os.path.abspath(fr.filename) == path:
            line = fr.lineno
    return f"{path}:{line}" if line else path


def load_model_file(path):
    """Run a model file and collect ``model``, ``experiment`` and ``measures``."""
    path = os.path.abspath(path)
    if not os.path.isfile(path):
        raise ModelFileError(f"{path}: no such model file")
    folder = os.path.dirname(path)
    added = folder not in sys.path
    if added:
        sys.path.insert(0, folder)
    try:
        ns = runpy.run_path(path, run_name="__acausal_model__")
    except SyntaxError as exc:
        raise ModelFileError(f"{exc.filename}:{exc.lineno}: syntax error: {exc.msg}") from None
    except AcausalError as exc:
        raise ModelFileError(f"{_where(exc, path)}: {exc}") from None
    except Exception as exc:  # a bug in the script: say where
        raise ModelFileError(f"{_where(exc, path)}: {type(exc).__name__}: {exc}") from None
    finally:
        if added:
            sys.path.remove(folder)
    model = ns.get("model")
    if not isinstance(model, Model):
        raise ModelFileError(f"{path}: a model file must bind a Model to the name 'model'"
                             + (f" (found {type(model).__name__})" if model is not None else ""))
    exp = ns.get("experiment") or Experiment()
    if not isinstance(exp, Experiment):
        raise ModelFileError(f"{path}: 'experiment' must be an acausal.Experiment")
    measures = ns.get("measures") or {}
    if not isinstance(measures, dict) or not all(callable(f) for f in measures.values()):
        raise ModelFileError(f"{path}: 'measures' must be a dict of name -> function(result)")
    free = ns.get("free_parameters") or {}
    if not isinstance(free, dict) or not all(
            isinstance(b, (tuple, list)) and len(b) == 2 for b in free.values()):
        raise ModelFileError(f"{path}: 'free_parameters' must be a dict of "
                             "name -> (low, high)")
    units, conditions = _measure_units(ns, measures, path), _conditions(ns, path)
    return ModelFile(path, model, exp, dict(measures), ns, {k: tuple(map(float, v))
                                                            for k, v in free.items()},
                     units, conditions)


def _measure_units(ns, measures, path):
    """measure -> SI unit from ``measure_units`` or the functions' ``unit``."""
    given = ns.get("measure_units") or {}
    if not isinstance(given, dict) or not all(isinstance(u, str) for u in given.values()):
        raise ModelFileError(f"{path}: 'measure_units' must be a dict of measure -> unit")
    unknown = sorted(set(given) - set(measures))
    if unknown:
        raise ModelFileError(f"{path}: 'measure_units' names {unknown[0]!r}, which is "
                             "not a measure")
    units = {name: getattr(fn, "unit", None) for name, fn in measures.items()}
    units.update(given)
    return {k: u for k, u in units.items() if isinstance(u, str)}


def _conditions(ns, path):
    """The ``conditions`` a model file declares, as a tuple of names."""
    given = ns.get("conditions") or ()
    if isinstance(given, str) or not all(isinstance(c, str) for c in given):
        raise ModelFileError(f"{path}: 'conditions' must be a list of parameter names")
    return tuple(given)


_CACHE = {}


def compile_file(path):
    """(ModelFile, CompiledModel) for a model file, compiled once per process
    and file version."""
    apath = os.path.abspath(path)
    key = (apath, os.path.getmtime(apath) if os.path.exists(apath) else None)
    hit = _CACHE.get(key)
    if hit is not None:
        return hit
    mf = load_model_file(apath)
    if mf.experiment.stop is not None:
        mf.model.event(mf.experiment.stop.event(mf.model))
    cm = compile_model(mf.model)
    _CACHE[key] = (mf, cm)
    return mf, cm


def evaluate_measures(mf, result):
    """name -> float for every measure; a measure that fails raises an error
    naming it."""
    out = {}
    for name, fn in mf.measures.items():
        try:
            out[name] = float(fn(result))
        except Exception as exc:
            raise ModelFileError(f"{mf.path}: measure {name!r} failed: "
                                 f"{type(exc).__name__}: {exc}") from None
    return out


def run_file(path, params=None, **overrides):
    """Simulate a model file; returns (result, measures)."""
    mf, cm = compile_file(path)
    opts = mf.experiment.run_options()
    opts.update({k: v for k, v in overrides.items() if v is not None})
    res = cm.simulate(params=params, **opts)
    return res, evaluate_measures(mf, res)


def sweep_task(path, point):
    """One sweep point: the model file compiled once per worker process
    (the compile cache is per process), simulated with ``point`` as
    parameter overrides; returns the measures. Module-level, so picklable."""
    return run_file(path, params=point)[1]
