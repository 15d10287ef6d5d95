"""ModelGraph: the diagnosis sites of the breaker and of example models."""
import os

import pytest

from acausal import Model, ModelError, compile_model
from acausal.diagnose import ModelGraph, Site
from acausal.diagnose.library.hypotheses import nominal_result
from acausal.modelfile import load_model_file
from acausal.mechanics.contact import Clearance
from acausal.mechanics.fourbar import fourbar_angles
from acausal.mechanics.rotational import Inertia, Torque
from acausal.mechanics.translational import Fixed, Mass, Position

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BREAKER = os.path.join(ROOT, "models", "breaker_24kv.py")
STICK_SLIP = os.path.join(ROOT, "models", "examples", "stick_slip.py")
HERTZ = os.path.join(ROOT, "models", "examples", "hertz_impact.py")


def paths(sites):
    return [s.path for s in sites]


def test_breaker_sites():
    g = ModelGraph(load_model_file(BREAKER).model)
    assert paths(g.bodies) == ["armature.mass", "hook.body", "main_shaft.body"]
    assert [s.domain for s in g.bodies] == ["translational", "rotational", "rotational"]
    assert paths(g.joints) == paths(g.bodies)
    assert all(isinstance(s, Site) and s.kind == "joint" for s in g.joints)
    assert "hook.friction (RotationalDamper)" in g.site("joint", "hook.body").note
    assert paths(g.springs) == ["armature.reset", "hook.reset", "main_shaft.open_spring",
                                "main_shaft.wipe_spring"]
    assert paths(g.contacts) == ["contact"]
    assert g.contacts[0].note == "Contact between hook.arm3, armature.mass"
    assert paths(g.sources) == ["armature.coil"]
    assert g.sources[0].note == "Force on armature.mass"
    assert g.sites("bodies") == g.bodies and g.sites("source") == g.sources
    with pytest.raises(ModelError, match="no site kind 'lever'"):
        g.sites("lever")
    with pytest.raises(ModelError, match="'hook.arm3' is not a spring"):
        g.site("spring", "hook.arm3")


def test_breaker_nodes_values_and_links():
    model = load_model_file(BREAKER).model
    g = ModelGraph(model)
    mass = model.find("armature.mass")
    assert g.body_at(model.find("contact").flange_b) is mass
    assert g.body_at(model.find("contact").flange_a) is None       # the lever's point
    at_hook = [c.path for c in g.at_node(model.find("hook.body").flange)]
    assert at_hook == ["cam", "hook.arm3", "hook.arm4", "hook.body", "hook.friction"]
    # links that carry motion to another body (not to the frame)
    hook = model.find("hook.body")
    assert g.reaches_body(model.find("hook.arm3"), hook)
    assert g.reaches_body(model.find("cam"), hook)
    assert not g.reaches_body(model.find("hook.arm4"), hook)        # reset spring to ground
    # parameter values through bindings (hook.body.J = hook.Jh, a model parameter)
    assert g.param(hook, "J") == pytest.approx(0.00044)
    theta0 = fourbar_angles(0.0)[1]          # s_rel0 = s1 * theta0, bound to main_shaft.s1
    assert g.param(model.find("main_shaft.open_spring"), "s_rel0") == pytest.approx(
        0.091 * theta0, rel=1e-12)
    free, dev = g.spring_deflection(model.find("main_shaft.open_spring"))
    assert dev == pytest.approx(5600.0 / 7.0e4)        # preload deflection without a result


def test_graph_leaves_the_model_untouched_and_compilable():
    mf = load_model_file(BREAKER)
    before = [list(m._connections) for m in mf.model.walk() if isinstance(m, Model)]
    ModelGraph(mf.model)
    after = [list(m._connections) for m in mf.model.walk() if isinstance(m, Model)]
    assert before == after
    assert compile_model(mf.model).dae.n_states == 4


def test_typical_magnitudes_from_the_nominal_run():
    g = ModelGraph(load_model_file(BREAKER).model, result=nominal_result(BREAKER))
    t = g.typical("hook.body")
    assert t["mass"] == pytest.approx(0.00044)
    assert 60 < t["speed"] < 90                       # peak hook speed [rad/s]
    assert t["travel"] == pytest.approx(0.0873, rel=1e-3)     # to the release angle, 5 deg
    assert t["time"] == pytest.approx(1.9e-3, rel=1e-3)
    assert t["force"] > 0
    bare = ModelGraph(load_model_file(BREAKER).model).typical("hook.body")
    assert bare["speed"] == 1.0 and bare["time"] == 1.0    # fallbacks without a result


def test_stick_slip_sites():
    g = ModelGraph(load_model_file(STICK_SLIP).model)
    assert paths(g.bodies) == ["block"] and paths(g.joints) == ["block"]
    assert "friction (GroundFriction)" in g.joints[0].note
    assert paths(g.springs) == ["spring"]
    assert g.contacts == [] and g.sources == []       # the driver is a prescribed motion


def test_hertz_impact_sites():
    g = ModelGraph(load_model_file(HERTZ).model)
    assert paths(g.bodies) == ["mass"] and paths(g.joints) == ["mass"]
    assert paths(g.contacts) == ["contact"]
    assert g.contacts[0].note == "Contact between mass, wall"
    assert g.springs == [] and g.sources == []


def test_fixed_or_driven_bodies_have_no_joint_and_clearance_sides_are_contacts():
    m = Model()
    m.wheel = Inertia(J=0.1)
    m.motor = Torque(tau=1.0)
    m.connect(m.wheel.flange, m.motor.flange)
    m.carriage = Mass(m=1.0)
    m.drive = Position(s=0.0)
    m.connect(m.carriage.flange, m.drive.flange)
    m.block = Mass(m=1.0)
    m.slot = Clearance(gap=1e-3)
    m.wall = Fixed()
    m.connect(m.block.flange, m.slot.flange_a)
    m.connect(m.slot.flange_b, m.wall.flange)
    g = ModelGraph(m)
    assert paths(g.bodies) == ["wheel", "carriage", "block"]
    assert paths(g.joints) == ["wheel", "block"]
    assert paths(g.sources) == ["motor"] and g.sources[0].domain == "rotational"
    assert paths(g.contacts) == ["slot.lower", "slot.upper"]
    assert g.contacts[0].note == "side of the clearance slot"
