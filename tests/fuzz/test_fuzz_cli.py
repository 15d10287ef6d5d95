"""Fuzzed command lines and large-trace files (issue 21, items 3, 5 and 8).

Option values: every command's options get values drawn from pools of
malformed, out-of-range and valid ones (times, tolerances, counts written
1e6, sizes, output paths in missing folders, figure formats, sweep ranges
against parameter bounds, huge counts, empty lists, unknown names). Each
command line must end with exit 0, 2 (a usage error: exactly one line on
stderr) or 3 (a run stopped or failed), never a traceback, within a time
limit (a 1e9-point grid, or an output grid of 1e13 rows, is refused before
anything is allocated).

Trace files: mutated traces read by the fast reader (pandas, numpy) give
the same values, or the same located error, as the exact reader.
"""
import os
import traceback
from collections import Counter
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from acausal.cli import main
from acausal.errors import AcausalError
from tests.faults.helpers import spring_file
from tests.fuzz import mutate as mu

pytestmark = pytest.mark.fuzz

ROOT = Path(__file__).resolve().parents[2]
LIMIT_S = 20.0

SPRING = spring_file("""\
experiment = Experiment(t_end=0.2, rtol=1e-6, atol=1e-8, output_step=1e-3)
measures = {"s_end": lambda res: res.final()["body.s"]}
""")

NUMBERS = ["-1", "0", "nan", "inf", "-inf", "1e6", "1e-300", "1e300", "abc", "", " ", "1,5",
           "0x10", "1_000", "3", "0.5", "1e999", "-0.0", "2.5e", "None"]
TIMES = ["-1", "0", "nan", "inf", "abc", "1e8", "1e-9", "0.05", "0.3", "1e300", "", "1e-200"]
SIZES = ["4GB", "512MB", "1KB", "0", "-1GB", "abc", "1e9", "2GiB", "100", "1XB", ""]
FIGS = ["o.png", "o.xyz", "o", "o.pdf", "o.PNG", "nodir/o.png", ".", "o.svg", "o.png/"]
OUTS = ["o.csv", "nodir/o.csv", ".", "o.txt", "deep/er/o.csv", "/proc/acausal_fuzz.csv",
        "/dev/full", "spring.py"]   # a full disk; the model file itself (the input)


def simulate_case(rng, model):
    args = ["simulate", model]
    for _ in range(rng.choice([1, 1, 2, 3])):
        opt = rng.choice(["--t-end", "--rtol", "--atol", "--max-rows", "--max-wall",
                          "--max-steps", "--max-memory", "--plot", "--out", "--set",
                          "--backend", "--bogus"])
        pool = {"--t-end": TIMES, "--max-memory": SIZES, "--plot": FIGS, "--out": OUTS,
                "--set": ["k.c=1e30", "k.c=-1", "body.m=nan", "nothing=1", "k.c", "k.c=5",
                          "body.v=0.1", "=3", "k.c=5e-324", "body.m=1e-320"],
                "--backend": ["sundae", "compiled", "fast"]}.get(opt, NUMBERS)
        args += [opt] if opt == "--bogus" else [opt, rng.choice(pool)]
    return args


def sweep_case(rng, model):
    counts = ["3", "1e9", "0", "-2", "2.5", "1e18", "abc", "1", "1_000_000_000"]
    spec = rng.choice([f"k.c=1:200:{rng.choice(counts)}", f"body.m={rng.choice(['-1', '0'])}:2:3",
                       "k.c=5,5", "k.c=", "=1:2:3", "k.c=1:2", "nothing=1:2:2", "k.c=1,nan",
                       f"body.m=1:2:{rng.choice(counts)}"])
    args = ["sweep", model, "--param", spec, "--measure",
            rng.choice(["s_end", "", "nope", "s_end,s_end", ","]), "--scheduler", "serial",
            "--no-progress", "--out", rng.choice(OUTS)]
    if rng.random() < 0.5:
        args += [rng.choice(["--max-points", "--max-memory", "--max-wall", "--workers"]),
                 rng.choice(NUMBERS + SIZES)]
    return args


def other_case(rng, model):
    data = str(ROOT / "data" / "report_24kv")
    breaker = str(ROOT / "models" / "breaker_24kv.py")
    return rng.choice([
        ["calibrate", breaker, data, "--fit", rng.choice(["", ",", "nothing", "contact.K:"])],
        ["calibrate", breaker, data, "--fit", "contact.K", "--experiments",
         rng.choice(["", ",", "V999"])],
        ["diagnose", breaker, data, "--locations", rng.choice(["nowhere", "", ",", "hook."]),
         "--report", "rep"],
        ["diagnose", breaker, data, "--hypotheses", rng.choice(["", "nothing", ","]),
         "--report", "rep"],
        ["diagnose", breaker, data, rng.choice(["--alpha", "--workers", "--starts",
                                                "--max-memory", "--max-wall"]),
         rng.choice(NUMBERS + ["1KB"]), "--report", "rep", "--locations", "nowhere"],
        ["animate", model, "--out", rng.choice(["a.gif", "nodir/a.gif"]), "--t-end",
         rng.choice(TIMES)],
        ["linearize", model, "--at", rng.choice(TIMES + ["start", "equilibrium",
                                                         "body.s=abc", "nothing=1", "body.s"])],
        ["linearize", model, rng.choice(["--inputs", "--outputs"]),
         rng.choice(["", ",", "nothing", "k.c,k.c", "body.s"])],
    ])


def run_command(args, folder):
    cwd = os.getcwd()
    os.chdir(folder)
    try:
        with mu.time_limit(LIMIT_S):
            return CliRunner().invoke(main, args)
    finally:
        os.chdir(cwd)


def check(r):
    """What every command line must give: exit 0, 2 or 3 (130 never here),
    one line for a usage error, no traceback."""
    if r.exception is not None and not isinstance(r.exception, SystemExit):
        raise AssertionError("".join(traceback.format_exception(r.exception))[-1500:])
    assert "Traceback" not in r.output, r.output[-1500:]
    assert r.exit_code in (0, 2, 3), (r.exit_code, r.output[-800:])
    if r.exit_code == 2:
        lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
        errors = [ln for ln in lines if "error:" in ln]
        assert len(errors) == 1 and len(lines) <= 2 + sum("warning:" in ln for ln in lines), \
            r.stderr
    return {0: "ran", 2: "usage error (one line)", 3: "stopped or failed"}[r.exit_code]


N_SIMULATE, N_SWEEP, N_OTHER = 80, 40, 30


def test_fuzzed_command_lines(tmp_path, terminal_report):
    model = tmp_path / "spring.py"
    model.write_text(SPRING)
    outcomes, failures = Counter(), []
    cases = ([("simulate", simulate_case)] * N_SIMULATE + [("sweep", sweep_case)] * N_SWEEP
             + [("other", other_case)] * N_OTHER)
    for k, (what, make) in enumerate(cases):
        rng = mu.rng_for(f"cli-{what}", k)
        args = make(rng, str(model))
        folder = tmp_path / f"c{k}"
        folder.mkdir()
        try:
            outcomes[check(run_command(args, folder))] += 1
        except mu.Hang:
            outcomes["hang"] += 1
            failures.append(f"{args}: hang")
        except AssertionError as exc:
            outcomes["wrong"] += 1
            failures.append(f"{args}: {exc}")
    terminal_report.append("fuzz command lines: " + ", ".join(
        f"{k} {v}" for k, v in sorted(outcomes.items())) + f" ({len(cases)} command lines)")
    assert not failures, f"{len(failures)} failed, e.g.:\n" + "\n".join(failures[:8])


# -- the fast trace reader agrees with the exact one --------------------------------------


def trace_seed():
    t = np.linspace(0.0, 1.9, 60)
    return ("# hook angle\ntime [ms],hook.phi [deg]\n" + "".join(
        f"{a:.6g},{-5.0 * (a / 1.9) ** 2:.6g}\n" for a in t)).encode()


def read(path, fast, monkeypatch):
    from acausal.data import table
    monkeypatch.setattr(table, "FAST_MIN_BYTES", 0 if fast else 1 << 60)
    try:
        tab, values = table.read_numeric_table(path, progress=False)
        return ("ok", tab.names, tab.units, tab.header_line, values.tolist())
    except AcausalError as err:
        return ("error", str(err).split(":")[0], err.line, err.column)


@pytest.mark.parametrize("pandas", [True, False])
def test_fast_trace_reader_agrees_with_the_exact_one(tmp_path, monkeypatch, pandas,
                                                     terminal_report):
    """Every mutation (bad cells, ragged rows, NUL and non-UTF-8 bytes, BOM,
    CRLF, comments, blank lines, quotes) gives the same values or the same
    error line as the line-by-line reader, with pandas and without."""
    from acausal.data import table
    if not pandas:
        monkeypatch.setattr(table, "_read_pandas", lambda *a: None)
    seed = trace_seed()
    outcomes, failures = Counter(), []
    for case in range(150):
        rng = mu.rng_for("trace", case)
        data = seed
        for _ in range(rng.choice([1, 1, 2])):
            data = rng.choice(mu.HARMFUL + mu.BENIGN)(data, rng)
        path = tmp_path / f"t{case}.csv"
        path.write_bytes(data)
        exact = read(path, False, monkeypatch)
        fast = read(path, True, monkeypatch)
        outcomes[exact[0]] += 1
        if exact != fast and not (exact[0] == fast[0] == "ok" and np.allclose(
                np.asarray(exact[4]), np.asarray(fast[4]), rtol=1e-15, atol=0)):
            failures.append(f"case {case}: exact {str(exact)[:200]} fast {str(fast)[:200]}")
    terminal_report.append(f"fuzz traces, fast reader ({'pandas' if pandas else 'numpy'}) "
                           f"against the exact one: {dict(outcomes)}")
    assert not failures, "\n".join(failures[:10])
