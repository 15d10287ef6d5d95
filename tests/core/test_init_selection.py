"""Core fixes found while building the four-bar (acausal/mechanics/fourbar.py):
start values given on eliminated aliases, state selection with a fixed
velocity but a free position, initialisation going to the nearest solution,
and assertions already violated at the initial point."""
import numpy as np
import pytest

from acausal import (Assertion, Eq, InitializationError, Model, Start, compile_model, der,
                     guess)
from acausal.lang.component import Component
from acausal.lang.declare import Variable

L, G = 1.0, 9.81


def pendulum(x, vx, y_start=Start(0.0, False), alias_guess=None):
    """Cartesian pendulum (index 3): der(x) = vx, der(y) = vy,
    der(vx) = -lam x, der(vy) = -lam y - g, x^2 + y^2 = L^2; numbers for
    ``x``, ``vx`` are fixed starts; optionally an alias ``ya = y + 1``
    carrying a guess."""
    def fixed(v):
        return v if isinstance(v, Start) else Start(v, True)

    m = Model()
    xs = m.variable("x", fixed(x))
    ys = m.variable("y", y_start)
    vxs = m.variable("vx", fixed(vx))
    vys = m.variable("vy", 0.0)
    lam = m.variable("lam", 0.0)
    m.equation(Eq(der(xs), vxs))
    m.equation(Eq(der(ys), vys))
    m.equation(Eq(der(vxs), -lam * xs))
    m.equation(Eq(der(vys), -lam * ys - G))
    m.equation(Eq(xs**2 + ys**2, L**2))
    if alias_guess is not None:
        ya = m.variable("ya", alias_guess)
        m.equation(Eq(ya, ys + 1.0))
    return m


def energy(res):
    return 0.5 * (res["vx"]**2 + res["vy"]**2) + G * res["y"]


def test_fixed_velocity_free_position_selects_a_position_state():
    # x is only a guess, vx is fixed: the fixed-start preference used to keep
    # der(vx) and drop der(x), leaving x with no state and no equation
    # ("internal: index-1 system has n equations for n+1 unknowns")
    m = pendulum(x=Start(0.6, False), vx=0.5, y_start=guess(-0.8))
    cm = compile_model(m)
    assert cm.dae.n_states == 2
    res = cm.simulate(t_end=1.0, rtol=1e-10, atol=1e-12)
    assert abs(res["vx"][0] - 0.5) < 1e-12
    assert np.max(np.abs(res["x"]**2 + res["y"]**2 - 1)) < 1e-9
    assert np.max(np.abs(energy(res) / energy(res)[0] - 1)) < 1e-8


@pytest.mark.parametrize("y0", [-0.8, 0.8])
def test_initialisation_goes_to_the_nearest_solution(y0):
    # x fixed, y guessed on either branch, a fixed velocity: the solution
    # found must be the branch of the guess (Jacobian scaling used to allow a
    # long step to the other branch)
    m = pendulum(x=0.6, vx=0.5, y_start=guess(y0))
    res = compile_model(m).simulate(t_end=1e-3, rtol=1e-10, atol=1e-12)
    assert abs(res["y"][0] - y0) < 1e-12


@pytest.mark.parametrize("ya0, y_expected", [(0.2, -0.8), (1.8, 0.8)])
def test_guess_on_an_eliminated_alias_reaches_the_root(ya0, y_expected):
    # ya = y + 1 is eliminated as an alias of y; its guess must still pick
    # the branch (it used to be ignored: y started from 0, a singular point)
    m = pendulum(x=0.6, vx=0.0, alias_guess=guess(ya0))
    cm = compile_model(m)
    res = cm.simulate(t_end=1e-3, rtol=1e-10, atol=1e-12)
    assert abs(res["y"][0] - y_expected) < 1e-12
    assert abs(res["ya"][0] - (y_expected + 1)) < 1e-12


class Guard(Component):
    """Asserts u > 0 for a model variable u."""

    u = Variable(0.0, "1", "guarded value")

    def assertions(self):
        return [Assertion(self.u, "u must stay positive")]


def test_assertion_violated_at_the_initial_point_is_an_error():
    m = pendulum(x=0.6, vx=0.0, y_start=guess(-0.8))
    m.guard = Guard()
    m.equation(Eq(m.guard.u, m.y + 0.5))        # -0.3 at the start
    with pytest.raises(InitializationError) as err:
        compile_model(m).simulate(t_end=1e-3)
    assert "guard: u must stay positive (at the initial point" in str(err.value)
