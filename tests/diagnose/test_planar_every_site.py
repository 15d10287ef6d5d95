"""Every hypothesis, and the located generic term, at every candidate site
of a planar loop (issue 24, item 4): the planar breaker
(models/breaker_24kv_planar.py) and a spring-returned planar slider-crank
with sites of every kind (tests/diagnose/planar_slider_crank.py). At a
loop joint the site's rate is an expression of the loop's states, and
sympy's own derivative of |v| there wrote re()/im() terms the code
printers cannot print (fixed in acausal/lang/fastdiff.py).

Default tier: each candidate's parameters are finite and it applies to a
fresh model; a planar body (not a site of a 1-D hypothesis) is refused in
one line. Slow tier: each candidate compiles (one compile each, cached on
disk: about 5-15 s each on 2 loaded cores, 50-70 candidates a model)."""
import copy
import os

import numpy as np
import pytest

from acausal import ModelError
from acausal.diagnose.library.generic import GENERIC
from acausal.diagnose.library.graph import ModelGraph
from acausal.diagnose.library.hypotheses import HYPOTHESES, build_extended
from acausal.modelfile import load_model_file

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
SLIDER_CRANK = os.path.join(HERE, "planar_slider_crank.py")
PLANAR_BREAKER = os.path.join(ROOT, "models", "breaker_24kv_planar.py")
ALL = list(HYPOTHESES.values()) + [GENERIC]


def _candidates(path):
    graph = ModelGraph.from_file(path)
    return graph, [(h, loc) for h in ALL for loc in h.candidates(graph)]


@pytest.mark.parametrize("path", [SLIDER_CRANK, pytest.param(PLANAR_BREAKER, marks=pytest.mark.slow)],
                         ids=["slider_crank", "planar_breaker"])   # the breaker's 6 s: slow tier
def test_every_candidate_applies_at_every_site(path):
    graph, cands = _candidates(path)
    joints = {s.path for s in graph.joints}
    kinds = {h.id for h, _ in cands}
    # every joint-site hypothesis is offered at every joint of the loop
    for h in ALL:
        if h.site_kinds == ("joint",):
            assert set(h.candidates(graph)) == joints, h.id
    assert {"stick_slip_friction", "viscous_damping", "generic_force"} <= kinds
    loaded = load_model_file(path).model
    generic_done = False
    for h, loc in cands:
        if h is GENERIC:     # its 26 hat terms cost ~5 s of sympy a site: one site here
            if generic_done:
                continue
            generic_done = True
        specs = h.params(graph, loc)
        assert specs, (h.id, loc)
        for s in specs:
            assert np.isfinite([s.low, s.high, s.scale, s.initial]).all(), (h.id, loc, s)
            assert s.low <= s.initial <= s.high, (h.id, loc, s)
        model = copy.deepcopy(loaded)          # a fresh model (a load costs ~1 s)
        h.apply(model, loc)
        assert h.prefix in model.children()


def test_a_planar_body_is_refused_in_one_line():
    graph, _ = _candidates(SLIDER_CRANK)
    assert "slider" in {s.path for s in graph.bodies}
    with pytest.raises(ModelError, match="slider: a planar Body is not a site of a 1-D "
                                         "hypothesis.*joint sites: crank_pin, rod_pin, wrist, "
                                         "guide"):
        HYPOTHESES["quadratic_damping"].params(graph, "slider")


@pytest.mark.slow
@pytest.mark.parametrize("path", [SLIDER_CRANK, pytest.param(PLANAR_BREAKER, marks=pytest.mark.slow)],
                         ids=["slider_crank", "planar_breaker"])   # the breaker's 6 s: slow tier
def test_every_candidate_compiles_at_every_site(path):
    _, cands = _candidates(path)
    failed = []
    for h, loc in cands:
        try:
            build_extended(path, h.id, loc, h=h)
        except Exception as exc:  # noqa: BLE001 - collected and reported below
            failed.append(f"{h.id} at {loc}: {type(exc).__name__}: {exc}")
    assert not failed, "\n".join(failed)
