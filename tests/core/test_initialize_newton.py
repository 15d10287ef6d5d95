"""Initialisation: Newton starts at the fixed start values of the states and
scales the columns of its least-squares steps."""
import numpy as np
import sympy as sp

from acausal import Model, compile_model
from acausal.runtime.initialize import _lstsq_scaled
from acausal.mechanics.levers import TwoArmLever
from acausal.mechanics.translational import Force, Mass


def test_newton_starts_at_fixed_state_values():
    """A steep law of a fixed velocity (regularised Coulomb friction, slope
    468/0.0038 N s/m at v = 0) whose state slot is der(m1.s): starting Newton
    from the guess v = 0 stalled there ("inconsistent fixed start values")."""
    m = Model()
    m.lever = TwoArmLever(a=0.1, b=0.3)
    m.m1 = Mass(m=0.22, s=1e-4, v=-3.8)
    m.m2 = Mass(m=0.05)
    m.fr = Force(f=-468.0 * sp.tanh(m.m1.v / 0.0038))
    m.coil = Force(f=-160.0)
    m.connect(m.m1.flange, m.fr.flange, m.coil.flange, m.lever.flange_a)
    m.connect(m.m2.flange, m.lever.flange_b)
    cm = compile_model(m)
    assert "der(m1.s)" in [s.name for s in cm.dae.y[:cm.dae.n_states]]
    res = cm.simulate(t_end=1e-3, rtol=1e-10, atol=1e-13, output_step=1e-4)
    # sliding backwards all along: (m1 + m2 (b/a)^2) a = 468 - 160
    acc = (468.0 - 160.0) / (0.22 + 0.05 * 9.0)
    assert abs(res["m1.v"][0] + 3.8) < 1e-12
    assert np.max(np.abs(res["m1.v"] - (-3.8 + acc * res.t))) < 1e-8


def test_scaled_least_squares_keeps_small_columns():
    """Columns 1e18 apart (a stiff spring's position column next to a light
    body's acceleration): a plain lstsq cuts the small one off as rank
    deficiency, the column-scaled one solves it."""
    J = np.array([[1e9, 0.0], [0.0, 1e-9]])
    b = J @ np.array([1.0, 1.0])
    assert abs(np.linalg.lstsq(J, b, rcond=None)[0][1]) < 1e-6
    assert np.allclose(_lstsq_scaled(J, b), [1.0, 1.0], rtol=1e-12)
