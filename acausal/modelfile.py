"""Model files: plain Python scripts that build a model.

A model file binds a :class:`~acausal.Model` to the module-level name
``model``; it may define ``experiment`` (an :class:`~acausal.Experiment`),
``measures``, a dict of name -> function(result) -> float (a scalar
computed from a result, such as a response time, in SI units; a
:class:`~acausal.Measure` also gives its unit and the unit it is printed
in), ``free_parameters``, a
dict of parameter -> (low, high) that calibration and diagnosis may fit,
``conditions``, a dict of parameter -> (low, high) or (low, high, unit): the
experiment conditions an experimenter can set and their ranges (an impact
velocity, a start position), which :mod:`acausal.design` searches for the
next experiment, and ``plot(result, path)``. A model file can import
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
from .experiment import Experiment, Measure


@dataclass
class ModelFile:
    path: str
    model: Model
    experiment: Experiment
    measures: dict = field(default_factory=dict)
    namespace: dict = field(default_factory=dict)
    free: dict = field(default_factory=dict)   # parameter -> (low, high) bounds
    conditions: dict = field(default_factory=dict)  # parameter -> (low, high, unit)


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
    return ModelFile(path, model, exp, dict(measures), ns, {k: tuple(map(float, v))
                                                            for k, v in free.items()},
                     _conditions(path, ns.get("conditions")))


def _conditions(path, given):
    """``conditions`` of a model file as name -> (low, high, unit)."""
    out = {}
    for name, spec in (given or {}).items():
        ok = isinstance(spec, (tuple, list)) and len(spec) in (2, 3)
        try:
            low, high = (float(spec[0]), float(spec[1])) if ok else (0.0, 0.0)
        except (TypeError, ValueError):
            ok = False
        if not ok or not isinstance(name, str) or not low < high:
            raise ModelFileError(f"{path}: conditions[{name!r}] must be (low, high) or "
                                 f"(low, high, unit) with low < high (found {spec!r})")
        out[name] = (low, high, str(spec[2]) if len(spec) == 3 else "")
    return out


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
    for name in mf.conditions:
        try:
            cm.param_index(name)
        except AcausalError as exc:
            raise ModelFileError(f"{apath}: conditions: {exc}") from None
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


def measure_unit(mf, name):
    """The SI unit a measure declares (a :class:`~acausal.Measure`), or None."""
    fn = mf.measures.get(name)
    return fn.unit if isinstance(fn, Measure) else None


def show_measure(mf, name, value):
    """``value`` (SI) as text in the measure's display unit: ``'1.89987 ms'``
    (a measure without a declared unit: the bare number)."""
    fn = mf.measures.get(name)
    if not isinstance(fn, Measure):
        return f"{value:.6g}"
    v, unit = fn.shown(value)
    return f"{v:.6g} {unit}" if unit != "1" else f"{v:.6g}"
def measure_values(mf, result):
    """(name -> float, name -> reason): every measure of the model file; one
    that cannot be computed from this result (an event that never happened,
    say) is NaN in the first dict and has its reason in the second, so the
    others are kept."""
    values, missing = {}, {}
    for name, fn in mf.measures.items():
        try:
            values[name] = float(fn(result))
        except Exception as exc:  # noqa: BLE001 - the model file's code: reported, not raised
            values[name] = float("nan")
            missing[name] = f"{type(exc).__name__}: {exc}"
            continue
        if values[name] != values[name]:
            missing[name] = "no value (the measure gave NaN)"
    return values, missing


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
    parameter overrides; returns the measures (NaN for one that cannot be
    computed, with its reason in ``"__missing__"``). Module-level, so picklable."""
    mf, cm = compile_file(path)
    opts = mf.experiment.run_options()
    values, missing = measure_values(mf, cm.simulate(params=point, **opts))
    return {**values, "__missing__": missing}
