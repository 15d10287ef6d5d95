"""Fuzzed inputs (issue 9, item 5): mutated dataset folders, model files and
``--set`` values, generated deterministically from the real datasets in
data/ and the model files in models/examples/.

Every case ends in a correct load or in a one-line AcausalError naming the
file (and the line, where the file has one), within a time limit; any other
exception, or a hang, fails the test. The counts are printed in the
terminal summary (``acausal summaries``).
"""
import math
import traceback
from collections import Counter
from pathlib import Path

import numpy as np
import pytest

from acausal.errors import AcausalError
from acausal.data import load_dataset
from tests.fuzz import mutate as mu

pytestmark = pytest.mark.fuzz

ROOT = Path(__file__).resolve().parents[2]
REPORT = ROOT / "data" / "report_24kv"
TABLES = ROOT / "data" / "report"
EXAMPLES = ROOT / "models" / "examples"
N_DATA, N_MODEL, N_SET = 750, 250, 300
LIMIT_S = 3.0
# errors about a whole file, which has no line to name
FILE_LEVEL = ("file not found", "a folder, not a file", "not a regular file", "no header row",
              "trace of unknown experiment")


@pytest.fixture(scope="module")
def breaker_units():
    """name -> unit maps of the breaker model (what calibration passes to
    load_dataset), from the flattened model: no compilation."""
    from acausal.studies.calibrate import _si
    from acausal.compiler.flatten import flatten
    from acausal.modelfile import load_model_file
    mf = load_model_file(ROOT / "models" / "breaker_24kv.py")
    flat = flatten(mf.model)
    params = {i.symbol.name: i.decl.unit for i in flat.params.values()
              if not i.decl.structural and not i.bound}
    return dict(parameters=params,
                measures={m: _si(mf, m) for m in mf.measures},
                variables={n: v.unit for n, v in flat.variables.items()},
                conditions=list(mf.conditions))


def seed_files():
    """The seed folder: the report's experiments and instrument, and a
    trace of the hook angle at 110 V (a smooth curve to 5 deg at 1.9 ms)."""
    t = np.linspace(0.0, 1.9, 20)
    trace = "# hook angle at 110 V\ntime [ms],hook.phi [deg]\n" + "".join(
        f"{a:.6g},{-5.0 * (a / 1.9) ** 2:.6g}\n" for a in t)
    return {"experiments.csv": (REPORT / "experiments.csv").read_bytes(),
            "instrument.csv": (REPORT / "instrument.csv").read_bytes(),
            "V110.csv": trace.encode()}


def write_folder(folder, files):
    folder.mkdir(parents=True)
    for name, data in files.items():
        if data is None:      # a directory where a file is expected
            (folder / name).mkdir()
        else:
            (folder / name).write_bytes(data)
    return folder


def folder_mutation(files, rng):
    """Mutations of the folder: missing files and traces, orphans, strangers."""
    what = rng.randrange(7)
    if what == 0:
        files.pop("experiments.csv")
    elif what == 1:
        files.pop("V110.csv")                    # a missing trace: still a valid folder
    elif what == 2:
        files["V999.csv"] = files.pop("V110.csv")  # a trace of no experiment
    elif what == 3:
        files.pop("instrument.csv")
    elif what == 4:
        table = rng.choice(sorted(TABLES.glob("*.csv")))
        files["experiments.csv"] = table.read_bytes()
    elif what == 5:
        files["experiments.csv"] = None
    else:
        files[rng.choice(["notes.csv", "V110 .csv", "v110.csv"])] = files["V110.csv"]
    return f"folder{what}"


def make_case(seeds, case):
    """(files, label, benign) of data fuzz case ``case``."""
    rng = mu.rng_for("data", case)
    files = dict(seeds)
    r = rng.random()
    if r < 0.1:
        return files, folder_mutation(files, rng), False
    name = rng.choice(["experiments.csv"] * 3 + ["instrument.csv", "V110.csv"])
    if r < 0.25:
        m = rng.choice(mu.BENIGN)
        files[name] = m(files[name], rng)
        return files, m.__name__, True
    labels = []
    for _ in range(rng.choice([1, 1, 2, 3])):
        m = rng.choice(mu.HARMFUL)
        files[name] = m(files[name], rng)
        labels.append(m.__name__)
    return files, "+".join(labels), False


def check_error(err, folder):
    """The error is one line naming a file of ``folder`` (and its line)."""
    msg = str(err)
    assert "\n" not in msg and "\r" not in msg, msg
    assert err.file is not None, f"no file in: {msg}"
    assert Path(err.file).parent == folder, msg
    if err.line is None:
        assert msg.startswith(f"{err.file}: ") or msg.startswith(f"{err.file}:"), msg
        assert any(w in msg for w in FILE_LEVEL), f"no line in: {msg}"
        return "error naming the file"
    assert msg.startswith(f"{err.file}:{err.line}: "), msg
    return "error naming file:line"


def check_dataset(ds, units):
    """What a correct load guarantees."""
    names = [e.name for e in ds.experiments]
    assert len(set(names)) == len(names) and all(names)
    for e in ds.experiments:
        assert set(e.conditions) <= set(units["parameters"])
        assert set(e.measures) <= set(units["measures"])
        assert all(math.isfinite(v) for v in [*e.conditions.values(), *e.measures.values()])
        if e.trace is not None:
            assert np.all(np.diff(e.trace.time) > 0)
            for sig, y in e.trace.signals.items():
                assert sig in units["variables"] and len(y) == len(e.trace.time)
                assert np.all(np.isfinite(y))
    for i in ds.instrument.values():
        assert i.resolution >= 0 and i.noise_std >= 0
        assert math.isfinite(i.resolution) and math.isfinite(i.noise_std)


def same(a, b):
    """Two datasets with the same content (folder aside)."""
    def flat(ds):
        return [(e.name, e.conditions, e.measures, e.use,
                 None if e.trace is None else (e.trace.time.tolist(),
                                                {k: v.tolist() for k, v in e.trace.signals.items()}))
                for e in ds.experiments], ds.instrument
    return flat(a) == flat(b)


def run_case(fn, outcomes, failures, label):
    """Run ``fn`` (returns an outcome) under the time limit; record."""
    try:
        with mu.time_limit(LIMIT_S):
            outcome = fn()
    except mu.Hang as exc:
        outcome = "hang"
        failures.append(f"{label}: {exc}")
    except AssertionError as exc:
        outcome = "wrong"
        failures.append(f"{label}: {exc}")
    except Exception as exc:  # noqa: BLE001 - any other exception is what we look for
        outcome = f"crash ({type(exc).__name__})"
        failures.append(f"{label}: {''.join(traceback.format_exception_only(exc)).strip()}")
    outcomes[outcome] += 1


def summary(report, what, n, outcomes, failures):
    parts = ", ".join(f"{k} {v}" for k, v in sorted(outcomes.items()))
    report.append(f"fuzz {what}: {n} mutated inputs: {parts}")
    assert not failures, f"{len(failures)} of {n} failed, e.g.:\n" + "\n".join(failures[:15])


def test_fuzzed_dataset_folders(tmp_path, breaker_units, terminal_report):
    seeds = seed_files()
    kw = breaker_units
    reference = load_dataset(write_folder(tmp_path / "seed", seeds), **kw)
    check_dataset(reference, kw)
    assert reference.experiment("V110").trace is not None
    outcomes, failures = Counter(), []
    for case in range(N_DATA):
        files, label, benign = make_case(seeds, case)
        folder = write_folder(tmp_path / f"c{case}", files)

        def one():
            try:
                ds = load_dataset(folder, **kw)
            except AcausalError as err:
                assert not benign, f"benign mutation refused: {err}"
                return check_error(err, folder)
            check_dataset(ds, kw)
            if benign:
                assert same(ds, reference), "a benign mutation changed the data"
            return "loaded"
        run_case(one, outcomes, failures, f"data case {case} ({label})")
    summary(terminal_report, "dataset folders", N_DATA, outcomes, failures)


MODEL_SEEDS = ["oscillator.py", "lever_masses.py", "hertz_impact.py", "fourbar.py",
               "newtons_cradle.py", "stick_slip.py"]


def float_literal(data, rng):
    """A float literal of a model file replaced by nan, inf, a huge, tiny,
    zero or negative number (integer literals, which may count loops, are
    left alone)."""
    import re
    nums = list(re.finditer(rb"(?<![\w.])\d+\.\d*(e[-+]?\d+)?|(?<![\w.])\d+e[-+]?\d+", data))
    if not nums:
        return data
    m = rng.choice(nums)
    new = rng.choice([b"float('nan')", b"float('inf')", b"-float('inf')", b"1e300", b"1e-300",
                      b"0.0", b"-1.0", b"1e999", b"-0.0", b"'3.0'", b"None"])
    return data[:m.start()] + new + data[m.end():]


def unit_string(data, rng):
    """A unit string of the file replaced."""
    import re
    units = list(re.finditer(rb'"(kg|m|s|N|N/m|m/s|rad|kg\*m\^2|N\*m|1)"', data))
    if not units:
        return data
    m = rng.choice(units)
    return data[:m.start()] + b'"' + rng.choice(mu.UNITS).encode() + b'"' + data[m.end():]


# statements a model file may end with that end the command, rebind its
# experiment badly or raise from the interpreter's own exits (a traceback, or
# exit 0 with nothing done, before they were checked)
TAILS = [b"import sys\nsys.exit(0)\n", b"raise SystemExit('bye')\n", b"exit(3)\n",
         b"experiment.stop = 5\n", b"experiment.rtol = 5.0\n", b"experiment.rtol = 1\n",
         b"experiment.stop = 'mass.s'\n", b"experiment.t_end = -experiment.t_end\n",
         b"measures = {'m': 3}\n", b"free_parameters = {'x': (2, 1)}\n",
         b"conditions = 'F'\n", b"model = model.children\n"]


def tail_statement(data, rng):
    """A statement from TAILS appended to the file."""
    return data + b"\n" + rng.choice(TAILS)


MODEL_MUTATIONS = [tail_statement, tail_statement, mu.truncate_line, mu.truncate_file, mu.drop_line, mu.duplicate_line,
                   mu.nul_byte, mu.latin1, mu.utf16, mu.flip_byte, mu.empty, mu.quote,
                   mu.semicolons, mu.swap_lines, float_literal, float_literal, float_literal,
                   unit_string, mu.bom, mu.crlf, mu.blank_and_comment_lines]


def build(path):
    """Load a model file: run it, which builds its Model (every component
    checks its parameters), and check what it binds. Flattening and the
    structure analysis are left out: at 0.1 to 1 s per file they would
    cost minutes, and their errors are tested in tests/core."""
    from acausal.modelfile import load_model_file
    return load_model_file(path)


def test_fuzzed_model_files(tmp_path, terminal_report):
    seeds = {n: (EXAMPLES / n).read_bytes() for n in MODEL_SEEDS}
    for n, data in seeds.items():       # every seed builds
        (tmp_path / n).write_bytes(data)
        assert build(tmp_path / n).model is not None
    outcomes, failures = Counter(), []
    for case in range(N_MODEL):
        rng = mu.rng_for("model", case)
        seed = rng.choice(MODEL_SEEDS)
        data, labels = seeds[seed], []
        for _ in range(rng.choice([1, 1, 2])):
            m = rng.choice(MODEL_MUTATIONS)
            data = m(data, rng)
            labels.append(m.__name__)
        folder = tmp_path / f"m{case}"
        folder.mkdir()
        path = folder / seed
        path.write_bytes(data)

        def one():
            try:
                build(path)
            except AcausalError as err:
                msg = str(err)
                assert "\n" not in msg, msg
                assert err.file is not None, msg
                assert Path(err.file) == path and msg.startswith(str(path)), msg
                if err.line is None:   # only when the file binds no model at all
                    assert "bind a Model to the name 'model'" in msg, msg
                    return "error naming the file"
                return "error naming file:line"
            return "loaded"
        run_case(one, outcomes, failures, f"model case {case} ({seed}: {'+'.join(labels)})")
    summary(terminal_report, "model files", N_MODEL, outcomes, failures)


SET_VALUES = ["inf", "-inf", "nan", "NaN", "1e999", "-1", "0", "-0.0", "1e-300", "1e300", "abc",
              "", " ", "1,5", "0x1p3", "1e", "2", "100", "0.5", "∞", "1_0", "+3", "None"]


def test_fuzzed_set_values(terminal_report):
    """``--set`` values as the command line parses and checks them (before
    any simulation): unknown paths, non-numbers, negative masses, NaN, inf,
    values outside a parameter's bounds."""
    from acausal.cli import _parse_sets
    from acausal.modelfile import compile_file
    mf, cm = compile_file(EXAMPLES / "lever_masses.py")
    names = [p.name for p in cm.params] + ["mass.q", "nothing", "m1", "lever.", ".m", "m1.m.m",
                                           ""] + list(cm.structural) + list(cm.bound)
    outcomes, failures = Counter(), []
    for case in range(N_SET):
        rng = mu.rng_for("set", case)
        items = [f"{rng.choice(names)}{rng.choice(['=', '=', ' = ', ':', '=='])}"
                 f"{rng.choice(SET_VALUES)}" for _ in range(rng.choice([1, 1, 2]))]

        def one():
            try:
                p = cm.param_vector(_parse_sets(items))
            except AcausalError as err:
                msg = str(err)
                assert "\n" not in msg
                assert any(i.split("=")[0].strip() in msg or repr(i) in msg for i in items), msg
                return "refused"
            assert np.all(np.isfinite(p))
            for entry, v in zip(cm.params, p):
                entry.decl.check_bounds(v, entry.name)
            return "accepted"
        run_case(one, outcomes, failures, f"--set case {case} {items}")
    summary(terminal_report, "--set values", N_SET, outcomes, failures)
