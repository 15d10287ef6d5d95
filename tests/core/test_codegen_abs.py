"""Code generation differentiates over real symbols, so Abs (and other
functions whose complex derivative needs re/im) appear in laws."""
import numpy as np
import sympy as sp

from acausal import Model, compile_model
from acausal.mechanics.translational import Force, Mass


def test_quadratic_drag_with_abs_closed_form():
    m = Model()
    c = m.parameter("c", 0.5, "N*s^2/m^2", "drag coefficient", min=0.0)
    m.mass = Mass(m=2.0, s=0.0, v=3.0)
    m.drag = Force(f=lambda s, v: -c * v * sp.Abs(v))
    m.connect(m.mass.flange, m.drag.flange)
    cm = compile_model(m)
    assert "re(" not in cm.source and "im(" not in cm.source
    res = cm.simulate(t_end=2.0, rtol=1e-10, atol=1e-12, output_step=0.01)
    # m dv/dt = -c v|v|, v0 > 0: v = v0 / (1 + c v0 t / m), s = m/c ln(1 + c v0 t / m)
    k = 0.5 * 3.0 / 2.0
    assert np.max(np.abs(res["mass.v"] - 3.0 / (1 + k * res.t))) < 1e-8
    assert np.max(np.abs(res["mass.s"] - 2.0 / 0.5 * np.log1p(k * res.t))) < 1e-8
    # moving backwards the drag still opposes the motion
    m2 = Model()
    m2.mass = Mass(m=2.0, s=0.0, v=-3.0)
    m2.drag = Force(f=lambda s, v: -0.5 * v * sp.Abs(v))
    m2.connect(m2.mass.flange, m2.drag.flange)
    res = compile_model(m2).simulate(t_end=2.0, rtol=1e-10, atol=1e-12, output_step=0.01)
    assert np.max(np.abs(res["mass.v"] + 3.0 / (1 + k * res.t))) < 1e-8
