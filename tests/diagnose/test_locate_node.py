"""Where "not explained by the library" points (issue 24, items 1 and 4):
whenever the verdict is ``not_explained``, ``unexplained`` names the
located generic term's best node (lowest held-out error over every node,
tied or not) with each node's held-out error, or says in one line why no
node could be judged; and the term's knots span what every experiment
covers, not only the model file's nominal run. Fast: small synthetic
inputs, no simulation (the data ranges on stand-in simulation results)."""
from types import SimpleNamespace

import numpy as np
import pytest

from acausal.diagnose.library import generic as gen
from acausal.diagnose.report.markdown import _where_sentence
from acausal.diagnose.report.result import unexplained
from acausal.diagnose.stages import locate as L

from .locate_fakes import RANGES, Decision as _Dec, Ranking as _Rk, term as _term
from acausal.diagnose.stages import verdict as vd



def _diagnosis(kind, loc, best_held=1.6):
    best = SimpleNamespace(candidate=SimpleNamespace(label="coulomb_friction at cam"),
                           heldout_rmse=best_held)
    return SimpleNamespace(verdict=vd.Verdict(kind), location=loc,
                           ranking=SimpleNamespace(best=best))


def _located(terms, lib_aicc, lib_held):
    """The located stage's verdict with a library best of ``lib_aicc``,
    ``lib_held`` (floors)."""
    lib = SimpleNamespace(aicc=lib_aicc, heldout_rmse=lib_held, S=1e9, k=2,
                          candidate=SimpleNamespace(label="coulomb_friction at cam"))
    rk = SimpleNamespace(best=lib, named=None, heldout0=30.0)
    terms = sorted(terms, key=lambda t: (t.fitted != "output error", t.heldout_rmse, t.aicc))
    return L._verdict(terms, _Dec(), rk, 1000)


def test_not_explained_names_the_terms_best_node_even_when_it_does_not_beat_the_library():
    """The verdict is "not explained" (the best library candidate leaves the
    held-out data), but no term beats that candidate by AICc: the node is
    still the term's best (by held-out error, not by order or AICc), with
    its held-out error and every node's, best first."""
    loc = _located([_term("cam", 3.1, aicc=90.0), _term("follower", 1.9, aicc=99.0),
                    _term("spring_end", 1.2, fitted="linearised")], lib_aicc=80.0,
                   lib_held=1.6)
    assert not loc.unexplained and loc.node is None      # the term does not beat the library
    un = unexplained(_diagnosis("not_explained", loc))
    assert un["value"] is True and un["beats_library"] is False
    assert un["node"] == "follower" and un["heldout_rmse"] == pytest.approx(1.9)
    assert [x["node"] for x in un["nodes"]] == ["follower", "cam", "spring_end"]
    assert [x["fitted"] for x in un["nodes"]][-1] == "linearised"
    assert un["nearest_heldout_rmse"] == pytest.approx(1.6) and un["why"] is None
    text = _where_sentence(un)
    assert "`follower`" in text and "does not beat" in text and "`cam` 3.1" in text


def test_a_term_that_beats_the_library_is_the_node_whatever_the_verdict_source():
    loc = _located([_term("m1", 2.0, aicc=500.0), _term("m2", 1.04, aicc=700.0)],
                   lib_aicc=1e4, lib_held=30.0)
    assert loc.unexplained and loc.node == "m2"
    un = unexplained(_diagnosis("not_explained", loc))
    assert un["node"] == "m2" and un["beats_library"] is True
    assert "removes most of the misfit" in _where_sentence(un)
    # a weak or named verdict points nowhere unless a term beats the library
    weak = unexplained(_diagnosis("weak", _located([_term("m1", 2.0)], 50.0, 1.0)))
    assert weak["value"] is False and weak["node"] is None


def test_tied_nodes_are_reported_with_the_best():
    loc = _located([_term("motor", 1.30), _term("load", 1.3005)], lib_aicc=80.0, lib_held=1.6)
    un = unexplained(_diagnosis("not_explained", loc))
    assert un["node"] == "motor" and un["tied_nodes"] == ["load"]
    assert "cannot tell it from `load`" in _where_sentence(un)


@pytest.mark.parametrize("loc, words", [
    (None, "was not run"),
    (L.Location(skipped="not run (generic=False)"), "generic=False"),
    (L.Location(skipped="no generic term could be built: guide: PrintMethodNotImplementedError",
                details=dict(failed={"guide": "PrintMethodNotImplementedError"})),
     "guide: PrintMethodNotImplementedError"),
    (L.Location(skipped="no generic term could be fitted",
                details=dict(failed={"m1": "every starting point failed"})),
     "m1: every starting point failed"),
])
def test_no_node_says_why_in_one_line(loc, words):
    un = unexplained(_diagnosis("not_explained", loc))
    assert un["value"] is True and un["node"] is None and un["nodes"] == []
    assert words in un["why"] and "\n" not in un["why"]
    assert un["heldout_rmse"] == pytest.approx(1.6)       # the best library candidate's
    assert _where_sentence(un).startswith(" No node could be judged: ")


def test_knot_ranges_span_every_run():
    """Runs of different strokes: the knots cover the widest, padded by
    PAD of the span; a coordinate that does not move gets +-1; missing or
    non-finite values are left out."""
    x = [np.linspace(0.0, 1.0, 50), np.linspace(0.0, 2.0, 50), np.array([np.nan, 0.5])]
    v = [np.linspace(-1.0, 0.5, 50), np.linspace(0.0, 3.0, 50)]
    lo, hi, vlo, vhi = gen.knot_ranges(x, v)
    assert (lo, hi) == pytest.approx((-gen.PAD * 2.0, 2.0 + gen.PAD * 2.0))
    assert (vlo, vhi) == pytest.approx((-1.0 - gen.PAD * 4.0, 3.0 + gen.PAD * 4.0))
    assert gen.knot_ranges(np.zeros(5), None) == pytest.approx(
        (-1.0, 1.0, -1.0 - 2 * gen.PAD, 1.0 + 2 * gen.PAD))
    names = [k for k, _ in gen.range_values((1, 2, 3, 4))]
    assert names == ["gen.x_lo", "gen.x_hi", "gen.v_lo", "gen.v_hi"]


def test_data_ranges_read_each_bodys_coordinates_over_every_experiment(monkeypatch):
    """A rotational body's phi and w over three runs (the largest drive
    swings four times as far as the smallest): the knots reach the largest
    run's; a run without the body's variables is skipped, and with none
    the ranges are None (the nominal run's are used)."""
    import acausal.diagnose.library.domain as dm
    monkeypatch.setattr(dm, "domain_of", lambda c: SimpleNamespace(across="phi", rate="w"))
    graph = SimpleNamespace(components={"motor": object()})
    runs = [{"motor.phi": np.linspace(0, a, 20), "motor.w": np.linspace(0, 3 * a, 20)}
            for a in (1.25, 2.5, 5.0)] + [{"other.phi": np.ones(3)}]
    got = L.data_ranges(graph, "motor", runs)
    assert got[0] == pytest.approx(-5.0 * gen.PAD) and got[1] == pytest.approx(
        5.0 * (1 + gen.PAD))
    assert got[3] == pytest.approx(15.0 * (1 + gen.PAD))
    assert L.data_ranges(graph, "motor", [{"other.phi": np.ones(3)}]) is None


def _row(hyp, loc, held=2.0, aicc=100.0):
    from acausal.diagnose.problem import Candidate, Param
    names = [f"h{i}.F" for i, _ in enumerate(hyp.split("+"))]
    params = tuple(Param(nm, 0.0, 0.0, 1.0, 0.1, 0.0) for nm in names)
    return SimpleNamespace(candidate=Candidate(hyp, loc, params), fit=object(),
                           heldout_rmse=held, aicc=aicc)


def test_term_goes_beside_the_named_cause_or_each_member_of_the_best_candidate():
    """Named single cause: beside it. Nothing named: beside each member of
    the library's best candidate that was fitted alone (a pair's members in
    its order, a member not fitted alone left out). A named pair: none."""
    cf, hs = _row("coulomb_friction", "cam"), _row("hardening_spring", "spring")
    pair = _row("coulomb_friction+hardening_spring", "cam+spring")
    other = _row("constant_load", "follower")
    rk = SimpleNamespace(named=None, best=pair, rows=(pair, other, hs, cf))
    assert L.beside_rows(rk) == [cf, hs]
    rk = SimpleNamespace(named=None, best=pair, rows=(pair, other, hs))
    assert L.beside_rows(rk) == [hs]
    assert L.beside_rows(SimpleNamespace(named=cf, best=cf, rows=(cf,))) == [cf]
    assert L.beside_rows(SimpleNamespace(named=pair, best=pair, rows=(pair, cf))) == []
    assert L.beside_rows(SimpleNamespace(named=None, best=None, rows=())) == []


def test_the_term_beside_a_cause_is_reported_with_the_cause_refitted():
    from acausal.diagnose.report.result import beside_of
    t = L.Term("follower", ("follower",), 90.0, 80.0, 1.05, RANGES, {},
               {"hyp_cf.tau": 8.8e-5, "gen.a0": 0.01}, beside="coulomb_friction at cam")
    loc = _located([_term("follower", 7.4), _term("cam", 9.0)], lib_aicc=120.0, lib_held=1.5)
    assert beside_of(loc) is None
    loc.beside, loc.second_force = t, True
    loc.beside_cause = dict(cause="coulomb_friction", location="cam",
                            values={"hyp_cf.tau": 8.8e-5}, alone_heldout=3.2, alone_aicc=150.0)
    un = unexplained(_diagnosis("not_explained", loc))
    b = un["beside"]
    assert (b["cause"], b["location"], b["node"]) == ("coulomb_friction", "cam", "follower")
    assert b["values"] == {"hyp_cf.tau": 8.8e-5} and b["second_force"] is True
    assert b["heldout_rmse"] == pytest.approx(1.05) and b["alone_heldout_rmse"] == 3.2
    text = _where_sentence(un)
    assert "beside coulomb_friction at `cam`" in text and "leaves a second force" in text


def test_the_command_line_names_the_node_or_says_why_not():
    """`acausal diagnose` printed 'located at the node of None'."""
    from acausal.cli import unexplained_line
    line = unexplained_line(dict(value=True, node=None, why="the located generic term was "
                                 "not run"))
    assert "None" not in line and line.endswith("no node located: the located generic term "
                                                "was not run")
    line = unexplained_line(dict(value=True, node="follower", heldout_rmse=7.37,
                                 beats_library=False, nearest_heldout_rmse=1.496))
    assert "node of follower (held-out 7.37" in line and "does not beat" in line
    assert "does not beat" not in unexplained_line(dict(value=True, node="motor",
                                                        heldout_rmse=2.1, beats_library=True))
