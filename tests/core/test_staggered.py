"""Staggered sensitivities along a finished run (:mod:`acausal.runtime.staggered`)
against closed forms and five-point central differences of tight runs
(independent of the sweep: the same simulator, no sensitivity equations), and
their limits (events: :class:`SweepUnavailable`; a fit then falls back to
differences).

The damped oscillator's closed form and its parameter derivatives are
sympy's (tests/core/test_sensitivities.py builds them independently of the
library). Measured (compiled backend, BDF order 3): relative error of d x /
d p 5e-6 at rtol 1e-10 and 5e-5 at rtol 1e-8; the slider-crank's slider
position and crank rate against five-point differences 1.6e-7 - 1e-6 (rtol
1e-10; order 2: 1.6e-5 - 6.9e-5).
"""
import os

import numpy as np
import pytest

from acausal import Model
from acausal.errors import ParameterError
from acausal.runtime import staggered
from acausal.runtime.backends import compiled_available
from acausal.runtime.model import compile_model
from acausal.runtime.staggered import SweepUnavailable
from acausal.studies.calibrate import SensitivityJacobian
from acausal.studies.differences import ForwardDifferences, SecantDifferences

from .test_sensitivities import _bouncing, _five_point, _oscillator, _oscillator_exact

pytestmark = pytest.mark.skipif(compiled_available() is not None,
                                reason="the staggered sweep needs the compiled backend")
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
NAMES = ["spring.c", "damper.d", "mass.m"]


@pytest.fixture(scope="module")
def oscillator():
    return compile_model(_oscillator())


@pytest.mark.parametrize("rtol, bound", [(1e-10, 2e-5), (1e-8, 2e-4)])
def test_oscillator_closed_form(oscillator, rtol, bound):
    """d x / d p against the closed form at output times between the steps;
    an observed variable (the spring force -c x) against its own closed
    form d/dc (-c x) = -(x + c dx/dc)."""
    grid = np.linspace(0.0, 0.6, 61)
    res = staggered.simulate(oscillator, {}, NAMES, t_end=0.6, rtol=rtol, atol=rtol * 1e-3,
                             output_times=grid)
    np.testing.assert_array_equal(res.t, grid)
    x, _ = _oscillator_exact("spring.c")
    assert np.max(np.abs(res["mass.s"] - x(grid))) < 1e3 * rtol
    for name in NAMES:
        exact = _oscillator_exact(name)[1](grid)
        err = np.max(np.abs(res.sensitivity("mass.s", name) - exact)) / np.max(np.abs(exact))
        assert err < bound, (name, err)
    dxdc = _oscillator_exact("spring.c")[1](grid)
    f_c = -(x(grid) + 100.0 * dxdc)
    got = res.sensitivity("spring.f", "spring.c")
    # (the force's sign follows the flange convention: compare magnitudes)
    assert np.max(np.abs(np.abs(got) - np.abs(f_c))) / np.max(np.abs(f_c)) < bound


def test_start_value_parameter():
    """A start value that is a parameter: d x / d x0 = x(t) / x0, from 1 at
    t = 0 (the implicit function theorem on the initial system); measured
    3.5e-6 off at most (the sweep's order-3 error at rtol 1e-10)."""
    model = Model()
    x0 = model.parameter("x0", 0.1, "m", "initial position")
    cm = compile_model(_oscillator(x0=x0, model=model))
    res = staggered.simulate(cm, {}, ["x0", "spring.c"], t_end=0.5, rtol=1e-10, atol=1e-13,
                             output_times=np.linspace(0, 0.5, 51))
    s = res.sensitivity("mass.s", "x0")
    assert s[0] == pytest.approx(1.0, abs=1e-9)
    np.testing.assert_allclose(s, res["mass.s"] / 0.1, rtol=0, atol=1e-5)


def test_slider_crank_against_central_differences():
    """A closed planar loop (algebraic unknowns: the index-reduced loop
    constraints): the slider's position and the crank's rate against
    five-point central differences of rtol 1e-11 runs."""
    from acausal.modelfile import compile_file
    mf, cm = compile_file(os.path.join(ROOT, "models", "examples", "slider_crank.py"))
    grid = np.linspace(0.0, 0.2, 41)
    kw = dict(t_end=0.2, rtol=1e-10, atol=1e-12, output_times=grid)
    names = ["slider.m", "rod_body.I", "flywheel.I"]
    res = staggered.simulate(cm, {}, names, **kw)
    tight = dict(kw, rtol=1e-11, atol=1e-13)
    for name in names:
        p0 = float(cm.param_vector()[cm.param_index(name)])
        h = 1e-3 * p0
        runs = {k: cm.simulate(params={name: p0 + k * h}, **tight) for k in (-2, -1, 1, 2)}
        for var in ("slider.x", "crank_pin.w"):
            fd = _five_point(runs, lambda r: np.interp(grid, r.t, r[var]), h)
            err = np.max(np.abs(res.sensitivity(var, name) - fd)) / np.max(np.abs(fd))
            assert err < 5e-6, (name, var, err)


def test_events_are_refused():
    """A run with events (the bouncing contact) is refused with the reason:
    the sweep carries no jumps at mode changes."""
    cm = _bouncing()
    with pytest.raises(SweepUnavailable, match="events"):
        staggered.simulate(cm, {}, ["contact.K"], t_end=0.03, rtol=1e-8, atol=1e-12)


def test_unknown_parameter_is_one_line(oscillator):
    with pytest.raises(ParameterError, match="no parameter 'spring.k'"):
        staggered.simulate(oscillator, {}, ["spring.k"], t_end=0.1)


def test_other_backend_is_refused(oscillator):
    with pytest.raises(SweepUnavailable, match="compiled backend"):
        staggered.simulate(oscillator, {}, NAMES, t_end=0.1, backend="sundae")


def test_jacobian_falls_back_to_the_secant_differences():
    """:class:`SensitivityJacobian` as the staggered fits use it
    (``give_up=SweepUnavailable``): the sensitivities where the sweep serves;
    where it cannot (SweepUnavailable) the secant differences from then on,
    without asking the sweep again."""
    A = np.array([[1.0, 2.0], [3.0, -1.0], [0.5, 0.25]])

    def fun(z):
        return A @ z + 0.1 * np.array([z[0] ** 2, z[1] ** 2, 0.0])

    def exact(z):
        return A + np.array([[0.2 * z[0], 0.0], [0.0, 0.2 * z[1]], [0.0, 0.0]])
    asked = []

    def jac_x(x):
        asked.append(x)
        if len(asked) > 1:
            raise SweepUnavailable("the run has 3 events")
        return exact(x)
    fd = ForwardDifferences(fun, 1e-6, np.array([np.inf, np.inf]))
    sj = SensitivityJacobian(jac_x, lambda z: z, lambda z: np.ones(2), SecantDifferences(fd),
                             give_up=SweepUnavailable)
    z = np.array([0.3, -0.2])
    np.testing.assert_allclose(sj.jac(z), exact(z))
    assert sj.fresh and sj.fallbacks == 0
    J = sj.jac(z + 0.1)
    np.testing.assert_allclose(J, exact(z + 0.1), atol=1e-5)
    assert sj.off and sj.fallbacks == 1
    sj.jac(z + 0.2)
    assert len(asked) == 2 and sj.fallbacks == 2


def test_nonlinear_parameter_takes_central_differences():
    """A parameter the residuals are not linear in (the stiffness bound to
    w^2) takes central differences in F_p, a linear one forward
    differences (:func:`staggered.linear_in`); d x / d w = 2 w d x / d c
    against the closed form."""
    model = Model()
    w = model.parameter("w", 10.0, "1/s", "natural frequency")
    cm = compile_model(_oscillator(c=w ** 2, model=model))
    assert list(staggered.linear_in(cm, ("w", "damper.d"))) == [False, True]
    grid = np.linspace(0.0, 0.6, 61)
    res = staggered.simulate(cm, {}, ["w", "damper.d"], t_end=0.6, rtol=1e-10, atol=1e-13,
                             output_times=grid)
    exact = 2 * 10.0 * _oscillator_exact("spring.c")[1](grid)
    err = np.max(np.abs(res.sensitivity("mass.s", "w") - exact)) / np.max(np.abs(exact))
    assert err < 2e-5, err
    exact = _oscillator_exact("damper.d")[1](grid)
    err = np.max(np.abs(res.sensitivity("mass.s", "damper.d") - exact)) / np.max(np.abs(exact))
    assert err < 2e-5, err


def test_parameter_near_zero_takes_steps_of_its_scale():
    """A parameter whose value is tiny but not zero (a fitted weight near 0):
    the difference steps follow the larger of its value and its typical
    magnitude, not the value alone (steps of 1e-15 of a unit are all
    rounding: they left the located weights' columns 2-6 % off). The
    stiffness 100 (1 + sin a) at a = 1e-9: d x / d a = 100 cos(a) d x / d c
    against the closed form, with and without the scale given."""
    import sympy as sp
    model = Model()
    a = model.parameter("a", 1e-9, "1", "stiffness modulation")
    cm = compile_model(_oscillator(c=100.0 * (1 + sp.sin(a)), model=model))
    assert list(staggered.linear_in(cm, ("a",))) == [False]
    grid = np.linspace(0.0, 0.6, 61)
    exact = 100.0 * np.cos(1e-9) * _oscillator_exact("spring.c")[1](grid)
    for scales in (None, [0.5]):
        res = staggered.simulate(cm, {}, ["a"], scales, t_end=0.6, rtol=1e-10, atol=1e-13,
                                 output_times=grid)
        err = np.max(np.abs(res.sensitivity("mass.s", "a") - exact)) / np.max(np.abs(exact))
        assert err < 2e-5, (scales, err)
