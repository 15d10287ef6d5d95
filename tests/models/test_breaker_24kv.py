"""The composed 24 kV breaker model against the report's own figures
(data/report/reported_results.csv, table2_thrt.csv) and against the
independent hand-written IDA reference (benchmarks/handwritten)."""
import csv
import os

import pytest

from acausal.modelfile import run_file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
MODEL = os.path.join(ROOT, "models", "breaker_24kv.py")


def measures(**params):
    return run_file(MODEL, params=params)[1]


def test_before_calibration_matches_report_fig7():
    m = measures(**{"contact.K": 8.3e9, "hook.bh": 0.0})
    assert abs(m["contact_period"] * 1e3 - 0.10) <= 0.01
    assert abs(m["thrt"] * 1e3 - 1.24) <= 0.06


def test_after_calibration_matches_report_fig10():
    m = measures(**{"contact.K": 6.25e8, "hook.bh": 0.219})   # the report's values
    assert abs(m["contact_period"] * 1e3 - 0.30) <= 0.02
    assert abs(m["thrt"] * 1e3 - 1.90) <= 0.02
    assert 3000 < m["peak_force"] < 5000          # Fig. 10 axis: about 4000 N


def test_model_file_defaults_are_the_projects_calibration():
    m = measures()
    assert abs(m["contact_period"] * 1e3 - 0.30) <= 0.02
    assert abs(m["thrt"] * 1e3 - 1.90) <= 0.02


def test_table2_calculated_column():
    with open(os.path.join(ROOT, "data", "report", "table2_thrt.csv")) as fh:
        rows = [r for r in csv.DictReader(line for line in fh if not line.startswith("#"))]
    assert len(rows) == 6
    for r in rows:
        m = measures(v_impact=float(r["impact_velocity_m_s"]))
        assert abs(m["thrt"] * 1e3 - float(r["calculated_thrt_ms"])) <= 0.1, r


def test_composed_model_equals_handwritten_reference():
    import sys
    sys.path.insert(0, os.path.join(ROOT, "benchmarks", "handwritten"))
    try:
        import breaker_sundae as ref
    except ImportError:  # pragma: no cover
        pytest.skip("reference not importable")
    r = ref.simulate(v_impact=3.8, K=6.25e8, bh=0.219)
    m = measures(**{"contact.K": 6.25e8, "hook.bh": 0.219})
    assert abs(m["thrt"] - r["thrt"]) < 2e-6
    assert abs(m["contact_period"] - r["contact_period"]) < 2e-6
