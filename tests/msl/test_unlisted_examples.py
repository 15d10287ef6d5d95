"""MSL mechanics examples that issue #23 did not list, ported afterwards
with the library alone as a new user would (models/msl/Rotational:
ElasticBearing, CoupledClutches, LossyGearDemo1, LossyGearDemo3,
OneWayClutchDisengaged; models/msl/Translational: PreLoad), against the
Modelica Association's reference results (MSL 4.0.0, Dymola 2020x, DASSL
at rtol 1e-6; data/msl_reference/README.md): csv-compare's tube, 1e-3 of
each signal's range and of the time span (tests/msl/harness.py), every
compared signal (modes and start flags included), at MSL's own tolerance
rtol 1e-6, on both backends (compiled: the slow tier).

Skipped where the reference files are absent. Measured (2026-11-27): the
smallest tube tolerance each example passes at and its worst signal, the
same on both backends: ElasticBearing 4.8e-5 (springDamper.w_rel; 1.3e-3,
outside the tube, before `nominal` reached a state's derivative),
CoupledClutches 8.0e-6 (clutch1.phi_rel), LossyGearDemo1 1.2e-5
(Inertia2.phi), LossyGearDemo3 9.8e-9 (Inertia2.phi), OneWayClutchDisengaged
8.0e-5 (inertiaIn.phi), PreLoad 1.8e-5 (outerContactA.v_rel).
"""
import math

import numpy as np
import pytest

from acausal.data.tube import tube_compare
from tests.msl.harness import assert_matches, load_reference, reference_or_skip
from tests.msl.test_friction_examples import model_file, simulate

EXAMPLES = [
    "Rotational.ElasticBearing", "Rotational.CoupledClutches", "Rotational.LossyGearDemo1",
    "Rotational.LossyGearDemo3", "Rotational.OneWayClutchDisengaged", "Translational.PreLoad",
]


@pytest.mark.parametrize("backend", ["sundae", pytest.param("compiled", marks=pytest.mark.slow)])
@pytest.mark.parametrize("name", EXAMPLES)
def test_unlisted_example_inside_the_reference_tube(name, backend):
    reference_or_skip(name)
    mf, res = simulate(name, backend)
    assert mf.experiment.rtol == 1e-6          # MSL's own tolerance
    assert_matches(name, res)


def test_every_unlisted_example_has_a_model_file_with_the_library_alone():
    """No component class and no function is defined in a model file."""
    for name in EXAMPLES:
        with open(model_file(name)) as fh:
            text = fh.read()
        assert "class " not in text and "def " not in text, name


def _needed_tol(t_ref, y_ref, t, y):
    """The smallest tube tolerance (relative, in time and value) the signal
    passes at."""
    lo, hi = math.log(1e-12), math.log(1e-3)
    if tube_compare(t_ref, y_ref, t, y, tol=1e-12).passed:
        return 1e-12
    for _ in range(30):
        mid = (lo + hi) / 2
        if tube_compare(t_ref, y_ref, t, y, tol=math.exp(mid)).passed:
            hi = mid
        else:
            lo = mid
    return math.exp(hi)


def test_elastic_bearing_housing_speed_is_held_by_its_nominal():
    """springDamper.w_rel (below 1e-3 rad/s) carries MSL's nominal 1e-4: it
    is the derivative of the state phi_rel, which the state row equates
    with housing.w; the nominal must reach that unknown. Measured: 4.8e-5
    of the tube with it, 1.3e-3 (outside) at the run's atol 1e-8 alone."""
    name = "Rotational.ElasticBearing"
    reference_or_skip(name)
    _, res = simulate(name, "sundae")
    t, ref = load_reference(name)
    assert _needed_tol(t, ref["springDamper.w_rel"], res.t, res["springDamper.w_rel"]) < 2e-4


def test_coupled_clutches_mode_sequence():
    """clutch2 closes at T2 = 0.4 s and clutch3 at T3 = 0.9 s (time events),
    and every mode change comes within 1e-5 s of the reference's."""
    name = "Rotational.CoupledClutches"
    reference_or_skip(name)
    _, res = simulate(name, "sundae")
    t, ref = load_reference(name)
    for c in ("clutch1", "clutch2", "clutch3"):
        y = ref[f"{c}.mode"]
        jumps = t[1:][np.diff(y) != 0]
        ours = res.t[1:][np.diff(res[f"{c}.mode"]) != 0]
        assert len(ours) == len(jumps), c
        assert np.max(np.abs(ours - jumps)) < 1e-5, c
