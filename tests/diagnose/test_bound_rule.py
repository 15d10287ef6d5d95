"""A cause whose own parameter ran to a bound of its range (other than its
neutral value) is not named (stages._bound_reasons)."""
from types import SimpleNamespace as NS

from acausal.diagnose.problem import Param
from acausal.diagnose.stages.chain import _bound_reasons


def _best(c, n):
    params = (Param("hyp_pd.c", 0.0, 0.0, 1.26e-3, 4e-4, 0.0),
              Param("hyp_pd.n", 2.0, 1.0, 3.0, 0.5, 2.0))
    return NS(candidate=NS(params=params), fit=NS(values={"hyp_pd.c": c, "hyp_pd.n": n}))


def test_a_parameter_at_its_far_bound_makes_the_evidence_weak():
    assert len(_bound_reasons(_best(1.26e-3, 2.07))) == 1
    assert "hyp_pd.n" in _bound_reasons(_best(1e-3, 3.0))[0]
    assert _bound_reasons(_best(1.2e-3, 2.07)) == []
    assert _bound_reasons(_best(0.0, 2.0)) == []        # neutral: not a bound hit
