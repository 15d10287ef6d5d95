"""Diagnosis sites on planar models (acausal.mechanics.planar): joints for
friction and loads (acting across the joint on its 1-D axis), bodies,
contacts from geometry; and a hypothesis applied across a planar joint
against its closed form."""
import os

import numpy as np
import pytest

from acausal import Model, compile_model
from acausal.diagnose.library.graph import ModelGraph
from acausal.diagnose.library.hypotheses import HYPOTHESES
from acausal.mechanics.planar.contact import CircleLineContact
from acausal.mechanics.planar.joints import Revolute
from acausal.mechanics.planar.parts import Body, Fixed
from acausal.modelfile import load_model_file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def paths(sites):
    return [s.path for s in sites]


def test_planar_breaker_offers_its_revolute_joints_bodies_and_contact():
    g = ModelGraph(load_model_file(os.path.join(ROOT, "models", "breaker_24kv_planar.py")).model)
    joints = {s.path: s for s in g.joints}
    # the roller and cam pins carry no 1-D body: they are joint sites of their own
    assert {"cam.pin_c", "cam.pin_d"} <= set(joints)
    assert joints["cam.pin_c"].domain == "rotational"
    # the hook and main-shaft pins' axes are the 1-D shafts: one site each, named so
    assert "cam.pin_a" in joints["hook.body"].note and "cam.pin_b" in joints["main_shaft.body"].note
    assert "cam.pin_a" not in joints and "cam.pin_b" not in joints
    assert {"armature.mass", "hook.body", "main_shaft.body"} <= set(paths(g.bodies))
    assert paths(g.contacts) == ["contact"]
    cf = HYPOTHESES["coulomb_friction"].candidates(g)
    assert {"cam.pin_c", "cam.pin_d", "hook.body", "main_shaft.body"} <= set(cf)


def test_planar_example_lists_planar_bodies_joints_and_a_geometric_contact():
    g = ModelGraph(load_model_file(os.path.join(ROOT, "models", "examples",
                                                "fourbar_planar.py")).model)
    assert set(paths(g.joints)) == {f"linkage.pin_{k}" for k in "abcd"}
    assert {s.path: s.domain for s in g.bodies} == {"hook": "planar", "shaft": "planar"}
    m = Model()
    m.ground = Fixed()
    m.ball = Body()
    m.c = CircleLineContact()
    m.connect(m.ground.frame, m.c.frame_a)
    m.connect(m.c.frame_b, m.ball.frame)
    g = ModelGraph(m)
    assert [(s.path, s.domain) for s in g.contacts] == [("c", "planar")]
    assert paths(g.joints) == []                       # a free body has no joint


def test_coulomb_friction_across_a_revolute_decelerates_as_tau_over_J():
    """A disc spinning on a pin (no gravity): the hypothesis' friction torque
    tau across the joint brakes it at tau / I exactly (tanh(w / v_eps) = 1
    while w >> v_eps)."""
    I, w0, tau = 0.01, 10.0, 0.02
    m = Model()
    m.ground = Fixed()
    m.pin = Revolute(phi=0.0, w=w0)
    m.disc = Body(m=1.0, I=I)
    m.connect(m.ground.frame, m.pin.frame_a)
    m.connect(m.pin.frame_b, m.disc.frame)
    assert "pin" in HYPOTHESES["coulomb_friction"].candidates(ModelGraph(m))
    HYPOTHESES["coulomb_friction"].apply(m, "pin", {"hyp_cf.tau": tau, "hyp_cf.v_eps": 1e-6})
    res = compile_model(m).simulate(t_end=1.0, rtol=1e-10, atol=1e-12, output_step=0.01)
    assert np.max(np.abs(res["pin.w"] - (w0 - tau / I * res.t))) < 1e-8
    assert np.max(np.abs(res["disc.w"] - res["pin.w"])) < 1e-12
