"""The next experiment, computed (acausal.design): closed-form rivals, and a
blind test on a slider where Coulomb friction and a constant load are
indistinguishable on the data so far; the truth is simulated by an
independent scipy solve_ivp simulator, not by the project's model code."""
import dataclasses
import json
import textwrap
import time

import numpy as np
import pytest
from scipy import integrate, optimize

from acausal.studies.design import (Condition, ModelRival, Search, Signal, conditions_of,
                            design_experiment, score)
from acausal.errors import ModelFileError
from acausal.modelfile import compile_file


# -- closed-form rivals ------------------------------------------------------------------

T = np.linspace(0.0, 1.0, 21)


def _line(c):
    return {"y": c["a"] * T + c["b"]}


def _parabola(c):
    return {"y": c["a"] * T ** 2 + c["b"]}


def test_two_rivals_separation_is_largest_at_the_analytic_optimum():
    # difference a (T - T^2): D = a^2 sum((T - T^2)^2) / floor^2, largest at |a| max
    conds = [Condition("a", -0.5, 2.0), Condition("b", 0.0, 1.0)]
    nxt = design_experiment({"line": _line, "parabola": _parabola}, conds,
                            [Signal("y", 0.01)], search=Search(seed=1))
    expected = 2.0 * np.sqrt(np.sum((T - T ** 2) ** 2)) / 0.01
    assert nxt.conditions["a"] == pytest.approx(2.0, abs=1e-6)
    assert nxt.separation == pytest.approx(expected, rel=1e-6)
    assert nxt.rms_floors == pytest.approx(expected / np.sqrt(T.size), rel=1e-6)
    np.testing.assert_allclose(nxt.predictions["line"], 2.0 * T + nxt.conditions["b"])
    json.dumps(nxt.to_dict())       # serialisable as the diagnosis's next_experiment


def test_next_experiment_plot_is_written(tmp_path):
    from acausal.studies.design import plot_next_experiment
    nxt = design_experiment({"line": _line, "parabola": _parabola},
                            [Condition("a", -0.5, 2.0), Condition("b", 0.0, 1.0)],
                            [Signal("y", 0.01)], search=Search(n_initial=12, n_refine=1),
                            times=T)
    assert nxt.to_dict()["times"] == pytest.approx(T.tolist())
    fig = plot_next_experiment(nxt, tmp_path / "next.png")
    assert (tmp_path / "next.png").stat().st_size > 5000
    assert [ln.get_label() for ln in fig.axes[0].get_lines()] == ["line", "parabola"]


def test_three_rivals_maximise_the_smallest_pairwise_separation():
    # rivals y = c*T, y = c*T^2, y = c*T^3 + k: the third differs from the others
    # by k everywhere, the first two only by c (T - T^2); min over pairs needs both
    def cubic(c):
        return {"y": c["c"] * T ** 3 + c["k"] * 0.2}
    rivals = {"p1": lambda c: {"y": c["c"] * T}, "p2": lambda c: {"y": c["c"] * T ** 2},
              "p3": cubic}
    conds = [Condition("c", 0.0, 1.0), Condition("k", -1.0, 1.0)]
    nxt = design_experiment(rivals, conds, [Signal("y", 0.01)], search=Search(seed=0))

    def min_d(c, k):
        ys = [c * T, c * T ** 2, c * T ** 3 + 0.2 * k]
        return min(np.sum((ys[i] - ys[j]) ** 2) for i, j in ((0, 1), (0, 2), (1, 2)))
    grid = max(min_d(c, k) for c in np.linspace(0, 1, 201) for k in np.linspace(-1, 1, 201))
    assert nxt.separation == pytest.approx(np.sqrt(grid) / 0.01, rel=2e-3)
    assert nxt.separation == pytest.approx(min(nxt.pairwise.values()))


def test_a_rival_that_cannot_predict_makes_the_experiment_unusable():
    def fragile(c):
        return None if c["a"] > 1.0 else _parabola(c)
    nxt = design_experiment({"line": _line, "parabola": fragile},
                            [Condition("a", -0.5, 2.0), Condition("b", 0.0, 1.0)],
                            [Signal("y", 0.01)])
    assert nxt.conditions["a"] <= 1.0
    assert score({"x": {"y": T}, "z": None}, [Signal("y", 1.0)]).signal is None


def test_rivals_no_condition_can_split_are_reported_as_not_decisive():
    # y = a T + b and y = a T + b + 1e-3 (a fixed offset of 0.1 floor)
    nxt = design_experiment({"one": _line, "two": lambda c: {"y": _line(c)["y"] + 1e-3}},
                            [Condition("a", -0.5, 2.0), Condition("b", 0.0, 1.0)],
                            [Signal("y", 0.01)])
    assert nxt.separation == pytest.approx(0.1 * np.sqrt(T.size))
    assert not nxt.decisive and "no experiment within the declared ranges" in nxt.message


def test_model_file_conditions_are_read_and_checked(tmp_path):
    f = tmp_path / "bad.py"
    f.write_text(_SLIDER.format(law="", conditions='{"v0": (1.0, -1.0)}'))
    with pytest.raises(ModelFileError, match=r"conditions\['v0'\].*low < high"):
        compile_file(str(f))
    g = tmp_path / "unknown.py"
    g.write_text(_SLIDER.format(law="", conditions='{"nope": (0.0, 1.0, "m")}'))
    with pytest.raises(ModelFileError, match="conditions: the model has no parameter 'nope'"):
        compile_file(str(g))


def test_model_rival_predicts_traces_and_measures(tmp_path):
    f = tmp_path / "slider.py"
    f.write_text(_SLIDER.format(law="measures = {'s_end': lambda res: res['mass.s'][-1]}",
                                conditions=_RANGES))
    pair = compile_file(str(f))
    assert conditions_of(pair[0]) == [Condition("s0", -0.1, 0.1, "m"),
                                      Condition("v0", -1.0, 1.0, "m/s")]
    times = np.linspace(0.0, 0.2, 5)
    out = ModelRival(pair, {"spring.c": 100.0}, ["mass.s", "s_end"], times)({"s0": 0.05})
    # undamped: x = s0 cos(10 t); the run's own t_end is 0.25 s
    np.testing.assert_allclose(out["mass.s"], 0.05 * np.cos(10.0 * times), atol=1e-6)
    assert out["s_end"] == pytest.approx([0.05 * np.cos(2.5)], abs=1e-6)
    assert ModelRival(pair, {"mass.m": -1.0}, ["mass.s"], times)({}) is None


# -- the blind test ----------------------------------------------------------------------

_SLIDER = textwrap.dedent('''
    from acausal import Model, Experiment
    from acausal.mechanics.translational import Mass, Spring, Fixed, Force
    from acausal.mechanics.friction import GroundFriction

    model = Model()
    s0 = model.parameter("s0", 0.1, "m", "start position of the slider")
    v0 = model.parameter("v0", 0.0, "m/s", "start velocity of the slider")
    model.mass = Mass(m=1.0, s=s0, v=v0)
    model.spring = Spring(c=80.0)
    model.ground = Fixed()
    model.connect(model.ground.flange, model.spring.flange_a)
    model.connect(model.spring.flange_b, model.mass.flange)
    {law}
    experiment = Experiment(t_end=0.25, rtol=1e-9, atol=1e-12, output_step=1e-3)
    conditions = {conditions}
''')
_COULOMB = textwrap.dedent('''
    F = model.parameter("F", 1.0, "N", "Coulomb friction force", min=0.0)
    model.fr = GroundFriction(F_c=F, F_s=F)
    model.connect(model.mass.flange, model.fr.flange)''')
_LOAD = textwrap.dedent('''
    F = model.parameter("F", 1.0, "N", "constant load along +s")
    model.load = Force(f=F)
    model.connect(model.mass.flange, model.load.flange)''')
_RANGES = '{"s0": (-0.1, 0.1, "m"), "v0": (-1.0, 1.0, "m/s")}'

MASS, STIFF, FRICTION = 1.0, 100.0, 2.0      # the truth
FLOOR = 1e-4                                  # position noise [m]
TIMES = np.arange(0.0, 0.25 + 1e-12, 1e-3)


def true_slider(s0, v0, times):
    """m x'' = -k x - F sign(x'), sticking at a stop when |k x| <= F: one
    solve_ivp per sliding phase, ended by the event v = 0."""
    out = np.full(times.size, np.nan)
    t, x, v = 0.0, s0, v0
    mode = np.sign(v) if v != 0 else (0.0 if abs(STIFF * x) <= FRICTION else -np.sign(x))
    while t < times[-1]:
        if mode == 0:                           # stuck for good (linear spring)
            out[times >= t] = x
            break

        def stop(_, y):
            return y[1]
        stop.terminal, stop.direction = True, -mode
        sol = integrate.solve_ivp(lambda _, y, m=mode: [y[1], (-STIFF * y[0] - FRICTION * m)
                                                        / MASS],
                                  (t, times[-1]), [x, v], rtol=1e-11, atol=1e-13,
                                  events=stop, dense_output=True)
        seg = (times >= t) & (times <= sol.t[-1])
        out[seg] = sol.sol(times[seg])[0]
        t, x, v = sol.t[-1], sol.y[0, -1], 0.0
        mode = 0.0 if abs(STIFF * x) <= FRICTION else -np.sign(x)
    return out


def _measure(s0, v0, rng):
    return true_slider(s0, v0, TIMES) + FLOOR * rng.standard_normal(TIMES.size)


def _fit(pair, experiments):
    """Output-error fit of spring.c and F to [(conditions, data)]: (values, chi2/n)."""
    names = ["spring.c", "F"]

    def res(z):
        p = dict(zip(names, z * [100.0, 1.0]))
        out = []
        for cond, data in experiments:
            pred = ModelRival(pair, p, ["mass.s"], TIMES)(cond)
            out.append((pred["mass.s"] - data) / FLOOR if pred else np.full(data.size, 1e3))
        return np.concatenate(out)
    sol = optimize.least_squares(res, [0.8, 1.0], diff_step=1e-5, xtol=1e-10, ftol=1e-10)
    n = sum(d.size for _, d in experiments)
    return dict(zip(names, sol.x * [100.0, 1.0])), float(2 * sol.cost / n)


def test_blind_next_experiment_splits_coulomb_friction_from_a_constant_load(tmp_path):
    t0 = time.perf_counter()
    rng = np.random.default_rng(11)
    pairs = {}
    for name, law in (("coulomb", _COULOMB), ("load", _LOAD)):
        f = tmp_path / f"slider_{name}.py"
        f.write_text(_SLIDER.format(law=law, conditions=_RANGES))
        pairs[name] = compile_file(str(f))
    old = [({"s0": 0.1, "v0": 0.0}, _measure(0.1, 0.0, rng))]
    fits = {n: _fit(p, old) for n, p in pairs.items()}
    # the data so far cannot tell them apart: both fit to the noise
    assert all(q < 1.3 for _, q in fits.values()), fits
    assert fits["coulomb"][0]["F"] == pytest.approx(FRICTION, rel=0.05)
    assert fits["load"][0]["F"] == pytest.approx(FRICTION, rel=0.05)

    rivals = {n: ModelRival(pairs[n], fits[n][0], ["mass.s", "mass.v"], TIMES) for n in pairs}
    conds = conditions_of(pairs["coulomb"][0])
    nxt = design_experiment(rivals, conds, [Signal("mass.s", FLOOR, "m"),
                                            Signal("mass.v", 1e-2, "m/s")],
                            reference=old[0][0], search=Search(n_refine=1, max_refine_evals=30))
    assert nxt.baseline < 3.0                   # the old experiment: within the noise
    assert nxt.separation > 100.0 and nxt.decisive  # the new one: many floors apart
    json.dumps(nxt.to_dict())

    new = (nxt.conditions, _measure(nxt.conditions["s0"], nxt.conditions["v0"], rng))
    refits = {n: _fit(p, old + [new]) for n, p in pairs.items()}
    assert refits["coulomb"][1] < 1.3, refits
    assert refits["load"][1] > 20.0, refits
    assert refits["coulomb"][0]["F"] == pytest.approx(FRICTION, rel=0.02)
    assert refits["coulomb"][0]["spring.c"] == pytest.approx(STIFF, rel=0.01)
    print(f"\nnext experiment {nxt.conditions}, {nxt.signal}: {nxt.separation:.0f} floors "
          f"(baseline {nxt.baseline:.2f}, {nxt.n_evaluations} experiments evaluated); "
          f"chi2/n after: coulomb {refits['coulomb'][1]:.3f}, load {refits['load'][1]:.1f}; "
          f"{time.perf_counter() - t0:.1f} s")


# -- the rivals' own uncertainty (Box-Hill / Buzzi-Ferraris weighting) -------------------
class _Loose:
    """The line rival whose prediction spreads as (s a^3)^2 per sample: its
    parameters determine it ever less as the condition a grows."""

    def __init__(self, s):
        self.s = s

    def __call__(self, c):
        return _line(c)

    def spread(self, c, prediction):
        return {"y": np.full(T.size, (self.s * c["a"] ** 3) ** 2)}


def test_a_loosely_predicted_experiment_is_weighed_down_to_the_closed_form_optimum():
    # D(a) = a^2 sum((T - T^2)^2) / (f^2 + s^2 a^6): largest at a^6 = f^2 / (2 s^2);
    # unweighted it would be the bound a = 2
    f, a_star = 0.01, 1.3
    s = f / np.sqrt(2.0 * a_star ** 6)
    nxt = design_experiment({"line": _Loose(s), "parabola": _parabola},
                            [Condition("a", 0.1, 2.0), Condition("b", 0.0, 1.0)],
                            [Signal("y", f)], search=Search(seed=1))
    assert nxt.conditions["a"] == pytest.approx(a_star, rel=2e-3)
    d2 = a_star ** 2 * np.sum((T - T ** 2) ** 2) / (f ** 2 + s ** 2 * a_star ** 6)
    assert nxt.separation == pytest.approx(np.sqrt(d2), rel=1e-5)


def test_covariance_steps_rebuild_the_least_squares_covariance():
    from acausal.studies.design import covariance_steps
    rng = np.random.default_rng(3)
    J = rng.normal(size=(40, 3)) * [1.0, 30.0, 0.01]         # badly scaled columns
    values = {"a": 2.0, "b": -0.5, "c": 300.0}
    for cost in (20.0, 74.0):                                # s2 below 1, then 2
        steps = covariance_steps(list(values), values, J, cost)
        got = sum(np.outer(list(st.values()), list(st.values())) for st in steps)
        want = np.linalg.inv(J.T @ J) * max(cost / 37.0, 1.0)
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12 * np.abs(want).max())
    # a direction the data do not determine is left out
    J0 = np.column_stack([J[:, 0], J[:, 0], J[:, 2]])
    assert len(covariance_steps(list(values), values, J0, 20.0)) == 2


def test_a_model_rivals_spread_is_its_sensitivity_times_the_step(tmp_path):
    """A mass on a spring (c = 80 N/m) pushed by a constant load F, started at
    rest at s0: s(t) = F/c + (s0 - F/c) cos(w t), linear in F, so the spread
    of a step dF is exactly (dF (1 - cos w t) / c)^2."""
    f = tmp_path / "load.py"
    f.write_text(_SLIDER.format(law=_LOAD, conditions=_RANGES))
    rival = ModelRival(str(f), {"F": 1.0}, ["mass.s"], TIMES, steps=[{"F": 0.3}])
    cond = {"s0": 0.05, "v0": 0.0}
    y = rival(cond)
    var = rival.spread(cond, y)["mass.s"]
    w = np.sqrt(80.0 / 1.0)
    np.testing.assert_allclose(np.sqrt(var), 0.3 * (1.0 - np.cos(w * TIMES)) / 80.0,
                               rtol=1e-5, atol=1e-9)
    assert ModelRival(str(f), {"F": 1.0}, ["mass.s"], TIMES).spread(cond, y) is None


class _Spreading:
    """y = a^4 T, spread (s a^3)^2 per sample: its difference from y = 0
    grows faster than its spread, so unweighed the design runs to the bound."""

    def __init__(self, s):
        self.s = s

    def __call__(self, c):
        return {"y": c["a"] ** 4 * T}

    def spread(self, c, prediction):
        return {"y": np.full(T.size, (self.s * c["a"] ** 3) ** 2)}


def test_an_experiment_beyond_the_spread_limit_is_weighed_down():
    # merit = D min(1, (f / (s a^3))^2), D = a^8 sum(T^2) / (f^2 + s^2 a^6): the
    # spread reaches one floor at a = 1.2, beyond which the merit falls as a^-4
    from acausal.studies.design import MAX_SPREAD
    f = 0.01
    s = f / 1.2 ** 3
    nxt = design_experiment({"quartic": _Spreading(s), "zero": lambda c: {"y": 0.0 * T}},
                            [Condition("a", 0.1, 2.0)], [Signal("y", f)],
                            search=Search(seed=2))
    a = np.linspace(0.1, 2.0, 190001)
    d2 = a ** 8 * np.sum(T ** 2) / (f ** 2 + s ** 2 * a ** 6)
    merit = d2 * np.minimum(1.0, (MAX_SPREAD * f / (s * a ** 3)) ** 2)
    assert nxt.conditions["a"] == pytest.approx(a[np.argmax(merit)], rel=2e-3)
    assert nxt.spread == pytest.approx(s * nxt.conditions["a"] ** 3 / f, rel=1e-9)
    assert a[np.argmax(d2)] == pytest.approx(2.0)       # unweighed: the bound


class _FileRival:
    """A rival that pickles: the model file's path and parameters; the
    :class:`ModelRival` is made where it runs (the model compiled once per
    process), as the diagnosis's rivals are."""

    def __init__(self, path, params, steps):
        self.path, self.params, self.steps = str(path), dict(params), list(steps)

    def _rival(self):
        return ModelRival(self.path, self.params, ["mass.s"], TIMES, steps=self.steps)

    def __call__(self, conditions):
        return self._rival()(conditions)

    def spread(self, conditions, prediction):
        return self._rival().spread(conditions, prediction)


def test_the_rivals_simulated_side_by_side_give_the_same_design(tmp_path):
    """The diagnosis runs the rivals' simulations on its workers (the
    design's ``Search.map_jobs``): the Coulomb slider and the constant-load slider,
    each with a covariance step, designed one by one here and on a pool of
    two processes, give the same experiment, separation, pairwise
    distances, predictions and evaluation count, bit for bit."""
    from acausal.diagnose.stages.context import Context
    from acausal.infra.executor import open_executor
    coulomb, load = tmp_path / "coulomb.py", tmp_path / "load.py"
    coulomb.write_text(_SLIDER.format(law=_COULOMB, conditions=_RANGES))
    load.write_text(_SLIDER.format(law=_LOAD, conditions=_RANGES))
    rivals = {"coulomb": _FileRival(coulomb, {"F": 2.0}, [{"F": 0.01}]),
              "load": _FileRival(load, {"F": -1.5}, [{"F": 0.02}])}
    conds = conditions_of(compile_file(str(load))[0])
    signals = [Signal("mass.s", FLOOR, "m")]
    search = Search(n_initial=6, n_refine=1, max_refine_evals=8, seed=1)
    one = design_experiment(rivals, conds, signals, search=search,
                            reference={"s0": 0.1, "v0": 0.0})
    jobs_seen = []
    with open_executor(None, 2) as ex:
        ctx = Context(ex, progress=False)

        def side_by_side(fn, jobs):
            jobs_seen.append(len(jobs))
            return ctx.run(fn, jobs, "design", checkpoint=False, progress=False)
        two = design_experiment(rivals, conds, signals,
                                search=dataclasses.replace(search, map_jobs=side_by_side),
                                reference={"s0": 0.1, "v0": 0.0})
    assert jobs_seen[0] == 2 * 7                  # the hypercube's 6 points and the centre
    assert two.conditions == one.conditions and two.signal == one.signal
    assert two.separation == one.separation and two.pairwise == one.pairwise
    assert two.n_evaluations == one.n_evaluations and two.baseline == one.baseline
    assert two.spread == one.spread
    for name in one.predictions:
        np.testing.assert_array_equal(two.predictions[name], one.predictions[name])
    assert one.separation > 3.0                   # a design that splits them (not all NaN)
