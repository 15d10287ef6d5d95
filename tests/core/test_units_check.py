"""Every equation is checked for dimensional consistency at build
(acausal/compiler/units.py): planted wrong units are caught with one line
naming the component, the equation and both units; the whole library and
every model file pass."""
import glob
import importlib
import inspect
import os
import pkgutil
import sys
import warnings

import pytest
import sympy as sp

from acausal import compile_model
from acausal.compiler.flatten import flatten
from acausal.compiler.units import check_units, dimension, show
from acausal.errors import ConnectionError_, ModelError
from acausal.lang import Component, Eq, Model, Parameter, Variable, der
from acausal.mechanics.partials import PartialCompliant
from acausal.mechanics.translational import Fixed, Mass

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def _on_a_mass(element):
    m = Model()
    m.ground = Fixed()
    m.element = element
    m.mass = Mass(m=1.0, s=0.1, v=0.0)
    m.connect(m.ground.flange, m.element.flange_a)
    m.connect(m.element.flange_b, m.mass.flange)
    return m


class SpringWrongUnit(PartialCompliant):
    c = Parameter(100.0, "N", "stiffness, declared with a wrong unit")

    def equations(self):
        return [Eq(self.f, self.c * self.s_rel)]


class RateWrongUnit(PartialCompliant):
    d = Parameter(2.0, "N*s/m", "damping")
    x = Variable(0.0, "m", "a state")

    def equations(self):
        return [Eq(der(self.x), self.f), Eq(self.f, self.d * der(self.s_rel))]


class AngleOfALength(PartialCompliant):
    c = Parameter(100.0, "N", "force amplitude")

    def equations(self):
        return [Eq(self.f, self.c * sp.sin(self.s_rel))]


class ModesAndLiterals(PartialCompliant):
    """A residual that is a different equation in each mode (stuck: the
    relative acceleration is zero; sliding: a force balance), and literal
    numbers beside dimensional terms: both are consistent."""
    F = Parameter(3.0, "N", "sliding force")
    d = Parameter(2.0, "N*s/m", "damping")
    v = Variable(0.0, "m/s", "relative speed")
    stuck = Parameter(0.0, "1", "1 when stuck")

    def equations(self):
        return [Eq(self.v, der(self.s_rel)),
                Eq(self.f, self.d * self.v + sp.Piecewise((self.F, self.v > 0),
                                                          (-self.F, True))),
                Eq(0, sp.Piecewise((der(self.v), sp.Eq(self.stuck, 1)), (self.f - self.F, True))),
                Eq(self.v, der(self.s_rel) + 2 * self.v - self.v * 2 + 0)]


def test_a_wrong_parameter_unit_is_named_with_both_units():
    with pytest.raises(ModelError) as exc:
        compile_model(_on_a_mass(SpringWrongUnit()), cache=False)
    msg = str(exc.value)
    assert msg.startswith("units: ") and "\n" not in msg
    assert "element (SpringWrongUnit)" in msg
    assert "[N]" in msg and "[N*m]" in msg
    assert "element.c*element.s_rel" in msg


def test_a_derivative_has_its_variable_unit_per_second():
    with pytest.raises(ModelError) as exc:
        check_units(flatten(_on_a_mass(RateWrongUnit())))
    assert "[m/s]" in str(exc.value) and "[N]" in str(exc.value)


def test_a_transcendental_function_takes_a_dimensionless_argument():
    with pytest.raises(ModelError) as exc:
        check_units(flatten(_on_a_mass(AngleOfALength())))
    assert "[m]" in str(exc.value) and "[1]" in str(exc.value)


def test_a_relation_compares_like_with_like():
    class Switch(PartialCompliant):
        F = Parameter(3.0, "N", "force")

        def equations(self):
            return [Eq(self.f, sp.Piecewise((self.F, self.s_rel > self.F), (0, True)))]
    with pytest.raises(ModelError) as exc:
        check_units(flatten(_on_a_mass(Switch())))
    assert "[m]" in str(exc.value) and "[N]" in str(exc.value)


def test_modes_and_literal_numbers_are_consistent():
    check_units(flatten(_on_a_mass(ModesAndLiterals())))


def test_dimensions_of_usual_units():
    assert show(dimension("kg*m/s^2")) == "N"
    assert show(dimension("N*m/rad")) == "N*m"    # an angle is dimensionless, as in SI
    assert dimension("N/m^gamma") is None          # unreadable: no unit, never rejected
    assert show(dimension("m^3/s")) == "m^3/s"


def _library_components():
    import acausal.mechanics
    packages = [acausal.mechanics]
    try:
        packages.append(importlib.import_module("acausal.blocks"))
    except ImportError:
        pass
    seen = {}
    for pkg in packages:
        for info in pkgutil.walk_packages(pkg.__path__, pkg.__name__ + "."):
            mod = importlib.import_module(info.name)
            for name, cls in vars(mod).items():
                if (inspect.isclass(cls) and issubclass(cls, Component)
                        and cls.__module__ == mod.__name__ and not name.startswith(("_", "Partial"))):
                    seen[f"{mod.__name__}.{name}"] = cls
    return seen


def test_every_library_component_is_consistent():
    checked = 0
    for path, cls in sorted(_library_components().items()):
        try:
            comp = cls()
        except (TypeError, ModelError):
            continue          # needs arguments: covered by the model files below
        # an input must have a source: bind each to 0 (MSL's modifier) to flatten it alone
        comp.set(**{n: 0 for n, c in comp.connectors().items()
                    if getattr(c, "causality", None) == "input"})
        m = Model()
        m.c = comp
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                flat = flatten(m)
            except ConnectionError_:
                continue      # a block whose input must be connected: the model files
            check_units(flat)
        checked += 1
    assert checked >= 40


@pytest.mark.parametrize("path", sorted(glob.glob(os.path.join(ROOT, "models", "**", "*.py"),
                                               recursive=True)))
def test_every_model_file_is_consistent(path):
    from acausal.modelfile import load_model_file
    sys.path.insert(0, os.path.dirname(path))
    try:
        mf = load_model_file(path)
    finally:
        sys.path.pop(0)
    check_units(flatten(mf.model))
