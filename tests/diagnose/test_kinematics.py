"""Kinematically equivalent sites (issue 11): sites whose motions are tied by
a constant ratio over the data are found from the calibrated nominal run,
the named cause's parameters are converted through the ratio, and the site
shown is never the data's choice among sites the data cannot tell apart.

The mechanism (tests/diagnose/lever_model.py): a wheel drives a slider
through a rigid lever of arm ARM (slider speed = ARM x wheel speed, closed
form), and a tip rings on its own spring beyond the slider (tied to
neither)."""
import os
from types import SimpleNamespace

import numpy as np
import pytest

from acausal.data import Dataset, MeasuredExperiment, Instrument, Trace, write_dataset
from acausal.diagnose.stages.fitting import Fit
from acausal.diagnose.library.hypotheses import HYPOTHESES, build_extended
from acausal.diagnose.stages.kinematics import (
    EquivalentSite, Kinematics, Tie, convert, equivalents, kinematics, prefer_site, tie)
from acausal.diagnose.problem import Candidate, Param, Problem, free_param
from acausal.diagnose.report.result import equivalent_sites
from acausal.diagnose.stages.chain import Ranking, Row
from acausal.diagnose.stages.tasks import Starts

HERE = os.path.dirname(__file__)
LEVER = os.path.join(HERE, "lever_model.py")
ARM = -0.05
FREE = (free_param("k.c", 500.0, 200.0, 1000.0),)


def _dataset(folder):
    """Two releases of the tip, the slider's travel traced (its own model)."""
    from acausal.modelfile import compile_file
    mf, cm = compile_file(LEVER)
    exps = []
    for name, x0 in (("a", 0.01), ("b", 0.016)):
        res = cm.simulate(params={"x0": x0}, **mf.experiment.run_options())
        trace = Trace(np.asarray(res.t), {"slider.s": np.asarray(res["slider.s"])})
        exps.append(MeasuredExperiment(name, {"x0": x0}, {}, trace))
    write_dataset(folder, Dataset(str(folder), exps,
                                  {"slider.s": Instrument("slider.s", 0.0, 1e-6)}))
    return folder


def test_a_rigid_lever_ties_its_sites_at_its_arm_and_a_spring_does_not(tmp_path):
    """The stage on the calibrated nominal runs of both experiments: one
    tie, wheel -> slider at the lever's arm (closed form, to 1e-6), with no
    spread; the tip, behind a spring, tied to nothing; the traced signal
    ``slider.s`` is the slider's coordinate."""
    problem = Problem(LEVER, str(_dataset(tmp_path / "data")), "acausal.diagnose.library.hypotheses",
                      FREE)
    kin = kinematics(problem, SimpleNamespace(fit=SimpleNamespace(values={"k.c": 500.0})))
    assert [(t.a, t.b) for t in kin.ties] == [("wheel", "slider")]
    assert kin.ties[0].ratio == pytest.approx(ARM, rel=1e-6)
    assert kin.ties[0].spread < 1e-5
    assert kin.tied("slider") == [("wheel", pytest.approx(1 / ARM, rel=1e-6),
                                   kin.ties[0].spread)]
    assert kin.tied("tip") == []
    assert kin.measured == (("slider", "slider.s"),)
    assert kin.signal_of("wheel") is None


def test_tie_needs_proportional_rates():
    """Proportional series are tied at their ratio; a second mode (5 %) or a
    site that does not move is not."""
    t = np.linspace(0, 1, 500)
    a = np.sin(7 * t) * np.exp(-t)
    assert tie(a, -3.0 * a) == pytest.approx((-3.0, 0.0), abs=1e-12)
    assert tie(a, a + 0.2 * np.std(a) * np.sin(31 * t)) is None
    assert tie(a, np.zeros_like(a)) is None


def test_parameters_convert_through_the_ratio():
    """Force / r and length x r: Coulomb friction tau / |r|, viscous b / r^2,
    quadratic drag c / |r|^3, a Stribeck speed x |r|; a constant load keeps
    its direction, so it takes the sign of r."""
    r = ARM
    assert convert(0.02, "N*m", "rotational", r) == pytest.approx(0.02 / 0.05)
    assert convert(0.3, "N*m*s/rad", "rotational", r) == pytest.approx(0.3 / 0.05 ** 2)
    assert convert(1e-4, "N*m*s^2/rad^2", "rotational", r) == pytest.approx(1e-4 / 0.05 ** 3)
    assert convert(2.0, "rad/s", "rotational", r) == pytest.approx(2.0 * 0.05)
    assert convert(0.02, "N*m", "rotational", r, odd=False) == pytest.approx(-0.02 / 0.05)
    assert convert(0.4, "N", "translational", 1 / r) == pytest.approx(0.4 * 0.05)
    assert convert(1.0, "1", "translational", r) == 1.0


def test_converted_friction_at_the_tied_site_acts_the_same():
    """Coulomb friction on the wheel and the converted friction on the
    slider give the same motion (the tip, to 1e-6 of its travel): the
    conversion is the same cause, not an approximation of it."""
    tau = 0.004
    F = convert(tau, "N*m", "rotational", ARM)
    runs = []
    for loc, name, v in (("wheel", "hyp_cf.tau", tau), ("slider", "hyp_cf.F", F)):
        mf, cm = build_extended(LEVER, "coulomb_friction", loc)
        res = cm.simulate(params={name: v}, **mf.experiment.run_options())
        runs.append(np.asarray(res["tip.s"]))
    assert np.max(np.abs(runs[0] - runs[1])) < 1e-6 * np.ptp(runs[0])
    mf, cm = build_extended(LEVER, "coulomb_friction", "slider")
    free = cm.simulate(**mf.experiment.run_options())
    assert np.max(np.abs(np.asarray(free["tip.s"]) - runs[1])) > 1e-2 * np.ptp(runs[0])


def _row(hid, loc, values, aicc):
    cand = Candidate(hid, loc, tuple(Param(k, 0.0, 0.0, 10.0, 1.0, 0.0)
                                     for k in values if k.startswith("hyp")))
    names = list(values)
    fit = Fit(names, dict(values), 1.0, np.zeros(3), np.zeros((3, len(names))), [], [])
    return Row(cand, fit, Starts(tested=True), {}, aicc, 1e-10, 1.0)


def _ranking(classes):
    rows = (_row("coulomb_friction", "slider", {"k.c": 500.0, "hyp_cf.F": 0.08}, 10.0),
            _row("coulomb_friction", "wheel", {"k.c": 500.0, "hyp_cf.tau": 0.0041}, 10.3),
            _row("quadratic_damping", "tip", {"k.c": 500.0, "hyp_qd.c": 1.0}, 30.0))
    return Ranking(rows, classes, 0, 0, None, [], (), 5.0)


TIED = Kinematics((Tie("wheel", "slider", ARM, 1e-8),), (("wheel", "wheel.phi"),))


def test_the_measured_site_is_shown_and_every_tied_site_reported():
    """Friction named on the slider, the same fitted on the wheel 0.3 AICc
    units behind in one class: the wheel is shown (its coordinate is the
    measured signal), the slider listed with the cause converted through
    the ratio and its own fit, and the reason says the data cannot tell them
    apart."""
    problem = Problem(LEVER, "", "acausal.diagnose.library.hypotheses", FREE)
    rk = prefer_site(_ranking([[0, 1], [2]]), TIED)
    assert rk.named.candidate.key == ("coulomb_friction", "wheel") and rk.after == 1
    (eq,) = equivalents(problem, TIED, rk)
    assert (eq.cause, eq.location) == ("coulomb_friction", "wheel")
    (site,) = eq.sites
    assert site.location == "slider" and site.ratio == pytest.approx(ARM)
    assert dict(site.values)["hyp_cf.F"] == pytest.approx(0.0041 / 0.05)
    assert dict(site.fitted) == {"hyp_cf.F": 0.08}
    assert site.daicc == pytest.approx(-0.3) and site.in_class and site.in_range
    assert "cannot tell `wheel` from `slider`" in eq.reason
    assert "measured signal `wheel.phi`" in eq.reason
    got = equivalent_sites(eq)
    assert got[0]["location"] == "slider" and got[0]["fitted"]["same_class"] is True
    assert got[0]["parameters"]["hyp_cf.F"] == pytest.approx(0.082)


def test_sites_the_data_tell_apart_or_untied_sites_keep_the_ranking():
    """The wheel's fit in another class: the slider stays shown, and the
    reason gives the AICc difference instead of claiming equivalence; with
    no tie nothing is reported."""
    problem = Problem(LEVER, "", "acausal.diagnose.library.hypotheses", FREE)
    rk = prefer_site(_ranking([[0], [1], [2]]), TIED)
    assert rk.after == 0
    (eq,) = equivalents(problem, TIED, rk)
    assert not eq.sites[0].in_class and "ranks +0.3 AICc units apart" in eq.reason
    # a friction on the slider too large for the wheel's declared range is said to be so
    big = Ranking((_row("coulomb_friction", "slider", {"k.c": 500.0, "hyp_cf.F": 1e6}, 10.0),),
                  [[0]], 0, 0, None, [], (), 5.0)
    (eq,) = equivalents(problem, TIED, big)
    assert not eq.sites[0].in_range and "outside the range declared there" in eq.reason
    none = Kinematics()
    assert prefer_site(_ranking([[0, 1], [2]]), none).after == 0
    assert equivalents(problem, none, _ranking([[0, 1], [2]])) == ()
    assert isinstance(eq.sites[0], EquivalentSite) and HYPOTHESES["constant_load"].odd is False


def test_a_pair_member_is_found_at_the_tied_site_in_either_order():
    """Drag on the tip + friction on the slider named; the pair with the
    friction on the wheel was fitted with its members the other way round:
    it is the friction's fit at the tied site."""
    problem = Problem(LEVER, "", "acausal.diagnose.library.hypotheses", FREE)
    named = _row("quadratic_damping+coulomb_friction", "tip+slider",
                 {"k.c": 500.0, "hyp_qd.c": 1.0, "hyp_cf.F": 0.08}, 10.0)
    alt = _row("coulomb_friction+quadratic_damping", "wheel+tip",
               {"k.c": 500.0, "hyp_cf.tau": 0.0041, "hyp_qd.c": 1.0}, 10.5)
    rk = Ranking((named, alt), [[0, 1]], 0, 0, None, [], (), 5.0)
    (eq,) = equivalents(problem, TIED, rk)
    assert (eq.cause, eq.location) == ("coulomb_friction", "slider")
    (site,) = eq.sites
    assert site.location == "wheel" and dict(site.fitted) == {"hyp_cf.tau": 0.0041}
    assert dict(site.values)["hyp_cf.tau"] == pytest.approx(0.08 * 0.05)
    assert prefer_site(rk, TIED).after == 1


def test_a_diagnosis_reports_the_tied_site(tmp_path):
    """The whole chain on the lever (data from the model with Coulomb friction
    at the wheel, the slider's travel traced): the friction is named with the
    other of wheel and slider as its tied site in the JSON and the report;
    when the data cannot tell them apart, the slider (its travel is the
    measured signal) is the site shown."""
    from acausal.diagnose.problem import FitSettings
    from acausal.diagnose.run import diagnose
    mf, cm = build_extended(LEVER, "coulomb_friction", "wheel")
    rng = np.random.default_rng(5)
    exps = []
    for name, x0 in (("a", 0.01), ("b", 0.016), ("c", 0.02)):
        res = cm.simulate(params={"x0": x0, "hyp_cf.tau": 0.002}, **mf.experiment.run_options())
        s = np.asarray(res["slider.s"]) + 1e-6 * rng.standard_normal(len(res.t))
        exps.append(MeasuredExperiment(name, {"x0": x0}, {},
                                       Trace(np.asarray(res.t), {"slider.s": s})))
    write_dataset(tmp_path / "data", Dataset(str(tmp_path / "data"), exps,
                                             {"slider.s": Instrument("slider.s", 0.0, 1e-6)}))
    out = diagnose(LEVER, tmp_path / "data", out_dir=tmp_path / "out", workers=1,
                   progress=False, hypotheses=["coulomb_friction"], generic=False, pairs=False,
                   families=False, profile=False, design=False, plots=False,
                   settings=FitSettings(lhs=1, refine=1))
    assert out["cause"] == "coulomb_friction" and out["location"] in ("wheel", "slider")
    (cause,) = out["causes"]
    (tied,) = cause["equivalent_sites"]
    assert {tied["location"], out["location"]} == {"wheel", "slider"}
    assert tied["ratio"] == pytest.approx(ARM if out["location"] == "wheel" else 1 / ARM,
                                          rel=1e-4)
    tau = out["parameters"]["hyp_cf.tau"]["value"] if out["location"] == "wheel" else \
        tied["parameters"]["hyp_cf.tau"]
    assert tau == pytest.approx(0.002, rel=0.05)
    if tied["fitted"] is not None and tied["fitted"]["same_class"]:
        assert out["location"] == "slider" and "measured signal `slider.s`" in cause["site_reason"]
    assert "Kinematically equivalent sites" in (tmp_path / "out" / "report.md").read_text()
