"""Least squares with the Jacobian from forward sensitivities
(``acausal.calibrate.least_squares(jacobian=...)``): the same optimum as
with finite differences, from fewer simulations, and the result says which
Jacobian ran."""
import numpy as np
import pytest

from acausal.studies import calibrate as cal
from acausal.data import Dataset, MeasuredExperiment, Instrument, Trace
from acausal.modelfile import compile_file

MODEL = '''
from acausal import Experiment, Model
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
experiment = Experiment(t_end=0.6, rtol=1e-9, atol=1e-12, output_step=0.01)
'''


def _data(tmp_path):
    """A position trace of the oscillator with c = 120 N/m, d = 3 N*s/m
    (closed form, not a simulation), rounded to 1e-5 m."""
    path = tmp_path / "osc.py"
    path.write_text(MODEL)
    t = np.linspace(0.0, 0.6, 61)
    c, d, m = 120.0, 3.0, 1.0
    zw = d / (2 * m)
    wd = np.sqrt(c / m - zw ** 2)
    x = 0.1 * np.exp(-zw * t) * (np.cos(wd * t) + zw / wd * np.sin(wd * t))
    x = np.round(x / 1e-5) * 1e-5
    exp = MeasuredExperiment("run1", {}, trace=Trace(t, {"mass.s": x}))
    return compile_file(str(path)), Dataset(None, [exp], {"mass.s": Instrument("mass.s", 1e-5)})


def test_exact_jacobian_fit_matches_differences(tmp_path):
    model, ds = _data(tmp_path)
    names = ["spring.c", "damper.d"]
    exact = cal.least_squares(model, ds, names)
    assert exact.jacobian == "sensitivities"
    fd = cal.least_squares(model, ds, names, jacobian="differences")
    assert fd.jacobian == "finite differences"
    for n, true in zip(names, (120.0, 3.0)):
        assert exact.values[n] == pytest.approx(true, rel=1e-3)
        assert exact.values[n] == pytest.approx(fd.values[n], rel=1e-6)
        lo, hi = exact.ci95[n]
        flo, fhi = fd.ci95[n]
        assert lo == pytest.approx(flo, rel=1e-3) and hi == pytest.approx(fhi, rel=1e-3)
    assert exact.n_sim < fd.n_sim


def test_jacobian_against_central_differences(tmp_path):
    model, ds = _data(tmp_path)
    x = {"spring.c": 110.0, "damper.d": 2.5}
    r, J = cal.residual_jacobian(model, ds, x, list(x))
    r0 = cal.residual_vector(model, ds, x)[0]
    np.testing.assert_allclose(r, r0, rtol=0, atol=1e-3 * np.max(np.abs(r0)))
    for k, n in enumerate(x):
        h = 1e-4 * x[n]
        up, dn = dict(x), dict(x)
        up[n] += h
        dn[n] -= h
        fd = (cal.residual_vector(model, ds, up)[0]
              - cal.residual_vector(model, ds, dn)[0]) / (2 * h)
        assert np.max(np.abs(J[:, k] - fd)) < 1e-4 * np.max(np.abs(fd)), n




HERTZ = '''
from acausal import Experiment, Measure, Model
from acausal.mechanics.contact import Contact, contact_period
from acausal.mechanics.translational import Fixed, Mass

model = Model()
model.mass = Mass(m=0.1, s=-1e-4, v=1.0)
model.wall = Fixed(s0=0.0)
model.contact = Contact(K=1e9, gamma=1.5, e=1.0, gap=0.0, delta_tol=0.0)
model.connect(model.mass.flange, model.contact.flange_a)
model.connect(model.contact.flange_b, model.wall.flange)
experiment = Experiment(t_end=6e-4, rtol=1e-10, atol=1e-14, output_step=0)
measures = {"contact_period": Measure(lambda res: contact_period(res, "contact"), "s")}
'''


@pytest.mark.slow
def test_measures_take_the_exact_jacobian(tmp_path):
    """Contact periods of a Hertz impact at two impact speeds (closed form
    with K = 1.3e9 N/m^1.5): K fitted with the Jacobian from the measure's
    sensitivity (the event times it reads) as with differences."""
    from scipy.special import beta
    path = tmp_path / "hertz.py"
    path.write_text(HERTZ)
    model = compile_file(str(path))

    def period(v0, K=1.3e9, m=0.1):
        return 0.8 * beta(0.4, 0.5) * (5 * m * v0 ** 2 / (4 * K)) ** 0.4 / v0
    exps = [MeasuredExperiment(f"v{v}", {"mass.v": v}, {"contact_period": period(v)})
            for v in (1.0, 2.0)]
    ds = Dataset(None, exps, {"contact_period": Instrument("contact_period", 1e-9)})
    exact = cal.least_squares(model, ds, ["contact.K"])
    fd = cal.least_squares(model, ds, ["contact.K"], jacobian="differences")
    assert exact.jacobian == "sensitivities" and fd.jacobian == "finite differences"
    assert exact.values["contact.K"] == pytest.approx(1.3e9, rel=1e-6)
    assert exact.values["contact.K"] == pytest.approx(fd.values["contact.K"], rel=1e-7)
    r, J = cal.residual_jacobian(model, ds, {"contact.K": 1.3e9}, ["contact.K"])
    # d T / dK = -(2/5) T / K, weighted by the 1e-9 s reading step / sqrt(12)
    sigma = 1e-9 / np.sqrt(12.0)
    np.testing.assert_allclose(J[:, 0], [-0.4 * period(v) / 1.3e9 / sigma for v in (1.0, 2.0)],
                               rtol=1e-7)


def test_diagnosis_fit_with_the_sensitivity_jacobian(tmp_path):
    """The diagnosis's fit (acausal.diagnose.fitting.fit) with
    jacobian="sensitivities": the same optimum as with differences, and its
    Jacobian against the differences' at the optimum."""
    from acausal.diagnose.problem import Param
    from acausal.diagnose.stages import fitting
    model, ds = _data(tmp_path)
    names = ["spring.c", "damper.d"]
    params = (Param("spring.c", 100.0, 10.0, 1e3, 100.0, 100.0),
              Param("damper.d", 2.0, 0.0, 20.0, 2.0, 2.0))
    a = fitting.fit(model, ds, params,
                    refinement=fitting.Refinement(jacobian="sensitivities"))
    b = fitting.fit(model, ds, params)
    assert a.ok and b.ok
    for n in names:
        assert a.values[n] == pytest.approx(b.values[n], rel=1e-6)
    np.testing.assert_allclose(a.jacobian, b.jacobian, rtol=0,
                               atol=1e-3 * np.max(np.abs(b.jacobian)))
    assert a.n_sim < b.n_sim
