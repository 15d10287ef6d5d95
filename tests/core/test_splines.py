"""``lang.splines.HatSum``: a linear spline as one expression node, evaluated
on x's interval only. Its value and slope against the written-out sum of
hats (an independent formula), its derivatives against differences, its
array and C forms against the scalar one bit for bit, and a geared drive
with a spline torque against a scipy integration that interpolates with
``numpy.interp`` (no code of acausal)."""
import ctypes
import math
import os

import numpy as np
import pytest
import sympy as sp

from acausal.compiler import codegen_c
from acausal.lang.fastdiff import diff
from acausal.lang.splines import (HatSlope, HatSum, hat_slope, hat_slope_array, hat_sum,
                                  hat_sum_array)

RNG = np.random.default_rng(7)
LO, HI, N = -1.3, 2.1, 9
W = list(RNG.normal(size=N))
H = (HI - LO) / (N - 1)


def written_out(x, lo, hi, w):
    """sum_i w_i max(0, 1 - |x - c_i|/h), term by term."""
    n = len(w)
    h = (hi - lo) / (n - 1)
    return sum(wi * max(0.0, 1.0 - abs(x - (lo + i * h)) / h) for i, wi in enumerate(w))


def test_value_is_the_sum_of_hats():
    xs = np.concatenate([RNG.uniform(LO - 2 * H, HI + 2 * H, 4000), LO + H * np.arange(-2, N + 2)])
    err = max(abs(hat_sum(x, LO, HI, W) - written_out(x, LO, HI, W)) for x in xs)
    assert err < 1e-14 * max(map(abs, W)) * 10
    # one spacing outside the knots and beyond: zero; at a NaN: zero (max(0, NaN) = 0)
    assert hat_sum(LO - H, LO, HI, W) == 0.0 and hat_sum(HI + 1.5 * H, LO, HI, W) == 0.0
    assert hat_sum(math.nan, LO, HI, W) == 0.0
    # the knots' values are the weights
    assert np.allclose([hat_sum(LO + i * H, LO, HI, W) for i in range(N)], W, atol=1e-14)


def test_slope_is_the_sums_derivative_and_the_mean_at_a_knot():
    xs = RNG.uniform(LO - 2 * H, HI + 2 * H, 4000)
    for x in xs:
        u = (x - LO) / H
        if abs(u - round(u)) < 1e-6:
            continue
        d = 1e-7 * H
        fd = (written_out(x + d, LO, HI, W) - written_out(x - d, LO, HI, W)) / (2 * d)
        assert abs(hat_slope(x, LO, HI, W) - fd) < 1e-6 * max(map(abs, W)) / H
    w = [1.0, 3.0, 2.0, 5.0]          # knots at 0, 1, 2, 3
    assert hat_slope(1.0, 0.0, 3.0, w) == (2.0 - 1.0) / 2      # (w2 - w0) / 2h
    assert hat_slope(0.0, 0.0, 3.0, w) == (3.0 - 0.0) / 2      # beyond the ends: 0
    assert hat_slope(3.0, 0.0, 3.0, w) == (0.0 - 2.0) / 2
    assert hat_slope(0.5, 0.0, 3.0, w) == 2.0 and hat_slope(-0.5, 0.0, 3.0, w) == 1.0


def test_arrays_give_the_scalar_values_bit_for_bit():
    xs = np.concatenate([RNG.uniform(LO - 2 * H, HI + 2 * H, 3000), LO + H * np.arange(-2, N + 2),
                         [math.nan, math.inf, -math.inf]])
    assert np.array_equal(hat_sum_array(xs, LO, HI, W), [hat_sum(x, LO, HI, W) for x in xs])
    assert np.array_equal(hat_slope_array(xs, LO, HI, W), [hat_slope(x, LO, HI, W) for x in xs])
    # weights that vary by row: element by element
    rows = RNG.normal(size=(N, xs.size))
    got = hat_sum_array(xs, LO, HI, list(rows))
    assert np.array_equal(got, [hat_sum(x, LO, HI, list(rows[:, k])) for k, x in enumerate(xs)])


def test_symbolic_derivatives():
    x, lo, hi = sp.symbols("x lo hi", real=True)
    w = sp.symbols(f"w0:{N}", real=True)
    e = HatSum(x, lo, hi, *w)
    assert isinstance(diff(e, x), HatSlope)
    assert diff(diff(e, x), x) == 0
    at = {x: 0.37, lo: LO, hi: HI, **dict(zip(w, W))}
    for k in (0, 3, N - 1):            # d/dw_k: the k-th hat
        hat = [0.0] * N
        hat[k] = 1.0
        assert float(diff(e, w[k]).subs(at)) == pytest.approx(hat_sum(0.37, LO, HI, hat), abs=1e-14)
    for s, v in ((lo, LO), (hi, HI)):  # d/dlo, d/dhi: central differences
        d = 1e-6
        moved = [dict(at), dict(at)]
        moved[0][s], moved[1][s] = v + d, v - d
        fd = (float(e.subs(moved[0])) - float(e.subs(moved[1]))) / (2 * d)
        assert float(diff(e, s).subs(at)) == pytest.approx(fd, rel=1e-6, abs=1e-9)
    # numbers in, a number out
    assert float(HatSum(0.37, LO, HI, *W)) == hat_sum(0.37, LO, HI, W)
    # too few weights: one clear line
    from acausal.errors import ModelError
    with pytest.raises(ModelError, match="at least 2 weights, got 4 arguments"):
        HatSum(x, lo, hi, w[0])


@pytest.fixture(scope="module")
def c_lib(c_library):
    lib = c_library("#include <math.h>\n" + "\n".join(codegen_c.HELPERS) + """
double s_sum(double x, double lo, double hi, int n, const double* w) { return acs_hatsum(x, lo, hi, n, w); }
double s_slope(double x, double lo, double hi, int n, const double* w) { return acs_hatslope(x, lo, hi, n, w); }
""")
    for f in (lib.s_sum, lib.s_slope):
        f.restype = ctypes.c_double
        f.argtypes = [ctypes.c_double] * 3 + [ctypes.c_int, ctypes.POINTER(ctypes.c_double)]
    return lib


def test_c_gives_the_python_values_bit_for_bit(c_lib):
    arr = (ctypes.c_double * N)(*W)
    xs = np.concatenate([RNG.uniform(LO - 2 * H, HI + 2 * H, 3000), LO + H * np.arange(-2, N + 2),
                         [math.nan]])
    for x in xs:
        assert c_lib.s_sum(x, LO, HI, N, arr) == hat_sum(x, LO, HI, W)
        assert c_lib.s_slope(x, LO, HI, N, arr) == hat_slope(x, LO, HI, W)


def test_printed_with_its_weights_read_in_place():
    x = sp.Symbol("y0", real=True)
    p = sp.symbols("p0:12", real=True)
    pr = codegen_c._Printer()
    assert pr.doprint(HatSum(x, p[0], p[1], *p[2:12])) == "acs_hatsum(y0, p0, p1, 10, pd + 2)"
    out = pr.doprint(HatSlope(x, p[0], p[1], p[5], p[3], 2.0))
    assert out.startswith("acs_hatslope(y0, p0, p1, 3, (const double[]){p5, p3, 2")


def test_a_spline_torque_against_scipy():
    """The geared drive with a spline torque on the motor (the located term's
    model, its velocity part zero) against M q'' = N tau - c q - d q'
    + N f(N q), f by numpy.interp, integrated by scipy's DOP853."""
    from scipy.integrate import solve_ivp

    from acausal.diagnose.library import generic as gen
    from tests.diagnose.independent import gear_truth as gt
    n_x, n_v = 17, 9
    x_lo, x_hi = -0.5, 3.5
    a = 0.02 * np.sin(np.linspace(0.0, 3 * np.pi, n_x)) + 0.01 * RNG.normal(size=n_x)
    vals = {**dict(gen.range_values((x_lo, x_hi, -50.0, 50.0))),
            **{f"gen.a{i}": float(v) for i, v in enumerate(a)},
            **{f"gen.b{j}": 0.0 for j in range(n_v)}}
    path = os.path.join(os.path.dirname(gt.__file__), gt.MODEL)
    _, cm = gen.build_at(path, "motor", n_x, n_v)
    cm = cm.with_defaults(vals)
    knots = np.linspace(x_lo, x_hi, n_x)
    M = gt.J_L + gt.N ** 2 * gt.J_M
    tau = 0.1

    def rhs(t, z):
        q, w = z
        f = np.interp(gt.N * q, knots, a)
        return [w, (gt.N * tau - gt.C * q - gt.D * w + gt.N * f) / M]

    t = np.linspace(0.0, 1.5, 1501)
    ref = solve_ivp(rhs, (0.0, 1.5), [0.0, 0.0], method="DOP853", rtol=1e-12, atol=1e-14,
                    t_eval=t)
    assert (gt.N * ref.y[0]).min() > x_lo and (gt.N * ref.y[0]).max() < x_hi   # on the knots
    span = np.ptp(ref.y[0])
    for backend in ("compiled", "sundae"):
        res = cm.simulate(t_end=1.5, params={"tau_m": tau}, rtol=1e-10, atol=1e-12,
                          output_times=t, backend=backend)
        got = np.interp(t, res.t, res["load.phi"])
        assert np.max(np.abs(got - ref.y[0])) < 1e-6 * span, backend
