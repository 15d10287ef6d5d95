"""Dry friction that makes a body stop and stick, and a viscous loss at a
joint: the hypotheses ``stick_slip_friction`` (the library's friction mode
machine, by events) and ``viscous_damping`` (issue 24, item 4), against
independent truths that share no code with the project
(tests/diagnose/stick_truth.py: an event-driven scipy simulator of the stick
rig; tests/diagnose/two_mass_truth.py). The fast tests check the
hypothesis's law against the truth and its sensitivities across the stick
events; the slow ones are full diagnoses (docs/diagnosis.md)."""
import os
import sys

import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import blind  # noqa: E402
import stick_truth  # noqa: E402

from acausal.diagnose.library.hypotheses import build_extended  # noqa: E402
from acausal.modelfile import compile_file  # noqa: E402

RIG = os.path.join(HERE, "stick_rig.py")
F_TRUE = 0.9          # N: every release of stick_truth.STARTS sticks within the record


def _rows(res, name):
    """(t, y) with the duplicate rows of events dropped (the later kept)."""
    t, y = np.asarray(res.t), np.asarray(res[name])
    keep = np.append(np.diff(t) > 0, True)
    return t[keep], y[keep]


@pytest.mark.parametrize("backend", ["compiled", pytest.param("sundae", marks=pytest.mark.slow)])
def test_stick_slip_hypothesis_follows_the_independent_truth(backend):
    """At the truth's level the extended model stops where and when the
    event-driven scipy truth does, and stays there: stop times within 1e-8
    s, positions within 1e-6 of the range at every sample."""
    _, cm = build_extended(RIG, "stick_slip_friction", "slider")
    for s0 in stick_truth.STARTS:
        t, s, stops = stick_truth.simulate(s0, "stick", F_TRUE)
        assert len(stops) == 1 and stops[0] < 0.9           # it sticks, and stays
        res = cm.simulate(t_end=1.0, rtol=1e-10, atol=1e-13, output_step=1e-3,
                          params={"hyp_ssf.F": F_TRUE, "s_start": s0}, backend=backend)
        slide_stops = [e[0] for e in res.events if e[1].endswith("slide_stop")]
        assert slide_stops[-1] == pytest.approx(stops[0], abs=1e-8)
        tt, y = _rows(res, "slider.s")
        assert np.max(np.abs(np.interp(t, tt, y) - s)) < 1e-6 * np.ptp(s)
        assert y[-1] == pytest.approx(s[-1], abs=1e-9)      # held against its spring
        assert abs(200.0 * y[-1]) < F_TRUE                  # where the spring cannot move it


def test_stick_slip_neutral_is_nominal_and_sensitivity_crosses_the_stick():
    """At F = 0 the extension is the nominal model (it breaks away at once
    at every reversal); at F_TRUE the exact sensitivity of the stuck
    position to F (through the stop event) equals the independent truth's
    central difference."""
    mf, cm0 = compile_file(RIG)
    _, cm = build_extended(RIG, "stick_slip_friction", "slider")
    opts = dict(t_end=1.0, rtol=1e-10, atol=1e-13, output_step=1e-3)
    t0, y0 = _rows(cm0.simulate(**opts), "slider.s")
    t1, y1 = _rows(cm.simulate(**opts), "slider.s")
    assert np.max(np.abs(np.interp(t0, t1, y1) - y0)) < 1e-8 * np.ptp(y0)
    s0, h = 0.04, 1e-5
    res = cm.simulate(params={"hyp_ssf.F": F_TRUE, "s_start": s0},
                      sensitivities=["hyp_ssf.F"], **opts)
    dsdF = np.asarray(res.sensitivity("slider.s", "hyp_ssf.F"))[-1]
    fd = (stick_truth.simulate(s0, "stick", F_TRUE + h)[1][-1]
          - stick_truth.simulate(s0, "stick", F_TRUE - h)[1][-1]) / (2 * h)
    assert dsdF == pytest.approx(fd, rel=1e-5)


def test_viscous_damping_follows_the_independent_truth():
    """viscous_damping at the slider (b on top of the model's damper) is
    the truth's viscous loss: positions within 1e-7 of the range."""
    _, cm = build_extended(RIG, "viscous_damping", "slider")
    t, s, _ = stick_truth.simulate(0.04, "viscous", 0.3)
    res = cm.simulate(t_end=1.0, rtol=1e-10, atol=1e-13, output_step=1e-3,
                      params={"hyp_vd.b": 0.3, "s_start": 0.04})
    tt, y = _rows(res, "slider.s")
    assert np.max(np.abs(np.interp(t, tt, y) - s)) < 1e-7 * np.ptp(s)


@pytest.mark.slow
@pytest.mark.parametrize("seed", [3])
def test_a_body_that_sticks_is_explained_by_stick_slip_friction(tmp_path, seed):
    """Dry friction strong enough to stop the slider and hold it against
    its spring (every release sticks; about 1000 noise floors): the smooth
    kinetic members cannot hold it; stick_slip_friction is named at the
    slider with its level within 10 %."""
    out, det, floors = blind.run_case(RIG, stick_truth, tmp_path, "stick", F_TRUE, seed=seed,
                                      name="stick rig stick")
    assert floors > 50
    assert blind.named(out) == {("stick_slip_friction", "slider")}
    assert blind.values(out)["hyp_ssf.F"] == pytest.approx(F_TRUE, rel=0.10)


@pytest.mark.slow
def test_a_viscous_loss_at_a_joint_is_named_viscous_damping(tmp_path):
    """A viscous loss in m2's guide of the two-mass chain (b = 0.05 N*s/m,
    about 94 noise floors; the free damper acts at m1, so it cannot absorb
    it): viscous_damping is named at m2 with b within 10 %."""
    import two_mass_truth
    model = os.path.join(HERE, "two_mass.py")
    out, det, floors = blind.run_case(model, two_mass_truth, tmp_path, "m2_viscous", 0.05,
                                      seed=11, name="two-mass m2_viscous 0.05")
    assert floors > 50
    assert blind.named(out) == {("viscous_damping", "m2")}
    assert blind.values(out)["hyp_vd.b"] == pytest.approx(0.05, rel=0.10)


def test_stick_slip_yields_to_coulomb_within_the_parsimony_margin():
    """On dry friction that never holds the body the two laws fit alike
    (the torsion rig: 0.6 AICc units apart): the head, Coulomb friction, is
    named; the stick-slip member only when it gains more than 2 units (a
    body that sticks: 24000 units on the stick rig)."""
    import dataclasses

    from test_families import _row

    from acausal.diagnose.stages.chain import Ranking
    from acausal.diagnose.stages.families import family_index, prefer_simplest
    rows = (_row("stick_slip_friction", "rotor", {"hyp_ssf.tau": 8e-3}),
            _row("coulomb_friction", "rotor", {"hyp_cf.tau": 8e-3}),
            _row("viscous_damping", "rotor", {"hyp_vd.b": 1e-4}))
    index = family_index(None)
    assert index.refines == {"stick_slip_friction"}
    for gap, named in ((0.6, "coulomb_friction"), (1.9, "coulomb_friction"),
                       (2.5, "stick_slip_friction")):
        rs = tuple(dataclasses.replace(r, aicc=a) for r, a in zip(rows, (10.0, 10.0 + gap,
                                                                        10.0 + gap + 0.1)))
        got = prefer_simplest(Ranking(rs, [[0, 1, 2]], 0, 0, None, [], (), 1.0), index)
        assert got.named.candidate.hypothesis == named, gap
