"""FourBarLinkage (acausal/mechanics/planar/linkages.py), named by a test of
its own (issue 21): its closed-form assembly closes the loop for any crank
angle it accepts, it refuses a geometry that cannot close with one line
naming itself, and in a simulation the joints stay on that closed form."""
import math

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from acausal.errors import ParameterError
from acausal.mechanics.planar.linkages import FourBarLinkage, fourbar_assembly

GEO = dict(xa=0.1, ya=0.0, phia=0.0, xb=0.0, yb=0.0, phib=0.0, a=0.02, b=0.06, c=0.1)


def joints(theta_a, mode, g):
    """World positions of D reached from A (crank) and from B (rocker, coupler)."""
    tb, tc, td = fourbar_assembly(theta_a, mode, **g)
    ua = g["phia"] + theta_a
    d_from_a = (g["xa"] + g["a"] * math.cos(ua), g["ya"] + g["a"] * math.sin(ua))
    ub = g["phib"] + tb
    uc = ub + tc
    d_from_b = (g["xb"] + g["b"] * math.cos(ub) + g["c"] * math.cos(uc),
                g["yb"] + g["b"] * math.sin(ub) + g["c"] * math.sin(uc))
    return d_from_a, d_from_b, (ua, uc, td)


@settings(max_examples=200, deadline=None)
@given(theta=st.floats(-math.pi, math.pi), mode=st.sampled_from([1, -1]),
       a=st.floats(0.01, 0.05), b=st.floats(0.03, 0.09), c=st.floats(0.05, 0.15))
def test_fourbar_assembly_closes_the_loop(theta, mode, a, b, c):
    g = dict(GEO, a=a, b=b, c=c)
    if fourbar_assembly(theta, mode, **g) is None:
        return                                 # the loop cannot close at this angle
    d_a, d_b, (ua, uc, td) = joints(theta, mode, g)
    assert d_a == pytest.approx(d_b, abs=1e-12)
    # the joint at D turns from the crank's direction to the coupler's
    assert math.remainder(uc - td - ua, 2 * math.pi) == pytest.approx(0.0, abs=1e-12)


def test_a_loop_that_cannot_close_is_refused_naming_the_linkage():
    with pytest.raises(ParameterError, match="FourBarLinkage: the loop cannot close") as info:
        FourBarLinkage(theta_a0=0.0, a=0.02, b=0.01, c=0.01)    # 0.1 m apart, 0.04 m of links
    assert "\n" not in str(info.value)


def test_a_simulated_fourbar_linkage_stays_on_its_closed_form():
    """The report's cam four-bar (models/examples/fourbar_planar.py, built on
    FourBarLinkage): at every output time the rocker angle and the coupler
    joint are those the closed form gives for the crank angle."""
    from acausal.modelfile import compile_file
    from pathlib import Path
    path = Path(__file__).resolve().parents[3] / "models" / "examples" / "fourbar_planar.py"
    mf, cm = compile_file(path)
    assert isinstance(mf.model.linkage, FourBarLinkage)
    res = cm.simulate(**mf.experiment.run_options())
    assert res.t[-1] > 1e-3 and len(res.t) > 10
    def at0(name):
        return float(res[f"linkage.{name}"][0])

    def length(frame_a, frame_b):
        return math.hypot(at0(f"{frame_b}.x") - at0(f"{frame_a}.x"),
                          at0(f"{frame_b}.y") - at0(f"{frame_a}.y"))
    p = dict(xa=at0("ground_a.frame.x"), ya=at0("ground_a.frame.y"),
             phia=at0("ground_a.frame.phi"), xb=at0("ground_b.frame.x"),
             yb=at0("ground_b.frame.y"), phib=at0("ground_b.frame.phi"),
             a=length("link_a.frame_a", "link_a.frame_b"),
             b=length("link_b.frame_a", "link_b.frame_b"),
             c=length("link_c.frame_a", "link_c.frame_b"))
    mode = -1      # the example's assembly mode in the linkage's convention (mode=-1 there)
    for k in range(0, len(res.t), max(1, len(res.t) // 25)):
        tb, tc, _ = fourbar_assembly(float(res["linkage.pin_a.phi"][k]), mode, **p)
        assert float(res["linkage.pin_b.phi"][k]) == pytest.approx(tb, abs=1e-6)
        assert float(res["linkage.pin_c.phi"][k]) == pytest.approx(tc, abs=1e-6)
