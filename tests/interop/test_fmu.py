"""FMU export (FMI 2.0 Co-Simulation), checked by FMPy: it validates the
modelDescription.xml and simulates the FMU, whose outputs are compared with
closed forms and with ``acausal simulate`` (the same model and tolerances);
events (stick/slip, the breaker's contact and release) happen inside the
FMU's steps; a parameter or start value changed through FMPy's
``start_values`` is honoured; an input drives the model; the life cycle
(reset, terminate, free) works; a failing simulation is fmi2Error with its
message logged; bad export input is one line."""
import math
import os

import numpy as np
import pytest

fmpy = pytest.importorskip("fmpy", reason="needs the fmu extra: pip install -e '.[fmu]'")

from click.testing import CliRunner  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

from acausal.cli import main  # noqa: E402
from acausal.errors import UsageError  # noqa: E402
from acausal.interop.fmu import export_fmu  # noqa: E402
from acausal.modelfile import compile_file, measure_values  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
MODELS = os.path.join(HERE, "..", "..", "models")
OSCILLATOR = os.path.join(MODELS, "examples", "oscillator.py")
STICK_SLIP = os.path.join(MODELS, "examples", "stick_slip.py")
BREAKER = os.path.join(MODELS, "breaker_24kv.py")


class Log:
    """An FMI logger callback keeping (status, message)."""

    def __init__(self):
        self.lines = []

    def __call__(self, env, name, status, category, message):
        self.lines.append((status, message.decode() if isinstance(message, bytes)
                           else str(message)))

    def text(self):
        return "\n".join(m for _, m in self.lines)


def reference(path, times, params=None, backend=None):
    """``acausal simulate``'s result of a model file on the FMU's output times."""
    mf, cm = compile_file(path)
    opts = {**mf.experiment.run_options(), "output_step": None}
    res = cm.simulate(params=params, output_times=times, backend=backend, **opts)
    return mf, res


def worst(fmu_result, res, name):
    """Worst deviation of the FMU's ``name`` from the reference, as a fraction
    of the reference's range."""
    ref = np.interp(fmu_result["time"], res.t, res[name])
    return float(np.max(np.abs(fmu_result[name] - ref)) / np.ptp(res[name]))


@pytest.fixture(scope="module")
def oscillator_fmu(tmp_path_factory):
    out = tmp_path_factory.mktemp("fmu") / "oscillator.fmu"
    return export_fmu(OSCILLATOR, out, outputs=["mass.s", "mass.v"], inputs=["spring.f0"])


# -- the oscillator: closed form, acausal simulate, units, start values, input


def test_oscillator_validates_with_units(oscillator_fmu):
    assert validate_fmu(oscillator_fmu) == []
    md = fmpy.read_model_description(oscillator_fmu)
    v = {sv.name: sv for sv in md.modelVariables}
    assert (v["mass.s"].causality, v["mass.s"].initial, v["mass.s"].unit) == \
        ("output", "exact", "m")
    assert float(v["mass.s"].start) == 0.1          # a fixed start value: settable
    assert (v["spring.c"].causality, v["spring.c"].variability, v["spring.c"].unit) == \
        ("parameter", "tunable", "N/m")
    assert (v["spring.f0"].causality, v["spring.f0"].unit) == ("input", "N")
    units = {u.name: u.baseUnit for u in md.unitDefinitions}
    assert (units["N/m"].kg, units["N/m"].m, units["N/m"].s) == (1, 0, -2)
    assert (units["m/s"].m, units["m/s"].s) == (1, -1)
    assert [md.modelVariables[u.variable.valueReference].name for u in md.outputs] == \
        ["mass.s", "mass.v"]


def test_oscillator_matches_closed_form_and_simulate(oscillator_fmu):
    r = fmpy.simulate_fmu(oscillator_fmu, output_interval=0.01)
    t = r["time"]
    assert t[-1] == pytest.approx(1.0)
    # exact: s = 0.1 cos(10 t); rtol 1e-8 over 1.6 periods and 100 restarts
    # of IDA at the communication points: the global error stays ~1e-7
    assert np.max(np.abs(r["mass.s"] - 0.1 * np.cos(10 * t))) / 0.2 < 2e-6
    assert np.max(np.abs(r["mass.v"] + np.sin(10 * t))) / 2.0 < 2e-6
    _, res = reference(OSCILLATOR, t)
    assert worst(r, res, "mass.s") < 2e-6


def test_oscillator_parameter_and_start_value_set_by_the_importer(oscillator_fmu):
    r = fmpy.simulate_fmu(oscillator_fmu, output_interval=0.01,
                          start_values={"spring.c": 400.0, "mass.s": 0.05})
    t = r["time"]   # omega = sqrt(400 / 1) = 20 rad/s
    assert np.max(np.abs(r["mass.s"] - 0.05 * np.cos(20 * t))) / 0.1 < 2e-6


def test_oscillator_input_step(oscillator_fmu):
    """spring.f0 (a preload force, tension positive) steps from 0 to 30 N at
    0.5 s: m s'' = -(c s + f0); after the step the mass oscillates about
    -f0/c, from the state it had at 0.5 s."""
    c, F, t1 = 100.0, 30.0, 0.5
    inp = np.array([(0.0, 0.0), (t1, 0.0), (t1, F), (1.0, F)],
                   dtype=[("time", float), ("spring.f0", float)])
    r = fmpy.simulate_fmu(oscillator_fmu, output_interval=0.01, input=inp)
    t = r["time"]
    s1, v1 = 0.1 * math.cos(10 * t1), -math.sin(10 * t1)
    after = -F / c + (s1 + F / c) * np.cos(10 * (t - t1)) + v1 / 10 * np.sin(10 * (t - t1))
    exact = np.where(t <= t1, 0.1 * np.cos(10 * t), after)
    assert np.max(np.abs(r["mass.s"] - exact)) / 0.7 < 2e-6


def test_life_cycle_reset_terminate_free(oscillator_fmu, tmp_path):
    """Two runs of one instance with a reset between them give the same
    values; a fixed start value set after initialisation is fmi2Error with a
    logged line, and the instance goes on; terminate and free work."""
    from fmpy import extract, read_model_description
    from fmpy.fmi1 import FMICallException
    from fmpy.simulation import instantiate_fmu
    md = read_model_description(oscillator_fmu)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    log = Log()
    fmu = instantiate_fmu(extract(oscillator_fmu, str(tmp_path / "x")), md,
                          fmi_type="CoSimulation", logger=log)
    runs = []
    for _ in range(2):
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        values = []
        for k in range(10):
            fmu.doStep(currentCommunicationPoint=0.05 * k, communicationStepSize=0.05)
            values.append(fmu.getReal([vr["mass.s"]])[0])
        runs.append(values)
        with pytest.raises(FMICallException):
            fmu.setReal([vr["mass.s"]], [0.3])
        assert "mass.s is a fixed start value: set it before fmi2ExitInitializationMode" \
            in log.text()
        fmu.reset()
    assert runs[0] == runs[1]
    assert runs[0][-1] == pytest.approx(0.1 * math.cos(5.0), abs=1e-6)
    fmu.terminate()
    fmu.freeInstance()


def test_failed_simulation_is_fmi2error_with_its_message(tmp_path):
    """An assertion that fails inside a step: doStep returns fmi2Error (FMPy
    raises), the message names the component and the time, and the process
    goes on."""
    model = tmp_path / "runaway.py"
    model.write_text(
        "from acausal import Component, Experiment, Model, Parameter, Variable, der, Eq\n"
        "from acausal import Assertion\n"
        "class Runaway(Component):\n"
        "    x = Variable(0.0, 'm', 'position', fixed=True)\n"
        "    v = Parameter(1.0, 'm/s', 'speed')\n"
        "    limit = Parameter(0.5, 'm', 'largest allowed position')\n"
        "    def equations(self):\n"
        "        return [Eq(der(self.x), self.v)]\n"
        "    def assertions(self):\n"
        "        return [Assertion(self.limit - self.x, 'position passed the limit')]\n"
        "model = Model()\n"
        "model.r = Runaway()\n"
        "experiment = Experiment(t_end=1.0)\n")
    path = export_fmu(model, tmp_path / "runaway.fmu", outputs=["r.x"])
    log = Log()
    with pytest.raises(Exception, match="fmi2DoStep"):
        fmpy.simulate_fmu(path, output_interval=0.1, logger=log)
    assert "r: position passed the limit (at t = 0.5 s)" in log.text()
    assert any(status == 3 for status, _ in log.lines)   # fmi2Error
    # the same FMU runs again in this process (the limit moved out of reach)
    r = fmpy.simulate_fmu(path, output_interval=0.1, start_values={"r.limit": 2.0})
    assert r["r.x"][-1] == pytest.approx(1.0, abs=1e-6)


# -- bad input: one line


def test_bad_input_one_line(tmp_path):
    runner = CliRunner()
    cases = [
        (["fmu", OSCILLATOR, "-o", str(tmp_path / "a.fmu")],
         "the FMU would have no outputs: the model file declares no measures; choose "
         "variables with --output NAME (e.g. --output mass.s)"),
        (["fmu", OSCILLATOR, "-o", str(tmp_path / "a.fmu"), "--output", "mass.x"],
         "--output mass.x: the model has no variable 'mass.x' (did you mean"),
        (["fmu", OSCILLATOR, "-o", str(tmp_path / "nowhere" / "a.fmu"), "--output",
          "mass.s"], f"folder {tmp_path / 'nowhere'} does not exist"),
        (["fmu", OSCILLATOR, "-o", str(tmp_path / "a.fmu"), "--output", "mass.s",
          "--input", "mass.s"], "--input mass.s: not a free parameter of the model"),
    ]
    for args, expected in cases:
        r = runner.invoke(main, args)
        assert r.exit_code == 2, r.output
        lines = r.output.strip().splitlines()
        assert len(lines) == 1 and expected in lines[0], r.output
    assert not list(tmp_path.glob("*.fmu"))
    with pytest.raises(UsageError, match="must end in .fmu"):
        export_fmu(OSCILLATOR, tmp_path / "a.zip", outputs=["mass.s"])


def test_cli_writes_a_valid_fmu(tmp_path):
    out = tmp_path / "osc.fmu"
    r = CliRunner().invoke(main, ["fmu", OSCILLATOR, "-o", str(out), "--output", "mass.s"])
    assert r.exit_code == 0, r.output
    assert r.output.strip() == f"wrote {out}"
    assert validate_fmu(str(out)) == []


# -- events inside the FMU: stick/slip and the breaker


@pytest.fixture(scope="module")
def stick_slip_fmu(tmp_path_factory):
    out = tmp_path_factory.mktemp("fmu") / "stick_slip.fmu"
    return export_fmu(STICK_SLIP, out, outputs=["block.v", "block.s"], backend="compiled")


def _stick_slip_closed_form(V):
    ns = {}
    with open(STICK_SLIP) as f:
        src = f.read()
    exec(compile(src.split("\nmodel = Model()")[0], STICK_SLIP, "exec"), ns)   # constants
    m, k, mu_k, mu_s, g = ns["M"], ns["K"], ns["MU_K"], ns["MU_S"], ns["G"]
    fc, fs = mu_k * m * g, mu_s * m * g
    w = math.sqrt(k / m)
    slip = (2 * math.pi - 2 * math.atan(w * (fs - fc) / (k * V))) / w
    return fs / (k * V), slip + 2 * (fs - fc) / (k * V)


@pytest.mark.parametrize("V", [None, pytest.param(0.08, marks=pytest.mark.slow)])
def test_stick_slip_events_inside_the_fmu(stick_slip_fmu, V):
    """Break-away and stop events fall inside the communication steps: the
    FMU's trajectory matches acausal simulate's, its measures (taken from
    the events) the closed form, also with the driver speed V changed
    through start_values."""
    assert validate_fmu(stick_slip_fmu) == []
    start = {} if V is None else {"V": V}
    r = fmpy.simulate_fmu(stick_slip_fmu, output_interval=0.01, start_values=start)
    mf, res = reference(STICK_SLIP, r["time"], params=start or None, backend="compiled")
    assert worst(r, res, "block.v") < 1e-6      # measured 8.3e-8 (rtol 1e-9)
    assert worst(r, res, "block.s") < 1e-6
    first, period = _stick_slip_closed_form(V or 0.05)
    assert r["first_break"][-1] == pytest.approx(first, abs=1e-6)
    assert r["period"][-1] == pytest.approx(period, rel=1e-5)
    sim = measure_values(mf, cm_simulate(STICK_SLIP, start))[0]
    for name in ("period", "dwell", "slip_time", "first_break", "max_speed"):
        assert r[name][-1] == pytest.approx(sim[name], rel=1e-7), name


def cm_simulate(path, params):
    mf, cm = compile_file(path)
    return cm.simulate(params=params or None, backend="compiled", **mf.experiment.run_options())


@pytest.fixture(scope="module")
def breaker_fmu(tmp_path_factory):
    out = tmp_path_factory.mktemp("fmu") / "breaker.fmu"
    return export_fmu(BREAKER, out, outputs=["hook.phi"], backend="compiled")


@pytest.mark.parametrize("v_impact", [None, pytest.param(4.2, marks=pytest.mark.slow)])
def test_breaker_thrt_and_hook_angle(breaker_fmu, v_impact):
    """The contact and the release happen inside the FMU; the release is a
    terminal event: doStep returns fmi2Discard with fmi2Terminated, FMPy
    stops there. THRT (a measure, an output) and hook.phi match acausal
    simulate, also with the impact velocity changed through start_values."""
    assert validate_fmu(breaker_fmu) == []
    md = fmpy.read_model_description(breaker_fmu)
    units = {v.name: (v.causality, v.unit, v.displayUnit) for v in md.modelVariables}
    assert units["thrt"] == ("output", "s", "ms")
    assert units["hook.phi"][:2] == ("output", "rad")
    start = {} if v_impact is None else {"v_impact": v_impact}
    log = Log()
    r = fmpy.simulate_fmu(breaker_fmu, output_interval=1e-4, start_values=start, logger=log)
    assert "terminal event 'release'" in log.text()
    mf, res = reference(BREAKER, r["time"], params=start or None, backend="compiled")
    assert r["time"][-1] == pytest.approx(res.t[-1], abs=1e-9)   # stopped at the release
    assert worst(r, res, "hook.phi") < 1e-6                     # measured 1.5e-7
    sim = measure_values(mf, cm_simulate(BREAKER, start))[0]
    assert abs(r["thrt"][-1] - sim["thrt"]) < 2e-9               # measured 4.6e-10 s
    assert np.isnan(r["thrt"][0])   # not determined before the release
    if v_impact is None:
        assert sim["thrt"] == pytest.approx(1.89987e-3, abs=5e-9)
