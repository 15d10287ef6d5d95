"""What a new user of the breaker model sees (issue 9, item 7): measures
with units, the default output at the solver's steps giving the same
measures as the dense grid, start values set per run, one sign for the
contact force."""
import os
import re

import numpy as np
import pytest
from click.testing import CliRunner

from acausal.cli import main
from acausal.modelfile import compile_file, evaluate_measures

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MODEL = os.path.join(ROOT, "models", "breaker_24kv.py")
VELOCITIES = (3.3, 3.5, 3.8, 4.0, 4.2, 4.5)    # data/report/table2_thrt.csv


@pytest.fixture(scope="module")
def breaker():
    return compile_file(MODEL)


def test_default_output_gives_the_dense_grids_measures(breaker):
    """The model file's default run (output at the solver's internal steps
    and events) and the dense 2 us grid give the same THRT and contact
    period to 1e-10 ms at all six voltages of Table 2: output times are
    interpolated by IDA and do not steer its steps."""
    mf, cm = breaker
    fast, dense = mf.experiment.run_options(), mf.experiment.run_options(dense=True)
    assert fast["output_step"] == 0 and dense["output_step"] == 2e-6
    for v in VELOCITIES:
        r_fast = cm.simulate(params={"v_impact": v}, **fast)
        r_dense = cm.simulate(params={"v_impact": v}, **dense)
        assert len(r_dense.t) > 1.5 * len(r_fast.t)     # the grids really differ
        m_fast, m_dense = evaluate_measures(mf, r_fast), evaluate_measures(mf, r_dense)
        for k in ("thrt", "contact_period"):
            assert abs(m_fast[k] - m_dense[k]) * 1e3 < 1e-10, (v, k, m_fast[k], m_dense[k])
        assert abs(m_fast["peak_force"] / m_dense["peak_force"] - 1) < 1e-12


def test_simulate_prints_thrt_in_ms_and_peak_force_in_newtons():
    r = CliRunner().invoke(main, ["simulate", MODEL])
    assert r.exit_code == 0, r.output
    thrt = re.search(r"thrt = ([0-9.]+) ms", r.output)
    assert thrt and abs(float(thrt.group(1)) - 1.90) <= 0.02, r.output
    assert re.search(r"peak_force = [0-9.]+ N\b", r.output), r.output
    assert re.search(r"contact_period = 0\.3[0-9]* ms", r.output), r.output


def test_armature_start_velocity_from_the_command_line(tmp_path):
    """``--set armature.mass.v=-3.3`` (a fixed start value, an alias of the
    solver's der(armature.mass.s)) runs the breaker as v_impact = 3.3 does:
    the file declares ``armature.mass.v`` = -v_impact at the start."""
    import json
    r = CliRunner().invoke(main, ["simulate", MODEL, "--set", "armature.mass.v=-3.3", "--json"])
    assert r.exit_code == 0, r.output
    by_start = json.loads(r.output)["measures"]
    r = CliRunner().invoke(main, ["simulate", MODEL, "--set", "v_impact=3.3", "--json"])
    by_param = json.loads(r.output)["measures"]
    assert abs(by_start["thrt"] - by_param["thrt"]) < 1e-12
    assert abs(by_start["thrt"] * 1e3 - 2.55) < 0.1        # Table 2: 2.50 calculated


def test_plot_shows_the_contact_force_with_the_sign_the_console_prints(breaker, tmp_path):
    """One sign: the plotted contact force is >= 0 and peaks at the printed
    ``peak_force`` (the event-located maximum; the 2 us grid samples it to
    about (pi step / period)^2 / 8 = 6e-5)."""
    mf, cm = breaker
    res = cm.simulate(**mf.experiment.run_options(dense=True))
    peak = evaluate_measures(mf, res)["peak_force"]
    fig = mf.namespace["plot"](res, str(tmp_path / "b.png"))
    force = fig.axes[0].lines[0].get_ydata()
    assert force.min() >= 0.0
    assert abs(force.max() / peak - 1) < 1e-3
    assert "[N]" in fig.axes[0].get_ylabel()
    assert (tmp_path / "b.png").stat().st_size > 1000
