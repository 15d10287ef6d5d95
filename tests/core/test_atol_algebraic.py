"""simulate(..., atol_algebraic=...): a separate absolute tolerance for the
algebraic unknowns (see acausal.simulate.simulate; found with the two-stage
breaker variant, tests/models/test_breaker_variants.py)."""
import os

import numpy as np
import pytest

from acausal import Experiment
from acausal.modelfile import compile_file, run_file
from acausal.runtime.hybrid import _atol_vector
from acausal.mechanics.fourbar import fourbar_angles
from acausal.errors import UsageError

EXAMPLE = os.path.join(os.path.dirname(__file__), "..", "..", "models", "examples",
                       "fourbar.py")


def test_vector_puts_the_algebraic_tolerance_after_the_states():
    _, cm = compile_file(EXAMPLE)
    n, ns = len(cm.dae.y), cm.dae.n_states
    assert 0 < ns < n                       # main shaft, cam angles, torques: algebraic
    assert _atol_vector(cm, 1e-10, None) == 1e-10
    vec = _atol_vector(cm, 1e-10, 1e-3)
    assert vec.shape == (n,)
    assert np.all(vec[:ns] == 1e-10) and np.all(vec[ns:] == 1e-3)


@pytest.mark.parametrize("bad", [0.0, -1e-3, float("nan"), float("inf")])
def test_bad_value_is_refused(bad):
    _, cm = compile_file(EXAMPLE)
    with pytest.raises(UsageError, match="atol_algebraic"):
        cm.simulate(t_end=0.1, atol_algebraic=bad)


def test_experiment_passes_it_only_when_set():
    assert "atol_algebraic" not in Experiment().run_options()
    assert Experiment(atol_algebraic=1e-2).run_options()["atol_algebraic"] == 1e-2


def test_loose_algebraic_tolerance_keeps_the_solution_accurate():
    """The four-bar example (hook state, main shaft algebraic through the
    closure) with atol_algebraic = 1e-2 against 1e-12 on everything: main
    shaft angle at release against eq. 10 (measured 8.4e-12 rad against
    7e-16), energy of the lossless linkage (5e-10 against 1e-12)."""
    res, meas = run_file(EXAMPLE, atol_algebraic=1e-2)
    ra = np.radians(5.0)
    dth3 = fourbar_angles(ra)[1] - fourbar_angles(0.0)[1]
    assert abs(meas["theta3_at_release_rad"] - dth3) < 1e-10
    c = 7.0e4 * 0.091**2 + 2.4e5 * 0.091**2
    E = 0.5 * 0.00044 * res["hook.w"]**2 + 0.5 * 0.02 * res["shaft.w"]**2 \
        + 0.5 * c * (res["shaft.phi"] + 0.035)**2
    assert np.max(np.abs(E / E[0] - 1)) < 1e-8


def test_error_test_failure_suggests_the_algebraic_tolerance():
    """IDA's 'error test failed' (status -3) with the algebraic unknowns held
    to the states' atol: the message says what to try, with the option's
    name; with atol_algebraic given it does not repeat the advice."""
    from acausal.runtime.hybrid import _Run, _failure
    _, cm = compile_file(EXAMPLE)
    p = cm.param_vector({})
    d = cm.discrete_start()
    cb = cm.callbacks(p, d)
    n = len(cm.dae.y)
    sol = type("Sol", (), dict(t=np.array([0.0, 1e-3]), y=np.zeros((2, n)),
                               yp=np.zeros((2, n)), status=-3,
                               message="Error tests failed too many times, or reached "
                                       "min step size."))
    for atol, advised in [(1e-10, True), (_atol_vector(cm, 1e-10, 1e-2), False)]:
        run = _Run(cm, p, 0.0, 1.0, 1e-8, atol, None, 1000)
        err = _failure(run, cm, sol, cb)
        assert "IDA failed at t = 0.001 s" in str(err)
        assert ("atol_algebraic" in str(err)) is advised
