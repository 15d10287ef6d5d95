"""The located generic term compiles and simulates at every site of a
planar loop (models/examples/slider_crank.py: the crank pin, whose rate
is a state, and the rod pin, wrist and guide, whose rates are expressions
of the loop's states). Issue #24: the term once compiled only at the crank
pin (sympy's derivative of Abs of a loop velocity wrote re()/im()).
With zero weights the extended model must reproduce the model file's own
run (the term adds no force), and a force from its position part must
change it."""
import os

import numpy as np
import pytest

from acausal.diagnose.library import generic as gen
from acausal.diagnose.library.graph import ModelGraph
from acausal.diagnose.library.nominal import nominal_result
from acausal.modelfile import compile_file, load_model_file

HERE = os.path.dirname(os.path.abspath(__file__))
SLIDER_CRANK = os.path.join(HERE, "..", "..", "models", "examples", "slider_crank.py")


@pytest.mark.slow
def test_generic_term_compiles_at_every_site_of_a_planar_loop():
    path = os.path.abspath(SLIDER_CRANK)
    graph = ModelGraph(load_model_file(path).model, result=nominal_result(path))
    sites = gen.GENERIC.candidates(graph)
    assert {"crank_pin", "rod_pin", "wrist", "guide"} <= set(sites)
    mf0, cm0 = compile_file(path)
    t_end = min(mf0.experiment.t_end, 0.05)
    ref = cm0.simulate(t_end=t_end)
    for site in sites:
        mf, cm = gen.build_at(path, site, 9, 9)
        res = cm.simulate(t_end=t_end)
        assert np.max(np.abs(res["crank_pin.phi"] - np.interp(res.t, ref.t, ref["crank_pin.phi"]))
                      ) < 1e-6, site
        F = graph.typical(site)["force"]
        # a constant force over the knots' range (every position weight)
        push = cm.simulate(t_end=t_end, params={f"{gen.GENERIC.prefix}.a{i}": 0.5 * F
                                                for i in range(9)})
        moved = np.interp(ref.t, push.t, push["crank_pin.phi"]) - ref["crank_pin.phi"]
        assert np.max(np.abs(moved)) > 1e-6, site
