"""The diagnosis's stages and their pieces, without the cost of a full
diagnosis: domains, declared sites, starting points, windows, the
"not tested" rule, the generic term's basis, picklable task/result types."""
import pickle

import numpy as np
import pytest
from sympy import Eq

from acausal import Component, Flange, Model, Parameter, Variable, der
from acausal.data import Dataset, MeasuredExperiment, Trace
from acausal.diagnose import HYPOTHESES, ModelGraph
from acausal.diagnose.library.domain import ROTATIONAL, TRANSLATIONAL, domain_of
from acausal.diagnose.stages.fitting import Fit
from acausal.diagnose.library.generic import N_V, N_X, hats, penalty, shape
from acausal.diagnose.problem import Candidate, FitSettings, Param, Problem
from acausal.diagnose.stages.tasks import CandidateFit, FitTask, Starts, _tested, lhs_values, \
    start_points, window
from acausal.mechanics.rotational import Inertia
from acausal.mechanics.translational import Fixed, Mass, Spring


def test_domains_are_described_once():
    assert domain_of(Mass()) is TRANSLATIONAL and domain_of(Inertia()) is ROTATIONAL
    assert TRANSLATIONAL.unit("{F}*s^2/{L}^2") == "N*s^2/m^2"
    assert ROTATIONAL.unit("{F}/{L}^3") == "N*m/rad^3"
    assert type(ROTATIONAL.source(1.0)).__name__ == "Torque"
    assert type(TRANSLATIONAL.component("body", m=2.0)).__name__ == "Mass"


class UserBody(Component):
    """A body of the user's own (not a library class) that declares its site."""

    diagnosis_site = "body"
    flange = Flange("flange")
    m = Parameter(2.0, "kg", "mass")
    s = Variable(0.0, "m", "position")
    v = Variable(0.0, "m/s", "velocity")

    def equations(self):
        return [Eq(self.flange.s, self.s), Eq(der(self.s), self.v),
                Eq(self.m * der(self.v), self.flange.f)]


def test_a_user_component_declares_its_site():
    m = Model()
    m.frame = Fixed()
    m.body = UserBody()
    m.spring = Spring(c=10.0)
    m.connect(m.frame.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.body.flange)
    g = ModelGraph(m)
    assert [s.path for s in g.bodies] == ["body"] and [s.path for s in g.joints] == ["body"]
    assert [s.path for s in g.springs] == ["spring"]
    assert HYPOTHESES["coulomb_friction"].candidates(g) == ["body"]


def test_latin_hypercube_starts_cover_the_bounds():
    p = Param("hyp.F", 0.0, -4.0, 10.0, 1.0, 0.0)
    q = Param("hyp.c", 0.0, 0.0, 5.0, 0.5, 0.0)
    pts = np.array(lhs_values([p, q], 8, seed=1))
    assert pts.shape == (8, 2)
    assert np.all((pts[:, 0] >= -4.0) & (pts[:, 0] <= 10.0))
    assert np.all((pts[:, 1] > 0.0) & (pts[:, 1] <= 5.0))
    assert (pts[:, 0] < 0).sum() == 4          # half the strata on each allowed side
    assert pts[:, 1].max() / pts[:, 1].min() > 20   # log-uniform: spans decades
    assert lhs_values([p, q], 8, seed=1) == lhs_values([p, q], 8, seed=1)


def test_starts_include_the_uncalibrated_free_values():
    free = (Param("k", 3.0, 1.0, 10.0, 1.0, 5.0),)       # calibrated 3, model file 5
    cand = Candidate("h", "x", (Param("hyp.F", 0.0, 0.0, 2.0, 0.2, 0.0),))
    prob = Problem("m.py", "d", "lib", free, FitSettings(lhs=4))
    pts = start_points(FitTask(prob, cand, free))
    xs = [tuple(x) for x, _ in pts]
    assert (3.0, 0.0) in xs and (5.0, 0.0) in xs
    assert sum(1 for _, prior in pts if prior) == 3       # the neutral start + 2 LHS
    assert len(pts) == 2 + 4 + 2


def test_window_cuts_traces_and_drops_measures():
    t = np.linspace(0.0, 1.0, 11)
    ds = Dataset(None, [MeasuredExperiment("E", {"a": 1.0}, {"m": 2.0}, Trace(t, {"x": t ** 2}))])
    w = window(ds, 0.3)
    assert w.experiments[0].measures == {}
    assert np.allclose(w.experiments[0].trace.time, [0.0, 0.1, 0.2, 0.3])
    assert window(ds, 1.0) is ds


def _fit(values, J):
    r = np.zeros(J.shape[0])
    return Fit(list(values), values, 0.0, r, J, ["E"] * r.size, ["x"] * r.size)


def test_not_tested_when_neutral_from_every_start_and_without_local_effect():
    ext = (Param("hyp.T", 0.0, 0.0, 1.0, 0.1, 0.0),)
    flat = np.zeros((50, 2))
    flat[:, 0] = 1.0                        # the free parameter acts, the extension not
    at_zero = _fit({"k": 1.0, "hyp.T": 1e-15}, flat)
    assert _tested([at_zero, at_zero], ext, flat) is False
    moved = _fit({"k": 1.0, "hyp.T": 0.05}, flat)
    assert _tested([at_zero, moved], ext, flat) is True
    # started away from neutral and pulled back: the data rejected it (a test)
    assert _tested([at_zero], ext, flat, [np.array([1.0, 0.3])]) is True
    assert _tested([at_zero], ext, flat, [np.array([1.0, 0.0])]) is False
    steep = flat.copy()
    steep[:, 1] = 10.0                      # at its neutral value but with an effect:
    assert _tested([at_zero], ext, steep) is True   # the data pushed it there


def test_generic_basis_and_penalty():
    z = np.linspace(-1.0, 2.0, 31)
    assert np.allclose(hats(z, -1.0, 2.0, N_X).sum(axis=1), 1.0)   # partition of unity
    P = penalty()
    lin = np.concatenate([np.linspace(0, 1, N_X), 2 - np.linspace(0, 3, N_V)])
    assert np.allclose(P @ lin, 0.0)         # a linear term is not penalised
    vals = {f"gen.a{i}": 2.0 * i for i in range(N_X)} | {f"gen.b{j}": 0.0 for j in range(N_V)}
    sh = shape(vals, "gen", (0.0, N_X - 1.0, -1.0, 1.0))
    assert np.allclose(sh["f_x"], 2.0 * sh["x"])   # knots at 0..N_X-1: weight 2i at x = i


def test_task_and_result_types_pickle():
    free = (Param("k", 3.0, 1.0, 10.0, 1.0, 5.0),)
    task = FitTask(Problem("m.py", "d", "lib", free), Candidate("h", "x"), free,
                   (["k"], np.ones((3, 1))), 60.0)
    f = _fit({"k": 1.0}, np.ones((4, 1)))
    res = CandidateFit(task.candidate, f, {"E": np.zeros(4)}, None, 1.0, Starts(5, 2, 2))
    back = pickle.loads(pickle.dumps((task, res)))
    assert back[0].candidate == task.candidate and back[1].starts.converged == 2
