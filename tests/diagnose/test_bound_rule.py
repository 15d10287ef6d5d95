"""A cause whose own parameter ran to a bound of its range (other than its
neutral value) is not named (stages._bound_reasons); a shape parameter
that ran to a bound left its physical range and is reported as a law that
may stand in for a mixture (stages.verdict.law_notes, issue 24)."""
from types import SimpleNamespace as NS

from acausal.diagnose.problem import Candidate, Param
from acausal.diagnose.stages.chain import _bound_reasons
from acausal.diagnose.stages.verdict import law_notes


def _best(c, n):
    params = (Param("hyp_pd.c", 0.0, 0.0, 1.26e-3, 4e-4, 0.0),
              Param("hyp_pd.n", 2.0, 1.0, 3.0, 0.5, 2.0))
    return NS(candidate=Candidate("power_drag", "mass", params),
              fit=NS(values={"hyp_pd.c": c, "hyp_pd.n": n}, ci95={}))


def test_a_parameter_at_its_far_bound_makes_the_evidence_weak():
    assert len(_bound_reasons(_best(1.26e-3, 2.07))) == 1
    assert _bound_reasons(_best(1.2e-3, 2.07)) == []
    assert _bound_reasons(_best(0.0, 2.0)) == []        # neutral: not a bound hit


def test_a_shape_parameter_at_its_bound_is_a_law_out_of_its_range():
    assert _bound_reasons(_best(1e-3, 3.0)) == []       # not an amplitude: a law note
    (note,) = law_notes(_best(1e-3, 3.0))
    assert note.at_bound and note.parameter == "hyp_pd.n" and "mixture of laws" in note.text
    assert law_notes(_best(1e-3, 2.07)) == []           # no interval: nothing excluded
