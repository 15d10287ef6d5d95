"""Tolerance studies (acausal/studies/tolerance.py, ``acausal tolerance``):
the sampling's marginals, variance shares against closed forms (a linear
model, the Ishigami function), resume after a simulated kill, bad specs in
one line each, and a small breaker study end to end."""
import json
import math
import os
import textwrap

import numpy as np
import pytest
from click.testing import CliRunner

from acausal.cli import main
from acausal.infra.executor import open_executor
from acausal.modelfile import compile_file
from acausal.studies import tolerance as tol
from acausal.studies.tolerance import Dist

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
BREAKER = os.path.join(ROOT, "models", "breaker_24kv.py")
THRT_NOMINAL = 1.89987e-3


# ---------------------------------------------------------------------------
# Sampling
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("sampling,n", [("lhs", 4000), ("sobol", 4096)])
def test_marginals_have_the_distributions_mean_std_and_bounds(sampling, n):
    dists = [Dist("a", "normal", 5.0, 0.5), Dist("b", "uniform", 2.0, 3.0)]
    X = tol.draw(dists, n, sampling, seed=3).X[:n]          # sobol: block A
    assert X.shape == (n, 2)
    assert abs(X[:, 0].mean() - 5.0) < 0.01 and abs(X[:, 0].std(ddof=1) - 0.5) < 0.005
    assert X[:, 1].min() >= 2.0 and X[:, 1].max() <= 3.0
    assert abs(X[:, 1].mean() - 2.5) < 0.005
    assert abs(X[:, 1].std(ddof=1) - 1 / math.sqrt(12)) < 0.003
    if sampling == "lhs":      # one point in each of the n strata of each parameter
        strata = np.floor((X[:, 1] - 2.0) * n).astype(int)
        assert sorted(strata) == list(range(n))


def test_sobol_needs_a_power_of_two_and_lhs_at_least_two_sets():
    with pytest.raises(tol.UsageError, match="power of 2.*use 1024 or 2048"):
        tol.draw([Dist("a", "normal", 0.0, 1.0)], 2000, "sobol")
    with pytest.raises(tol.UsageError, match="integer >= 2"):
        tol.draw([Dist("a", "normal", 0.0, 1.0)], 1, "lhs")


def test_saltelli_design_blocks():
    d = [Dist("a", "uniform", 0.0, 1.0), Dist("b", "uniform", 0.0, 1.0),
         Dist("c", "uniform", 0.0, 1.0)]
    des = tol.draw(d, 64, "sobol", seed=1)
    X = des.X.reshape(5, 64, 3)
    A, B = X[0], X[1]
    for i in range(3):
        expect = A.copy()
        expect[:, i] = B[:, i]
        assert np.array_equal(X[2 + i], expect)


# ---------------------------------------------------------------------------
# Variance shares against closed forms
# ---------------------------------------------------------------------------


def _linear_case():
    a, b = 2.0, -3.0
    dists = [Dist("x1", "normal", 1.0, 0.5), Dist("x2", "uniform", 0.0, 0.6),
             Dist("x3", "normal", 0.0, 1.0)]                # x3 does not enter y
    v1, v2 = 0.5 ** 2, 0.6 ** 2 / 12
    total = a * a * v1 + b * b * v2
    return dists, (lambda X: a * X[:, 0] + b * X[:, 1]), [a * a * v1 / total, b * b * v2 / total, 0.0]


def test_sobol_indices_of_a_linear_model_match_the_closed_form():
    dists, f, S = _linear_case()
    des = tol.draw(dists, 4096, "sobol", seed=0)
    idx = tol.sobol_indices(f(des.X), des.n, 3)
    np.testing.assert_allclose(idx["S1"], S, atol=0.01)
    np.testing.assert_allclose(idx["ST"], S, atol=0.01)     # additive: ST = S1


def test_regression_and_correlation_ratios_of_a_linear_model_on_lhs():
    dists, f, S = _linear_case()
    des = tol.draw(dists, 4000, "lhs", seed=0)
    reg = tol.regression_shares(des.X, f(des.X))
    assert reg["r2"] > 1 - 1e-12
    np.testing.assert_allclose(reg["src"] ** 2, S, atol=0.005)
    np.testing.assert_allclose(reg["slope"], [2.0, -3.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(tol.correlation_ratios(des.X, f(des.X)), S, atol=0.02)


def test_sobol_indices_of_the_ishigami_function_with_interactions():
    """Ishigami (a = 7, b = 0.1, x_i ~ U(-pi, pi)): closed-form indices
    (Sobol' & Levitan 1999); x1 and x3 interact, so ST1 > S1 and S3 = 0 < ST3.
    The linear fit cannot see this: its R^2 is low."""
    a, b = 7.0, 0.1
    dists = [Dist(f"x{i}", "uniform", -math.pi, math.pi) for i in (1, 2, 3)]
    des = tol.draw(dists, 8192, "sobol", seed=0)
    X = des.X
    y = np.sin(X[:, 0]) + a * np.sin(X[:, 1]) ** 2 + b * X[:, 2] ** 4 * np.sin(X[:, 0])
    V = a ** 2 / 8 + b * math.pi ** 4 / 5 + b ** 2 * math.pi ** 8 / 18 + 0.5
    V1 = 0.5 * (1 + b * math.pi ** 4 / 5) ** 2
    V2 = a ** 2 / 8
    V13 = b ** 2 * math.pi ** 8 * (1 / 18 - 1 / 50)
    idx = tol.sobol_indices(y, des.n, 3)
    np.testing.assert_allclose(idx["S1"], [V1 / V, V2 / V, 0.0], atol=0.02)
    np.testing.assert_allclose(idx["ST"], [(V1 + V13) / V, V2 / V, V13 / V], atol=0.02)
    assert tol.regression_shares(X, y)["r2"] < 0.3


def test_failed_sets_are_counted_and_left_out_of_the_indices():
    dists, f, S = _linear_case()
    des = tol.draw(dists, 1024, "sobol", seed=0)
    y = f(des.X)
    y[[3, 1024 + 7, 2 * 1024 + 9]] = np.nan                 # in A, B and AB_1
    status = np.where(np.isfinite(y), "ok", "failed").astype(object)
    s = tol.summarize(des, {"y": y}, status)["y"]
    assert s["n_failed"] == 3 and s["n_ok"] == len(y) - 3
    assert list(s["used"]) == [1024 - 3, 1024 - 2, 1024 - 2]
    np.testing.assert_allclose(s["S1"], S, atol=0.03)
    assert math.isfinite(s["mean"]) and set(s["percentiles"]) == {1, 5, 50, 95, 99}


# ---------------------------------------------------------------------------
# A small model with a closed form: resume after a simulated kill
# ---------------------------------------------------------------------------

OSCILLATOR = textwrap.dedent('''
    """A mass on a spring released from s = 0.1 m: s(t) = 0.1 cos(sqrt(c/m) t)."""
    from acausal import Experiment, Measure, Model
    from acausal.mechanics.translational import Fixed, Mass, Spring

    model = Model()
    model.mass = Mass(m=1.0, s=0.1, v=0.0)
    model.spring = Spring(c=100.0, s_rel0=0.0)
    model.ground = Fixed()
    model.connect(model.ground.flange, model.spring.flange_a)
    model.connect(model.spring.flange_b, model.mass.flange)
    experiment = Experiment(t_end=0.3, rtol=1e-9, atol=1e-12, output_step=0.3)
    measures = {"s_end": Measure(lambda r: r["mass.s"][-1], "m", display="mm")}
''')


@pytest.fixture
def oscillator(tmp_path):
    path = tmp_path / "osc.py"
    path.write_text(OSCILLATOR)
    return str(path)


def _osc_dists(path):
    spec = os.path.join(os.path.dirname(path), "osc_tol.csv")
    with open(spec, "w") as f:
        f.write("name, distribution, a, b, unit\n"
                "spring.c, normal, nominal, 5%, N/m\n"
                "mass.m, uniform, 980, 1020, g\n")
    return tol.parse_spec(spec, compile_file(path)[1])


def test_resume_after_a_kill_loses_and_repeats_no_set(oscillator, tmp_path, monkeypatch):
    dists = _osc_dists(oscillator)
    assert dists[1].a == pytest.approx(0.98) and dists[1].b == pytest.approx(1.02)
    out = tmp_path / "osc.csv"
    calls, real = [], tol.run_chunk

    def dying(path, names, rows, *args):
        if len(calls) == 2:
            raise KeyboardInterrupt("killed")              # the third chunk: a kill
        calls.append([i for i, _ in rows])
        return real(path, names, rows, *args)

    monkeypatch.setattr(tol, "run_chunk", dying)
    kw = dict(executor=None, measures=["s_end"], out_csv=out,
              run=tol.StudyRun(chunk=8, backend=None))
    with open_executor("serial") as ex, pytest.raises(KeyboardInterrupt):
        tol.run_tolerance(oscillator, dists, 40, **{**kw, "executor": ex})
    assert not out.exists() and len(calls) == 2

    calls.clear()
    monkeypatch.setattr(tol, "run_chunk", lambda *a: calls.append([i for i, _ in a[2]]) or real(*a))
    said = []
    with open_executor("serial") as ex:
        run = tol.StudyRun(chunk=8, backend=None,
                           on_resume=lambda done, total: said.append((done, total)))
        res = tol.run_tolerance(oscillator, dists, 40, **{**kw, "executor": ex, "run": run})
    assert said == [(16, 40)] and res.resumed == 16
    assert sorted(i for c in calls for i in c) == list(range(16, 40))
    # the CSV holds each set once, and every value is the closed form's
    rows = tol_rows(out)
    assert [int(r["set"]) for r in rows] == list(range(40))
    for r in rows:
        c, m = float(r["spring.c"]), float(r["mass.m"])
        assert r["status"] == "ok"
        assert float(r["s_end"]) == pytest.approx(0.1 * math.cos(math.sqrt(c / m) * 0.3), abs=1e-7)
    # and the values equal an uninterrupted run's
    with open_executor("serial") as ex:
        fresh = tol.run_tolerance(oscillator, dists, 40, **{**kw, "executor": ex,
                                                            "out_csv": tmp_path / "fresh.csv"})
    np.testing.assert_array_equal(fresh.values["s_end"], res.values["s_end"])
    assert not (tmp_path / "osc.csv.partial").exists()     # done: the journal is gone


def tol_rows(path):
    from acausal.studies.sweep import read_rows
    return read_rows(path)


def test_a_set_outside_the_parameter_bounds_fails_alone_and_is_counted(oscillator, tmp_path):
    dists = [Dist("spring.c", "normal", 100.0, 5.0), Dist("mass.m", "normal", 0.05, 0.05)]
    with open_executor("serial") as ex:
        res = tol.run_tolerance(oscillator, dists, 32, executor=ex, measures=["s_end"],
                                out_csv=tmp_path / "o.csv", run=tol.StudyRun(backend=None))
    bad = res.design.X[:, 1] <= 0
    assert bad.any() and res.n_failed == bad.sum()
    assert all("mass.m" in res.errors[i] for i in np.flatnonzero(bad))
    assert res.summary["s_end"]["n_failed"] == bad.sum()
    assert np.isnan(res.values["s_end"][bad]).all() and np.isfinite(res.values["s_end"][~bad]).all()


# ---------------------------------------------------------------------------
# Bad specs: one line each
# ---------------------------------------------------------------------------


def test_bad_spec_rows_are_each_one_line_naming_file_and_line(oscillator, tmp_path):
    spec = tmp_path / "bad.csv"
    spec.write_text("# a comment\n"
                    "spring.cc, normal, 100, 5, N/m\n"          # 2: no such parameter
                    "spring.c, normal, 100, -5, N/m\n"          # 3: negative std
                    "mass.m, uniform, 1.0, 1.0, kg\n"           # 4: empty range
                    "mass.m, normal, 1.0, 0.01, N/m\n"          # 5: wrong dimension
                    "spring.c, gauss, 100, 5, N/m\n"            # 6: unknown distribution
                    "spring.c, normal, abc, 5, N/m\n"           # 7: not a number
                    "spring.c, normal, 100, 5\n"                # 8: a field missing
                    "mass.m, uniform, -1, 2, kg\n")             # 9: outside the bounds (m > 0)
    cm = compile_file(oscillator)[1]
    with pytest.raises(tol.SpecError) as info:
        tol.parse_spec(spec, cm)
    lines = str(info.value).splitlines()
    assert [ln.split(":")[1] for ln in lines] == [str(k) for k in range(2, 10)]
    assert all(ln.startswith(f"{spec}:") for ln in lines)
    for k, text in enumerate(["no parameter 'spring.cc'", "negative standard deviation",
                              "empty range", "wrong unit", "'gauss' is not", "'abc' is not a number",
                              "expected 5 fields", "mass.m"]):
        assert text in lines[k], lines[k]
    assert "a stiffness" in lines[3] and "a mass" in lines[3]

    runner = CliRunner()
    r = runner.invoke(main, ["tolerance", oscillator, "--spec", str(spec), "-n", "8",
                             "--out", str(tmp_path / "x.csv")])
    assert r.exit_code == 2
    err = r.stderr.strip().splitlines()
    assert len(err) == 8 and "Traceback" not in r.output + r.stderr


def test_a_duplicated_parameter_and_an_empty_spec_are_refused(oscillator, tmp_path):
    cm = compile_file(oscillator)[1]
    spec = tmp_path / "dup.csv"
    spec.write_text("spring.c, normal, 100, 5, N/m\nspring.c, uniform, 90, 110, N/m\n")
    with pytest.raises(tol.SpecError, match=r"dup.csv:2: spring.c: already given on line 1"):
        tol.parse_spec(spec, cm)
    spec.write_text("# nothing\n")
    with pytest.raises(tol.SpecError, match="no parameter rows"):
        tol.parse_spec(spec, cm)


def test_cli_budget_and_sobol_count_refused_before_anything_runs(oscillator, tmp_path):
    spec = tmp_path / "t.csv"
    spec.write_text("spring.c, normal, nominal, 5%, N/m\n")
    runner = CliRunner()
    r = runner.invoke(main, ["tolerance", oscillator, "--spec", str(spec), "-n", "1000",
                             "--sampling", "sobol"])
    assert r.exit_code == 2 and "power of 2" in r.stderr and len(r.stderr.splitlines()) == 1
    r = runner.invoke(main, ["tolerance", oscillator, "--spec", str(spec), "-n", "1024",
                             "--sampling", "sobol", "--max-points", "2000"])
    assert r.exit_code == 2 and "3,072 simulations" in r.stderr


# ---------------------------------------------------------------------------
# The breaker end to end
# ---------------------------------------------------------------------------


def test_breaker_study_end_to_end(tmp_path):
    """64 Latin-hypercube sets of the breaker's drawing tolerances on two
    worker processes: THRT's mean is the nominal 1.89987 ms within four
    standard errors (plus the 1 us the nonlinearity shifts it, measured on
    2000 sets), the friction dominates its variance, plots and JSON written."""
    spec = tmp_path / "tol.csv"
    spec.write_text("contact.K, normal, nominal, 3.33%, N/m^1.5\n"
                    "hook.bh, normal, nominal, 3.33%, N*m*s/rad\n"
                    "armature.ma, normal, nominal, 0.67%, kg\n"
                    "hook.s3, uniform, 54.9, 55.1, mm\n")
    out = tmp_path / "thrt.csv"
    r = CliRunner().invoke(main, ["tolerance", BREAKER, "--spec", str(spec), "-n", "64",
                                  "--measure", "thrt", "--workers", "2", "--chunk", "16",
                                  "--out", str(out), "--plot", str(tmp_path / "b"),
                                  "--json", str(tmp_path / "s.json"), "--no-progress"])
    assert r.exit_code == 0, r.output + r.stderr
    s = json.loads((tmp_path / "s.json").read_text())["thrt"]
    assert s["n_ok"] == 64 and s["n_failed"] == 0
    assert abs(s["mean"] - THRT_NOMINAL) < 4 * s["std"] / 8 + 2e-6
    assert 2e-5 < s["std"] < 8e-5
    assert max(s["eta2"], key=s["eta2"].get) == "hook.bh" and s["r2"] > 0.95
    assert "thrt: mean 1.9" in r.output and " ms" in r.output
    for kind in ("hist", "tornado"):
        assert (tmp_path / f"b_thrt_{kind}.png").stat().st_size > 10_000
    assert len(tol_rows(out)) == 64


def test_the_declared_unit_with_a_symbolic_exponent_is_accepted(tmp_path):
    """'N/m^gamma' is contact.K's declared unit, as `acausal variables` lists
    it; a spec in that unit was refused ('not a unit expression'). It reads
    as the model's own unit, the same as the resolved 'N/m^1.5'."""
    cm = compile_file(BREAKER)[1]
    dists = []
    for unit in ("N/m^gamma", "N/m^1.5"):
        spec = tmp_path / "tol.csv"
        spec.write_text(f"contact.K, uniform, 1e7, 2e7, {unit}\n")
        dists.append(tol.parse_spec(spec, cm)[0])
    same = ("name", "kind", "a", "b", "unit")
    assert [getattr(dists[0], f) for f in same] == [getattr(dists[1], f) for f in same]
    assert (dists[0].a, dists[0].b) == (1e7, 2e7)
