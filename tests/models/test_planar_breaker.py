"""The breaker with its four-bar from planar parts against the 1-D breaker
(models/breaker_24kv.py, closed-form FourBar): THRT and contact period at the
report's six impact velocities (Table 2)."""
import csv
import os

import pytest

from acausal.modelfile import run_file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PLANAR = os.path.join(ROOT, "models", "breaker_24kv_planar.py")
BASE = os.path.join(ROOT, "models", "breaker_24kv.py")


def velocities():
    with open(os.path.join(ROOT, "data", "report", "table2_thrt.csv")) as fh:
        rows = list(csv.DictReader(line for line in fh if not line.startswith("#")))
    return [float(r["impact_velocity_m_s"]) for r in rows]


def compare(v):
    planar = run_file(PLANAR, params={"v_impact": v})[1]
    base = run_file(BASE, params={"v_impact": v})[1]
    assert abs(planar["thrt"] - base["thrt"]) < 1e-6
    assert abs(planar["contact_period"] - base["contact_period"]) < 1e-6
    return planar


def test_planar_breaker_thrt_equals_1d_at_3_8():
    m = compare(3.8)
    assert abs(m["thrt"] * 1e3 - 1.90) <= 0.02            # Table 2 / Fig. 10


@pytest.mark.slow
@pytest.mark.parametrize("v", velocities())
def test_planar_breaker_thrt_equals_1d_at_table2_velocities(v):
    compare(v)
