"""The pair search's partners (acausal/diagnose/pairsearch.py, stages.partners):
the best tested single is paired with every other candidate at another site,
tested alone or not, the partner at its neutral value; the screened pairs
kept for full fits are the lowest in S below the best single; the
screening's starts move only the partner; a member of the best pair that
was not tested alone but acted in the pair is not its rival. Pure data, no
simulation (the blind pair cases in test_blind_*.py run the search)."""
import numpy as np
import pytest

from acausal.diagnose.stages.fitting import Fit
from acausal.diagnose.stages.pairsearch import (
    SCREEN_LHS,
    PairScreenTask,
    Screened,
    keep,
    screen_starts,
)
from acausal.diagnose.library.loader import FamilyIndex
from acausal.diagnose.problem import Candidate, Param, Problem
from acausal.diagnose.stages.chain import Row, _acted_in, partners
from acausal.diagnose.stages.tasks import Starts


def _row(hid, loc, values, tested=True, cost=1.0):
    cand = Candidate(hid, loc, tuple(Param(k, 0.0, -10.0, 10.0, 1.0, 0.0)
                                     for k in values if k.startswith("hyp")))
    names = list(values)
    fit = Fit(names, dict(values), cost, np.zeros(3), np.zeros((3, len(names))), [], [])
    return Row(cand, fit, Starts(tested=tested), {}, 0.0, 1.0, 1.0)


class _Dec:
    def __init__(self, rows):
        self.rows, self.failed = tuple(rows), ()


def test_the_best_single_meets_every_candidate_but_its_own_family_at_its_site():
    dec = _Dec([_row("constant_load", "m1", {"k.c": 52.0, "hyp_cl.F": 1.5}, tested=False),
                _row("position_dependent_force", "coil", {"k.c": 51.0, "hyp_pf.k": 3.0}),
                _row("coulomb_friction", "m1", {"k.c": 55.0, "hyp_cf.F": 0.0}, tested=False),
                _row("quadratic_damping", "coil", {"k.c": 50.0, "hyp_qd.c": 0.2}),
                _row("constant_load", "m2", {"k.c": 50.0, "hyp_cl.F": 4.0}),
                _row("a+b", "m1+m2", {"k.c": 50.0, "hyp_a.x": 1.0, "hyp_b.y": 1.0})])
    got = partners(dec, done={("position_dependent_force+constant_load", "coil+m2")})
    # the best *tested* single leads; pairs already done are left out; another
    # family at the best single's own site is a partner (issue 24)
    assert [(c.hypothesis, c.location) for c in got] == [
        ("position_dependent_force+constant_load", "coil+m1"),
        ("position_dependent_force+coulomb_friction", "coil+m1"),
        ("position_dependent_force+quadratic_damping", "coil+coil")]
    # ... but not a member of its own family there
    index = FamilyIndex({"position_dependent_force": ("force", 0),
                         "quadratic_damping": ("force", 1)},
                        {"force": ("position_dependent_force", "quadratic_damping")})
    got_f = partners(dec, done=set(), index=index)
    assert ("position_dependent_force+quadratic_damping", "coil+coil") not in [
        (c.hypothesis, c.location) for c in got_f]
    first, second = got[1].params
    assert (first.name, first.start, first.prior) == ("hyp_pf.k", 3.0, 0.0)  # seeded from its fit
    assert (second.name, second.start) == ("hyp_cf.F", 0.0)                # partner at neutral
    # one hypothesis at two sites: the partner's sub-model is renamed
    again = partners(_Dec([_row("constant_load", "m1", {"hyp_cl.F": 1.0}),
                           _row("constant_load", "m2", {"hyp_cl.F": 2.0})]), done=set())
    assert [p.name for p in again[0].params] == ["hyp_cl.F", "hyp_cl2.F"]
    assert [p.start for p in again[0].params] == [1.0, 0.0]


def test_screened_pairs_kept_lowest_first_and_below_the_best_single():
    best = _row("h", "a", {"hyp_h.k": 1.0}, cost=100.0)
    c = Candidate("h+g", "a+b", ())
    got = [Screened(c, 90.0, {}, 6), Screened(c, 20.0, {}, 6), Screened(c, 150.0, {}, 6),
           Screened(c, 5.0, {}, 6, error="ValueError: no"), Screened(c, np.inf, {}, 0),
           Screened(c, 50.0, {}, 6)]
    assert [r.cost for r in keep(best, got, n=2)] == [20.0, 50.0]
    assert [r.cost for r in keep(best, got, n=9)] == [20.0, 50.0, 90.0]


def test_screening_starts_move_only_the_partner():
    pair = Candidate("h+g", "a+b", (Param("hyp_h.k", 2.0, 0.0, 10.0, 1.0, 0.0),
                                    Param("hyp_g.c", 0.0, -5.0, 5.0, 0.5, 0.0)))
    free = (Param("k.c", 51.0, 10.0, 100.0, 50.0, 50.0),)
    task = PairScreenTask(Problem("m.py", "", "lib", free), pair, free,
                          ([], np.zeros((0, 0))))
    pts = screen_starts(task, n_first=1)
    assert len(pts) == 1 + SCREEN_LHS
    assert list(pts[0]) == [51.0, 2.0, 0.0]
    for x in pts[1:]:
        assert list(x[:2]) == [51.0, 2.0] and x[2] != 0.0 and -5.0 <= x[2] <= 5.0


def test_a_member_of_the_best_pair_untested_alone_is_not_its_rival():
    pair = _row("h+g", "a+b", {"k.c": 1.0, "hyp_h.k": 2.0, "hyp_g.c": 0.3})
    assert _acted_in(pair) == {("h", "a"), ("g", "b")}
    stayed = _row("h+g", "a+b", {"k.c": 1.0, "hyp_h.k": 2.0, "hyp_g.c": 0.0})
    assert _acted_in(stayed) == {("h", "a")}
    assert _acted_in(_row("h", "a", {"hyp_h.k": 2.0})) == set()


def test_a_cause_is_sized_against_its_neutral_value():
    """The 'poorly determined' rule's ratio: the 95 % half-width of the
    cause's parameter over its distance from its neutral value (the prior).
    A law switch whose restitution stays the model's is a well determined
    effect, though its fitted shift is near 0 (the breaker's Hunt-Crossley
    blind case); with a neutral value of 0 it is the relative half-width."""
    from acausal.diagnose.stages.chain import _ci_rel

    def row(prior, value, half):
        cand = Candidate("h", "a", (Param("hyp_h.de", prior, -0.5, 0.26, 0.05, prior),))
        fit = Fit(["k.c", "hyp_h.de"], {"k.c": 1.0, "hyp_h.de": value}, 1.0, np.zeros(3),
                  np.zeros((3, 2)), [], [], ci95={"hyp_h.de": (value - half, value + half)})
        return Row(cand, fit, Starts(), {}, 0.0, 1.0, 1.0)

    assert _ci_rel(row(0.0338, -0.000232, 0.00018)) == pytest.approx(0.00018 / 0.034032)
    assert _ci_rel(row(0.0, -0.000232, 0.00018)) == pytest.approx(0.00018 / 0.000232)
    assert _ci_rel(row(0.0338, 0.0338, 0.001)) == float("inf")
