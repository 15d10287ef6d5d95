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


def torsion_oscillator(nominal, reversed_=False, phi0=0.3):
    """An inertia (J = 1) on a spring-damper (c = 400, d = 0) to a flange
    fixed at ``phi0``, started 1e-5 rad off it: ``phi_rel`` is the inertia's
    angle with an offset (the parameter ``wall.phi0``; reversed, with a
    sign), ``w_rel`` the derivative of that state, which the state row
    equates with ``inertia.w``."""
    from acausal.mechanics.rotational import Fixed as RFixed, Inertia, SpringDamper
    m = Model()
    m.wall = RFixed(phi0=phi0)
    m.inertia = Inertia(J=1.0, phi=phi0 + 1e-5, w=0.0)
    m.sd = SpringDamper(c=400.0, d=0.0)
    a, b = (m.sd.flange_b, m.sd.flange_a) if reversed_ else (m.sd.flange_a, m.sd.flange_b)
    m.connect(m.wall.flange, a)
    m.connect(b, m.inertia.flange_a)
    if nominal:
        m.sd.with_nominal(phi_rel=1e-5, w_rel=2e-4)
    return compile_model(m, cache=False)


@pytest.mark.parametrize("reversed_", [False, True])
def test_nominal_reaches_an_alias_with_offset_and_sign_and_a_state_derivative(reversed_):
    cm = torsion_oscillator(True, reversed_)
    slots = {names[0]: i for i, names in enumerate(cm.slot_names())}
    sign = -1.0 if reversed_ else 1.0
    assert cm.scaled_slot_of("sd.phi_rel") == (slots["inertia.phi"], sign)
    assert cm.scaled_slot_of("sd.w_rel") == (slots["inertia.w"], sign)
    vec = nominal_atol(cm, 1e-6, 1e-4)
    assert vec[slots["inertia.phi"]] == pytest.approx(1e-9)    # 1e-4 * 1e-5
    assert vec[slots["inertia.w"]] == pytest.approx(2e-8)      # 1e-4 * 2e-4


@pytest.mark.parametrize("backend", ["sundae", "compiled"])
def test_a_nominal_on_an_offset_alias_and_a_derivative_makes_them_accurate(backend):
    """The offset is the parameter ``wall.phi0``, here 0: the solver's
    unknown is the inertia's absolute angle, and IDA's weight
    ``rtol*(|y| + nominal)`` holds it to rtol of its own size, so a 1e-5
    oscillation about 0.3 rad is only as accurate as 0.3 rad allows (2e-4
    of its range at rtol 1e-6, measured) whatever its nominal: as in
    Modelica, the nominal scales the unknown the tool integrates."""
    errs = {}
    for nominal in (False, True):
        res = torsion_oscillator(nominal, phi0=0.0).simulate(t_end=2.0, rtol=1e-6, atol=1e-6,
                                                   backend=backend)
        e_phi = np.max(np.abs(res["sd.phi_rel"] - 1e-5 * np.cos(20 * res.t))) / 2e-5
        e_w = np.max(np.abs(res["sd.w_rel"] + 2e-4 * np.sin(20 * res.t))) / 4e-4
        errs[nominal] = max(e_phi, e_w)
    # of the range; measured: 6.2e-2 without, 1.6e-5 (w_rel; phi_rel 4.0e-6)
    # with the nominal values, on both backends
    assert errs[False] > 1e-2
    assert errs[True] < 5e-5


def test_a_parameter_gain_sets_no_nominal():
    """A variable that is a parameter times an unknown (an ideal gear's
    input angle, ``ratio*inertia.phi``) sets none: parameters are run-time
    values, and the nominal is fixed per compiled model (a numeric gain
    divides it: ``nominal_slots``)."""
    from acausal.mechanics.rotational import Fixed as RFixed, IdealGear, Inertia, SpringDamper
    m = Model()
    m.wall = RFixed()
    m.sd = SpringDamper(c=400.0, d=1.0)
    m.gear = IdealGear(ratio=4.0)
    m.inertia = Inertia(J=1.0, phi=1e-5, w=0.0)
    m.connect(m.wall.flange, m.sd.flange_a)
    m.connect(m.sd.flange_b, m.gear.flange_a)
    m.connect(m.gear.flange_b, m.inertia.flange_a)
    m.sd.with_nominal(phi_rel=4e-5)
    cm = compile_model(m, cache=False)
    assert cm.scaled_slot_of("sd.phi_rel") is None
    assert nominal_atol(cm, 1e-6, 1e-4) == 1e-6
