"""Stand-ins for the located generic term's inputs, shared by the unit
tests of :mod:`acausal.diagnose.stages.locate` (node ranking, resolution,
verdict): no model, no simulation."""
from acausal.diagnose.stages import locate as L

RANGES = (-1.2, 1.2, -3.0, 3.0)   # knot ranges (x, v) of the synthetic term


def term(node, held, aicc=100.0, fitted="output error"):
    """A located term at ``node`` with held-out error ``held``."""
    return L.Term(node, (node,), 100.0, aicc, held, RANGES, {}, {}, fitted=fitted)


class Ranking:
    """The ranking stage's result as the located stage reads it: nothing named."""
    best = named = None
    heldout0 = 30.0


class Decision:
    """The decision stage's result: the nominal's AICc and the noise scale."""
    a0 = 1e4
    c_hat = 20.0
