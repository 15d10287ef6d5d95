"""Derivatives of Abs, Max and Min of expressions (lang/fastdiff.py).

Every variable is real, so d|u|/dx = sign(u) du/dx. sympy's own rule, for a
symbol not known to be real, writes re() and im() terms that the code
printers cannot generate: a quadratic drag at a planar loop's joint (its
velocity an expression of the loop's states) failed to compile that way.
"""
import math

import numpy as np
import pytest
import sympy as sp

from acausal.lang.fastdiff import diff

x, y = sp.symbols("x y")


def _numeric(expr, at, h=1e-7):
    f = sp.lambdify((x, y), expr, "math")
    return (f(at[0] + h, at[1]) - f(at[0] - h, at[1])) / (2 * h)


@pytest.mark.parametrize("expr", [
    sp.Abs(y * sp.sin(x)),
    -0.3 * y * sp.cos(x) * sp.Abs(y * sp.cos(x)),
    sp.Max(0, 1 - sp.Abs(x - 0.2) / 0.5),
    sp.Min(x**2, y) + sp.Abs(x**3 - y),
])
@pytest.mark.parametrize("at", [(0.6, 1.3), (-1.1, 0.4), (2.5, -0.8)])
def test_derivative_is_real_and_matches_differences(expr, at):
    d = diff(expr, x)
    assert not d.has(sp.re, sp.im, sp.Derivative), d
    value = float(d.subs({x: at[0], y: at[1]}))
    assert math.isclose(value, _numeric(expr, at), rel_tol=1e-6, abs_tol=1e-8)


def test_quadratic_drag_at_a_planar_joint_compiles_and_runs():
    """The slider-crank's guide: a drag -c v|v| on the prismatic joint's
    flange, whose speed is an expression of the crank's states."""
    from acausal import Model, compile_model
    from acausal.mechanics.translational import Force

    import importlib.util
    import pathlib
    path = pathlib.Path(__file__).resolve().parents[2] / "models" / "examples" / "slider_crank.py"
    spec = importlib.util.spec_from_file_location("slider_crank_for_abs", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    model = mod.build()
    guide = model.guide
    model.drag = Force(f=lambda s, v: -0.5 * v * sp.Abs(v))
    model.connect(model.drag.flange, guide.axis)
    cm = compile_model(model, cache=False)
    res = cm.simulate(t_end=0.05)
    w = np.asarray(res["crank_pin.w"])
    assert np.all(np.isfinite(w))
    assert abs(w[-1]) < abs(w[0])   # the drag takes energy out of the free-running crank
