"""A model whose every variable is explicit (all motion prescribed) has
nothing for IDA to integrate: compiling it must raise a clear ModelError
(it used to fail with an IndentationError in the generated code)."""
import pytest
import sympy as sp

from acausal import Model, ModelError, compile_model, time
from acausal.mechanics.translational import Mass, Position


def test_fully_prescribed_model_gives_a_clear_error():
    model = Model()
    model.drive = Position(s=0.1 * sp.sin(3 * time))
    model.mass = Mass(m=2.0)
    model.connect(model.drive.flange, model.mass.flange)
    with pytest.raises(ModelError, match="nothing to integrate"):
        compile_model(model)
