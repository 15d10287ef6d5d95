"""Modelica's connector rule: an unconnected flange carries no force (no
error); the model check lists it."""
import json
import textwrap

import numpy as np
from click.testing import CliRunner

from acausal import Model, compile_model
from acausal.cli import main
from acausal.compiler.check import check_model
from acausal.mechanics import rotational as rot
from acausal.mechanics.translational import Damper, Fixed, Mass, Spring


def test_an_unconnected_flange_has_zero_force():
    """A spring between a wall and a mass, and a damper hanging from the
    mass by one flange: the damper's free flange takes no force, so the
    mass oscillates as if the damper were not there."""
    m = Model()
    m.wall = Fixed()
    m.spring = Spring(c=100.0)
    m.mass = Mass(m=1.0, s=0.1, v=0.0)
    m.damper = Damper(d=5.0)
    m.connect(m.wall.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.mass.flange, m.damper.flange_a)
    res = compile_model(m, cache=False).simulate(t_end=1.0, rtol=1e-10, atol=1e-12)
    assert np.max(np.abs(res["mass.s"] - 0.1 * np.cos(10 * res.t))) < 1e-8
    assert np.max(np.abs(res["damper.flange_b.f"])) == 0.0
    assert np.max(np.abs(res["damper.f"])) == 0.0


def test_the_check_lists_unconnected_connectors_and_is_no_error():
    m = Model()
    m.inertia = rot.Inertia(J=1.0, phi=0.0, w=1.0)
    m.spring = rot.Spring(c=10.0)
    m.connect(m.inertia.flange, m.spring.flange_a)
    report = check_model(m, cache=False)
    assert report.unconnected == ["spring.flange_b"]
    assert "unconnected connector(s), their force/torque is zero: spring.flange_b" in \
        "\n".join(report.lines())
    res = compile_model(m, cache=False).simulate(t_end=1.0)
    assert np.max(np.abs(res["inertia.w"] - 1.0)) < 1e-12      # nothing acts on it


def test_acausal_check_command(tmp_path):
    p = tmp_path / "model.py"
    p.write_text(textwrap.dedent("""\
        from acausal import Model
        from acausal.blocks import Step
        from acausal.mechanics.translational import Force, Mass, Spring
        model = Model()
        model.mass = Mass(m=1.0, s=0.1, v=0.0)
        model.spring = Spring(c=100.0)
        model.step = Step(startTime=0.5)
        model.force = Force()
        model.connect(model.step.y, model.force.f)
        model.connect(model.force.flange, model.mass.flange)
        model.connect(model.spring.flange_b, model.mass.flange)
        """))
    r = CliRunner().invoke(main, ["check", str(p)])
    assert r.exit_code == 0, r.output
    assert "unconnected connector(s), their force/torque is zero: spring.flange_a" in r.output
    assert "time = step.startTime" in r.output and "2 states: mass.s, mass.v" in r.output
    r = CliRunner().invoke(main, ["check", "--json", str(p)])
    out = json.loads(r.output)
    assert out["unconnected"] == ["spring.flange_a"] and out["states"] == ["mass.s", "mass.v"]
