"""FMU export: a model file as an FMI 2.0 Co-Simulation FMU.

A layer above :mod:`acausal.runtime` and :mod:`acausal.modelfile` (nothing
below imports it). :func:`export_fmu` writes an ``.fmu`` (a zip) holding

* ``modelDescription.xml``: the free parameters (causality ``parameter``;
  variability ``tunable`` when the equations, events or outputs use them,
  ``fixed`` when only start values do), the parameters bound to others
  (``calculatedParameter``), the variables whose start value is fixed (a
  runtime value: ``initial="exact"``, settable before initialisation), the
  outputs (the model file's measures and the chosen variables), the inputs
  (declared: free parameters driven by the importer, held over each
  communication step), every one with its unit in ``UnitDefinitions`` (SI
  base-unit exponents from pint, a measure's display unit as a
  ``DisplayUnit``), the model file's experiment as ``DefaultExperiment``;
* ``binaries/<platform>/<id>.so``: ``fmi2_python.c`` compiled here, which
  forwards every fmi2 call to :class:`acausal.interop.fmu_instance.Instance`
  in the importer's Python (or one it starts: the binary is linked to the
  exporting Python's libpython);
* ``resources/``: the model file and the sibling modules it imports, and
  ``acausal_fmu.json`` (the variables and the run settings).

Why Python runs inside the FMU and not only the generated C: ``docs/fmu.md``.
The importing machine needs the Python the FMU was exported with (same
major.minor version) with acausal installed; the binary adds the exporting
environment's ``sys.path`` when acausal is not importable.
"""
import json
import os
import re
import shutil
import subprocess
import sys
import sysconfig
import tempfile
import uuid
import zipfile
from datetime import datetime, timezone
from xml.dom import minidom
from xml.etree import ElementTree as ET

import sympy as sp

from ..errors import AcausalError, UsageError
from ..lang.experiment import Measure
from .fmu_instance import SPEC_FILE, load_for_fmu

SHIM = os.path.join(os.path.dirname(os.path.abspath(__file__)), "fmi2_python.c")
PLATFORM = {"linux": "linux64", "darwin": "darwin64", "win32": "win64"}
_BASE_UNITS = {"kilogram": "kg", "meter": "m", "second": "s", "ampere": "A", "kelvin": "K",
               "mole": "mol", "candela": "cd", "radian": "rad"}


class FmuExportError(AcausalError):
    """An FMU cannot be written (no C compiler, no Python headers, ...)."""


def export_fmu(model_path, out, outputs=(), inputs=(), measures=True, backend=None):
    """Write the FMU of the model file ``model_path`` to ``out`` (``.fmu``);
    returns the path written.

    ``outputs``: variable names (any of the model's variables or discrete
    values, aliases included) exported as outputs besides the model file's
    measures (all of them, unless ``measures=False``); ``inputs``: names of
    free parameters the importer drives as inputs (held over each step);
    ``backend``: the integrator inside the FMU (``None``: the library's
    default or ``ACAUSAL_BACKEND`` where the FMU runs). Bad input raises an
    AcausalError of one line naming it."""
    out = _check_out(out)
    if sys.platform not in PLATFORM:
        raise FmuExportError(f"FMU export: platform {sys.platform!r} is not supported")
    mf, cm, opened = load_for_fmu(model_path)
    table = _variables(mf, cm, list(outputs), list(inputs), measures, opened)
    if not any(v["kind"] in ("output", "measure") or v.get("output") for v in table):
        raise UsageError(f"{mf.path}: the FMU would have no outputs: the model file declares "
                         "no measures; choose variables with --output NAME (e.g. "
                         f"--output {_example(cm)})")
    model_id = _identifier(os.path.splitext(os.path.basename(mf.path))[0])
    guid = "{" + str(uuid.uuid4()) + "}"
    spec = dict(guid=guid, model_file="model/" + os.path.basename(mf.path), backend=backend,
                experiment=_experiment(mf), variables=table)
    xml = _model_description(mf, cm, model_id, guid, table)
    with tempfile.TemporaryDirectory(prefix="acausal_fmu_") as tmp:
        binary = os.path.join(tmp, model_id + _suffix())
        _compile_shim(model_id, binary)
        _write_zip(out, xml, spec, binary, model_id, _model_sources(mf))
    return out


def _check_out(out):
    out = os.path.abspath(os.fspath(out))
    folder = os.path.dirname(out)
    if not out.endswith(".fmu"):
        raise UsageError(f"FMU output {out}: the file name must end in .fmu")
    if not os.path.isdir(folder):
        raise UsageError(f"FMU output {out}: folder {folder} does not exist")
    if not os.access(folder, os.W_OK):
        raise UsageError(f"FMU output {out}: folder {folder} is not writable")
    return out


def _example(cm):
    states = [n for n in cm.var_names if cm.y_column(n) is not None]
    return (states or cm.var_names or ["x"])[0]


def _identifier(stem):
    ident = re.sub(r"\W", "_", stem)
    return ident if re.match(r"[A-Za-z_]", ident) else "_" + ident


def _suffix():
    return ".dll" if sys.platform == "win32" else (".dylib" if sys.platform == "darwin"
                                                   else ".so")


def _experiment(mf):
    e = mf.experiment
    if isinstance(e.atol, dict):
        raise UsageError(f"{mf.path}: FMU export needs one absolute tolerance; the "
                         "experiment gives atol per variable")
    return dict(t0=float(e.t0), t_end=float(e.t_end), rtol=float(e.rtol), atol=float(e.atol),
                atol_algebraic=e.atol_algebraic, max_step=e.max_step,
                output_step=e.output_step)


# ---------------------------------------------------------------------------
# The variable table (resources/acausal_fmu.json and modelDescription.xml)
# ---------------------------------------------------------------------------

def _variables(mf, cm, outputs, inputs, with_measures, opened=()):
    """The FMU's variables, one dict each: vr, name, kind (parameter, input,
    calculated, start, output, measure), unit, description, variability,
    start (where the importer may set it), output (a start value also
    exported as an output), param (the parameter behind an input). The
    inputs are the declared ones (free parameters) and ``opened``, the
    input connectors with no source (:func:`bind_open_inputs`)."""
    known = set(cm.var_names) | {d.symbol.name for d in cm.discretes}
    for name in outputs:
        if name not in known and name not in mf.measures:
            raise UsageError(f"--output {name}: the model has no variable {name!r}"
                             + _close(name, known | set(mf.measures)))
    behind = {o["param"] for o in opened}
    free = {e.name: e for e in cm.params if e.name not in behind}
    for name in inputs:
        if name not in free:
            raise UsageError(f"--input {name}: not a free parameter of the model"
                             + _close(name, set(free)) + " (an input is a free parameter "
                             "the importer drives)")
    driven = {o["name"] for o in opened}
    for name in outputs:
        if name in driven:
            raise UsageError(f"--output {name}: an input of the FMU (an input connector "
                             "nothing sets) cannot also be an output")
    wanted = [n for n in dict.fromkeys(outputs) if n in known]
    used = _used_parameters(cm)
    table = []

    def add(**v):
        v["vr"] = len(table)
        table.append(v)

    for e in cm.params:
        if e.name in inputs or e.name in behind:
            continue
        add(name=e.name, kind="parameter", unit=e.unit, description=e.desc,
            variability="tunable" if sp.Symbol(e.name) in used else "fixed",
            start=float(e.default))
    for name in cm.bound:
        info = cm.flat.params[name]
        add(name=name, kind="calculated", unit=info.decl.unit, description=info.decl.desc,
            variability="fixed")
    for name in cm.var_names:
        info = cm.flat.variables[name]
        if not info.start.fixed or getattr(info, "internal", False):
            continue
        add(name=name, kind="start", unit=info.unit, description=info.desc or "",
            variability="continuous", start=_start_value(cm, info.start.value),
            output=name in wanted)
    starts = {v["name"] for v in table if v["kind"] == "start"}
    for name in wanted:
        if name in starts:
            continue
        info = cm.flat.variables.get(name)
        disc = next((d for d in cm.discretes if d.symbol.name == name), None)
        unit = info.unit if info is not None else disc.decl.unit
        desc = info.desc if info is not None else disc.decl.desc
        add(name=name, kind="output", unit=unit, description=desc or "",
            variability="continuous" if info is not None else "discrete")
    chosen = set(outputs)
    for name, fn in mf.measures.items():
        if not (with_measures or name in chosen):
            continue
        if name in {v["name"] for v in table}:
            raise UsageError(f"{mf.path}: measure {name!r} has the name of a model variable "
                             "or parameter; rename the measure to export it")
        desc = fn.desc if isinstance(fn, Measure) else (fn.__doc__ or "").strip()
        add(name=name, kind="measure", unit=mf.measure_unit(name) or "1",
            description=(desc or "measure of the model file") + " (NaN until the run "
            "so far determines it)", variability="continuous",
            display=fn.display if isinstance(fn, Measure) else None)
    for name in inputs:
        e = free[name]
        add(name=name, kind="input", unit=e.unit, description=e.desc, variability="continuous",
            start=float(e.default), param=name)
    for o in opened:
        add(name=o["name"], kind="input", unit=o["unit"], description=o["description"],
            variability="continuous", start=0.0, param=o["param"])
    return table


def _close(name, names):
    import difflib
    hits = difflib.get_close_matches(name, sorted(names), n=3)
    return f" (did you mean {', '.join(hits)}?)" if hits else ""


def _start_value(cm, value):
    """A start value at the default parameters (it may be an expression of them)."""
    if isinstance(value, sp.Basic) and not value.is_number:
        return float(cm.resolve(value).xreplace(dict(zip(cm.param_syms, cm.param_vector()))))
    return float(value)


def _used_parameters(cm):
    """The free parameter symbols the equations, the event and assertion
    conditions or the outputs use (a change between steps matters there);
    the others only enter start values."""
    exprs = list(cm.dae.residuals) + cm.observed_exprs()
    exprs += [cm.resolve(e.expr) for e in cm.events] + \
        [cm.resolve(a.expr) for a in cm.assertions]
    used = set()
    for e in exprs:
        used |= sp.sympify(e).free_symbols
    return used & set(cm.param_syms) | _action_parameters(cm)


def _action_parameters(cm):
    """Parameters an event action may read: every free parameter of a
    component that has an event with an action (an action is Python code;
    what it reads is not known without running it)."""
    owners = {e.owner for e in cm.events if e.action is not None}
    return {sp.Symbol(e.name) for e in cm.params if e.owner in owners}


# ---------------------------------------------------------------------------
# modelDescription.xml
# ---------------------------------------------------------------------------

def _model_description(mf, cm, model_id, guid, table):
    version = _version()
    exp = mf.experiment
    root = ET.Element("fmiModelDescription", dict(
        fmiVersion="2.0", modelName=model_id, guid=guid,
        description=_doc_line(mf), generationTool=f"acausal {version}",
        generationDateAndTime=datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        variableNamingConvention="structured", numberOfEventIndicators="0"))
    ET.SubElement(root, "CoSimulation", dict(
        modelIdentifier=model_id, needsExecutionTool="false",
        canHandleVariableCommunicationStepSize="true", canInterpolateInputs="false",
        maxOutputDerivativeOrder="0", canRunAsynchronuously="false",
        canBeInstantiatedOnlyOncePerProcess="false", canNotUseMemoryManagementFunctions="true",
        canGetAndSetFMUstate="false", canSerializeFMUstate="false",
        providesDirectionalDerivative="false"))
    units = _unit_definitions(table)
    if len(units):
        root.append(units)
    cats = ET.SubElement(root, "LogCategories")
    for name in ("logStatusWarning", "logStatusDiscard", "logStatusError", "logAll"):
        ET.SubElement(cats, "Category", dict(name=name))
    ET.SubElement(root, "DefaultExperiment", dict(
        startTime=repr(float(exp.t0)), stopTime=repr(float(exp.t_end)),
        tolerance=repr(float(exp.rtol))))
    mv = ET.SubElement(root, "ModelVariables")
    for v in table:
        mv.append(_scalar_variable(v, units))
    ms = ET.SubElement(root, "ModelStructure")
    outs = [k + 1 for k, v in enumerate(table) if _causality(v) == "output"]
    if outs:
        el = ET.SubElement(ms, "Outputs")
        for k in outs:
            ET.SubElement(el, "Unknown", dict(index=str(k)))
    initial = [k + 1 for k, v in enumerate(table)
               if (_causality(v) == "output" and v["kind"] != "start")
               or v["kind"] == "calculated"]
    if initial:
        el = ET.SubElement(ms, "InitialUnknowns")
        for k in initial:
            ET.SubElement(el, "Unknown", dict(index=str(k)))
    text = ET.tostring(root, encoding="unicode")
    return minidom.parseString(text).toprettyxml(indent="  ", encoding="UTF-8")


def _version():
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("acausal")
    except PackageNotFoundError:
        return "(source tree)"


def _doc_line(mf):
    doc = (mf.namespace.get("__doc__") or "").strip().splitlines()
    return doc[0] if doc else os.path.basename(mf.path)


def _causality(v):
    kind = v["kind"]
    if kind == "start":
        return "output" if v.get("output") else "local"
    return {"parameter": "parameter", "calculated": "calculatedParameter", "input": "input",
            "output": "output", "measure": "output"}[kind]


def _scalar_variable(v, units):
    attrs = dict(name=v["name"], valueReference=str(v["vr"]), causality=_causality(v),
                 variability=v["variability"])
    if v.get("description"):
        attrs["description"] = v["description"]
    if v["kind"] in ("parameter", "start"):
        attrs["initial"] = "exact"
    elif v["kind"] == "calculated":
        attrs["initial"] = "calculated"
    sv = ET.Element("ScalarVariable", attrs)
    real = {}
    unit = v.get("unit")
    if unit and unit in units.names:
        real["unit"] = unit
        if v.get("display") and v["display"] != unit:
            real["displayUnit"] = v["display"]
    if "start" in v:
        real["start"] = repr(float(v["start"]))
    ET.SubElement(sv, "Real", real)
    return sv


class _Units(ET.Element):
    """``<UnitDefinitions>``, with the set of unit names it defines."""
    names = ()


def _unit_definitions(table):
    """``<UnitDefinitions>`` of the table's units (the dimensionless "1"
    left out): each unit's SI base-unit exponents and factor, a measure's
    display unit as a DisplayUnit (value_display = factor * value)."""
    from ..data.units import parse_unit, ureg
    el = _Units("UnitDefinitions")
    displays = {}
    for v in table:
        if v.get("display"):
            displays.setdefault(v["unit"], set()).add(v["display"])
    names = []
    for unit in sorted({v["unit"] for v in table if v.get("unit") not in (None, "", "1")}):
        try:
            q = ureg().Quantity(1.0, parse_unit(unit)).to_base_units()
        except Exception:   # noqa: BLE001 - a unit pint cannot read: exported without one
            continue
        base = {}
        for name, exp in q.unit_items():
            if name not in _BASE_UNITS or exp != int(exp):
                break
            base[_BASE_UNITS[name]] = str(int(exp))
        else:
            if q.magnitude != 1.0:
                base["factor"] = repr(float(q.magnitude))
            u = ET.SubElement(el, "Unit", dict(name=unit))
            ET.SubElement(u, "BaseUnit", base)
            for disp in sorted(displays.get(unit, ())):
                try:
                    f = float(ureg().Quantity(1.0, parse_unit(unit)).to(parse_unit(disp))
                              .magnitude)
                except Exception:   # noqa: BLE001
                    continue
                ET.SubElement(u, "DisplayUnit", dict(name=disp, factor=repr(f)))
            names.append(unit)
    el.names = frozenset(names)
    return el


# ---------------------------------------------------------------------------
# The binary and the archive
# ---------------------------------------------------------------------------

def _compile_shim(model_id, binary):
    """Compile ``fmi2_python.c`` against this Python (headers and libpython)."""
    cc = os.environ.get("CC") or shutil.which("cc") or shutil.which("gcc")
    if not cc:
        raise FmuExportError("FMU export needs a C compiler (cc or gcc) to build the FMU's "
                             "binary; none was found")
    inc = sysconfig.get_paths()["include"]
    if not os.path.isfile(os.path.join(inc, "Python.h")):
        raise FmuExportError(f"FMU export needs Python's C headers: {inc}/Python.h is "
                             "missing (install the python3-dev package of this Python)")
    libdir = sysconfig.get_config_var("LIBDIR") or ""
    ldlib = sysconfig.get_config_var("LDLIBRARY") or ""
    link, libpython = [], ""
    if sysconfig.get_config_var("Py_ENABLE_SHARED") and ldlib.endswith(".so"):
        name = ldlib[3:-3]   # libpython3.11.so -> python3.11
        link = [f"-L{libdir}", f"-l{name}", f"-Wl,-rpath,{libdir}"]
        soname = sysconfig.get_config_var("INSTSONAME") or ldlib
        libpython = os.path.join(libdir, soname)
    paths = [p for p in sys.path if p and os.path.isdir(p) and ":" not in p]
    defs = [f'-DACS_MODEL_ID="{model_id}"', f'-DACS_PYTHON="{_c(sys.executable)}"',
            f'-DACS_LIBPYTHON="{_c(libpython)}"', f'-DACS_SYSPATH="{_c(":".join(paths))}"']
    cmd = cc.split() + ["-O1", "-shared", "-fPIC", "-fvisibility=hidden", f"-I{inc}", *defs,
                        SHIM, "-o", binary] + link + ["-ldl"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    if proc.returncode != 0:
        first = (proc.stderr.strip().splitlines() or ["(no message)"])[0]
        raise FmuExportError(f"FMU export: the C compiler failed on fmi2_python.c: {first}")


def _c(text):
    return text.replace("\\", "\\\\").replace('"', '\\"')


def _model_sources(mf):
    """The model file and the modules it imported from its own folder
    (``from breaker_24kv import build``): (path, name in the FMU)."""
    folder = os.path.dirname(mf.path)
    files = {mf.path}
    for mod in list(sys.modules.values()):
        f = getattr(mod, "__file__", None)
        if f and f.endswith(".py") and os.path.dirname(os.path.abspath(f)) == folder:
            files.add(os.path.abspath(f))
    return [(f, "resources/model/" + os.path.basename(f)) for f in sorted(files)]


def _write_zip(out, xml, spec, binary, model_id, sources):
    tmp = out + ".part"
    try:
        with zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("modelDescription.xml", xml)
            z.write(binary, f"binaries/{PLATFORM[sys.platform]}/{model_id}{_suffix()}")
            z.writestr(f"resources/{SPEC_FILE}", json.dumps(spec, indent=1))
            for path, arc in sources:
                z.write(path, arc)
        os.replace(tmp, out)
    except OSError as exc:
        raise UsageError(f"FMU output {out}: cannot write it: {exc.strerror}") from None
    finally:
        if os.path.exists(tmp):
            os.remove(tmp)

