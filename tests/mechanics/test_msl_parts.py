"""The MSL-shaped translational and rotational parts (issue 23) against
closed forms and independent solutions (scipy solve_ivp on hand-written
equations that share no code with the library). IDA runs at rtol 1e-10;
each tolerance is a few times the error measured with the law as written.
"""
import numpy as np
import pytest
import sympy as sp
from click.testing import CliRunner
from scipy.integrate import solve_ivp

from acausal import Model, compile_model, time
from acausal.blocks import Constant
from acausal.cli import main
from acausal.errors import ConnectionError_, ModelError, ParameterError
from acausal.mechanics import rotational as R
from acausal.mechanics import translational as T

TOL = dict(rtol=1e-10, atol=1e-12)


def run(model, t_end=1.0, step=1e-3, backend="sundae", **kw):
    res = compile_model(model).simulate(t_end=t_end, output_step=step, backend=backend,
                                        **TOL, **kw)
    assert res.status == "ok", res.message
    return res


def rel(a, b):
    """Largest |a - b| relative to the largest |b|."""
    b = np.broadcast_to(b, np.shape(a))
    return float(np.max(np.abs(np.asarray(a) - b)) / max(np.max(np.abs(b)), 1e-300))


# -- Mass, Rod ---------------------------------------------------------------------
def test_mass_flanges_sit_at_its_ends_and_every_force_counts():
    """A mass of length L: flange_a at s - L/2, flange_b at s + L/2, the
    centre flange at s; forces at all three add up: m a = F1 + F2 + F3."""
    m, L, F1, F2, F3 = 2.0, 0.6, 3.0, -1.0, 0.5
    model = Model()
    model.mass = T.Mass(m=m, L=L, s=0.2, v=0.1)
    model.f1, model.f2, model.f3 = T.Force(F1), T.Force(F2), T.Force(F3)
    model.connect(model.f1.flange, model.mass.flange_a)
    model.connect(model.f2.flange, model.mass.flange_b)
    model.connect(model.f3.flange, model.mass.flange)
    res = run(model)
    t, a = res.t, (F1 + F2 + F3) / m
    s = 0.2 + 0.1 * t + a * t ** 2 / 2
    assert rel(res["mass.s"], s) < 1e-12
    assert rel(res["mass.flange_a.s"], s - L / 2) < 1e-12
    assert rel(res["mass.flange_b.s"], s + L / 2) < 1e-12
    assert rel(res["mass.flange.s"], s) < 1e-12
    assert rel(res["mass.a"], a) < 1e-9


def test_rod_keeps_its_length_and_passes_the_force_unchanged():
    """A force pushes a mass through a massless rod: m a = F, the rod's
    flanges are L apart, flange_a takes F and flange_b gives it on."""
    m, L, F = 1.5, 0.8, 6.0
    model = Model()
    model.push = T.Force(F)
    model.rod = T.Rod(L=L)
    model.mass = T.Mass(m=m, L=0.2, s=0.0, v=0.0)
    model.connect(model.push.flange, model.rod.flange_a)
    model.connect(model.rod.flange_b, model.mass.flange_a)
    res = run(model)
    t = res.t
    assert rel(res["mass.s"], F / m * t ** 2 / 2 + 1e-300) < 1e-12
    assert rel(res["rod.flange_b.s"], res["mass.s"] - 0.1) < 1e-12
    assert rel(res["rod.flange_b.s"] - res["rod.flange_a.s"], L) < 1e-12
    assert rel(res["rod.flange_a.f"], F) < 1e-12
    assert rel(res["rod.flange_b.f"], -F) < 1e-12


def test_unconnected_mass_flanges_carry_no_force():
    """A mass used MSL's way with only flange_b connected, and the breaker's
    way with only the centre flange: the same motion on a spring."""
    m, c = 1.0, 100.0
    for flange in ("flange_b", "flange"):
        model = Model()
        model.ground = T.Fixed()
        model.spring = T.Spring(c=c)
        model.mass = T.Mass(m=m, L=0.4 if flange == "flange_b" else 0.0, s=0.1, v=0.0)
        model.connect(model.ground.flange, model.spring.flange_a)
        model.connect(model.spring.flange_b, getattr(model.mass, flange))
        res = run(model)
        x0 = 0.1 + (0.2 if flange == "flange_b" else 0.0)
        exact = x0 * np.cos(np.sqrt(c / m) * res.t)
        got = res["mass.s"] + (0.2 if flange == "flange_b" else 0.0)
        assert rel(got, exact) < 1e-7, flange


# -- compliant elements ----------------------------------------------------------
def test_damper_loss_power_integrates_to_the_lost_kinetic_energy():
    """A mass thrown against a damper: v = v0 exp(-d t/m), v_rel and s_rel
    are the damper's, and the integral of lossPower is the kinetic energy
    lost."""
    m, d, v0 = 2.0, 3.0, 4.0
    model = Model()
    model.ground = T.Fixed()
    model.damper = T.Damper(d=d)
    model.mass = T.Mass(m=m, s=0.0, v=v0)
    model.connect(model.ground.flange, model.damper.flange_a)
    model.connect(model.damper.flange_b, model.mass.flange_a)
    res = run(model, step=1e-4)
    v = v0 * np.exp(-d * res.t / m)
    assert rel(res["mass.v"], v) < 1e-8
    assert rel(res["damper.v_rel"], v) < 1e-8
    assert rel(res["damper.s_rel"], m * v0 / d * (1 - np.exp(-d * res.t / m))) < 1e-8
    lost = 0.5 * m * (v0 ** 2 - res["mass.v"][-1] ** 2)
    power = res["damper.lossPower"]
    integral = float(np.sum((power[1:] + power[:-1]) / 2 * np.diff(res.t)))
    assert integral == pytest.approx(lost, rel=1e-6)   # trapezoid rule on a 1e-4 s grid


def test_spring_damper_starts_from_its_relative_state():
    """Fixed start values on a SpringDamper's s_rel and v_rel (MSL's
    InitialConditions) set the mass's initial position and speed."""
    m, c, d = 1.0, 50.0, 0.4
    model = Model()
    model.ground = T.Fixed(s0=-1.0)
    model.sd = T.SpringDamper(c=c, d=d, s_rel0=1.0, s_rel=1.2, v_rel=-0.5)
    model.mass = T.Mass(m=m, L=1.0)
    model.connect(model.ground.flange, model.sd.flange_a)
    model.connect(model.sd.flange_b, model.mass.flange_a)
    res = run(model)
    assert res["mass.s"][0] == pytest.approx(-1.0 + 1.2 + 0.5, abs=1e-12)
    assert res["mass.v"][0] == pytest.approx(-0.5, abs=1e-12)
    w0, z = np.sqrt(c / m), d / (2 * np.sqrt(c * m))
    wd = w0 * np.sqrt(1 - z * z)
    x0, v0, t = 0.2, -0.5, res.t
    x = np.exp(-z * w0 * t) * (x0 * np.cos(wd * t) + (v0 + z * w0 * x0) / wd * np.sin(wd * t))
    assert rel(res["sd.s_rel"] - 1.0, x) < 1e-7


def _gap_solution(m, c, d, n, s_rel0, s0, v0, t_end):
    """MSL's ElastoGap law between the ground (flange_a at 0) and a mass
    (flange_b), written out for solve_ivp with the touch and lift as
    events; returns a function of time giving (s, v)."""
    def force(s, v):                       # f = flange_b.f; the mass receives -f
        if s >= s_rel0:
            return 0.0
        f_c = -c * (s_rel0 - s) ** n
        f_d = min(max(d * v, f_c), -f_c)
        return f_c + f_d

    def rhs(t, x):
        return [x[1], -force(x[0], x[1]) / m]

    def touch(t, x):
        return x[0] - s_rel0
    pieces, t0, x0 = [], 0.0, [s0, v0]
    while t0 < t_end:
        sol = solve_ivp(rhs, (t0, t_end), x0, method="DOP853", rtol=1e-12, atol=1e-14,
                        events=touch, dense_output=True)
        later = sol.t_events[0][sol.t_events[0] > t0 + 1e-9]
        t1 = later[0] if len(later) else t_end
        pieces.append((t0, t1, sol.sol))
        t0, x0 = t1, sol.sol(t1)
    def at(t):
        out = np.empty((2, len(t)))
        for k, tk in enumerate(t):
            f = next(p for a_, b_, p in pieces if tk <= b_)
            out[:, k] = f(tk)
        return out
    return at


def test_elastogap_matches_an_independent_solution_and_never_pulls():
    """A mass thrown at an ElastoGap with strong damping (n = 1.5): the
    motion matches a solve_ivp of MSL's law; the clamp keeps the contact
    force pushing (f <= 0, tension-positive) and continuous, although
    d*v_rel alone would pull while the mass rebounds."""
    m, c, d, n, s_rel0 = 1.0, 1e4, 150.0, 1.5, 0.5
    model = Model()
    model.ground = T.Fixed()
    model.gap = T.ElastoGap(c=c, d=d, n=n, s_rel0=s_rel0)
    model.mass = T.Mass(m=m, s=1.0, v=-2.0)
    model.connect(model.ground.flange, model.gap.flange_a)
    model.connect(model.gap.flange_b, model.mass.flange)
    res = run(model, t_end=0.6, step=1e-3)
    x = _gap_solution(m, c, d, n, s_rel0, 1.0, -2.0, 0.6)(res.t)
    assert rel(res["mass.s"], x[0]) < 1e-7
    assert rel(res["mass.v"], x[1]) < 1e-6
    f = res["gap.f"]
    assert f.max() <= 1e-9 and f.min() < -1.0          # pushes, never pulls
    inside = res["gap.contact"] == 1
    assert np.any(d * res["gap.v_rel"][inside] + res["gap.f_c"][inside] > 0)  # clamp at work
    assert np.all(res["gap.f"][~inside] == 0)
    names = [n_ for _, n_ in res.events]
    assert names.count("gap.touch") == 1 and names.count("gap.lift") == 1
    t_touch = [t_ for t_, n_ in res.events if n_ == "gap.touch"][0]
    assert t_touch == pytest.approx(0.25, abs=1e-9)     # 0.5 m at 2 m/s


def test_elastogap_static_deflection_follows_the_exponent():
    """A constant force pressing a damped mass into an ElastoGap settles at
    c * delta^n = F."""
    F, c, n = 20.0, 500.0, 2.5
    model = Model()
    model.ground = T.Fixed()
    model.gap = T.ElastoGap(c=c, d=30.0, n=n, s_rel0=0.3)
    model.mass = T.Mass(m=0.5, s=0.3, v=0.0)
    model.load = T.ConstantForce(f_constant=-F)
    model.connect(model.ground.flange, model.gap.flange_a)
    model.connect(model.gap.flange_b, model.mass.flange, model.load.flange)
    res = run(model, t_end=5.0, step=1e-2)
    assert 0.3 - res["mass.s"][-1] == pytest.approx((F / c) ** (1 / n), rel=1e-8)


def test_phi_nominal_given_explicitly_is_the_nominal_of_phi_rel():
    """MSL's phi_nominal / s_nominal: given, they are the nominal value of
    phi_rel / s_rel (the solver's absolute tolerance rtol*nominal on that
    unknown); left at the default they set none (earlier models keep their
    tolerances); with_nominal wins."""
    from acausal.runtime.nominal import nominal_slots
    assert R.SpringDamper(c=1.0).nominal("phi_rel") is None
    assert R.ElastoBacklash(phi_nominal=1.0).nominal("phi_rel") == 1.0
    assert R.Damper(phi_nominal=0.0).nominal("phi_rel") == 1.0       # MSL: 1 below eps
    assert R.Damper(phi_nominal=1e-3).with_nominal(phi_rel=5e-2).nominal("phi_rel") == 5e-2
    assert T.SpringDamper(s_nominal=1e-3).nominal("s_rel") == 1e-3
    assert T.Damper().nominal("s_rel") is None
    model = Model()
    model.a = R.Inertia(J=1.0, phi=0.0, w=0.0)
    model.sd = R.SpringDamper(c=100.0, d=1.0, phi_nominal=1e-3, phi_rel=0.01, w_rel=0.0)
    model.b = R.Inertia(J=1.0)
    model.connect(model.a.flange, model.sd.flange_a)
    model.connect(model.sd.flange_b, model.b.flange)
    cm = compile_model(model)
    slots = [k for k, names in enumerate(cm.slot_names()) if "sd.phi_rel" in names]
    assert slots and nominal_slots(cm)[slots[0]] == 1e-3


# -- backlash ----------------------------------------------------------------------
@pytest.mark.parametrize("cls", [R.ElastoBacklash, R.ElastoBacklash2])
def test_free_inertia_crosses_the_backlash_at_the_closed_form_times(cls):
    """An undamped inertia starting in the middle of the gap at w0: contact
    at b/2/w0, a half spring period of contact, back across the gap b at
    -w0, a half period on the other side, and so on."""
    J, c, b, w0 = 0.5, 800.0, 0.2, 1.5
    model = Model()
    model.ground = R.Fixed()
    model.eb = cls(c=c, d=0.0, b=b)
    model.body = R.Inertia(J=J, phi=0.0, w=w0)
    model.connect(model.ground.flange, model.eb.flange_a)
    model.connect(model.eb.flange_b, model.body.flange_a)
    res = run(model, t_end=1.0, step=1e-3)
    half = np.pi / np.sqrt(c / J)
    t1 = b / 2 / w0
    expected = [(t1, "eb.upper_contact"), (t1 + half, "eb.upper_release"),
                (t1 + half + b / w0, "eb.lower_contact"),
                (t1 + 2 * half + b / w0, "eb.lower_release"),
                (t1 + 2 * half + 2 * b / w0, "eb.upper_contact")]
    got = [(t, n) for t, n in res.events if n.startswith("eb.")][:5]
    assert [n for _, n in got] == [n for _, n in expected]
    for (tg, _), (te, _) in zip(got, expected):
        assert tg == pytest.approx(te, abs=1e-8)
    # in contact the spring acts from the gap's edge: phi - b/2 = w0/omega sin(...)
    omega = np.sqrt(c / J)
    sel = (res.t > t1) & (res.t < t1 + half)
    exact = b / 2 + w0 / omega * np.sin(omega * (res.t[sel] - t1))
    assert rel(res["body.phi"][sel], exact) < 1e-7


def test_backlash_damping_is_clamped_in_elastobacklash_only():
    """At the onset of contact ElastoBacklash's torque starts at 0 (the
    damping torque is limited by the spring torque), ElastoBacklash2's
    jumps to d*w_rel; neither ever pulls (tau >= 0 on the upper side,
    <= 0 on the lower)."""
    J, c, d, b, w0 = 0.5, 800.0, 8.0, 0.2, 1.5
    out = {}
    for cls in (R.ElastoBacklash, R.ElastoBacklash2):
        model = Model()
        model.ground = R.Fixed()
        model.eb = cls(c=c, d=d, b=b)
        model.body = R.Inertia(J=J, phi=0.0, w=w0)
        model.connect(model.ground.flange, model.eb.flange_a)
        model.connect(model.eb.flange_b, model.body.flange_a)
        res = run(model, t_end=0.6, step=1e-4)
        on = [t for t, n in res.events if n == "eb.upper_contact"][0]
        k = int(np.flatnonzero(res.t == on)[-1])      # the row after the event
        out[cls.__name__] = res["eb.tau"][k]
        up, low = res["eb.region"] == 1, res["eb.region"] == -1
        assert res["eb.tau"][up].min() >= -1e-9 and res["eb.tau"][low].max() <= 1e-9
        assert np.all(res["eb.tau"][res["eb.region"] == 0] == 0)
    assert out["ElastoBacklash"] == pytest.approx(0.0, abs=1e-9)
    assert out["ElastoBacklash2"] == pytest.approx(d * w0, rel=1e-6)


def test_zero_backlash_is_a_spring_damper():
    J, c, d = 0.2, 300.0, 1.0
    res = {}
    for name, elem in (("eb", R.ElastoBacklash(c=c, d=d, b=0.0)),
                       ("sd", R.SpringDamper(c=c, d=d))):
        model = Model()
        model.ground = R.Fixed()
        model.add(name, elem)
        model.body = R.Inertia(J=J, phi=0.1, w=0.0)
        model.connect(model.ground.flange, elem.flange_a)
        model.connect(elem.flange_b, model.body.flange)
        res[name] = run(model)
        assert not [e for e in res[name].events if e[1].startswith(name)]
    assert rel(res["eb"]["body.phi"], res["sd"]["body.phi"]) < 1e-12


_LOADED_BACKLASH = {}


@pytest.mark.parametrize("cls", [R.ElastoBacklash, R.ElastoBacklash2])
@pytest.mark.parametrize("load, phi0", [
    (2.0, 3 * 2.0 / 100.0),            # |load| <= c*b/4: on the line (c/3)*phi_diff
    (-2.0, -3 * 2.0 / 100.0),
    (20.0, 20.0 / 100.0 + 0.1),        # beyond 1.5*b/2: the contact law, c*(phi_diff - b/2)
])
def test_backlash_initialises_on_msls_initial_characteristic(cls, load, phi0):
    """An inertia at rest under a constant load, its acceleration fixed at
    0: the initialisation must invert the backlash's characteristic, which
    is flat in the gap (singular). MSL replaces it while initializing by a
    strictly rising one (c/3 slope inside 1.5*b/2, the contact law
    outside): phi_rel = 3*load/c inside, load/c + b/2 beyond. The run then
    goes on with the true law (in the gap: no torque, the load accelerates
    the inertia at load/J)."""
    c, b, J = 100.0, 0.2, 1.0
    if cls not in _LOADED_BACKLASH:             # one compile per class; the load is a parameter
        model = Model()
        model.ground = R.Fixed()
        model.eb = cls(c=c, d=1.0, b=b)
        model.body = R.Inertia(J=J, w=0.0, a=0.0)
        model.load = R.ConstantTorque(tau_constant=1.0)
        model.connect(model.ground.flange, model.eb.flange_a)
        model.connect(model.eb.flange_b, model.body.flange_a)
        model.connect(model.body.flange_b, model.load.flange)
        _LOADED_BACKLASH[cls] = compile_model(model)
    res = _LOADED_BACKLASH[cls].simulate(t_end=0.01, rtol=1e-10, atol=1e-12,
                                         params={"load.tau_constant": load})
    assert res["eb.phi_rel"][0] == pytest.approx(phi0, rel=1e-12, abs=1e-14)
    assert res.final()["eb.initializing"] == 0
    if abs(phi0) < 0.1:           # in the gap after the start: free flight under the load
        t = res.t
        assert rel(res["eb.phi_rel"], phi0 + load / J * t ** 2 / 2) < 1e-8
    else:                         # in contact: at rest, holding the load
        assert np.max(np.abs(res["eb.phi_rel"] - phi0)) < 1e-9
        assert np.max(np.abs(res["eb.tau"] - load)) < 1e-6


def test_disc_turns_its_right_flange_by_delta_phi_and_relative_states_read_it():
    """A Disc between a motor-driven inertia and a spring-loaded one: a
    rigid offset deltaPhi, the torque passes unchanged; RelativeStates
    across it reads phi_rel = deltaPhi, w_rel = 0 and takes no torque."""
    J1, J2, c, dphi = 0.2, 0.3, 40.0, 0.25
    model = Model()
    model.a = R.Inertia(J=J1, phi=0.0, w=0.0)
    model.disc = R.Disc(deltaPhi=dphi)
    model.b = R.Inertia(J=J2)
    model.spring = R.Spring(c=c, phi_rel0=dphi)
    model.ground = R.Fixed()
    model.motor = R.ConstantTorque(tau_constant=1.0)
    model.rel = R.RelativeStates()
    model.connect(model.motor.flange, model.a.flange_a)
    model.connect(model.a.flange_b, model.disc.flange_a, model.rel.flange_a)
    model.connect(model.disc.flange_b, model.b.flange_a, model.rel.flange_b)
    model.connect(model.b.flange_b, model.spring.flange_b)
    model.connect(model.spring.flange_a, model.ground.flange)
    res = run(model)
    w = np.sqrt(c / (J1 + J2))
    assert rel(res["a.phi"], 1.0 / c * (1 - np.cos(w * res.t))) < 1e-8
    assert rel(res["b.phi"] - res["a.phi"], dphi) < 1e-12
    assert rel(res["rel.phi_rel"], dphi) < 1e-12
    assert np.max(np.abs(res["rel.w_rel"])) < 1e-10


# -- gears and wheels --------------------------------------------------------------
def test_ideal_gear_support_conserves_angular_momentum():
    """A motor between a free housing and the input shaft of a gear whose
    support is that housing: no external torque, so J_a w_a + J_b w_b +
    J_h w_h stays 0; the kinematics hold relative to the housing."""
    Ja, Jb, Jh, ratio, tau = 0.1, 2.0, 5.0, 4.0, 3.0
    model = Model()
    model.housing = R.Inertia(J=Jh, phi=0.0, w=0.0)
    model.motor = R.Torque2(tau)
    model.a = R.Inertia(J=Ja, phi=0.0, w=0.0)
    model.gear = R.IdealGear(ratio=ratio, useSupport=True)
    model.b = R.Inertia(J=Jb)
    model.connect(model.motor.flange_a, model.housing.flange, model.gear.support)
    model.connect(model.motor.flange_b, model.a.flange, model.gear.flange_a)
    model.connect(model.gear.flange_b, model.b.flange)
    res = run(model)
    L = Ja * res["a.w"] + Jb * res["b.w"] + Jh * res["housing.w"]
    assert np.max(np.abs(L)) < 1e-9 * np.max(np.abs(Ja * res["a.w"]))
    assert rel(res["a.phi"] - res["housing.phi"],
               ratio * (res["b.phi"] - res["housing.phi"])) < 1e-10
    assert rel(res["gear.support.tau"], -(res["gear.flange_a.tau"] + res["gear.flange_b.tau"])) \
        < 1e-12
    # closed form: constant accelerations from the three bodies' balances
    # (g = torque of the gear on shaft a) and the kinematics relative to the housing
    A = np.array([[Ja, 0, 0, -1], [0, Jb, 0, ratio], [0, 0, Jh, -(ratio - 1)],
                  [1, -ratio, ratio - 1, 0]])
    acc = np.linalg.solve(A, [tau, 0, -tau, 0])
    for k, name in enumerate(("a", "b", "housing")):
        assert rel(res[f"{name}.w"], acc[k] * res.t + 1e-300) < 1e-10, name


def test_ideal_gear_grounded_equals_support_on_the_ground():
    """useSupport=False is the support fixed to the ground (FirstGrounded vs
    First): the same motion to round-off."""
    out = []
    for use in (False, True):
        model = Model()
        model.motor = R.Torque(2.0 * sp.sin(7 * time), useSupport=use)
        model.a = R.Inertia(J=0.1, phi=0.0, w=0.0)
        model.gear = R.IdealGear(ratio=-3.0, useSupport=use)
        model.b = R.Inertia(J=1.0)
        model.spring = R.Spring(c=50.0)
        model.ground = R.Fixed()
        model.connect(model.motor.flange, model.a.flange_a)
        model.connect(model.a.flange_b, model.gear.flange_a)
        model.connect(model.gear.flange_b, model.b.flange_a)
        model.connect(model.b.flange_b, model.spring.flange_a)
        model.connect(model.spring.flange_b, model.ground.flange)
        if use:
            model.connect(model.motor.support, model.gear.support, model.ground.flange)
        out.append(run(model))
    assert rel(out[0]["b.phi"], out[1]["b.phi"]) < 1e-9


def test_levers_still_exports_the_gear():
    from acausal.mechanics.levers import IdealGear
    assert IdealGear is R.IdealGear


def test_rolling_wheel_conserves_power_and_matches_the_closed_form():
    """A constant torque drives an inertia on a wheel of radius r pushing a
    mass against a damper: s = r phi, flangeR.tau w + flangeT.f v = 0,
    (J + m r^2) dw/dt = tau - d r^2 w."""
    J, m, r, d, tau = 0.3, 2.0, 0.25, 4.0, 1.5
    model = Model()
    model.motor = R.ConstantTorque(tau_constant=tau)
    model.wheel_inertia = R.Inertia(J=J, phi=0.0, w=0.0)
    model.wheel = R.IdealRollingWheel(radius=r)
    model.mass = T.Mass(m=m)
    model.damper = T.Damper(d=d)
    model.ground = T.Fixed()
    model.connect(model.motor.flange, model.wheel_inertia.flange_a)
    model.connect(model.wheel_inertia.flange_b, model.wheel.flangeR)
    model.connect(model.wheel.flangeT, model.mass.flange_a)
    model.connect(model.mass.flange_b, model.damper.flange_b)
    model.connect(model.damper.flange_a, model.ground.flange)
    res = run(model, t_end=2.0)
    k = d * r * r / (J + m * r * r)
    w = tau / (d * r * r) * (1 - np.exp(-k * res.t))
    assert rel(res["wheel_inertia.w"], w) < 1e-8
    assert rel(res["mass.s"], r * res["wheel_inertia.phi"]) < 1e-12
    power = res["wheel.flangeR.tau"] * res["wheel_inertia.w"] + res["wheel.flangeT.f"] * res["mass.v"]
    assert np.max(np.abs(power)) < 1e-12 * np.max(np.abs(tau * w))


def test_gear_r2t_oscillator():
    """An inertia geared to a mass on a spring (phi = ratio*s): the mass
    oscillates at sqrt(k / (m + J ratio^2))."""
    J, m, k, ratio, s0 = 0.01, 0.5, 200.0, 20.0, 0.03
    model = Model()
    model.body = R.Inertia(J=J)
    model.gear = R.IdealGearR2T(ratio=ratio)
    model.mass = T.Mass(m=m, s=s0, v=0.0)
    model.spring = T.Spring(c=k)
    model.ground = T.Fixed()
    model.connect(model.body.flange, model.gear.flangeR)
    model.connect(model.gear.flangeT, model.mass.flange, model.spring.flange_b)
    model.connect(model.spring.flange_a, model.ground.flange)
    res = run(model)
    omega = np.sqrt(k / (m + J * ratio ** 2))
    assert rel(res["mass.s"], s0 * np.cos(omega * res.t)) < 1e-7
    assert rel(res["body.phi"], ratio * res["mass.s"]) < 1e-12


# -- sources -----------------------------------------------------------------------
def test_constant_force_against_quadratic_drag_reaches_tanh_speed():
    """m dv/dt = F - F_d (v/v_n)^2: v = v_t tanh(F t/(m v_t)), v_t = v_n sqrt(F/F_d)."""
    m, F, Fd, vn = 2.0, 10.0, 40.0, 3.0
    model = Model()
    model.mass = T.Mass(m=m, s=0.0, v=0.0)
    model.push = T.ConstantForce(f_constant=F)
    model.drag = T.QuadraticSpeedDependentForce(f_nominal=-Fd, v_nominal=vn,
                                                ForceDirection=False)
    model.connect(model.mass.flange, model.push.flange, model.drag.flange)
    res = run(model, t_end=2.0)
    vt = vn * np.sqrt(F / Fd)
    assert rel(res["mass.v"], vt * np.tanh(F * res.t / (m * vt))) < 1e-8
    assert rel(res["push.f"], -F) < 1e-12                # MSL: f = flange.f


def test_torque_sources_rotational_counterparts():
    """ConstantTorque against QuadraticSpeedDependentTorque: the same tanh
    law; LinearSpeedDependentTorque (TorqueDirection=False) is a damper."""
    J, tau, taud, wn, b = 0.5, 4.0, 16.0, 10.0, 2.0
    model = Model()
    model.body = R.Inertia(J=J, phi=0.0, w=0.0)
    model.motor = R.ConstantTorque(tau_constant=tau)
    model.drag = R.QuadraticSpeedDependentTorque(tau_nominal=-taud, w_nominal=wn)
    model.connect(model.body.flange, model.motor.flange, model.drag.flange)
    res = run(model, t_end=2.0)
    wt = wn * np.sqrt(tau / taud)
    assert rel(res["body.w"], wt * np.tanh(tau * res.t / (J * wt))) < 1e-8
    model = Model()
    model.body = R.Inertia(J=J, phi=0.0, w=3.0)
    model.visc = R.LinearSpeedDependentTorque(tau_nominal=-b, w_nominal=1.0,
                                              TorqueDirection=False)
    model.connect(model.body.flange, model.visc.flange)
    res = run(model)
    assert rel(res["body.w"], 3.0 * np.exp(-b * res.t / J)) < 1e-8


@pytest.mark.parametrize("reg", ["Linear", "Exp"])
def test_sign_force_brakes_at_constant_deceleration_then_regularises(reg):
    """SignForce as a load (f_nominal < 0): the body decelerates at F/m
    while its speed is far above v0; with the linear regularisation it
    then decays exponentially, v = v0 exp(-F (t - t0)/(m v0))."""
    m, F, v0, vi = 1.0, 2.0, 0.1, 1.0
    model = Model()
    model.mass = T.Mass(m=m, s=0.0, v=vi)
    model.brake = T.SignForce(f_nominal=-F, v0=v0, reg=reg)
    model.connect(model.mass.flange, model.brake.flange)
    res = run(model, t_end=1.0)
    t0 = (vi - v0) / (F / m)                 # reaches v0
    if reg == "Linear":
        v = np.where(res.t < t0, vi - F / m * res.t, v0 * np.exp(-F * (res.t - t0) / (m * v0)))
        assert rel(res["mass.v"], v) < 1e-7
    else:                                     # 2/(1+exp(-v/(0.01 v0)))-1 = 1 - 2e-43 at v0
        early = res.t < t0
        assert rel(res["mass.v"][early], vi - F / m * res.t[early]) < 1e-8
        assert abs(res["mass.v"][-1]) < 0.01 * v0


def test_sign_torque_regularisations_are_continuous_and_odd():
    from acausal.mechanics.translational.sources import regularized_sign
    x, x0 = sp.Symbol("x"), 0.2
    for reg in ("Exp", "Sine", "Linear", "CoSine"):
        f = sp.lambdify(x, regularized_sign(x, x0, reg))
        for v in (-1.0, -0.2, -0.05, 0.05, 0.2, 1.0):
            assert f(-v) == pytest.approx(-f(v), abs=1e-15)
        assert f(x0 * (1 + 1e-12)) == pytest.approx(f(x0 * (1 - 1e-12)), abs=1e-9)
        assert f(2.0) == pytest.approx(1.0, abs=1e-12)
    J, tau = 1.0, 0.5
    model = Model()
    model.body = R.Inertia(J=J, phi=0.0, w=1.0)
    model.brake = R.SignTorque(tau_nominal=-tau, w0=0.05, reg="Sine")
    model.connect(model.body.flange, model.brake.flange)
    res = run(model, t_end=1.0)
    early = res.t < (1.0 - 0.05) / tau
    assert rel(res["body.w"][early], 1.0 - tau / J * res.t[early]) < 1e-8


def test_linear_speed_dependent_force_is_a_viscous_load():
    m, b, vi = 2.0, 3.0, 1.5
    for direction in (False, True):
        model = Model()
        model.mass = T.Mass(m=m, s=0.0, v=vi)
        model.visc = T.LinearSpeedDependentForce(f_nominal=-b, v_nominal=1.0,
                                                 ForceDirection=direction)
        model.connect(model.mass.flange, model.visc.flange)
        res = run(model)
        # v > 0 throughout: |v| = v, both directions give m dv/dt = -b v
        assert rel(res["mass.v"], vi * np.exp(-b * res.t / m)) < 1e-8


def test_rolling_resistance_decelerates_a_coasting_mass():
    """m dv/dt = -Cr W cos(atan(i)) while v > v0 (linear regularisation);
    the coefficient and the inclination may be inputs."""
    m, W, Cr, i, vi = 10.0, 98.0, 0.02, 0.1, 2.0
    model = Model()
    model.mass = T.Mass(m=m, s=0.0, v=vi)
    model.roll = T.RollingResistance(fWeight=W, useCrInput=True, useInclinationInput=True,
                                     reg="Linear", v0=1e-3)
    model.cr, model.incl = Constant(k=Cr), Constant(k=i)
    model.connect(model.cr.y, model.roll.cr)
    model.connect(model.incl.y, model.roll.inclination)
    model.connect(model.mass.flange, model.roll.flange)
    res = run(model, t_end=5.0)
    dec = Cr * W * np.cos(np.arctan(i)) / m
    assert rel(res["mass.v"], vi - dec * res.t) < 1e-9
    assert rel(res["roll.f_nominal"], -Cr * W * np.cos(np.arctan(i))) < 1e-12


def test_vehicle_reaches_the_speed_where_the_resistances_balance_the_torque():
    """A Vehicle with a drive-train inertia and a wind input, driven by a
    constant torque, settles where tau/R = Cd A rho/2 (v - v_wind)^2 +
    Cr m g; its s, v are its mass's."""
    m, J, R_, tau, Cd, A, rho, Cr, vw = 10.0, 0.1, 0.3, 6.0, 0.6, 1.0, 1.0, 0.01, 2.0
    model = Model()
    model.car = T.Vehicle(m=m, J=J, R=R_, A=A, Cd=Cd, rho=rho, CrConstant=Cr,
                          useWindInput=True, s=0.0, v=0.0)
    model.wind = Constant(k=vw)
    model.motor = R.ConstantTorque(tau_constant=tau)
    model.connect(model.wind.y, model.car.vWind)
    model.connect(model.motor.flange, model.car.flangeR)
    res = run(model, t_end=40.0, step=0.1)
    v_end = vw + np.sqrt((tau / R_ - Cr * m * 9.80665) / (Cd * A * rho / 2))
    assert res["car.v"][-1] == pytest.approx(v_end, rel=1e-6)
    assert rel(res["car.s"], res["car.mass.s"]) < 1e-12
    assert rel(res["car.inertia.w"] * R_, res["car.v"]) < 1e-10


def test_force_step_and_torque_step_are_time_events():
    m, J, F, tq, t0 = 2.0, 0.5, 3.0, 1.0, 0.37
    model = Model()
    model.mass = T.Mass(m=m, s=0.0, v=0.0)
    model.step = T.ForceStep(stepForce=F, offsetForce=0.5, startTime=t0)
    model.body = R.Inertia(J=J, phi=0.0, w=0.0)
    model.tstep = R.TorqueStep(stepTorque=tq, offsetTorque=0.0, startTime=t0)
    model.connect(model.mass.flange, model.step.flange)
    model.connect(model.body.flange, model.tstep.flange)
    res = run(model)
    assert any(abs(t - t0) < 1e-12 for t, _ in res.events)
    v = 0.5 / m * res.t + np.where(res.t > t0, F / m * (res.t - t0), 0.0)
    assert rel(res["mass.v"], v) < 1e-10
    assert rel(res["body.w"], np.where(res.t > t0, tq / J * (res.t - t0), 0.0)) < 1e-10


def test_force2_pushes_two_masses_apart_and_keeps_momentum():
    m1, m2, F = 1.0, 3.0, 2.0
    model = Model()
    model.a = T.Mass(m=m1, s=0.0, v=0.0)
    model.b = T.Mass(m=m2, s=1.0, v=0.0)
    model.push = T.Force2()
    model.k = Constant(k=F)
    model.connect(model.k.y, model.push.f)
    model.connect(model.a.flange, model.push.flange_a)
    model.connect(model.push.flange_b, model.b.flange)
    res = run(model)
    assert rel(res["a.v"], -F / m1 * res.t + 1e-300) < 1e-12
    assert rel(res["b.v"], F / m2 * res.t + 1e-300) < 1e-12


def test_force_with_support_reacts_on_its_support():
    """A force between a mass and a free 'housing' mass through the support:
    momentum stays 0, the support takes -flange.f."""
    model = Model()
    model.load = T.Mass(m=1.0, s=0.0, v=0.0)
    model.housing = T.Mass(m=4.0, s=0.0, v=0.0)
    model.push = T.Force(f=2.0, useSupport=True)
    model.connect(model.push.flange, model.load.flange)
    model.connect(model.push.support, model.housing.flange)
    res = run(model)
    assert np.max(np.abs(res["load.v"] + 4.0 * res["housing.v"])) < 1e-12
    assert rel(res["push.s"], res["load.s"] - res["housing.s"]) < 1e-12
    assert rel(res["load.v"], 2.0 * res.t + 1e-300) < 1e-12


def test_torque_input_from_a_signal_and_torque2():
    model = Model()
    model.k = Constant(k=3.0)
    model.motor = R.Torque()
    model.body = R.Inertia(J=2.0, phi=0.0, w=0.0)
    model.connect(model.k.y, model.motor.tau)
    model.connect(model.motor.flange, model.body.flange)
    res = run(model)
    assert rel(res["body.w"], 1.5 * res.t + 1e-300) < 1e-12
    assert rel(res["motor.tau"], 3.0) < 1e-12


# -- sensors -----------------------------------------------------------------------
def test_translational_sensors_on_a_driven_mass():
    """Power, multi and relative-acceleration sensors on a sine-driven mass:
    power = the rate of the kinetic energy downstream, MultiSensor's f is
    the driving force (MSL's sign, f = flange_a.f) and power = f v."""
    m, A, W = 0.5, 4.0, 6.0
    model = Model()
    model.drive = T.Force(A * sp.sin(W * time))
    model.power = T.PowerSensor()
    model.multi = T.MultiSensor()
    model.mass = T.Mass(m=m, s=0.0, v=0.0)
    model.ground = T.Fixed()
    model.acc = T.RelAccSensor()
    model.speed = T.RelSpeedSensor()
    model.pos = T.RelPositionSensor()
    model.connect(model.drive.flange, model.power.flange_a)
    model.connect(model.power.flange_b, model.multi.flange_a)
    model.connect(model.multi.flange_b, model.mass.flange_a, model.acc.flange_b,
                  model.speed.flange_b, model.pos.flange_b)
    model.connect(model.ground.flange, model.acc.flange_a, model.speed.flange_a,
                  model.pos.flange_a)
    res = run(model, step=1e-3)
    t = res.t
    f = A * np.sin(W * t)
    v = A / (m * W) * (1 - np.cos(W * t))
    assert rel(res["mass.v"], v) < 1e-8
    assert rel(res["power.power"], f * v) < 1e-8
    assert rel(res["multi.power"], f * v) < 1e-8
    assert rel(res["multi.f"], f) < 1e-8
    assert rel(res["multi.v"], v) < 1e-8
    assert rel(res["speed.v_rel"], v) < 1e-8
    assert rel(res["pos.s_rel"], res["mass.s"]) < 1e-12
    assert rel(res["acc.a_rel"], f / m) < 1e-6


def test_rotational_power_and_multi_sensors():
    J, A, W = 0.2, 1.0, 5.0
    model = Model()
    model.drive = R.Torque(A * sp.sin(W * time))
    model.power = R.PowerSensor()
    model.multi = R.MultiSensor()
    model.body = R.Inertia(J=J, phi=0.0, w=0.0)
    model.ground = R.Fixed()
    model.acc = R.RelAccSensor()
    model.connect(model.drive.flange, model.power.flange_a)
    model.connect(model.power.flange_b, model.multi.flange_a)
    model.connect(model.multi.flange_b, model.body.flange, model.acc.flange_b)
    model.connect(model.ground.flange, model.acc.flange_a)
    res = run(model)
    tau = A * np.sin(W * res.t)
    w = A / (J * W) * (1 - np.cos(W * res.t))
    assert rel(res["power.power"], tau * w) < 1e-8
    assert rel(res["multi.tau"], tau) < 1e-8
    assert rel(res["multi.w"], w) < 1e-8
    assert rel(res["multi.power"], tau * w) < 1e-8
    assert rel(res["acc.a_rel"], tau / J) < 1e-6


def test_sensor_outputs_are_signals():
    """A sensor's output drives a block input (MSL's RealOutput)."""
    from acausal.blocks import Gain
    model = Model()
    model.mass = T.Mass(m=1.0, s=0.0, v=1.0)
    model.sensor = T.SpeedSensor()
    model.gain = Gain(k=-2.0)
    model.brake = T.Force()
    model.connect(model.mass.flange, model.sensor.flange, model.brake.flange)
    model.connect(model.sensor.v, model.gain.u)
    model.connect(model.gain.y, model.brake.f)
    res = run(model)
    assert rel(res["mass.v"], np.exp(-2.0 * res.t)) < 1e-8


# -- bad input ---------------------------------------------------------------------
@pytest.mark.parametrize("build, words", [
    (lambda: T.Mass(m=-1.0), ["Mass.m = -1 [kg] must be > 0"]),
    (lambda: T.Rod(L=-0.5), ["Rod.L = -0.5 [m] must be >= 0"]),
    (lambda: R.IdealGear(ratio=0), ["IdealGear.ratio = 0", "non-zero"]),
    (lambda: R.IdealGearR2T(ratio=0.0), ["IdealGearR2T.ratio = 0", "non-zero"]),
    (lambda: R.IdealRollingWheel(radius=0.0), ["IdealRollingWheel.radius = 0 [m] must be > 0"]),
    (lambda: R.ElastoBacklash(b=-0.1), ["ElastoBacklash.b = -0.1 [rad] must be >= 0"]),
    (lambda: R.ElastoBacklash2(c=0.0), ["ElastoBacklash2.c = 0", "must be > 0"]),
    (lambda: T.ElastoGap(n=0.5), ["ElastoGap.n = 0.5 [1] must be >= 1"]),
    (lambda: R.Inertia(J=0.0), ["Inertia.J = 0", "must be > 0"]),
    (lambda: T.SignForce(reg="Tanh"), ["SignForce.reg = 'Tanh' is not one of"]),
    (lambda: T.QuadraticSpeedDependentForce(v_nominal=0.0), ["v_nominal = 0", "must be > 0"]),
])
def test_bad_parameter_is_one_line_naming_it(build, words):
    with pytest.raises(ParameterError) as info:
        build()
    msg = str(info.value)
    assert "\n" not in msg
    for w in words:
        assert w in msg, (w, msg)


def test_disabled_support_is_named_with_its_flag():
    model = Model()
    model.torque = R.Torque(1.0)
    with pytest.raises(ModelError) as info:
        model.torque.support
    msg = str(info.value)
    assert "\n" not in msg and "torque" in msg and "useSupport=True" in msg
    model.wheel = R.IdealRollingWheel(radius=0.3)
    with pytest.raises(ModelError, match="useSupportT=True"):
        model.wheel.supportT


def test_force_input_left_unconnected_is_named():
    model = Model()
    model.mass = T.Mass(m=1.0, s=0.0, v=0.0)
    model.force = T.Force()
    model.connect(model.force.flange, model.mass.flange)
    with pytest.raises(ConnectionError_, match=r"^force\.f: input not connected"):
        compile_model(model)


def test_bad_part_in_a_model_file_is_one_line_on_the_command_line(tmp_path):
    path = tmp_path / "rod.py"
    path.write_text("from acausal import Model\n"
                    "from acausal.mechanics.translational import Rod\n"
                    "model = Model()\n"
                    "model.rod = Rod(L=-2.0)\n")
    r = CliRunner().invoke(main, ["simulate", str(path)])
    assert r.exit_code == 2, r.output
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in r.output
    assert "rod.py:4" in lines[0] and "Rod.L = -2 [m] must be >= 0" in lines[0]
