"""The error hierarchy (issue 9, item 2): every error a user can cause is an
AcausalError carrying where it happened, printed on one line; no bare
ValueError/KeyError is raised where a user can reach it."""
import pickle
import re
from pathlib import Path

import pytest

from acausal import errors
from acausal.errors import (AcausalError, DataError, SolverError, StructuralError,
                            UnknownNameError)

PACKAGE = Path(__file__).resolve().parents[2] / "acausal"


def test_every_error_class_is_an_acausal_error():
    classes = [c for c in vars(errors).values()
               if isinstance(c, type) and issubclass(c, BaseException)]
    assert len(classes) >= 14
    assert all(issubclass(c, AcausalError) for c in classes)
    from acausal.studies.calibrate import CalibrationError
    from acausal.data import DataError as DataError2
    from acausal.diagnose.run import DiagnosisError
    assert issubclass(CalibrationError, AcausalError) and issubclass(DiagnosisError, AcausalError)
    assert DataError2 is DataError


def test_payload_and_one_line():
    e = AcausalError("bad\nvalue", component="hook", variable="hook.Jh", file="m.py", line=7,
                     column="Jh", t=0.5)
    assert (e.component, e.variable, e.file, e.line, e.column, e.t) == (
        "hook", "hook.Jh", "m.py", 7, "Jh", 0.5)
    assert str(e) == "m.py:7: column 'Jh': bad; value"
    assert str(DataError("missing value", "a.csv", 3, "v")) == "a.csv:3: column 'v': missing value"
    assert str(AcausalError("m.py:7: already located", file="m.py", line=7)) == \
        "m.py:7: already located"
    s = StructuralError("singular:\n  - x (of a)\n  - y (of b)", excess=[1], missing=[2])
    assert str(s) == "singular: x (of a); y (of b)"


@pytest.mark.parametrize("err", [
    DataError("missing value", Path("a.csv"), 3, "v"),
    SolverError("failed", t=1.5, component="contact"),
    StructuralError("x", excess=[1], missing=[2], component="m"),
    UnknownNameError("no variable 'q'", variable="q"),
])
def test_errors_pickle_with_their_payload(err):
    back = pickle.loads(pickle.dumps(err))
    assert type(back) is type(err) and str(back) == str(err)
    assert back.__dict__ == err.__dict__


def test_unknown_name_is_still_a_key_error():
    assert issubclass(UnknownNameError, KeyError)


def test_no_bare_value_or_key_error_a_user_can_reach():
    """Acceptance: grep 'raise ValueError|raise KeyError' in acausal/ finds
    only lines commented as internal."""
    hits = []
    for path in PACKAGE.rglob("*.py"):
        for k, line in enumerate(path.read_text().splitlines(), start=1):
            if re.search(r"raise (ValueError|KeyError)\b", line) and "# internal" not in line:
                hits.append(f"{path.relative_to(PACKAGE.parent)}:{k}: {line.strip()}")
    assert not hits, "\n".join(hits)
