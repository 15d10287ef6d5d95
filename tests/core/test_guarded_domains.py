"""A guarded sqrt/log/power/division shared by several expressions (so that
code generation computes it before its guard) runs on both backends, as C's
IEEE arithmetic lets it: the branch that is not taken drops the NaN
(acausal.codegen, _IEEE_ERRORS)."""
import math

import numpy as np
import pytest
import sympy as sp

from acausal import Eq, Model, Parameter, compile_model
from acausal.mechanics.partials import PartialCompliant
from acausal.mechanics.translational import Fixed, Mass


class _TensionOnly(PartialCompliant):
    """f = c x + 0 * (sqrt(x) + log(x) + x^1.5 + 1/x) for x = s_rel - L > 0,
    else 0: the guarded terms are shared by the residual and its Jacobian
    and vanish in value, so the motion is a linear spring's while it is
    stretched, free flight when slack."""
    c = Parameter(100.0, "N/m", "stiffness")
    L = Parameter(0.1, "m", "free length")
    z = Parameter(0.0, "N", "weight of the guarded terms")

    def equations(self):
        x = self.s_rel - self.L
        u = x / self.L        # dimensionless, so that the junk terms add up in units
        junk = sp.sqrt(u) + sp.log(u) + u ** sp.Rational(3, 2) + 1 / u
        return [Eq(self.f, sp.Piecewise((self.c * x + self.z * junk * sp.sqrt(u), x > 0),
                                        (0, True)))]


def _model():
    m = Model()
    m.ground = Fixed()
    m.spring = _TensionOnly()
    m.mass = Mass(m=1.0, s=0.1, v=-0.5)        # starts at the free length, moving in
    m.connect(m.ground.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.mass.flange)
    return m


@pytest.mark.parametrize("backend", ["sundae", "compiled"])
def test_guarded_terms_outside_their_domain(backend):
    cm = compile_model(_model(), cache=False)
    if backend == "compiled":
        from acausal.runtime.backends import compiled
        try:
            compiled._compiler()
        except compiled.Unavailable:
            pytest.skip("no C compiler")
    res = cm.simulate(t_end=0.3, rtol=1e-9, atol=1e-12, backend=backend)
    # slack (x < 0) all the way: free flight s = 0.1 - 0.5 t
    t = res.t
    assert np.allclose(res["mass.s"], 0.1 - 0.5 * t, atol=1e-9)
    assert res.stats["backend"] == backend


def test_guarded_terms_inside_their_domain_follow_the_linear_spring():
    cm = compile_model(_model(), cache=False)
    res = cm.simulate(t_end=0.3, rtol=1e-10, atol=1e-13,
                      params={"mass.v": 0.5})    # moving out: stretched from t = 0
    w = math.sqrt(100.0)
    assert np.allclose(res["mass.s"], 0.1 + 0.5 / w * np.sin(w * res.t), atol=1e-8)


def test_sensitivities_through_guarded_terms():
    """The sensitivity model's generated code is guarded too. Stretched from
    t = 0 (s0 = L): s = L + (s0 - L) cos(w t) + v/w sin(w t), w = sqrt(c/m),
    so d s/d L = 1 - cos(w t) and d s/d c = v (t cos(w t)/w - sin(w t)/w^2)
    / (2 w m)."""
    cm = compile_model(_model(), cache=False)
    res = cm.simulate(t_end=0.3, rtol=1e-10, atol=1e-13, params={"mass.v": 0.5},
                      sensitivities=["spring.L", "spring.c"])
    t, w, v = res.t, 10.0, 0.5
    dsdc = v * (t * np.cos(w * t) / w - np.sin(w * t) / w**2) / (2 * w)
    assert np.allclose(res.sensitivity("mass.s", "spring.L"), 1 - np.cos(w * t), atol=1e-7)
    assert np.allclose(res.sensitivity("mass.s", "spring.c"), dsdc, atol=1e-8)
