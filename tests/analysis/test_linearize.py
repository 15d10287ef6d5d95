"""acausal.analysis: linearisation against closed forms and against finite
differences of simulated responses; trim against closed-form equilibria;
bad input in one line."""
import json
import math
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner
from scipy.linalg import expm
from scipy.optimize import brentq

from acausal import Model, compile_model
from acausal.analysis import linearize, trim
from acausal.analysis.linearize import RunSettings
from acausal.blocks.sources import Constant
from acausal.cli import main
from acausal.errors import AnalysisError
from acausal.mechanics import rotational as rot
from acausal.mechanics import translational as tr
from acausal.mechanics.contact import EndStop
from acausal.mechanics.planar import Body, BodyShape, Revolute, World
from acausal.mechanics.planar.linkages import FourBarLinkage
from acausal.modelfile import compile_file

ROOT = Path(__file__).resolve().parents[2]
G_N = 9.80665
M, C, D = 2.0, 50.0, 3.0           # the damped oscillator


def oscillator(signal=False):
    """A mass on a spring-damper to a wall, driven by a force u (a declared
    input, or a Constant source wired into the force's RealInput)."""
    m = Model()
    m.wall = tr.Fixed()
    m.sd = tr.SpringDamper(c=C, d=D)
    m.mass = tr.Mass(m=M, s=0.1, v=0.0)
    if signal:
        m.force = tr.Force()
        m.u = Constant(k=0.0)
        m.connect(m.u.y, m.force.f)
    else:
        u = m.parameter("u", 0.0, "N", "driving force")
        m.force = tr.Force(f=u)
    m.connect(m.wall.flange, m.sd.flange_a)
    m.connect(m.sd.flange_b, m.mass.flange, m.force.flange)
    return m


def test_oscillator_eigenvalues_against_the_closed_form():
    """models/examples/oscillator.py: x'' = -(c/m) x, eigenvalues +-10 i."""
    _, cm = compile_file(ROOT / "models" / "examples" / "oscillator.py")
    lin = linearize(cm)
    assert lin.states == ["mass.s", "mass.v"]
    ev = lin.eigenvalues
    assert np.allclose(ev, [-10j, 10j], atol=1e-12)
    assert np.allclose(lin.A, [[0, 1], [-100, 0]], atol=1e-12)


@pytest.mark.parametrize("signal", [False, True], ids=["parameter", "signal"])
def test_damped_oscillator_abcd_against_the_closed_form(signal):
    """A, B, C, D of m x'' + d x' + c x = u with the outputs the spring
    force and the acceleration (an output through the states' derivative:
    C = [-c/m, -d/m], D = 1/m); the input a declared parameter or a
    Constant source wired into the force's RealInput."""
    cm = compile_model(oscillator(signal))
    name = "force.f" if signal else "u"
    lin = linearize(cm, inputs={name: 4.0}, outputs=["sd.f", "mass.a"])
    assert lin.inputs == [name] and lin.u0[0] == pytest.approx(4.0)
    assert np.allclose(lin.A, [[0, 1], [-C / M, -D / M]], rtol=1e-12, atol=1e-12)
    assert np.allclose(lin.B, [[0], [1 / M]], rtol=1e-12, atol=1e-12)
    assert np.allclose(lin.C, [[C, D], [-C / M, -D / M]], rtol=1e-12, atol=1e-12)
    assert np.allclose(lin.D, [[0], [1 / M]], rtol=1e-12, atol=1e-12)
    zeta = D / (2 * M)
    wd = math.sqrt(C / M - zeta**2)
    assert np.allclose(lin.eigenvalues, [-zeta - 1j * wd, -zeta + 1j * wd], atol=1e-12)
    # the point: the start, with the force u = 4 N and the spring at 0.1 m
    assert lin.y0[0] == pytest.approx(C * 0.1) and lin.y0[1] == pytest.approx((4 - 5) / M)


def pendulum(d=0.1, phi=0.0, torque=True):
    """MSL's Pendulum in the plane (a body of 1 kg, centre of mass 0.5 m
    from the pin, I = 0.001 kg m^2, a damper d on the pin), with a torque
    input u on the pin's axis."""
    m = Model()
    m.world = World()
    m.rev = Revolute(phi=phi, w=0.0)
    m.damper = rot.Damper(d=d)
    m.body = BodyShape(m=1.0, I=0.001, r_CM_x=0.5)
    m.connect(m.world.frame_b, m.rev.frame_a)
    m.connect(m.damper.flange_b, m.rev.axis)
    m.connect(m.rev.support, m.damper.flange_a)
    m.connect(m.body.frame_a, m.rev.frame_b)
    if torque:
        u = m.parameter("u", 0.0, "N*m", "torque on the pin")
        m.torque = rot.Torque(tau=u)
        m.connect(m.torque.flange, m.rev.axis)
    return m


J, MGL, DAMP = 0.001 + 0.25, G_N * 0.5, 0.1      # about the pin


def test_pendulum_lower_and_upper_equilibria_against_the_closed_form():
    """J th'' = -d th' - m g L cos(th) + u: about the hanging equilibrium
    (th = -pi/2) lambda = -z +- i sqrt(mgL/J - z^2), z = d/(2J); about the
    upright one (th = pi/2) lambda = -z +- sqrt(mgL/J + z^2), one unstable.
    Both from trim (the hanging one from the horizontal start, the upright
    from a start near it) and from given states."""
    cm = compile_model(pendulum())
    z = DAMP / (2 * J)
    low = [-z - 1j * math.sqrt(MGL / J - z**2), -z + 1j * math.sqrt(MGL / J - z**2)]
    high = [-z - math.sqrt(MGL / J + z**2), -z + math.sqrt(MGL / J + z**2)]
    hanging = trim(cm)
    assert hanging["rev.phi"] == pytest.approx(-math.pi / 2, abs=1e-12)
    upright = trim(cm, start={"rev.phi": 1.3})
    assert upright["rev.phi"] == pytest.approx(math.pi / 2, abs=1e-12)
    for at, ref in ((hanging, low), (upright, high),
                    ({"rev.phi": -math.pi / 2, "rev.w": 0.0}, low),
                    ({"body.phi": math.pi / 2, "rev.w": 0.0}, high)):
        lin = linearize(cm, at=at, inputs=["u"], outputs=["body.x"])
        assert np.allclose(lin.eigenvalues, ref, rtol=1e-10, atol=1e-10), at
        assert np.allclose(lin.B, [[0], [1 / J]], rtol=1e-10, atol=1e-12)
        s = math.sin(lin.x0[0])
        assert np.allclose(lin.C, [[-0.5 * s, 0]], atol=1e-12)    # body.x = L cos(th)
    assert max(linearize(cm, at=upright).eigenvalues.real) > 4.0


def _sim_states(cm, starts, u, T, ts=None):
    """The states (rev.phi, rev.w) at T from the given start, torque u."""
    res = cm.simulate(t_end=T, params={"rev.phi": starts[0], "rev.w": starts[1], "u": u},
                      output_times=[0.0, T], rtol=1e-12, atol=1e-14)
    return np.array([res["rev.phi"][-1], res["rev.w"][-1]]), res


def test_a_and_b_against_finite_differences_of_the_simulated_response():
    """About an equilibrium held by a torque (th0 = -1 rad, u0 = m g L
    cos(th0)), deviations of the simulated states after T = 0.3 s from
    perturbed starts and inputs (central differences) equal exp(A T) and
    int_0^T exp(A s) ds B. Away from equilibrium, central differences of
    the simulated start derivative x'(0) give A's columns and B."""
    cm = compile_model(pendulum(phi=-1.0))
    th0 = -1.0
    u0 = MGL * math.cos(th0)
    lin = linearize(cm, at={"rev.phi": th0, "rev.w": 0.0}, inputs={"u": u0})
    x0, T = np.array([th0, 0.0]), 0.3
    base, _ = _sim_states(cm, x0, u0, T)
    assert np.allclose(base, x0, atol=1e-10)                 # it is an equilibrium
    h = 1e-5
    Phi = np.column_stack([(_sim_states(cm, x0 + h * e, u0, T)[0]
                            - _sim_states(cm, x0 - h * e, u0, T)[0]) / (2 * h)
                           for e in np.eye(2)])
    Gam = (_sim_states(cm, x0, u0 + h, T)[0] - _sim_states(cm, x0, u0 - h, T)[0]) / (2 * h)
    big = expm(np.block([[lin.A, lin.B], [np.zeros((1, 3))]]) * T)
    assert np.allclose(Phi, big[:2, :2], rtol=1e-6, atol=1e-7)
    assert np.allclose(Gam, big[:2, 2], rtol=1e-6, atol=1e-7)
    # away from equilibrium: x' at the start of simulated runs
    x1, u1 = np.array([0.4, 1.5]), 0.7
    lin1 = linearize(cm, at={"rev.phi": x1[0], "rev.w": x1[1]}, inputs={"u": u1})

    def rate(x, u):
        res = cm.simulate(t_end=0.0, output_step=0,
                          params={"rev.phi": x[0], "rev.w": x[1], "u": u})
        k = [cm.dae.y.index(s) for s in cm.dae.y[:2]]
        return res.yp[0][k]
    A_fd = np.column_stack([(rate(x1 + h * e, u1) - rate(x1 - h * e, u1)) / (2 * h)
                            for e in np.eye(2)])
    B_fd = (rate(x1, u1 + h) - rate(x1, u1 - h)) / (2 * h)
    assert np.allclose(lin1.A, A_fd, rtol=1e-7, atol=1e-7)
    assert np.allclose(lin1.B[:, 0], B_fd, rtol=1e-7, atol=1e-7)


def test_linearisation_at_a_simulated_time_and_from_a_result():
    cm = compile_model(pendulum(torque=False))
    res = cm.simulate(t_end=0.7, output_step=0.1, rtol=1e-10, atol=1e-12)
    a = linearize(cm, at=0.7, run=RunSettings(rtol=1e-10, atol=1e-12))
    b = linearize(cm, at=res)
    assert a.t == pytest.approx(0.7) and b.t == pytest.approx(0.7)
    assert np.allclose(a.x0, b.x0, atol=1e-8)
    th, w = b.x0
    assert np.allclose(b.A, [[0, 1], [MGL * math.sin(th) / J, -DAMP / J]], rtol=1e-10)


def test_trim_holds_a_pendulum_with_the_torque_it_solves_for():
    cm = compile_model(pendulum())
    eq = trim(cm, hold={"rev.phi": -math.pi / 3}, free=["u"])
    assert eq.inputs["u"] == pytest.approx(MGL * 0.5, rel=1e-12)
    assert eq["rev.phi"] == pytest.approx(-math.pi / 3)
    # it holds: a run from there with that torque stays put
    res = cm.simulate(t_end=1.0, params={"rev.phi": -math.pi / 3, "rev.w": 0.0, **eq.params},
                      rtol=1e-10, atol=1e-12)
    assert np.max(np.abs(res["rev.phi"] + math.pi / 3)) < 1e-9


def latch(preload=40.0, K=1e8, s0=0.0):
    """A mass pressed by a preloaded spring (compressed: it pushes the
    mass along +s with preload + c * compression) against a Hertz end stop
    at s = 0 (a latch face): it holds still with the stop indented by
    delta, K delta^1.5 = preload - c delta."""
    m = Model()
    m.wall = tr.Fixed(s0=-0.05)
    m.spring = tr.Spring(c=2000.0, s_rel0=0.05, f0=-preload)
    m.mass = tr.Mass(m=0.2, s=s0 + 1e-6, v=0.0)
    m.stop = EndStop(s_limit=s0, side="upper", K=K, e=0.8)
    m.connect(m.wall.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.mass.flange, m.stop.flange)
    return m


def test_trim_finds_a_preloaded_latch_holding_still():
    cm = compile_model(latch())
    eq = trim(cm)
    delta = brentq(lambda x: 1e8 * x**1.5 - (40.0 - 2000.0 * x), 0.0, 1e-3, xtol=1e-16)
    assert eq["mass.s"] == pytest.approx(delta, rel=1e-9)
    assert eq["stop.fc"] == pytest.approx(40.0 - 2000.0 * delta, rel=1e-9)
    assert eq["mass.v"] == 0.0
    # it holds still when simulated from there
    res = cm.simulate(t_end=0.05, params={"mass.s": eq["mass.s"]}, rtol=1e-10, atol=1e-14)
    assert np.max(np.abs(res["mass.s"] - delta)) < 1e-9 * delta + 1e-15
    # linearised in contact (Lankarani-Nikravesh, F = K D^1.5 (1 + chi D' / v_i)):
    # m x'' = -(1.5 K delta^0.5 + c) x - K delta^1.5 chi / v_i x', with
    # chi = 3 (1 - e^2)/4 and v_i = v_min = 1e-4 m/s (closed at the start)
    A = linearize(cm, at=eq).A
    chi = 3 * (1 - 0.8**2) / 4
    assert A[1, 0] == pytest.approx(-(1.5e8 * delta**0.5 + 2000.0) / 0.2, rel=1e-9)
    assert A[1, 1] == pytest.approx(-1e8 * delta**1.5 * chi / 1e-4 / 0.2, rel=1e-9)


def test_no_equilibrium_is_one_clear_line():
    """A mass pushed by a constant force with nothing to resist it."""
    m = Model()
    m.mass = tr.Mass(m=1.0, s=0.0, v=0.0)
    m.force = tr.Force(f=3.0)
    m.connect(m.force.flange, m.mass.flange)
    with pytest.raises(AnalysisError) as err:
        trim(compile_model(m))
    text = str(err.value)
    assert "\n" not in text and text.startswith("no static equilibrium") and "mass" in text


@pytest.mark.parametrize("kw, words", [
    (dict(inputs=["nope"]), "'nope' is not an input of the model"),
    (dict(inputs=["body.x"]), "body.x is a variable that the model computes"),
    (dict(outputs=["nope"]), "'nope' is not a variable of the model"),
    (dict(at={"body.x": 0.3}), "body.x is not a state of the model"),
    (dict(at={"rev.phi": 0.3, "body.phi": 0.5}), "inconsistent linearisation point"),
    (dict(at="later"), "at: expected"),
])
def test_bad_input_is_one_clear_line(kw, words):
    cm = compile_model(pendulum())
    with pytest.raises(AnalysisError) as err:
        linearize(cm, **kw)
    text = str(err.value)
    assert "\n" not in text and words in text


def test_a_point_where_a_loop_cannot_close_is_inconsistent():
    """A non-Grashof four-bar (crank 0.6 m at (1, 0), rocker 0.6 m at the
    origin, coupler 0.5 m) given a crank angle where its links cannot meet:
    the crank's end 1.6 m from the rocker's pivot, beyond 0.6 + 0.5 m."""
    m = Model()
    m.linkage = FourBarLinkage(theta_a0=math.pi, xa=1.0, a=0.6, b=0.6, c=0.5)
    m.linkage.pin_a.set(phi=math.pi, w=0.0)
    m.crank = Body(m=1.0, I=0.01)
    m.connect(m.linkage.crank, m.crank.frame)
    cm = compile_model(m)
    assert linearize(cm, at={"linkage.pin_a.phi": 3.0}).A.shape == (2, 2)
    with pytest.raises(AnalysisError) as err:
        linearize(cm, at={"linkage.pin_a.phi": 0.0})
    text = str(err.value)
    assert "\n" not in text and "inconsistent linearisation point" in text
    assert "loop" in text


def test_python_control_statespace():
    control = pytest.importorskip("control")
    cm = compile_model(oscillator())
    sys_ = linearize(cm, inputs=["u"], outputs=["mass.s"]).to_statespace()
    assert isinstance(sys_, control.StateSpace)
    assert np.allclose(np.sort_complex(sys_.poles()),
                       np.sort_complex(np.linalg.eigvals([[0, 1], [-C / M, -D / M]])))
    assert sys_.input_labels == ["u"] and sys_.output_labels == ["mass_s"]
    assert control.dcgain(sys_) == pytest.approx(1 / C)


def test_cli_prints_the_matrices_and_writes_them(tmp_path):
    out = tmp_path / "lin.json"
    r = CliRunner().invoke(main, ["linearize", str(ROOT / "models/msl/MultiBody/Pendulum.py"),
                                  "--at", "equilibrium", "--outputs", "body.x",
                                  "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert "A =" in r.output and "eigenvalues:" in r.output
    data = json.loads(out.read_text())
    z = DAMP / (2 * J)
    ev = sorted((complex(a, b) for a, b in data["eigenvalues"]), key=lambda e: e.imag)
    assert np.allclose([e.imag for e in ev], [-math.sqrt(MGL / J - z**2),
                                               math.sqrt(MGL / J - z**2)], rtol=1e-9)
    assert data["x0"][0] == pytest.approx(-math.pi / 2)
    npz = tmp_path / "lin.npz"
    r = CliRunner().invoke(main, ["linearize", str(ROOT / "models/examples/oscillator.py"),
                                  "--at", "0.25", "--out", str(npz)])
    assert r.exit_code == 0, r.output
    assert np.allclose(np.load(npz)["A"], [[0, 1], [-100, 0]])


@pytest.mark.parametrize("args, words", [
    (["--inputs", "nope"], "'nope' is not an input"),
    (["--at", "rev.phi=abc"], "is not a number"),
    (["--at", "body.x=0.2"], "body.x is not a state"),
])
def test_cli_bad_input_exits_2_with_one_line(args, words):
    r = CliRunner().invoke(main, ["linearize", str(ROOT / "models/msl/MultiBody/Pendulum.py"),
                                  *args])
    assert r.exit_code == 2
    lines = [ln for ln in r.output.splitlines() if ln.strip()]
    assert len(lines) == 1 and words in lines[0]


def test_double_pendulum_of_boxes_about_its_hanging_equilibrium():
    """models/msl/MultiBody/DoublePendulum.py (two steel BodyBoxes, m =
    7700*0.5*0.06^2 = 13.86 kg, centre c = 0.25 m, I_z = m (0.5^2 + 0.06^2)/12)
    trimmed to hanging (from its horizontal start) and linearised: the
    eigenvalues of [[0, I], [-M^-1 K, -M^-1 Dm]] with, in the joint angles,
    M = [[2I + m(2c^2 + L^2 + 2Lc), I + m(c^2 + Lc)], [., I + m c^2]],
    K = m g [[2c + L, c], [c, c]], Dm = diag(d, 0) (docs/msl_laws.md, section 6)."""
    _, cm = compile_file(ROOT / "models" / "msl" / "MultiBody" / "DoublePendulum.py")
    eq = trim(cm)
    assert eq["revolute1.phi"] == pytest.approx(-math.pi / 2, abs=1e-12)
    assert eq["revolute2.phi"] == pytest.approx(0.0, abs=1e-12)
    m, L, c, d = 7700 * 0.5 * 0.06**2, 0.5, 0.25, 0.1
    Iz = m * (L**2 + 0.06**2) / 12
    Mm = np.array([[2 * Iz + m * (2 * c**2 + L**2 + 2 * L * c), Iz + m * (c**2 + L * c)],
                   [Iz + m * (c**2 + L * c), Iz + m * c**2]])
    K = m * G_N * np.array([[2 * c + L, c], [c, c]])
    Dm = np.array([[d, 0.0], [0.0, 0.0]])
    A_ref = np.block([[np.zeros((2, 2)), np.eye(2)],
                      [-np.linalg.solve(Mm, K), -np.linalg.solve(Mm, Dm)]])
    ref = np.linalg.eigvals(A_ref)
    ev = linearize(cm, at=eq).eigenvalues
    key = (lambda e: (round(e.imag, 6), e.real))
    assert np.allclose(sorted(ev, key=key), sorted(ref, key=key), rtol=1e-9, atol=1e-12)


def test_a_point_with_its_own_parameters_refuses_other_values():
    cm = compile_model(pendulum())
    eq = trim(cm)
    with pytest.raises(AnalysisError, match="name the inputs without values"):
        linearize(cm, at=eq, inputs={"u": 1.0})
    assert linearize(cm, at=eq, inputs=["u"]).u0[0] == 0.0
