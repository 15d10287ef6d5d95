"""The dead-centre measure of acausal.mechanics.planar.deadcentre on
configurations with known angles (no simulation: the slow test in
tests/models/test_planar_examples.py drives a four-bar into its dead
centre)."""
import math

import pytest
import sympy as sp

from acausal.mechanics.planar.deadcentre import minor_sine


def rev(x, y):
    return ("r", sp.Float(x), sp.Float(y))


def slider(angle):
    return ("p", sp.Float(math.cos(angle)), sp.Float(math.sin(angle)))


@pytest.mark.parametrize("bend_deg", [0.0, 1.0, 2.9, 30.0, 90.0])
@pytest.mark.parametrize("order", [(0, 1, 2), (1, 0, 2), (2, 1, 0), (1, 2, 0)])
def test_three_pins_give_the_sine_of_the_bend_at_the_middle_one(bend_deg, order):
    """Pins A, C (middle), D with links 0.06 and 0.08 bent by bend_deg at C:
    |sine| = sin(bend) whatever the order of the three columns."""
    b = math.radians(bend_deg)
    pts = [(0.0, 0.0), (0.06, 0.0), (0.06 + 0.08 * math.cos(b), 0.08 * math.sin(b))]
    cols = [rev(*pts[k]) for k in order]
    assert abs(abs(float(minor_sine(cols))) - math.sin(b)) < 1e-12


def test_slider_crank_dead_centre_is_the_rod_across_the_axis():
    """Pins P (crank end) and W (wrist), slider along angle 0.3: the minor
    vanishes when the rod P -> W is at right angles to the axis."""
    ax = 0.3
    for rod_deg, want in ((90.0, 0.0), (60.0, math.sin(math.radians(30.0))), (0.0, 1.0)):
        r = ax + math.radians(rod_deg)
        cols = [rev(0.1, 0.2), rev(0.1 + 0.05 * math.cos(r), 0.2 + 0.05 * math.sin(r)),
                slider(ax)]
        assert abs(abs(float(minor_sine(cols))) - want) < 1e-12
    assert minor_sine([slider(0.0), slider(1.0), slider(2.0)]) is None
