"""The compiled backend's C for the hybrid loop between segments
(acausal/backends/compiled.py ``CCallbacks``, reinit.c): the residual, root
functions, Jacobians and observed variables equal the generated Python's;
the consistent re-initialisation and the initialisation's Newton give the
Python implementation's point to round-off, and hand over to it where they
must (a non-finite point). Skipped without a C compiler."""
import os

import numpy as np
import pytest

from acausal.runtime.backends import compiled_available, make_solver
from acausal.runtime.initialize import _newton, initial_point, reinitialize
from acausal.modelfile import compile_file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
# the two examples the default-tier agreement tests build too (stick_slip has
# algebraic unknowns)
pytestmark = pytest.mark.skipif(compiled_available() is not None,
                                reason=f"compiled backend unavailable: {compiled_available()}")
OPTS = dict(rtol=1e-8, atol=1e-11, max_step=0.0, max_num_steps=1000)


@pytest.fixture(scope="module", params=["hertz_impact", "stick_slip"])
def model(request):
    _, cm = compile_file(os.path.join(ROOT, "models", "examples", request.param + ".py"))
    p, d = cm.param_vector({}), cm.discrete_start()
    py = cm.callbacks(p, d)
    c = make_solver("compiled", cm, p, OPTS).serve(cm, p, d)
    assert c.reinit is not None and c is not py
    return cm, p, d, py, c


def _points(cm, py):
    p, d = cm.param_vector({}), cm.discrete_start()
    y, yp = initial_point(cm, p, d, py, 0.0)
    rng = np.random.default_rng(3)
    return [(0.0, y, yp), (0.01, y * (1 + 0.1 * rng.standard_normal(len(y))) + 1e-3,
                           yp + 0.1 * rng.standard_normal(len(yp)))]


def test_c_callbacks_equal_the_python(model):
    cm, _, _, py, c = model
    n = len(cm.dae.y)
    for t, y, yp in _points(cm, py):
        r1, r2 = np.zeros(n), np.zeros(n)
        py[0](t, y, yp, r1), c[0](t, y, yp, r2)
        np.testing.assert_allclose(r2, r1, rtol=1e-12, atol=1e-12 * np.max(np.abs(r1)))
        g1, g2 = np.zeros(cm.n_roots), np.zeros(cm.n_roots)
        py[2](t, y, yp, g1), c[2](t, y, yp, g2)
        np.testing.assert_allclose(g2, g1, rtol=1e-12, atol=1e-15)
        J = [np.zeros((n, n)) for _ in range(4)]
        py[3](t, y, yp, J[0], J[1]), c[3](t, y, yp, J[2], J[3])
        np.testing.assert_allclose(J[2], J[0], rtol=1e-12, atol=1e-12 * np.max(np.abs(J[0])))
        np.testing.assert_allclose(J[3], J[1], rtol=1e-12, atol=1e-12 * np.max(np.abs(J[1])))
        o1, o2 = np.asarray(py[4](t, y, yp)), c[4](t, y, yp)
        np.testing.assert_allclose(o2, o1, rtol=1e-12, atol=1e-12 * np.max(np.abs(o1)))


def test_initial_point_and_reinitialisation_in_c(model):
    cm, p, d, py, c = model
    taken = []
    newton = c.init_newton
    c.init_newton = lambda *a: taken.append(newton(*a)) or taken[-1]
    try:
        y1, yp1 = initial_point(cm, p, d, c, 0.0)
    finally:
        c.init_newton = newton
    y2, yp2 = initial_point(cm, p, d, py, 0.0)
    assert taken and taken[0] is not NotImplemented and taken[0] is not None
    scale = max(np.max(np.abs(y2)), 1.0)
    np.testing.assert_allclose(y1, y2, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(yp1, yp2, rtol=0, atol=1e-9 * max(np.max(np.abs(yp2)), 1.0))
    # re-initialisation from a disturbed point: algebraic unknowns and rates
    t, y, yp = _points(cm, py)[1]
    assert c.reinit(t, y, yp) is not None
    a, b = reinitialize(cm, c, t, y, yp), reinitialize(cm, py, t, y, yp)
    for u, v in zip(a, b):
        np.testing.assert_allclose(u, v, rtol=1e-9, atol=1e-9 * max(np.max(np.abs(v)), 1.0))


def test_c_hands_over_at_a_non_finite_point(model):
    """A NaN start: the C re-initialisation declines (the Python one then
    runs); the C Newton returns None exactly where the Python one does."""
    cm, p, d, py, c = model
    n, ns = len(cm.dae.y), cm.dae.n_states
    y, yp = np.full(n, np.nan), np.zeros(n)
    assert c.reinit(0.0, y, yp) is None
    z0 = np.full(n + ns, np.nan)
    fixed = cm.fixed_starts(p)
    assert c.init_newton(0.0, z0, [], fixed) is None

    def fun(z):
        r = np.zeros(n)
        py[0](0.0, z[:n], np.r_[z[n:], np.zeros(n - ns)], r)
        return r
    assert _newton(fun, None, z0) is None
