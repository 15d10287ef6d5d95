"""Rivals in the best candidate's class (verdict.class_rivals, issue 24: no
name the data cannot decide). A row of the class that names another cause
and explains the held-out data makes the verdict weak; the same cause at a
kinematically tied site, by another member of its family, or by a law
that becomes it at a standard shape (power drag with n = 1 is viscous
damping) is no rival, nor is a pair that only adds a cause to the best.
Rows here are built by hand (no fit): what is checked is the rule."""
import dataclasses
from types import SimpleNamespace

from acausal.diagnose.library.loader import family_index
from acausal.diagnose.problem import Candidate, Param
from acausal.diagnose.stages import verdict as vd
from acausal.diagnose.stages.kinematics import Kinematics, Tie

FAM = family_index(None)
LAWS = vd.same_laws(None)


def _row(hyps, locs, ci=None, aicc=100.0, heldout=1.0):
    """A ranking row of ``hyps`` at ``locs`` (lists: one, or two for a pair)
    with one parameter per member, or ``ci`` ({short name: interval}) for
    the named parameters of a single member."""
    prefixes = [f"h{i}" for i in range(len(hyps))]
    params, ci95, values = [], {}, {}
    for p, h in zip(prefixes, hyps):
        names = list(ci) if ci and len(hyps) == 1 else ["a"]
        for short in names:
            name = f"{p}.{short}"
            params.append(Param(name, 0.0, -10.0, 10.0, 1.0, 0.0))
            lo, hi = (ci or {}).get(short, (0.5, 1.5))
            ci95[name], values[name] = (lo, hi), (lo + hi) / 2
    cand = Candidate("+".join(hyps), "+".join(locs), tuple(params))
    return SimpleNamespace(candidate=cand, fit=SimpleNamespace(ci95=ci95, values=values),
                           aicc=aicc, heldout_rmse=heldout)


def _rivals(rows, same):
    return vd.class_rivals(rows, list(range(len(rows))), 0, same, lambda r: r.heldout_rmse < 2)


def test_another_cause_in_the_class_is_a_rival_and_gives_its_numbers():
    best = _row(["coulomb_friction"], ["mass"], heldout=1.01)
    load = _row(["constant_load"], ["mass"], aicc=101.5, heldout=1.02)
    rows = [best, load]
    got = _rivals(rows, vd.SameCause(FAM, None, LAWS))
    assert got == [1]
    (r,) = vd.rival_reasons(rows, got, 0)
    assert r.code == "rival_tied"
    assert "constant_load at mass" in r.text and "+1.5" in r.text and "1.02" in r.text


def test_a_rival_that_leaves_the_held_out_data_unexplained_is_none():
    rows = [_row(["coulomb_friction"], ["mass"]), _row(["constant_load"], ["mass"], heldout=5.0)]
    assert _rivals(rows, vd.SameCause(FAM, None, LAWS)) == []


def test_same_family_tied_site_and_added_cause_are_not_rivals():
    best = _row(["stribeck_friction"], ["cam"])
    same = [_row(["coulomb_friction"], ["cam"]),               # family member, same site
            _row(["coulomb_friction"], ["shaft"]),             # tied site
            _row(["stribeck_friction", "hardening_spring"], ["cam", "spring"]),  # adds a cause
            _row(["coulomb_friction", "quadratic_damping"], ["shaft", "cam"])]   # both
    kin = Kinematics(ties=(Tie("cam", "shaft", 2.0, 0.01),))
    assert _rivals([best] + same, vd.SameCause(FAM, kin, LAWS)) == []
    # untied, the other site is another cause (alone, or in a pair without
    # the best's friction at the cam)
    got = _rivals([best] + same, vd.SameCause(FAM, Kinematics(), LAWS))
    assert got == [2, 4]


def test_a_single_member_of_a_best_pair_is_left_to_the_pair_rule():
    best = _row(["coulomb_friction", "quadratic_damping"], ["cam", "cam"])
    assert _rivals([best, _row(["coulomb_friction"], ["cam"])],
                   vd.SameCause(FAM, None, LAWS)) == []


def test_power_drag_at_a_viscous_exponent_is_viscous_damping():
    """Power drag whose exponent's interval holds n = 1 names the viscous
    damping of the friction family; at n = 2 +- 0.05 it does not (there it
    is quadratic drag: another cause than viscous damping)."""
    best = _row(["viscous_damping"], ["follower"])
    viscous = _row(["power_drag"], ["follower"], ci={"c": (1.0, 2.0), "n": (0.98, 1.07)})
    quadratic = _row(["power_drag"], ["follower"], ci={"c": (1.0, 2.0), "n": (1.95, 2.05)})
    same = vd.SameCause(FAM, None, LAWS)
    assert _rivals([best, viscous], same) == []
    assert _rivals([best, quadratic], same) == [1]
    # without the library's declared laws, the exponent does not count
    assert _rivals([best, viscous], dataclasses.replace(same, same_law={})) == [1]


# -- what every tied candidate holds (verdict.partial) ---------------------------------------
def _weak(rows, rivals):
    reasons = tuple(vd.rival_reasons(rows, rivals, 0))
    return vd.Verdict("weak", reasons, None, rows[0].heldout_rmse)


def test_a_cause_every_tied_pair_holds_is_named_in_part_with_its_spread():
    """Coulomb friction at the cam in every tied pair, the drag at the cam
    or at the follower (cam friction + drag at 30 floors): the friction is
    named with its site and values, the drag's sites are left undecided."""
    best = _row(["coulomb_friction", "quadratic_damping"], ["cam", "cam"])
    other = _row(["coulomb_friction", "quadratic_damping"], ["cam", "follower"], aicc=101.0)
    other.fit.values["h0.a"] = 1.2                       # the friction's value in the rival
    stick = _row(["stick_slip_friction", "quadratic_damping"], ["cam", "follower"], aicc=101.5)
    rows = [best, other, stick]
    same = vd.SameCause(FAM, Kinematics(), LAWS)
    rivals = _rivals(rows, same)
    assert rivals == [1, 2]
    v = vd.with_partial(_weak(rows, rivals), rows, rivals, same)
    c, drag = v.partial.shared
    assert (c.family, c.member, c.location, c.sites) == ("friction", "coulomb_friction", "cam",
                                                         ("cam",))
    assert c.site_decided and c.values == {"h0.a": 1.0} and c.spread == {"h0.a": (1.0, 1.2)}
    # the drag is in every tied pair too, at the cam or the follower
    assert drag.member == "quadratic_damping" and drag.sites == ("cam", "follower")
    assert not drag.site_decided and v.partial.undecided == ()
    assert "a friction-family law (the best's: coulomb_friction) at cam:" in v.partial.sentence()
    assert "at cam or follower (its site is undecided)" in v.partial.sentence()
    # a tied pair without the drag leaves it undecided, the friction shared
    spring = _row(["coulomb_friction", "hardening_spring"], ["cam", "spring"], aicc=101.8)
    rows = rows + [spring]
    v = vd.with_partial(_weak(rows, [1, 2, 3]), rows, [1, 2, 3], same)
    assert [x.member for x in v.partial.shared] == ["coulomb_friction"]
    assert v.partial.undecided == ("quadratic_damping at cam", "quadratic_damping at follower",
                                   "hardening_spring at spring")
    assert v.kind == "weak"                  # the whole answer is still undecided


def test_a_shared_family_at_untied_sites_leaves_the_site_undecided():
    best = _row(["stribeck_friction"], ["cam"])
    rival = _row(["stribeck_friction", "constant_load"], ["follower", "follower"], aicc=100.5)
    rows = [best, rival]
    same = vd.SameCause(FAM, Kinematics(), LAWS)
    v = vd.with_partial(_weak(rows, _rivals(rows, same)), rows, [1], same)
    (c,) = v.partial.shared
    assert c.sites == ("cam", "follower") and not c.site_decided
    assert v.partial.undecided == (vd.NOTHING_ELSE, "constant_load at follower")
    # a site tied to the cam's decides it
    tied = vd.SameCause(FAM, Kinematics(ties=(Tie("cam", "follower", 2.0, 0.01),)), LAWS)
    rival2 = _row(["stribeck_friction", "constant_load"], ["follower", "cam"], aicc=100.5)
    rows2 = [best, rival2]
    v2 = vd.with_partial(_weak(rows2, [1]), rows2, [1], tied)
    assert v2.partial.shared[0].site_decided


def test_no_shared_cause_or_another_objection_gives_no_partial_name():
    best = _row(["coulomb_friction"], ["mass"])
    load = _row(["constant_load"], ["mass"], aicc=101.0)
    rows = [best, load]
    same = vd.SameCause(FAM, None, LAWS)
    assert vd.with_partial(_weak(rows, [1]), rows, [1], same).partial is None
    drag = _row(["coulomb_friction", "quadratic_damping"], ["mass", "mass"])
    spring = _row(["coulomb_friction", "hardening_spring"], ["mass", "spring"], aicc=101.0)
    rows = [drag, spring]
    v = _weak(rows, [1])
    v = dataclasses.replace(v, reasons=v.reasons + (vd.Reason("not_strong", "weak effect"),))
    assert vd.with_partial(v, rows, [1], same).partial is None


def test_the_next_experiments_rivals_are_distinct_causes():
    """The next experiment takes one row per set of (family, site): the
    family variants of the best pair are one rival, so the drag at the
    follower and a friction at the follower get the places."""
    from acausal.diagnose.stages.nextexp import class_rows
    rows = [_row(["coulomb_friction", "quadratic_damping"], ["cam", "cam"]),
            _row(["stick_slip_friction", "quadratic_damping"], ["cam", "cam"]),
            _row(["quadratic_damping", "stribeck_friction"], ["cam", "cam"]),   # order
            _row(["coulomb_friction", "quadratic_damping"], ["cam", "follower"]),
            _row(["stribeck_friction", "hardening_spring"], ["follower", "spring"]),
            _row(["stribeck_friction"], ["cam"])]
    rk = SimpleNamespace(best=rows[0], classes=[list(range(len(rows)))], after=0, rows=rows)
    got = class_rows(SimpleNamespace(discrepancy=True), rk, FAM)
    assert [r.candidate.label for r in got] == [rows[i].candidate.label for i in (0, 3, 4, 5)]
