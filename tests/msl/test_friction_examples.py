"""The MSL examples with friction elements, ported with the library alone
(models/msl/Translational: Friction, Brake; models/msl/Rotational:
Friction, OneWayClutch, LossyGearDemo2, SimpleGearShift), against the
Modelica Association's reference results (MSL 4.0.0, Dymola, DASSL at rtol
1e-6): csv-compare's tube, 1e-3 of each signal's range and of the time
span (tests/msl/harness.py), every compared signal (modes and start flags
included), on both backends (compiled: the slow tier), at the model files'
tolerance, MSL's own rtol 1e-6.

Skipped where the reference files are absent (see data/msl_reference/README.md).
Measured (2026-11-27): the smallest tube tolerance each example passes at,
its worst signal, the same on both backends: Translational.Friction 6e-5
(stop1.v), Translational.Brake 1e-11, Rotational.Friction 6e-6
(spring.w_rel), Rotational.OneWayClutch 9.3e-5 (inertiaIn.phi),
Rotational.LossyGearDemo2 9.4e-6 (Inertia2.w), Rotational.SimpleGearShift
1.6e-6 (clutch.phi_rel).
"""
import math
import os

import numpy as np
import pytest

from acausal import compile_model
from acausal.data.tube import tube_compare
from acausal.modelfile import load_model_file
from tests.msl.harness import assert_matches, load_reference, reference_or_skip

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

EXAMPLES = [
    "Translational.Friction", "Translational.Brake",
    "Rotational.Friction", "Rotational.OneWayClutch", "Rotational.LossyGearDemo2",
    "Rotational.SimpleGearShift",
]

_compiled = {}
_results = {}


def model_file(name):
    lib, example = name.split(".")
    return os.path.join(ROOT, "models", "msl", lib, f"{example}.py")


def simulate(name, backend):
    """The example's model file simulated with its experiment on ``backend``
    (once per test session)."""
    if (name, backend) not in _results:
        if name not in _compiled:
            mf = load_model_file(model_file(name))
            _compiled[name] = (mf, compile_model(mf.model))
        mf, cm = _compiled[name]
        res = cm.simulate(backend=backend, **mf.experiment.run_options())
        assert res.status == "ok", res.message
        _results[name, backend] = (mf, res)
    return _results[name, backend]


# the compiled backend builds a C library per example (2-4 s each on a cold
# cache): in the slow tier; the sundae runs are the default tier's
@pytest.mark.parametrize("backend", ["sundae", pytest.param("compiled", marks=pytest.mark.slow)])
@pytest.mark.parametrize("name", EXAMPLES)
def test_example_inside_the_reference_tube(name, backend):
    reference_or_skip(name)
    mf, res = simulate(name, backend)
    assert mf.experiment.rtol == 1e-6          # MSL's own tolerance
    # the backend asked for is the one that ran (OneWayClutch and
    # Translational.Friction once fell back to sundae: C without <stdbool.h>)
    assert "backend_fallback" not in res.stats, res.stats["backend_fallback"]
    assert_matches(name, res)


def test_every_listed_example_has_a_model_file_with_the_library_alone():
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


@pytest.mark.parametrize("name, bound", [
    ("Translational.Friction", 2e-4), ("Rotational.Friction", 2e-5),
    ("Rotational.LossyGearDemo2", 3e-5),
])
def test_continuous_signals_well_inside_the_tube(name, bound):
    """Not only inside the 1e-3 tube: the positions and velocities (not the
    modes) pass a tube a few times the measured one, so a regression of
    the integration shows before it reaches the acceptance tube."""
    reference_or_skip(name)
    _, res = simulate(name, "sundae")
    t, ref = load_reference(name)
    worst = max(_needed_tol(t, y, res.t, res[s]) for s, y in ref.items()
                if not s.endswith(("mode", "startForward", "startBackward")))
    assert worst < bound


def test_translational_friction_stop2_hits_the_left_stop_and_resets():
    """stop2 starts at -5 m/s, hits its left stop (s = smin + L/2 = -0.4 m)
    at 0.0605970 s (the reference: 0.0605969541 s), its velocity is 0 there
    and it breaks away forward at the same instant (75 N > f0_max)."""
    _, res = simulate("Translational.Friction", "sundae")
    hit = [t for t, n in res.events if n == "stop2.stop_at_smin"]
    assert len(hit) == 1 and abs(hit[0] - 0.0605969541) < 2e-7
    k = np.searchsorted(res.t, hit[0])
    assert abs(res["stop2.s"][k] - (-0.4)) < 1e-12
    after = np.nonzero(res.t == hit[0])[0][-1]
    assert res["stop2.v"][after] == 0.0 and res["stop2.mode"][after] == 1


def test_lossy_gear_demo2_mode_sequence():
    """The gear and the bearing stick together twice (the holding torques
    are then not determined): the machine keeps the gear locked and starts
    the bearing; the mode changes come at the reference's instants."""
    _, res = simulate("Rotational.LossyGearDemo2", "sundae")
    gear = [(t, n) for t, n in res.events if n.startswith("gear.")]
    ref = {"slide_stop": [0.06359110458471218, 0.3083068461006042],
           "break_forward": [0.2303740158850011], "break_backward": [5.9e-11, 0.4562426604846289]}
    for what, times in ref.items():
        ours = [t for t, n in gear if n == "gear." + what]
        assert len(ours) == len(times), what
        assert np.max(np.abs(np.array(ours) - times)) < 1e-6, what
