"""Choosing the backend: res.stats says which ran; an unknown name is one
clear AcausalError."""
import os

import pytest

from acausal.errors import AcausalError
from acausal.modelfile import compile_file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
OSC = os.path.join(ROOT, "models", "examples", "oscillator.py")


def test_stats_name_the_backend_and_unknown_names_are_refused():
    _, cm = compile_file(OSC)
    res = cm.simulate(t_end=0.01, backend="sundae")
    assert res.stats["backend"] == "sundae"
    with pytest.raises(AcausalError, match="unknown backend 'nope'"):
        cm.simulate(t_end=0.01, backend="nope")
