"""Issue 24's acceptance on independent mechanisms outside ``models/``
(slow tier): a cam follower and a geared drive written as a user would,
data from hand-written scipy truths (``cam_truth``, ``gear_truth``: no
code of acausal), one case per failure shape of the issue
(``cases.CASES``) at 30 noise floors (the stick cases at the friction that
makes them stick), seed 0. Each asserts ``judge.judge``: both causes named
within 10 % when two act; "not explained by the library" at the right
node when the cause has no hypothesis (any cause named beside it right
within 10 %); no cause the truth lacks; nothing named on a null.

Written to fail where today's diagnosis fails (issue 24; those still
failing are marked in ``OPEN`` with their numbers): the table of
every shape, effect and seed is ``benchmarks/independent_cases.py``'s
(docs/independent_cases.md)."""
import os
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "..", "..", "benchmarks"))
import cases as C  # noqa: E402

EFFECT = 30.0

# Issue 24's targets still missed on final main, with what was measured
# (docs/independent_cases_2026-11-27.md): strict, so a case that starts to
# pass says so and its mark is removed. Each is an open acceptance item, not
# an accepted behaviour.
OPEN = {
    "cam_friction_drag": "issue 24 open: on e0856b0 weak: the best is coulomb_friction + "
                         "quadratic_damping at the cam (the truth), but the same friction with "
                         "the drag at the follower is 1-2 AICc units behind and explains the "
                         "held-out data too (rival_tied: the drag's site is not decided at 30 "
                         "floors on three runs); the friction is named in part (F +5.4 %), and "
                         "the next experiment, run, names both (the test below); on ac8c704 it "
                         "was named with the drag c 11.2 % off",
}
# gear_friction_cogging (Coulomb friction at the load + a cogging torque of the
# motor) left OPEN on 2026-11-27: it passed on c28f4e3 (the slow tier) and on
# b5d0c32 (docs/independent_cases_2026-11-27.md: not explained @ load, a tied site
# of the motor's, 411 s).


def _case(name):
    if name in OPEN:
        return pytest.param(name, marks=pytest.mark.xfail(
            reason=OPEN[name], strict=True))
    return name


@pytest.mark.slow
@pytest.mark.parametrize("name", [_case(n) for n in C.CASES])
def test_independent_case(name):
    import independent_cases as B
    case = C.CASES[name]
    row = B.run_one(case, EFFECT, 0)
    print(f"INDEPENDENT {name}: effect {row['effect']:.1f} floors; {row['verdict']}; "
          f"errors {row['errors']}; held-out {row['heldout_before']:.3f} -> "
          f"{row['heldout_after']:.3f}; {row['wall_s']:.0f} s, {row['n_sim']} simulations")
    assert not row["wrong"], f"named a cause the truth lacks: {row['wrong']}"
    # issue 24: a cause at a site tied to another is fitted at both before
    # either is shown (the geared drive's motor and load are rigidly tied)
    assert not row["unfitted_tied"], f"named, not fitted at its tied sites: {row['unfitted_tied']}"
    un = row["unexplained"]
    if un["value"]:    # "not explained" always points somewhere, or says why not
        assert un["node"] or un["why"], f"not explained, no node and no reason: {un}"
        assert not un["node"] or un["node"] == un["nodes"][0]["node"]
    assert row["ok"], f"{row['why']}: got {row['verdict']}, errors {row['errors']} %"


@pytest.mark.slow
def test_the_next_experiment_run_names_both_causes(tmp_path):
    """The loop a user runs: cam friction + quadratic drag at the cam, 30
    floors, seed 0. The three runs cannot decide the drag's site (nor, by
    two tied rows, the friction's): weak, with the friction named in part
    and a next experiment computed. That experiment is then run on the
    independent truth (its start speed; the first runs' noise unchanged)
    and the diagnosis repeated on the four runs: both causes named within
    10 % (2026-11-28: w0 = 24.34 rad/s, errors 1.1 % and 1.7 %; with
    numpy 2.4.6 and scipy 1.17.1, w0 = 25.0, Coulomb + viscous friction and the
    drag at the cam, 2.5 % and 6.3 %; the plain
    criterion's w0 = 24.65, where one standard deviation of the rivals'
    parameters decides whether the cam goes over its top, left the run
    unexplained, docs/next_experiment.md)."""
    import types
    import datawriter
    import independent_cases as B
    import judge as J
    from acausal.diagnose.run import diagnose
    case = C.CASES["cam_friction_drag"]
    laws, _ = B.laws_of(case, EFFECT)
    datawriter.write(tmp_path / "data", case.truth, laws, seed=0)
    first = diagnose(case.model, tmp_path / "data", out_dir=tmp_path / "out", workers=2,
                     progress=False, plots=False)
    assert first["cause"] is None and first["verdict"]["kind"] == "weak"
    part = first["verdict"]["partial"]
    assert part and any(c["family"] == "friction" for c in part["shared"]), part
    nxt = first["next_experiment"]
    # the design weighs an experiment whose rivals' spread passes 1 floor down by
    # (1/spread)^2, it does not exclude it: 1.25 at w0 = 25.0 measured with numpy
    # 2.4.6 (at most 1 at w0 = 24.34 before); the near-top choice it keeps away had 3.5
    assert nxt["computed"] and nxt["decisive"] and nxt["spread_floors"] < 2.0, nxt
    t = case.truth
    truth = types.SimpleNamespace(CONDITIONS=list(t.CONDITIONS) + [nxt["conditions"]],
                                  SIGNALS=t.SIGNALS, NOISE=t.NOISE,
                                  RESOLUTION=t.RESOLUTION, run=t.run)
    datawriter.write(tmp_path / "data4", truth, laws, seed=0)
    second = diagnose(case.model, tmp_path / "data4", out_dir=tmp_path / "out4", workers=2,
                      progress=False, plots=False)
    j = J.judge(case, laws, second, B.TIED)
    print(f"NEXT cam_friction_drag: w0 = {nxt['conditions']}; {J.verdict(first)} -> "
          f"{J.verdict(second)}; errors {j['errors']}")
    assert not j["wrong"], j["wrong"]
    assert j["ok"], f"{j['why']}: got {J.verdict(second)}, errors {j['errors']} %"
