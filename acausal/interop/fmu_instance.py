"""The running side of an acausal FMU: one :class:`Instance` per FMI
instance, created and called by the FMU's binary (``fmi2_python.c``) from
inside the importing tool's process.

A layer above :mod:`acausal.runtime` and :mod:`acausal.modelfile`: the
instance compiles the model file the FMU carries in its resources (the
on-disk compile cache makes that a load after the first time), and steps
the hybrid loop (:class:`acausal.runtime.hybrid.Stepper`) from one
communication point to the next, across every event inside the step.

Every method returns an FMI status (0 OK, 2 discard, 3 error) or a value;
what goes wrong is logged (:meth:`take_messages`, which the binary hands to
the importer's logger) and answered with fmi2Error, never a crash. An
exception that escapes is turned into fmi2Error with its text by the binary.
"""
import json
import math
import os
import warnings
from urllib.parse import unquote, urlparse

import numpy as np
import sympy as sp

from ..compiler.flatten import flatten
from ..runtime.model import compile_model
from ..errors import AcausalError, ConnectionError_
from ..modelfile import load_model_file, measure_values
from ..runtime.hybrid import Stepper

SPEC_FILE = "acausal_fmu.json"   # in the FMU's resources: the variables and settings
OK, WARNING, DISCARD, ERROR = 0, 1, 2, 3
LAST_SUCCESSFUL_TIME, TERMINATED = 2, 3     # fmi2StatusKind
_CATEGORY = {OK: "logAll", WARNING: "logStatusWarning", DISCARD: "logStatusDiscard",
             ERROR: "logStatusError"}
# the states of an instance (FMI 2.0, section 4.2.4)
INSTANTIATED, INITIALIZING, STEPPING, TERMINATED_STATE, FAILED = (
    "instantiated", "initialization mode", "step mode", "terminated", "failed")


class FmuError(AcausalError):
    """What an FMI call asked that this instance cannot do (logged, fmi2Error)."""


def load_for_fmu(path):
    """(ModelFile, CompiledModel, open inputs) of a model file as an FMU runs
    it: every causal input connector (``RealInput``) with no source is
    bound to a new top-level parameter, which the FMU's input of the same
    name (the connector's path) drives (:func:`bind_open_inputs`); then it
    is compiled as :func:`acausal.modelfile.compile_file` does."""
    mf = load_model_file(path)
    opened = bind_open_inputs(mf.model)
    if mf.experiment.stop is not None:
        mf.model.event(mf.experiment.stop.event(mf.model))
    return mf, compile_model(mf.model), opened


def bind_open_inputs(model):
    """Bind each input connector that nothing sets (no output connected to
    it, no expression bound to it: what compiling refuses as 'input not
    connected') to a new parameter of ``model``, default 0 in the
    connector's unit; returns one dict per input: ``name`` (the connector's
    path), ``param`` (the parameter), ``unit``, ``description``. Flattening
    names the open inputs one at a time; a model without input connectors
    is not flattened here."""
    ports = {}
    for comp in model.walk():
        for name, ctype in comp.connectors().items():
            if getattr(ctype, "causality", None) == "input":
                port = comp.port(name)
                ports[port.path] = port
    opened = []
    while ports:
        try:
            flatten(model)
            break
        except ConnectionError_ as exc:
            port = ports.pop(exc.component, None)
            if port is None or "not connected" not in str(exc):
                raise
        param = "fmu_input_" + port.path.replace(".", "_")
        unit = getattr(port.ctype, "unit", None)
        desc = f"the FMU's input {port.path}"
        port.owner.set(**{port.name: model.parameter(param, 0.0, unit, desc)})
        opened.append(dict(name=port.path, param=param, unit=unit or "1",
                           description=port.ctype.desc or desc))
    return opened


def resource_path(uri):
    """The folder of a resource location URI (``file:///tmp/x/resources/``,
    ``file:/tmp/x/resources``) or plain path."""
    if uri.startswith("file:"):
        parsed = urlparse(uri)
        path = unquote(parsed.path)
        if parsed.netloc and parsed.netloc != "localhost":
            path = f"//{parsed.netloc}{path}"
        return path
    return uri


class Instance:
    """One FMI 2.0 Co-Simulation instance of an acausal model."""

    def __init__(self, name, guid, resource_uri, model_id="", logging_on=False):
        self.name, self.logging = name, bool(logging_on)
        self.messages = []
        self.resources = resource_path(resource_uri)
        spec_path = os.path.join(self.resources, SPEC_FILE)
        if not os.path.isfile(spec_path):
            raise FmuError(f"{spec_path}: missing: the resource location {resource_uri!r} "
                           "is not this FMU's resources folder")
        with open(spec_path, encoding="utf-8") as f:
            self.spec = json.load(f)
        if guid != self.spec["guid"]:
            raise FmuError(f"GUID {guid!r} is not this FMU's ({self.spec['guid']}): the "
                           "modelDescription.xml and the binary come from different exports")
        self.vars = {v["vr"]: v for v in self.spec["variables"]}
        self.mf, self.cm, _ = load_for_fmu(os.path.join(self.resources,
                                                        self.spec["model_file"]))
        self.var_index = {n: k for k, n in enumerate(self.cm.var_names)}
        self.disc_index = {d.symbol.name: j for j, d in enumerate(self.cm.discretes)}
        self.reset()

    # -- logging ------------------------------------------------------------
    def log(self, status, text):
        if status >= WARNING or self.logging:
            self.messages.append((status, _CATEGORY[status], text))
        return status

    def take_messages(self):
        out, self.messages = self.messages, []
        return out

    def set_debug_logging(self, on, categories):
        self.logging = bool(on)
        return OK

    # -- the life cycle -----------------------------------------------------
    def reset(self):
        """Back to the state after instantiation, every value its start."""
        exp = self.spec["experiment"]
        self.state = INSTANTIATED
        self.values = {vr: v["start"] for vr, v in self.vars.items() if "start" in v}
        self.set_names = set()      # parameters and start values the importer set
        self.pending = {}           # tunable parameters and inputs set in step mode
        self.stepper = None
        self.t0, self.t_stop, self.rtol = float(exp["t0"]), float(exp["t_end"]), None
        self.terminated, self.steps, self._measures = False, 0, None
        return OK

    def setup_experiment(self, tolerance_defined, tolerance, start_time, stop_time,
                         stop_defined):
        if self.state != INSTANTIATED:
            return self.log(ERROR, f"fmi2SetupExperiment: not allowed in {self.state}")
        self.t0 = float(start_time)
        if stop_defined:
            if not stop_time > start_time:
                return self.log(ERROR, f"fmi2SetupExperiment: stop time {stop_time:g} s is "
                                f"not after the start time {start_time:g} s")
            self.t_stop = float(stop_time)
        elif self.t_stop <= self.t0:
            self.t_stop = self.t0 + (self.spec["experiment"]["t_end"]
                                     - self.spec["experiment"]["t0"])
        if tolerance_defined:
            if not (tolerance > 0 and math.isfinite(tolerance)):
                return self.log(ERROR, f"fmi2SetupExperiment: tolerance {tolerance!r} must "
                                "be a positive number")
            self.rtol = float(tolerance)
        return OK

    def enter_initialization_mode(self):
        if self.state != INSTANTIATED:
            return self.log(ERROR, f"fmi2EnterInitializationMode: not allowed in {self.state}")
        self.state = INITIALIZING
        return OK

    def exit_initialization_mode(self):
        if self.state != INITIALIZING:
            return self.log(ERROR, f"fmi2ExitInitializationMode: not allowed in {self.state}")
        try:
            self._start()
        except AcausalError as exc:
            self.state = FAILED
            return self.log(ERROR, f"initialisation failed: {exc}")
        self.state = STEPPING
        return OK

    def terminate(self):
        self.state = TERMINATED_STATE
        return OK

    def free(self):
        self.stepper = None
        return OK

    def cancel_step(self):
        return self.log(ERROR, "fmi2CancelStep: doStep always completes (not asynchronous)")

    # -- the simulation -----------------------------------------------------
    def _run_values(self):
        """name -> value of what the importer set, for the Stepper."""
        out = {}
        for vr, v in self.vars.items():
            if v["kind"] in ("parameter", "input", "start") and \
                    (v["name"] in self.set_names or v["kind"] == "input"):
                out[v.get("param", v["name"])] = self.values[vr]
        return out

    def _start(self):
        """The Stepper at the start time, from the values set so far."""
        exp, keep = self.spec["experiment"], any(v["kind"] == "measure"
                                                 for v in self.vars.values())
        opts = dict(t_end=self.t_stop, rtol=self.rtol or exp["rtol"], atol=exp["atol"],
                    atol_algebraic=exp.get("atol_algebraic"), max_step=exp.get("max_step"),
                    backend=self.spec.get("backend"), output_step=exp.get("output_step"))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            self.stepper = Stepper(self.cm, self._run_values(), self.t0, keep=keep, **opts)
        self.terminated = self.stepper.stopped
        self._measures = None

    def do_step(self, t, h):
        if self.state != STEPPING:
            why = (" (the FMU was terminated by a terminal event of the model)"
                   if self.terminated else "")
            return self.log(ERROR, f"fmi2DoStep: not allowed in {self.state}{why}")
        st = self.stepper
        if self.terminated:
            return self.log(ERROR, f"fmi2DoStep at t = {t:.9g} s: the model stopped at "
                            f"t = {st.t:.9g} s (a terminal event)")
        if not h >= 0:
            return self.log(ERROR, f"fmi2DoStep: communication step {h!r} must be >= 0")
        if abs(t - st.t) > 1e-9 * max(1.0, abs(t)):
            return self.log(ERROR, f"fmi2DoStep: the communication point t = {t:.12g} s is "
                            f"not where the FMU is (t = {st.t:.12g} s)")
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                if self.pending:
                    st.set_parameters(self.pending)
                    self.pending = {}
                st.advance(t + h)
        except Exception as exc:   # noqa: BLE001 - logged, fmi2Error: never into the importer
            self.state = FAILED
            what = str(exc) if isinstance(exc, AcausalError) else \
                f"{type(exc).__name__}: {exc}"
            return self.log(ERROR, f"simulation failed in the step from t = {t:.9g} s: {what}")
        self.steps += 1
        self._measures = None
        if st.stopped:
            self.terminated = True
            return self.log(DISCARD, f"the model stopped at t = {st.t:.9g} s (terminal event "
                            f"{self._last_event()}): fmi2Terminated")
        return OK

    def _last_event(self):
        events = self.stepper.run.events
        return repr(events[-1][1]) if events else "?"

    def real_status(self, kind):
        if kind != LAST_SUCCESSFUL_TIME or self.stepper is None:
            raise FmuError(f"fmi2GetRealStatus: status kind {kind} is not available")
        return float(self.stepper.t)

    def boolean_status(self, kind):
        if kind != TERMINATED:
            raise FmuError(f"fmi2GetBooleanStatus: status kind {kind} is not available")
        return bool(self.terminated)

    # -- values -------------------------------------------------------------
    def _var(self, vr, call):
        v = self.vars.get(vr)
        if v is None:
            raise FmuError(f"{call}: no Real variable has value reference {vr}")
        return v

    def get_real(self, vrs):
        return [self._value(self._var(vr, "fmi2GetReal")) for vr in vrs]

    def _value(self, v):
        kind, name = v["kind"], v["name"]
        if kind in ("parameter", "input"):
            return self.values[v["vr"]]
        if kind == "calculated":
            p = self._parameter_values()
            return float(self.cm.resolve(sp.Symbol(name)).xreplace(p))
        if kind == "start" and (self.state == INSTANTIATED or
                                (self.stepper is None and not v.get("output"))):
            return self.values[v["vr"]]
        if self.stepper is None:
            if self.state == INSTANTIATED:
                raise FmuError(f"fmi2GetReal: {name} has no value before "
                               "fmi2EnterInitializationMode")
            self._start()   # the initial point, asked for in initialization mode
        if kind == "measure":
            return self._measure(name)
        if name in self.var_index:
            return float(self.stepper.observed()[self.var_index[name]])
        return float(self.stepper.d[self.disc_index[name]])

    def _parameter_values(self):
        """symbol -> value of every free parameter now."""
        if self.stepper is not None:
            return dict(zip(self.cm.param_syms, self.stepper.run.p))
        p = self.cm.param_vector({k: val for k, val in self._run_values().items()
                                  if k not in self.cm.flat.variables})
        return dict(zip(self.cm.param_syms, p))

    def _measure(self, name):
        """A measure of the run so far (NaN while it cannot be computed yet,
        e.g. a response time before the response)."""
        if self._measures is None:
            with warnings.catch_warnings(), np.errstate(all="ignore"):
                warnings.simplefilter("ignore")
                self._measures = measure_values(self.mf, self.stepper.result())[0]
        return float(self._measures.get(name, float("nan")))

    def set_real(self, vrs, values):
        for vr, value in zip(vrs, values):
            v = self._var(vr, "fmi2SetReal")
            status = self._set(v, float(value))
            if status != OK:
                return status
        return OK

    def _set(self, v, value):
        kind, name = v["kind"], v["name"]
        if kind not in ("parameter", "input", "start"):
            return self.log(ERROR, f"fmi2SetReal: {name} is {_KIND_WORDS[kind]}: it cannot "
                            "be set")
        if self.state in (TERMINATED_STATE, FAILED):
            return self.log(ERROR, f"fmi2SetReal: not allowed in {self.state}")
        before_start = self.state in (INSTANTIATED, INITIALIZING)
        tunable = kind == "input" or v.get("variability") == "tunable"
        if not before_start and not tunable:
            return self.log(ERROR, f"fmi2SetReal: {name} is a fixed "
                            f"{'start value' if kind == 'start' else 'parameter'}: set it "
                            "before fmi2ExitInitializationMode")
        try:
            if kind == "start":
                self.cm.split_overrides({name: value})
            else:
                self.cm.param_vector({v.get("param", name): value})
        except AcausalError as exc:
            return self.log(ERROR, f"fmi2SetReal: {exc}")
        self.values[v["vr"]] = value
        self.set_names.add(name)
        if before_start:
            self.stepper = None   # an initial point computed in initialization mode is stale
        else:
            self.pending[v.get("param", name)] = value
        return OK

    def no_variables(self, call):
        return self.log(ERROR, f"{call}: this FMU has Real variables only")

    def unsupported(self, call):
        return self.log(ERROR, f"{call} is not supported by this FMU (see its "
                        "modelDescription.xml capability flags)")


_KIND_WORDS = {"output": "an output", "measure": "an output (a measure of the model file)",
               "calculated": "a calculated parameter (bound to other parameters)"}
