"""One definition of the weighted residuals (acausal.studies.residuals) for
the calibration and the diagnosis: the same numbers from both, one checked
``subset``, the instrument floor as the weight."""
import numpy as np
import pytest

from acausal.data import Dataset, Instrument, MeasuredExperiment, Trace
from acausal.diagnose.stages import fitting
from acausal.errors import CalibrationError
from acausal.modelfile import compile_file
from acausal.studies import calibrate as cal
from acausal.studies import residuals as rs

MODEL = '''
from acausal import Experiment, Measure, Model
from acausal.mechanics.translational import Damper, Fixed, Mass, Spring

model = Model()
model.mass = Mass(m=1.0, s=0.1, v=0.0)
model.spring = Spring(c=100.0, s_rel0=0.0)
model.damper = Damper(d=2.0)
model.ground = Fixed()
model.connect(model.ground.flange, model.spring.flange_a)
model.connect(model.spring.flange_b, model.mass.flange)
model.connect(model.ground.flange, model.damper.flange_a)
model.connect(model.damper.flange_b, model.mass.flange)
experiment = Experiment(t_end=0.5, rtol=1e-9, atol=1e-12, output_step=0.01)
measures = {"s_end": Measure(lambda r: r["mass.s"][-1], "m")}
'''
T = np.linspace(0.0, 0.5, 26)


def _oscillator(c, d, s0=0.1):
    """x(t) of the damped oscillator (m = 1, closed form), and x at 0.5 s."""
    zw = d / 2
    wd = np.sqrt(c - zw ** 2)

    def x(t):
        return s0 * np.exp(-zw * t) * (np.cos(wd * t) + zw / wd * np.sin(wd * t))
    return x(T), float(x(0.5))


def _model(tmp_path):
    path = tmp_path / "osc.py"
    path.write_text(MODEL)
    return compile_file(str(path))


def _dataset(with_measures=True):
    exps = []
    for name, s0 in (("a", 0.1), ("b", 0.05)):
        x, end = _oscillator(120.0, 3.0, s0)
        measures = {"s_end": end} if with_measures else {}
        exps.append(MeasuredExperiment(name, {"mass.s": s0}, measures, Trace(T, {"mass.s": x})))
    return Dataset(None, exps, {"mass.s": Instrument("mass.s", 1e-5, 1e-5)})


def test_calibration_and_diagnosis_residuals_are_the_same_numbers(tmp_path):
    """With a measure in every experiment both simulate each experiment on
    the dense grid: the weighted residuals (and the sensitivity Jacobians)
    are identical, entry by entry, with the same labels; the raw residuals
    are the weighted ones times the floor (s_end has no instrument entry:
    its weight is 1e-3 of its measured value)."""
    model, ds = _model(tmp_path), _dataset()
    params = {"spring.c": 110.0, "damper.d": 2.5}
    vec, labels, raw = cal.residual_vector(model, ds, params)
    got = fitting.residuals_of(model, ds, params)
    np.testing.assert_array_equal(got.vector, vec)
    assert got.labels == labels
    assert labels[0] == ("a", "s_end") and labels[1:27] == [("a", "mass.s")] * 26
    floor = ds.instrument["mass.s"].floor()
    np.testing.assert_allclose(raw["b"]["mass.s"], vec[28:] * floor, rtol=1e-12)
    assert raw["a"]["s_end"] == pytest.approx(vec[0] * 1e-3 * abs(ds.experiments[0].measures[
        "s_end"]), rel=1e-12)
    names = ["spring.c", "damper.d"]
    r1, J1 = cal.residual_jacobian(model, ds, params, names)
    r2, J2 = rs.weighted_jacobian(model, ds, params, names, fitting.FitRuns())
    np.testing.assert_array_equal(r1, r2)      # (the augmented runs take other steps:
    np.testing.assert_allclose(r1, vec, rtol=0, atol=1e-4)   # the same to the solver's error)
    np.testing.assert_array_equal(J1, J2)
    assert J1.shape == (len(vec), 2)


def test_a_trace_only_experiment_is_simulated_to_its_last_sample_by_the_diagnosis(tmp_path):
    """Without measures the diagnosis's runs stop at the last sample and
    output at the sample times: the residuals agree with the calibration's
    (dense grid) to far below the floor."""
    model, ds = _model(tmp_path), _dataset(with_measures=False)
    params = {"spring.c": 110.0, "damper.d": 2.5}
    vec = cal.residual_vector(model, ds, params)[0]
    got = fitting.residuals_of(model, ds, params).vector
    assert got.size == vec.size == 52
    assert np.max(np.abs(got - vec)) < 1e-3
    assert np.max(np.abs(vec)) > 10.0          # the residuals themselves are not small


def test_subset_checks_names_and_keeps_their_order():
    ds = _dataset()
    assert [e.name for e in rs.subset(ds, ["b", "a"]).experiments] == ["b", "a"]
    assert rs.subset(ds, ["b"]).instrument is ds.instrument
    assert cal.subset is rs.subset
    with pytest.raises(CalibrationError) as err:
        rs.subset(ds, ["a", "c"])
    msg = str(err.value)
    assert "no experiment 'c'" in msg and "a, b" in msg and "\n" not in msg


def test_sigma_is_the_floor_else_a_thousandth_of_the_values():
    ds = _dataset()
    assert rs.sigma(ds, "mass.s", [1.0]) == pytest.approx(np.hypot(1e-5, 1e-5 / np.sqrt(12)))
    assert rs.sigma(ds, "s_end", np.array([-2.0, 0.5])) == pytest.approx(2e-3)
    assert rs.sigma(ds, "s_end", [0.0]) == pytest.approx(1e-15)


def test_signals_keeps_only_the_named_ones(tmp_path):
    model, ds = _model(tmp_path), _dataset()
    got = rs.weighted_residuals(model, ds, {}, cal.ExperimentRuns(), signals=["s_end"])
    assert got.labels == [("a", "s_end"), ("b", "s_end")]
    assert set(got.raw["a"]) == {"s_end"}
