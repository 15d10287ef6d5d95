"""The breaker variants (models/breaker_24kv_*.py, docs/breaker_variants.md):
each runs with its own Experiment and gives the base file's measures; one
physical check each against the base design at the same impact velocity.

The first impact of every design is a Lankarani-Nikravesh impact of two
bodies with reduced mass mu = m1 m2 / (m1 + m2) (m = J / arm^2 for a body
on a lever). Scaled by delta* = (mu v^2 / K)^(2/5) and delta*/v the impact
equation mu delta'' = -K delta^1.5 (1 + chi delta'/v) has no parameter left,
so at equal v and K the peak force goes as mu^(3/5) and the contact period
as mu^(2/5). The hook friction, Fe and the four-bar load (a few hundred N
at the contact point against 3-5 kN) are what keeps it from being exact.
"""
import math
import os
import sys

import numpy as np
import pytest

from acausal import compile_model
from acausal.modelfile import run_file
from acausal.mechanics import contact as ct

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MODELS = os.path.join(ROOT, "models")
BASE = os.path.join(MODELS, "breaker_24kv.py")
MA, S3, JH, LA, FE, KA = 0.22, 0.055, 0.44e-3, 0.025, 160.0, 0.013
MEASURES = ("thrt", "contact_period", "peak_force", "impact_velocity")


def path(variant):
    return os.path.join(MODELS, f"breaker_24kv_{variant}.py")


def mu(m1, m2):
    return m1 * m2 / (m1 + m2)


def hertz_ratios(m, mb, mu_ratio):
    """(peak force, contact period) of a variant over the base, each divided
    by its similarity prediction mu_ratio^(3/5), mu_ratio^(2/5)."""
    return (m["peak_force"] / mb["peak_force"] / mu_ratio ** 0.6,
            m["contact_period"] / mb["contact_period"] / mu_ratio ** 0.4)


@pytest.fixture(scope="module")
def base():
    return run_file(BASE)


@pytest.mark.parametrize("variant, thrt_ms, impacts", [
    ("light_hook", 2.095, 2), ("rotary_armature", 2.551, 1), ("two_stage", 2.172, 1)])
def test_variant_runs_with_the_base_measures(variant, thrt_ms, impacts):
    """Numbers of docs/breaker_variants.md at 3.8 m/s (regression, 0.002 ms)."""
    res, m = run_file(path(variant))
    assert set(MEASURES) <= set(m)
    assert res.event_times("release"), "stopped at the release angle"
    assert m["thrt"] * 1e3 == pytest.approx(thrt_ms, abs=2e-3)
    assert m["impact_velocity"] == pytest.approx(3.8, abs=1e-3)   # 1 um of Fe first
    assert m["n_impacts"] == impacts


def test_light_hook_first_impact_scales_with_the_reduced_mass(base):
    """Jh 0.44e-3 -> 0.30e-3: mu 0.0876 -> 0.0684 kg; peak force within 1 %
    (measured +0.4 %), contact period within 2 % (+1.1 %) of the scaling."""
    _, mb = base
    _, m = run_file(path("light_hook"))
    ratio = mu(MA, 0.30e-3 / S3**2) / mu(MA, JH / S3**2)
    peak, period = hertz_ratios(m, mb, ratio)
    assert peak == pytest.approx(1.0, abs=0.01)
    assert period == pytest.approx(1.0, abs=0.02)


def test_light_hook_leaves_faster_with_less_momentum_and_releases_later(base):
    """At 3.8 m/s the lighter hook comes off the armature faster (82 against
    73 rad/s: v_h ~ (1+e) ma / (ma + mh)) but with less angular momentum
    (Jh w: 0.025 against 0.032 N*m*s, ~ ma mh / (ma + mh)); under the viscous
    latch friction the coasting angle is Jh w / bh, so it does not release
    sooner but 0.19 ms later, on a second push of the armature."""
    resb, mb = base
    res, m = run_file(path("light_hook"))
    w = np.max(-res["hook.body.w"][res.t < 0.8e-3])
    wb = np.max(-resb["hook.body.w"][resb.t < 0.8e-3])
    assert w > 1.1 * wb
    assert 0.30e-3 * w < 0.8 * JH * wb
    assert m["thrt"] > mb["thrt"] + 0.1e-3
    assert m["n_impacts"] == 2 and ct.n_impacts(resb, "contact") == 1


def _rotary():
    sys.path.insert(0, MODELS)
    try:
        import breaker_24kv_rotary_armature as rot
    finally:
        sys.path.remove(MODELS)
    return rot


@pytest.mark.parametrize("exact, tol_thrt, tol_peak", [(False, 1e-9, 1e-3), (True, 1e-6, 1.0)])
def test_rotary_armature_with_the_plunger_inertia_is_the_base_model(base, exact, tol_thrt,
                                                                    tol_peak):
    """Ja = ma la^2, Te = Fe la, kr = ka la^2: with the small-angle lever the
    same equations as the base (measured THRT difference 3e-12 s); the exact
    lever (pin on a circle, 0.2 rad of clapper travel) adds 1.1e-7 s."""
    _, mb = base
    rot = _rotary()
    model = rot.build(exact=exact)
    model.event(rot.experiment.stop.event(model))
    res = compile_model(model).simulate(
        params={"armature.Ja": MA * LA**2, "armature.Te": FE * LA, "armature.kr": KA * LA**2},
        **rot.experiment.run_options())
    thrt = res.event_times("release")[0] - ct.impacts(res, "contact")[0].t_onset
    assert thrt == pytest.approx(mb["thrt"], abs=tol_thrt)
    assert ct.peak_force(res, "contact") == pytest.approx(mb["peak_force"], abs=tol_peak)


def test_rotary_armature_first_impact_scales_with_the_reduced_mass(base):
    """Clapper Ja/la^2 = 0.16 kg against the 0.22 kg plunger: mu 0.0876 ->
    0.0762 kg; peak force (+0.45 %) and contact period (-0.1 %) within 1 %.
    A wrong lever reflection (Ja/la instead of Ja/la^2) would be off by x25."""
    _, mb = base
    _, m = run_file(path("rotary_armature"))
    ratio = mu(1.0e-4 / LA**2, JH / S3**2) / mu(MA, JH / S3**2)
    peak, period = hertz_ratios(m, mb, ratio)
    assert peak == pytest.approx(1.0, abs=0.01)
    assert period == pytest.approx(1.0, abs=0.01)


def test_two_stage_first_peak_is_the_armature_on_the_free_trip_lever(base):
    """The first force maximum of the armature contact comes before the trip
    lever touches the hook (0.094 < 0.099 ms), so it is the impact of the
    armature on the free lever (J1/a1^2 = 0.067 kg, mu 0.0511 kg): within
    3 % of the mu^(3/5) scaling (measured -1.6 %: the lever's reset spring
    and friction, and the hook contact closing right after)."""
    _, mb = base
    res, _ = run_file(path("two_stage"))
    t_peak = res.event_times("contact.peak")[0]
    assert t_peak < res.event_times("latch_contact.onset")[0]
    after = res["contact.f_peak"][res.t >= t_peak]
    first = after[after > 0][0]
    ratio = mu(MA, 6.0e-5 / 0.03**2) / mu(MA, JH / S3**2)
    assert first / mb["peak_force"] / ratio ** 0.6 == pytest.approx(1.0, abs=0.03)


def test_two_stage_hook_gets_less_momentum_and_releases_later(base):
    """Through the trip lever the hook gets 65 instead of 73 rad/s (the extra
    impacts, e = 0.74 each, and the lever's own share of the momentum), so it
    releases 0.27 ms later at 3.8 m/s (later at every speed of the sweep)."""
    resb, mb = base
    res, m = run_file(path("two_stage"))
    w = np.max(-res["hook.body.w"][res.t < 0.8e-3])
    wb = np.max(-resb["hook.body.w"][resb.t < 0.8e-3])
    assert w < 0.95 * wb
    assert m["thrt"] > mb["thrt"] + 0.2e-3


@pytest.mark.parametrize("v", [3.3, 3.6])
def test_two_stage_runs_where_the_algebraic_error_test_collapsed_the_step(v):
    """With atol 1e-11 also on the algebraic unknowns IDA failed at 3.3 and
    3.6 m/s when this was found (step size -> 1e-25 s; on 2026-11-22 the
    current pipeline runs 3.0-4.5 m/s without it, in 750-1240 steps);
    atol_algebraic = 1e-2 runs in ~1000 steps. Its THRT against a tight reference (rtol 1e-10, atol_algebraic
    1e-6): measured 1.5e-9 s at 3.3 m/s (5e-7 relative; the looser
    algebraic tolerance costs accuracy there, atol_algebraic 1e-6 at rtol
    1e-8 is within 0.3e-9 s), bounded here at 1e-6 relative."""
    res, m = run_file(path("two_stage"), params={"v_impact": v})
    assert res.stats["steps"] < 3000
    ref, mr = run_file(path("two_stage"), params={"v_impact": v}, atol_algebraic=1e-6,
                       rtol=1e-10)
    assert m["thrt"] == pytest.approx(mr["thrt"], rel=1e-6)
    assert math.isfinite(m["thrt"])
