"""Profile-likelihood intervals (acausal.profile) against closed forms and a
brute-force grid."""
import numpy as np
import pytest
from scipy import stats

from acausal.studies.profile import Confidence, Coordinates, Tracing, profile_likelihood, threshold

Q95 = stats.chi2.ppf(0.95, 1)


def _quadratic_data(seed=3, sigma=0.2):
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 2.0, 15)
    X = np.column_stack([np.ones_like(t), t, t ** 2])
    y = X @ np.array([1.0, -0.5, 0.3]) + sigma * rng.standard_normal(t.size)
    return X, y, sigma


@pytest.mark.parametrize("index", [0, 1, 2])
def test_linear_model_profile_equals_closed_form_wald(index):
    X, y, sigma = _quadratic_data()
    beta = np.linalg.lstsq(X, y, rcond=None)[0]
    sd = sigma * np.sqrt(np.diag(np.linalg.inv(X.T @ X)))
    p = profile_likelihood(lambda b: (X @ b - y) / sigma, beta, index)
    half = np.sqrt(Q95) * sd[index]
    assert p.lower == pytest.approx(beta[index] - half, abs=1e-4 * half)
    assert p.upper == pytest.approx(beta[index] + half, abs=1e-4 * half)
    assert p.wald[0] == pytest.approx(beta[index] - half, abs=1e-4 * half)
    assert not (p.open_lower or p.open_upper)
    assert p.trustworthy
    # every traced point lies on the exact quadratic profile
    expected = ((p.values - beta[index]) / sd[index]) ** 2
    np.testing.assert_allclose(p.delta_chi2, expected, atol=1e-6)


def test_linear_model_with_estimated_noise_is_the_student_t_interval():
    X, y, _ = _quadratic_data(seed=5)
    n, k = X.shape
    beta = np.linalg.lstsq(X, y, rcond=None)[0]
    r = X @ beta - y
    s2 = float(r @ r) / (n - k)        # unit weights: the noise is estimated
    sd = np.sqrt(s2 * np.diag(np.linalg.inv(X.T @ X)))
    p = profile_likelihood(lambda b: X @ b - y, beta, 1, confidence=Confidence(dispersion=s2, dof=n - k))
    half = stats.t.ppf(0.975, n - k) * sd[1]
    assert p.threshold == pytest.approx(threshold(0.95, s2, n - k))
    assert (p.lower, p.upper) == pytest.approx((beta[1] - half, beta[1] + half), abs=1e-4 * half)


def _decay(sigma, seed=1):
    rng = np.random.default_rng(seed)
    t = np.linspace(0.0, 1.0, 8)
    y = 1.0 * np.exp(-3.0 * t) + sigma * rng.standard_normal(t.size)
    return t, y


def _brute_force_interval(t, y, sigma):
    """k on a fine grid, the amplitude at its exact optimum for each k."""
    ks = np.linspace(0.5, 12.0, 230001)
    E = np.exp(-np.outer(ks, t))
    amp = (E @ y) / np.einsum("ij,ij->i", E, E)
    chi = (((amp[:, None] * E - y) / sigma) ** 2).sum(axis=1)
    inside = ks[chi - chi.min() <= Q95]
    return inside.min(), inside.max(), ks[1] - ks[0]


def test_exponential_rate_gives_asymmetric_interval_matching_a_grid():
    from scipy import optimize
    t, y = _decay(0.15)
    sigma = 0.15

    def res(x):
        return (x[0] * np.exp(-x[1] * t) - y) / sigma
    opt = optimize.least_squares(res, [1.0, 1.0], xtol=1e-14, ftol=1e-14, gtol=1e-14).x
    p = profile_likelihood(res, opt, 1, coords=Coordinates(bounds=([0.0, 0.0], [np.inf, np.inf])),
                           name="k")
    lo, hi, step = _brute_force_interval(t, y, sigma)
    assert p.lower == pytest.approx(lo, abs=2 * step)
    assert p.upper == pytest.approx(hi, abs=2 * step)
    # clearly asymmetric: the upper side is much longer, so the Wald interval
    # (symmetric) is not trustworthy
    assert (p.upper - p.estimate) > 1.3 * (p.estimate - p.lower)
    assert not p.trustworthy
    assert p.wald[1] < hi - 0.2       # the linearised interval misses the upper end


def test_one_over_p_parameter_profile_on_log_scale_matches_grid():
    """y = 1 / (1 + t / tau): tau profiled on its logarithm."""
    rng = np.random.default_rng(7)
    t = np.linspace(0.0, 3.0, 10)
    sigma = 0.05
    y = 1.0 / (1.0 + t / 0.8) + sigma * rng.standard_normal(t.size)

    def res(x):
        return (1.0 / (1.0 + t / x[0]) - y) / sigma
    taus = np.exp(np.linspace(np.log(0.2), np.log(5.0), 400001))
    chi = (((1.0 / (1.0 + np.outer(1.0 / taus, t)) - y) / sigma) ** 2).sum(axis=1)
    best = taus[chi.argmin()]
    inside = taus[chi - chi.min() <= Q95]
    p = profile_likelihood(res, [best], 0, coords=Coordinates(bounds=([1e-6], [np.inf]), log=True))
    assert p.lower == pytest.approx(inside.min(), rel=1e-4)
    assert p.upper == pytest.approx(inside.max(), rel=1e-4)


def test_unidentifiable_parameter_gives_open_profile():
    rng = np.random.default_rng(2)
    t = np.linspace(0.0, 1.0, 12)
    y = 2.0 * t + 0.1 * rng.standard_normal(t.size)
    # only the product a*b is identifiable: the profile of a is flat to its bounds
    prod = float(t @ y / (t @ t))       # the least-squares product
    p = profile_likelihood(lambda x: (x[0] * x[1] * t - y) / 0.1, [1.0, prod], 0,
                           coords=Coordinates(bounds=([0.1, 0.01], [10.0, 100.0]), log=True))
    assert p.open_lower and p.open_upper
    assert (p.lower, p.upper) == pytest.approx((0.1, 10.0))
    assert not p.trustworthy
    assert np.all(np.abs(p.delta_chi2) < 0.05 * p.threshold)
    # without bounds the open ends are None
    q = profile_likelihood(lambda x: ((x[0] + x[1]) * t - y) / 0.1, [1.0, prod - 1.0], 0,
                           tracing=Tracing(max_points=25))
    assert q.lower is None and q.upper is None and q.open_lower and q.open_upper
    assert q.to_dict()["lower"] is None


def test_linear_check_accepts_linear_and_rejects_asymmetric():
    from acausal.studies.profile import linear_check
    from scipy import optimize
    X, y, sigma = _quadratic_data()
    beta = np.linalg.lstsq(X, y, rcond=None)[0]
    ok, ratios = linear_check(lambda b: (X @ b - y) / sigma, beta, 1, thresh=Q95)
    assert ok and ratios == pytest.approx((1.0, 1.0), rel=1e-6)
    t, y = _decay(0.15)

    def res(x):
        return (x[0] * np.exp(-x[1] * t) - y) / 0.15
    opt = optimize.least_squares(res, [1.0, 1.0], xtol=1e-14, ftol=1e-14, gtol=1e-14).x
    ok, ratios = linear_check(res, opt, 1, thresh=Q95)
    assert not ok


@pytest.mark.slow
def test_breaker_K_over_all_voltages_has_an_open_profile():
    """The report data's K interval (docs/calibration.md): the Wald interval
    [2.0e8, 4.3e9] on log K is not trustworthy; the profile (bh re-fitted at
    each K) is closed below, near 2.9e8, and open up to the bound 1e10.
    About 1100 simulations (1.5 min of CPU)."""
    import os
    from acausal.studies import calibrate as cal
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    model = os.path.join(root, "models", "breaker_24kv.py")
    ds = cal.model_dataset(model, os.path.join(root, "data", "report_24kv"))
    out = cal.least_squares(model, ds, ["contact.K", "hook.bh"], profile="auto")
    assert list(out.profile_ci95) == ["contact.K"]      # bh's Wald interval passes the check
    p = out.profile_ci95["contact.K"]
    assert not p.trustworthy and p.open_upper and not p.open_lower
    assert p.upper == pytest.approx(1e10)
    assert 2.5e8 < p.lower < 3.3e8 and p.lower > out.ci95["contact.K"][0] * 1.2
    assert p.threshold == pytest.approx(out.cost / out.dof * stats.t.ppf(0.975, out.dof) ** 2)


@pytest.mark.slow
def test_breaker_K_at_110V_profile_is_closed_and_shifted():
    """Two readings for two parameters (dof 0: threshold 3.84): the profile of
    K is closed, [4.07e8, 1.02e9] against the Wald [3.91e8, 9.74e8]."""
    import os
    from acausal.studies import calibrate as cal
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    model = os.path.join(root, "models", "breaker_24kv.py")
    ds, _ = cal.split(cal.model_dataset(model, os.path.join(root, "data", "report_24kv")))
    out = cal.least_squares(model, ds, ["contact.K", "hook.bh"], profile="auto")
    p = out.profile_ci95["contact.K"]
    assert p.threshold == pytest.approx(Q95)
    assert not (p.open_lower or p.open_upper)
    assert p.lower == pytest.approx(4.07e8, rel=0.02) and p.upper == pytest.approx(1.025e9, rel=0.02)
    assert p.lower > out.ci95["contact.K"][0] and p.upper > out.ci95["contact.K"][1]


def test_profiles_auto_profiles_only_what_the_linear_check_rejects():
    from scipy import optimize
    from acausal.studies.profile import jacobian_in_profile_variables, profiles
    t, y = _decay(0.15)

    def res(x):
        return (x[0] * np.exp(-x[1] * t) - y) / 0.15
    opt = optimize.least_squares(res, [1.0, 1.0], xtol=1e-14, ftol=1e-14, gtol=1e-14).x
    jx = np.column_stack([np.exp(-opt[1] * t), -opt[0] * t * np.exp(-opt[1] * t)]) / 0.15
    # on k itself the profile is skewed (see above); on log k it is nearly quadratic
    for log, flagged in (([False, False], {"k"}), ([False, True], set())):
        ju = jacobian_in_profile_variables(jx, opt, log=log)
        auto = profiles(res, opt, ["A", "k"], coords=Coordinates(log=log), jacobian=ju)
        every = profiles(res, opt, ["A", "k"], every=True, coords=Coordinates(log=log))
        assert set(auto) == flagged
        assert {n for n, p in every.items() if not p.trustworthy} == flagged
        for name, p in auto.items():      # what auto profiled, it profiled the same way
            assert (p.lower, p.upper) == pytest.approx((every[name].lower, every[name].upper),
                                                       rel=1e-6)


def test_a_failing_objective_ends_the_profile_open_not_closed():
    X, y, sigma = _quadratic_data()
    beta = np.linalg.lstsq(X, y, rcond=None)[0]
    sd = sigma * np.sqrt(np.diag(np.linalg.inv(X.T @ X)))
    wall = beta[1] + 0.5 * sd[1]          # beyond this the "simulation" fails

    def res(b):
        return np.full(y.size, np.nan) if b[1] > wall else (X @ b - y) / sigma
    p = profile_likelihood(res, beta, 1)
    assert p.open_upper and p.upper is None and "failed" in p.message
    assert not p.open_lower and not p.trustworthy
    assert p.values.max() <= wall


_COASTING = '''
from acausal import Model, Experiment
from acausal.mechanics.translational import Mass, Damper, Fixed

model = Model()
v0 = model.parameter("v0", 1.0, "m/s", "launch speed")
model.mass = Mass(m=1.0, s=0.0, v=v0)
model.damper = Damper(d=1.0)
model.ground = Fixed()
model.connect(model.ground.flange, model.damper.flange_a)
model.connect(model.damper.flange_b, model.mass.flange)
experiment = Experiment(t_end=2.0, rtol=1e-10, atol=1e-12, output_step=0.5)
measures = {"s_end": lambda res: res["mass.s"][-1]}
free_parameters = {"damper.d": (0.01, 100.0)}
'''


def test_calibrate_cli_profile_interval_matches_closed_form(tmp_path):
    """A mass launched at v0 against a damper d: s(2 s) = v0 (1 - exp(-2 d)) / d.
    Three launches, d fitted on its logarithm; the profile interval printed by
    `acausal calibrate --profile all --json` against a grid on the closed form."""
    import json
    from click.testing import CliRunner
    from acausal.cli import main
    (tmp_path / "coast.py").write_text(_COASTING)
    data = tmp_path / "data"
    data.mkdir()
    v0s, sigma = np.array([1.0, 2.0, 3.0]), 0.05

    def s_end(d, v):
        return v * (1.0 - np.exp(-2.0 * d)) / d
    meas = s_end(0.8, v0s) + sigma * np.array([0.9, -1.3, 0.4])
    (data / "experiments.csv").write_text("name,v0 [m/s],s_end [m]\n" + "".join(
        f"E{k},{v},{m:.17g}\n" for k, (v, m) in enumerate(zip(v0s, meas))))
    (data / "instrument.csv").write_text(f"signal,resolution [m],noise_std [m]\ns_end,,{sigma}\n")
    args = ["calibrate", str(tmp_path / "coast.py"), str(data), "--fit", "damper.d",
            "--profile", "all"]
    r = CliRunner().invoke(main, args + ["--json"])
    assert r.exit_code == 0, r.output
    out = json.loads(r.output)
    p = out["profile_ci95"]["damper.d"]
    ds = np.exp(np.linspace(np.log(0.2), np.log(3.0), 200001))
    chi = (((s_end(ds[:, None], v0s) - meas) / sigma) ** 2).sum(axis=1)
    S, dof = chi.min(), 2
    thr = max(S / dof, 1.0) * stats.t.ppf(0.975, dof) ** 2
    inside = ds[chi - S <= thr]
    assert p["threshold"] == pytest.approx(thr, rel=1e-4)
    assert p["lower"] == pytest.approx(inside.min(), rel=2e-3)
    assert p["upper"] == pytest.approx(inside.max(), rel=2e-3)
    assert p["wald"] == pytest.approx(out["ci95"]["damper.d"], rel=1e-6)


def test_cli_profile_line_names_open_ends():
    from acausal.cli import _profile_line
    t = np.linspace(0.0, 1.0, 12)
    y = 2.0 * t
    prod = float(t @ y / (t @ t))
    p = profile_likelihood(lambda x: (x[0] * x[1] * t - y) / 0.1, [1.0, prod], 0,
                           coords=Coordinates(bounds=([0.1, 0.01], [10.0, 100.0]), log=True))
    assert _profile_line(p).startswith(
        "profile-likelihood 95% CI [open at bound 0.1, open at bound 10] "
        "(the linearised interval is not trustworthy;")
    X, y, sigma = _quadratic_data()
    q = profile_likelihood(lambda b: (X @ b - y) / sigma, np.linalg.lstsq(X, y, rcond=None)[0], 0)
    assert f"[{q.lower:.6g}, {q.upper:.6g}] (agrees with the linearised" in _profile_line(q)
