"""nominal (Modelica's attribute) sets the absolute tolerance of a
variable's solver unknown to rtol*|nominal| on both backends: a variable
of 1e-5 scale is integrated to the relative accuracy asked, where a fixed
absolute tolerance of the order of its size is not."""
import numpy as np
import pytest

from acausal import Model, compile_model
from acausal.errors import ParameterError
from acausal.lang import Variable
from acausal.mechanics.translational import Fixed, Mass, Spring
from acausal.runtime.nominal import nominal_atol


def oscillator(nominal):
    m = Model()
    m.mass = Mass(m=1.0, s=1e-5, v=0.0)      # amplitude 1e-5 m at 20 rad/s
    m.spring = Spring(c=400.0)
    m.wall = Fixed()
    m.connect(m.wall.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.mass.flange)
    if nominal:
        m.mass.with_nominal(s=1e-5, v=2e-4)
    return compile_model(m, cache=False)


@pytest.mark.parametrize("backend", ["sundae", "compiled"])
def test_a_small_variable_is_accurate_with_its_nominal(backend):
    errs = {}
    for nominal in (False, True):
        res = oscillator(nominal).simulate(t_end=2.0, rtol=1e-6, atol=1e-6, backend=backend)
        exact = 1e-5 * np.cos(20 * res.t)
        errs[nominal] = np.max(np.abs(res["mass.s"] - exact)) / 2e-5   # of the range
    # measured: 6.2e-2 of the range without, 4.0e-6 with the nominal value
    assert errs[False] > 1e-2
    assert errs[True] < 2e-5


def test_the_rule_and_what_overrides_it():
    cm = oscillator(True)
    slots = {names[0]: i for i, names in enumerate(cm.slot_names())}
    vec = nominal_atol(cm, 1e-6, 1e-4)
    assert vec[slots["mass.s"]] == pytest.approx(1e-9)        # 1e-4 * 1e-5
    assert vec[slots["mass.v"]] == pytest.approx(2e-8)
    # an explicit atol for a variable wins over its nominal
    vec = nominal_atol(cm, np.full(len(cm.dae.y), 1e-6), 1e-4, {"mass.s": 3e-7})
    assert vec[slots["mass.s"]] == 1e-6 and vec[slots["mass.v"]] == pytest.approx(2e-8)
    # no nominal anywhere: atol untouched
    assert nominal_atol(oscillator(False), 1e-6, 1e-4) == 1e-6


def test_bad_nominal_values_are_named():
    with pytest.raises(ParameterError, match="nominal value of mass.v must be a non-zero"):
        m = Model()
        m.mass = Mass(m=1.0)
        m.mass.with_nominal(v=0.0)
    with pytest.raises(ParameterError, match="has no variable 'm'"):
        Mass(m=1.0).with_nominal(m=1.0)
    with pytest.raises(ParameterError, match="nominal value of speed"):
        Variable(0.0, "m/s", "speed", nominal="big")
