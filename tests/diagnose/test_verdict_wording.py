"""The named verdict's sentence says on what the name rests: "within the
held-out threshold" only when the plain held-out error is within it; a name
rescued by the whitened and directional parts (verdict.rescued) says its
plain error exceeds the threshold (a kept cam friction + drag run said
"5.02 ... within the held-out threshold" against a threshold of 1.022)."""
from types import SimpleNamespace

from acausal.diagnose.report.markdown import verdict

THRESHOLD = dict(rms=1.022, level=0.01, n=6006, k=5, experiments=3, sentence="...")


def _summary(before, after, caveats=()):
    gain = dict(before=dict(heldout=before, train=1.23), after=dict(heldout=after, train=1.0))
    v = dict(kind="named", reasons=[], caveats=list(caveats), undetermined=[],
             heldout_threshold=THRESHOLD, laws=[])
    return dict(gain=gain, verdict=v, cause="stribeck_friction", location="cam",
                equivalent_causes=[], cause_class=None)


def test_a_name_within_the_threshold_says_so():
    text = verdict(SimpleNamespace(tied=()), _summary(10.1, 1.01))
    assert "1.01 floor units (train 1.23 -> 1), within the held-out threshold." in text


def test_a_rescued_name_says_its_plain_error_exceeds_the_threshold():
    note = ("its plain held-out error, 5.02 floors, exceeds 1.022 (the threshold assumes "
            "every experiment carries an equal share): without one experiment the others "
            "determine a parameter only loosely")
    text = verdict(SimpleNamespace(tied=()),
                   _summary(10.1, 5.02, [dict(code="heldout_one_experiment", text=note)]))
    assert "within the held-out threshold" not in text
    assert "5.02 floor units (train 1.23 -> 1); its plain held-out error, 5.02 floors, " \
           "exceeds 1.022" in text
