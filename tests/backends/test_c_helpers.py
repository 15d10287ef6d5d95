"""The generated C's inline max and min (``codegen_c.HELPERS``) give C99's
fmax/fmin of the C library bit for bit, NaN and signed zeros included, so
that printing them in place of libm's calls (which gcc does not inline at
-O1) leaves every trajectory as it was; and a model's max/min prints as
those helpers, nested as sympy nests fmax."""
import ctypes
import itertools
import math
import os
import struct

import pytest
import sympy as sp

from acausal.compiler import codegen_c

VALUES = (0.0, -0.0, 1.0, -1.0, 2.5, 1e-300, -1e-300, 5e-324, math.inf, -math.inf, math.nan)


def _bits(x):
    return struct.pack("<d", x)


@pytest.fixture(scope="module")
def helpers(c_library):
    lib = c_library("#include <math.h>\n" + "\n".join(codegen_c.HELPERS) + """
double h_max(double a, double b) { return acs_fmax(a, b); }
double h_min(double a, double b) { return acs_fmin(a, b); }
double h_heaviside(double x) { return acs_heaviside(x); }
double c_max(double a, double b) { return fmax(a, b); }
double c_min(double a, double b) { return fmin(a, b); }
""")
    for name in ("h_max", "h_min", "c_max", "c_min"):
        f = getattr(lib, name)
        f.restype, f.argtypes = ctypes.c_double, [ctypes.c_double, ctypes.c_double]
    lib.h_heaviside.restype, lib.h_heaviside.argtypes = ctypes.c_double, [ctypes.c_double]
    return lib


@pytest.mark.parametrize("which", ["max", "min"])
def test_helpers_equal_the_c_library(helpers, which):
    mine, libm = getattr(helpers, f"h_{which}"), getattr(helpers, f"c_{which}")
    for a, b in itertools.product(VALUES, repeat=2):
        got, want = mine(a, b), libm(a, b)
        if math.isnan(want):
            assert math.isnan(got), (which, a, b)
        elif a == 0 and b == 0:
            # 0 and -0: C99 (F.9.9.2) leaves the sign open; glibc on x86-64
            # gives the second, as the helpers do
            assert got == 0, (which, a, b, got)
        else:
            assert _bits(got) == _bits(want), (which, a, b, got, want)


def test_heaviside_is_one_half_at_zero(helpers):
    assert [helpers.h_heaviside(x) for x in (-1.0, -0.0, 0.0, 1e-300, 2.0)] == \
        [0.0, 0.5, 0.5, 1.0, 1.0]


def test_max_and_min_print_as_the_helpers_nested():
    x, y, z = sp.symbols("x y z", real=True)
    p = codegen_c._Printer()
    assert p.doprint(sp.Max(x, y, evaluate=False)) == "acs_fmax(x, y)"
    text = p.doprint(sp.Min(x, y, z, evaluate=False))
    assert text.count("acs_fmin(") == 2 and "fmin(" not in text.replace("acs_fmin(", "")
    assert "fmax(" not in p.doprint(sp.Max(x, y) + 1).replace("acs_fmax(", "")


def test_cold_functions_give_the_optimised_values(c_library):
    """acs_jacs, acs_fixjac and acs_observe are compiled at -O0 (ACS_COLD);
    acs_jacs and acs_observe give the same bytes as at -O1 (-DACS_COLD=), at
    random points of the breaker (events, a four-bar, contact: many
    primitives). (With -ffast-math on the second, this fails.)"""
    import numpy as np

    from acausal.modelfile import compile_file
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    _, cm = compile_file(os.path.join(root, "models", "breaker_24kv.py"))
    src = codegen_c.generate_c(cm)
    assert all(f"ACS_COLD void {name}(" in src.text for name in codegen_c.COLD)
    libs = [c_library(src.text, flags) for flags in ([], ["-DACS_COLD="])]
    n, n_obs = src.n, libs[0].acs_n_observed()
    pd = np.concatenate([cm.param_vector(), np.asarray(cm.discrete_start(), float)])
    rng = np.random.default_rng(3)
    for _ in range(20):
        y, yp = rng.normal(size=n), rng.normal(size=n)
        outs = []
        for lib in libs:
            Jy, Jyp, o = np.zeros(n * n), np.zeros(n * n), np.zeros(n_obs)
            args = (ctypes.c_double(0.3), y.ctypes.data_as(ctypes.c_void_p),
                    yp.ctypes.data_as(ctypes.c_void_p), pd.ctypes.data_as(ctypes.c_void_p))
            lib.acs_jacs(*args, Jy.ctypes.data_as(ctypes.c_void_p),
                         Jyp.ctypes.data_as(ctypes.c_void_p))
            lib.acs_observe(*args, o.ctypes.data_as(ctypes.c_void_p))
            outs.append((Jy.tobytes(), Jyp.tobytes(), o.tobytes()))
        assert outs[0] == outs[1]
