"""Units in every output, start values set per run, the default plot
(issue 9, item 7), on a model written here: a mass on a spring,
m s'' = -c s, with s(t) = s0 cos(w t) + v0 / w sin(w t), w = sqrt(c / m)."""
import csv
import json
import textwrap

import numpy as np
import pytest
from click.testing import CliRunner

from acausal import Measure, Model, ParameterError, compile_model
from acausal.cli import main
from acausal.mechanics.translational import Fixed, Mass, Spring

M, C = 2.0, 50.0
W = np.sqrt(C / M)


def exact(t, s0, v0):
    return s0 * np.cos(W * t) + v0 / W * np.sin(W * t)


@pytest.fixture(scope="module")
def cm():
    m = Model()
    m.body = Mass(m=M, s=0.1, v=0.0)
    m.spring = Spring(c=C)
    m.ground = Fixed()
    m.connect(m.ground.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.body.flange)
    return compile_model(m)


def model_file(tmp_path):
    p = tmp_path / "osc.py"
    p.write_text(textwrap.dedent(f"""\
        from acausal import Experiment, Measure, Model
        from acausal.mechanics.translational import Fixed, Mass, Spring
        model = Model()
        model.body = Mass(m={M}, s=0.1, v=0.0)
        model.spring = Spring(c={C})
        model.ground = Fixed()
        model.connect(model.ground.flange, model.spring.flange_a)
        model.connect(model.spring.flange_b, model.body.flange)
        experiment = Experiment(t_end=0.5, rtol=1e-10, atol=1e-12, output_step=1e-3)
        measures = {{"s_end": Measure(lambda r: r.final()["body.s"], "m", display="mm"),
                     "t_end": Measure(lambda r: r.t[-1], "s", display="ms"),
                     "bare": lambda r: 1.5}}
        """))
    return str(p)


def test_start_values_are_runtime_values(cm):
    t = 0.7
    for s0, v0 in ((0.1, 0.0), (-0.02, 3.0), (0.0, -1.5)):
        res = cm.simulate(t_end=t, rtol=1e-10, atol=1e-12,
                          params={"body.s": s0, "body.v": v0, "spring.c": C})
        assert res["body.s"][0] == s0 and res["body.v"][0] == v0
        assert abs(res.final()["body.s"] - exact(t, s0, v0)) < 1e-7


def test_a_guess_or_a_non_finite_start_is_refused(cm):
    with pytest.raises(ParameterError, match="spring.s_rel.*guess"):
        cm.simulate(t_end=0.1, params={"spring.s_rel": 1.0})
    with pytest.raises(ParameterError, match="body.v.*not finite"):
        cm.simulate(t_end=0.1, params={"body.v": float("inf")})
    with pytest.raises(ParameterError, match="no parameter 'body.q'"):
        cm.simulate(t_end=0.1, params={"body.q": 1.0})


def test_cli_set_start_value_and_units_in_csv_and_json(tmp_path):
    path, out = model_file(tmp_path), tmp_path / "r.csv"
    r = CliRunner().invoke(main, ["simulate", path, "--set", "body.v=3", "--out", str(out),
                                  "--json"])
    assert r.exit_code == 0, r.output
    js = json.loads(r.output)
    assert abs(js["final"]["body.s"] - exact(0.5, 0.1, 3.0)) < 1e-7
    assert js["units"]["final"]["body.s"] == "m" and js["units"]["final"]["body.v"] == "m/s"
    assert js["units"]["final"]["spring.f"] == "N" and js["units"]["time"] == "s"
    assert js["units"]["measures"] == {"s_end": "m", "t_end": "s", "bare": None}
    with open(out) as fh:
        rows = list(csv.reader(fh))
    head = rows[0]
    assert head[0] == "time [s]" and "body.s [m]" in head and "body.v [m/s]" in head
    last = dict(zip(head, map(float, rows[-1])))
    assert abs(last["body.s [m]"] - js["final"]["body.s"]) < 1e-15


def test_cli_prints_measures_in_their_display_unit(tmp_path):
    r = CliRunner().invoke(main, ["simulate", model_file(tmp_path)])
    assert r.exit_code == 0, r.output
    s_mm = float(r.output.split("s_end = ")[1].split(" mm")[0])
    assert abs(s_mm - 1e3 * exact(0.5, 0.1, 0.0)) < 1e-3
    assert "t_end = 500 ms" in r.output
    assert "bare = 1.5\n" in r.output


def test_measure_display_unit_of_another_dimension_is_refused():
    from acausal import ModelError
    with pytest.raises(ModelError, match=r"\[s\].*\[mm\]"):
        Measure(lambda r: 0.0, "s", display="mm").shown(1.0)


def test_default_plot_shows_the_states_with_units(cm, tmp_path):
    res = cm.simulate(t_end=0.2)
    fig = res.plot(path=str(tmp_path / "p.png"))
    labels = [ax.get_ylabel() for ax in fig.axes]
    assert labels == ["body.s [m]", "body.v [m/s]"]
    ys = fig.axes[1].lines[0].get_ydata()
    assert np.allclose(ys, res["body.v"])
