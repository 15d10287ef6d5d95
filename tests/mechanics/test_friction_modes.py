"""The friction mode machine (acausal.mechanics.frictionmodes) and MSL's
friction elements against closed forms, an independent scipy solution and
bad input.

Sign convention (acausal.lang.connectors): a friction force/torque is what
the outside applies on the element; it acts on the sliding body with the
opposite sign and has the sign of the sliding velocity.
"""
import math

import numpy as np
import pytest

from acausal import Model, compile_model
from acausal.blocks.sources import Constant, Ramp, Step
from acausal.errors import ConnectionError_, InitializationError, ParameterError
from acausal.mechanics import rotational as rot
from acausal.mechanics import translational as tr

TIGHT = dict(rtol=1e-10, atol=1e-12)


def _events(res, path):
    return [(t, n[len(path) + 1:]) for t, n in res.events if n.startswith(path + ".")]


# -- a block on a support: sticks below break-away, slides above ---------------------

def _block_on_ramp(rate, peak=1.5, f0=4.0, m=2.0, duration=None, height=None):
    """A mass on SupportFriction (Coulomb f0, break-away peak*f0), pushed by
    a force ramping at ``rate`` N/s (to ``height`` N when given)."""
    model = Model()
    model.mass = tr.Mass(m=m, s=0, v=0)
    model.fr = tr.SupportFriction(f_pos=[[0, f0]], peak=peak)
    model.force = tr.Force()
    if height is None:
        model.ramp = Ramp(height=rate * 100.0, duration=100.0)
    else:
        model.ramp = Ramp(height=height, duration=height / rate)
    model.connect(model.force.flange, model.mass.flange_a)
    model.connect(model.mass.flange_b, model.fr.flange_a)
    model.connect(model.ramp.y, model.force.f)
    return model


def test_block_slides_at_the_exact_break_away_time():
    rate, peak, f0, m = 3.0, 1.5, 4.0, 2.0
    res = compile_model(_block_on_ramp(rate, peak, f0, m)).simulate(
        t_end=4.0, output_step=0.01, **TIGHT)
    t_b = peak * f0 / rate                       # the force reaches the break-away level
    ev = _events(res, "fr")
    assert [n for _, n in ev] == ["initial_mode", "break_forward"]
    assert abs(ev[1][0] - t_b) < 1e-9
    before = res.t < t_b
    assert np.all(res["mass.s"][before] == 0.0) and np.all(res["fr.mode"][before] == 0)
    assert np.allclose(res["fr.f"][before], rate * res.t[before], rtol=1e-12, atol=1e-12)
    # after: m a = rate t - f0 (the friction drops to the sliding level)
    t = res.t[res.t > t_b]
    v = (rate / 2 * (t ** 2 - t_b ** 2) - f0 * (t - t_b)) / m
    s = (rate / 6 * (t ** 3 - t_b ** 3) - rate / 2 * t_b ** 2 * (t - t_b)
         - f0 / 2 * (t - t_b) ** 2) / m
    assert np.max(np.abs(res["mass.v"][res.t > t_b] - v)) < 1e-8
    assert np.max(np.abs(res["mass.s"][res.t > t_b] - s)) < 1e-8
    after = res.t > ev[1][0]                     # (both rows of the event are at its time)
    assert np.all(res["fr.mode"][after] == 1)
    assert np.allclose(res["fr.f"][after], f0, rtol=1e-12)


def test_block_sticks_below_break_away():
    """The force rises to 5.9 N, under the break-away 6 N (but above the
    sliding level 4 N): the block never moves, the friction holds it."""
    res = compile_model(_block_on_ramp(3.0, height=5.9)).simulate(
        t_end=10.0, output_step=0.05, **TIGHT)
    assert [n for _, n in _events(res, "fr")] == ["initial_mode"]
    assert np.all(res["mass.s"] == 0.0) and np.all(res["mass.v"] == 0.0)
    assert abs(res.final()["fr.f"] - 5.9) < 1e-12 and res.final()["fr.locked"] == 1


def test_bearing_table_spin_down_against_scipy():
    """BearingFriction with a rising table tau(w) = 0.5 + 0.5 w: an inertia
    spinning down, m-independent solution by scipy solve_ivp; it stops at
    w = 0 and stays (the table's break-away 0.5 N*m exceeds no load)."""
    from scipy.integrate import solve_ivp
    J, w0 = 0.3, 4.0
    model = Model()
    model.inertia = rot.Inertia(J=J, phi=0, w=w0)
    model.bearing = rot.BearingFriction(tau_pos=[[0, 0.5], [1, 1.0]])
    model.connect(model.inertia.flange_b, model.bearing.flange_a)
    res = compile_model(model).simulate(t_end=2.0, output_step=0.01, **TIGHT)
    # J w' = -(0.5 + 0.5 w) while w > 0: w = (w0 + 1) exp(-t/(2J)) - 1
    t_stop = 2 * J * math.log(w0 + 1)
    ev = _events(res, "bearing")
    assert [n for _, n in ev] == ["initial_mode", "slide_stop"]
    assert abs(ev[1][0] - t_stop) < 1e-9
    ref = solve_ivp(lambda t, y: [y[1], -(0.5 + 0.5 * y[1]) / J], (0, t_stop), [0, w0],
                    rtol=1e-12, atol=1e-14, dense_output=True)
    sl = res.t < t_stop
    assert np.max(np.abs(res["inertia.phi"][sl] - ref.sol(res.t[sl])[0])) < 1e-8
    assert abs(res.final()["inertia.phi"] - ref.y[0, -1]) < 1e-8
    assert abs(res.final()["inertia.w"]) < 1e-12 and res.final()["bearing.mode"] == 0


# -- a clutch engaging: the lock time from momentum conservation --------------------

def _two_inertias(clutch, J1=0.4, J2=1.2, w1=20.0, w2=-5.0, t_on=0.2):
    model = Model()
    model.a = rot.Inertia(J=J1, phi=0, w=w1)
    model.b = rot.Inertia(J=J2, phi=0, w=w2)
    model.clutch = clutch
    model.engage = Step(startTime=t_on)
    model.connect(model.a.flange_b, model.clutch.flange_a)
    model.connect(model.clutch.flange_b, model.b.flange_a)
    model.connect(model.engage.y, model.clutch.f_normalized)
    return model


def test_clutch_engages_and_locks_at_the_momentum_time():
    J1, J2, w1, w2, t_on = 0.4, 1.2, 20.0, -5.0, 0.2
    fn_max, cgeo, mu = 200.0, 0.1, 0.4
    model = _two_inertias(rot.Clutch(fn_max=fn_max, cgeo=cgeo, mu_pos=[[0, mu]], peak=1.2),
                          J1, J2, w1, w2, t_on)
    res = compile_model(model).simulate(t_end=2.0, output_step=0.01, **TIGHT)
    tau = cgeo * mu * fn_max                     # sliding torque once engaged
    t_lock = t_on + (w1 - w2) / (tau * (1 / J1 + 1 / J2))
    ev = _events(res, "clutch")
    assert [n for _, n in ev] == ["initial_mode", "engage", "slide_stop"]
    assert abs(ev[1][0] - t_on) < 1e-12
    assert abs(ev[2][0] - t_lock) < 1e-9
    # free before the engagement: mode 2, no torque, speeds constant
    free = res.t < t_on
    assert np.all(res["clutch.mode"][free] == 2) and np.all(res["clutch.tau"][free] == 0)
    assert np.all(res["a.w"][free] == w1)
    # slipping: flange_b (slower) is dragged forward: tau = -cgeo*mu*fn
    slip = (res.t > t_on) & (res.t < t_lock)
    assert np.all(res["clutch.mode"][slip] == -1)
    assert np.allclose(res["clutch.tau"][slip], -tau, rtol=1e-12)
    wc = (J1 * w1 + J2 * w2) / (J1 + J2)       # momentum is conserved
    fin = res.final()
    assert abs(fin["a.w"] - wc) < 1e-9 and abs(fin["b.w"] - wc) < 1e-9
    assert fin["clutch.mode"] == 0 and abs(fin["clutch.tau"]) < 1e-9
    phi_a = w1 * t_lock - tau / J1 * (t_lock - t_on) ** 2 / 2 + wc * (2.0 - t_lock)
    assert abs(fin["a.phi"] - phi_a) < 1e-8
    # the friction's loss power (linear in t while slipping) integrates to the
    # kinetic energy lost
    lost = 0.5 * J1 * w1 ** 2 + 0.5 * J2 * w2 ** 2 - 0.5 * (J1 + J2) * wc ** 2
    p = res["clutch.lossPower"]
    assert abs(np.sum((p[1:] + p[:-1]) / 2 * np.diff(res.t)) - lost) < 1e-9 * lost
    assert np.min(p) > -1e-9


@pytest.mark.parametrize("backend", ["sundae", pytest.param("compiled", marks=pytest.mark.slow)])
def test_lock_time_sensitivity_to_the_normal_force(backend):
    """The event-time sensitivity of the lock through the mode machine's
    roots: t_lock = t_on + (w1 - w2)/(cgeo*mu*fn_max*(1/J1 + 1/J2)), so
    d t_lock/d fn_max = -(t_lock - t_on)/fn_max."""
    J1, J2, w1, w2, t_on, fn = 0.4, 1.2, 20.0, -5.0, 0.2, 200.0
    model = _two_inertias(rot.Clutch(fn_max=fn, cgeo=0.1, mu_pos=[[0, 0.4]], peak=1.2),
                          J1, J2, w1, w2, t_on)
    res = compile_model(model).simulate(t_end=1.5, output_step=0.01, backend=backend,
                                        sensitivities=["clutch.fn_max"], **TIGHT)
    t_lock = t_on + (w1 - w2) / (0.1 * 0.4 * fn * (1 / J1 + 1 / J2))
    k = [n for _, n in res.events].index("clutch.slide_stop")
    dt = res.event_sensitivity("clutch.fn_max")[k]
    assert abs(dt - (-(t_lock - t_on) / fn)) < 1e-9


def test_clutch_released_slips_then_goes_free():
    """Locked and carrying 1 N*m (b accelerates with a at 1 rad/s^2), the
    normal force ramps down to 0 between 0.5 and 0.75 s: the clutch slips
    when its break-away torque 0.5*100*cmd falls to the 1 N*m it carries
    (cmd = 0.02, t = 0.745 s), is free (mode 2, no torque) from 0.75 s on,
    and b coasts at the speed it had then."""
    model = Model()
    model.a = rot.Inertia(J=1.0, phi=0, w=3.0)
    model.b = rot.Inertia(J=1.0, phi=0, w=3.0)
    model.clutch = rot.Clutch(fn_max=100.0)
    model.cmd = Ramp(height=-1.0, offset=1.0, startTime=0.5, duration=0.25)
    model.motor = rot.Torque()
    model.drive = Constant(k=2.0)
    model.connect(model.a.flange_b, model.clutch.flange_a)
    model.connect(model.clutch.flange_b, model.b.flange_a)
    model.connect(model.cmd.y, model.clutch.f_normalized)
    model.connect(model.motor.flange, model.a.flange_a)
    model.connect(model.drive.y, model.motor.tau)
    res = compile_model(model).simulate(t_end=1.5, output_step=0.01, **TIGHT)
    ev = _events(res, "clutch")
    assert [n for _, n in ev] == ["initial_mode", "break_backward", "release"]
    assert abs(ev[1][0] - 0.745) < 1e-9
    assert abs(ev[2][0] - 0.75) < 1e-12         # fn reaches exactly 0 at the ramp's end
    locked = res.t < 0.745
    assert np.allclose(res["a.w"][locked], 3.0 + res.t[locked], rtol=0, atol=1e-9)
    assert np.allclose(res["clutch.tau"][locked], -1.0, rtol=1e-9)   # it pulls b along
    # slipping: J_b w_b' = 100*0.5*cmd(t), cmd = 1 - (t - 0.5)/0.25, from 0.745 to 0.75
    wb = 3.0 + 0.745 + 50 * ((0.75 - 0.745) - ((0.75 - 0.5) ** 2 - (0.745 - 0.5) ** 2) / 0.5)
    free = res.t > 0.75
    assert np.all(res["clutch.mode"][free] == 2) and np.all(res["clutch.tau"][free] == 0)
    assert np.allclose(res["b.w"][free], wb, rtol=0, atol=1e-9)
    # the clutch only moves momentum between them: J_a w_a + J_b w_b = 6 + 2 t
    assert np.allclose(res["a.w"] + res["b.w"], 6.0 + 2.0 * res.t, rtol=0, atol=1e-9)


# -- one-way clutch ----------------------------------------------------------------------

def test_one_way_clutch_freewheels_then_locks():
    """Disengaged one-way clutch: the output (w = 5) overruns the input (w =
    1), which a constant torque accelerates; the freewheel transmits nothing
    until the input catches up at t1 = J_in*(5 - 1)/T, then it locks and both
    accelerate together at T/(J_in + J_out)."""
    J_in, J_out, T = 0.5, 2.0, 4.0
    model = Model()
    model.inp = rot.Inertia(J=J_in, phi=0, w=1.0)
    model.out = rot.Inertia(J=J_out, phi=0, w=5.0)
    model.owc = rot.OneWayClutch(fn_max=10.0, peak=2)
    model.off = Constant(k=0.0)
    model.motor = rot.Torque()
    model.drive = Constant(k=T)
    model.connect(model.motor.flange, model.inp.flange_a)
    model.connect(model.drive.y, model.motor.tau)
    model.connect(model.inp.flange_b, model.owc.flange_a)
    model.connect(model.owc.flange_b, model.out.flange_a)
    model.connect(model.off.y, model.owc.f_normalized)
    res = compile_model(model).simulate(t_end=1.5, output_step=0.01, **TIGHT)
    t1 = J_in * (5.0 - 1.0) / T
    ev = _events(res, "owc")
    assert [n for _, n in ev] == ["initial_mode", "slide_stop"]
    assert abs(ev[1][0] - t1) < 1e-9
    free = res.t < t1
    assert np.all(res["owc.tau"][free] == 0) and np.all(res["out.w"][free] == 5.0)
    assert np.allclose(res["inp.w"][free], 1.0 + T / J_in * res.t[free], rtol=0, atol=1e-9)
    after = res.t > t1
    w = 5.0 + T / (J_in + J_out) * (res.t[after] - t1)
    assert np.max(np.abs(res["out.w"][after] - w)) < 1e-9
    assert np.max(np.abs(res["inp.w"][after] - w)) < 1e-9
    assert np.all(res["owc.mode"][after] == 0)
    # the locked freewheel carries the torque that accelerates the output
    assert np.allclose(res["owc.tau"][after], -J_out * T / (J_in + J_out), rtol=1e-9)


def test_one_way_clutch_never_turns_backward():
    """A torque pulling the output backward against a locked freewheel: the
    whole train decelerates as one (w_rel stays 0); pulled forward, the
    output slips ahead freely (disengaged)."""
    model = Model()
    model.inp = rot.Inertia(J=1.0, phi=0, w=0.0)
    model.out = rot.Inertia(J=1.0, phi=0, w=0.0)
    model.owc = rot.OneWayClutch(fn_max=10.0)
    model.off = Constant(k=0.0)
    model.pull = rot.Torque()
    model.cmd = Step(height=2.0, offset=-1.0, startTime=1.0)   # -1 N*m, then +1
    model.connect(model.inp.flange_b, model.owc.flange_a)
    model.connect(model.owc.flange_b, model.out.flange_a)
    model.connect(model.off.y, model.owc.f_normalized)
    model.connect(model.pull.flange, model.out.flange_b)
    model.connect(model.cmd.y, model.pull.tau)
    res = compile_model(model).simulate(t_end=2.0, output_step=0.01, **TIGHT)
    back = res.t < 1.0
    assert np.max(np.abs(res["owc.w_rel"][back])) < 1e-12
    assert np.allclose(res["out.w"][back], -0.5 * res.t[back], rtol=0, atol=1e-9)
    fwd = res.t > 1.0 + 1e-9
    assert np.all(res["owc.w_rel"][fwd] > 0)
    assert np.allclose(res["inp.w"][fwd], -0.5, rtol=0, atol=1e-9)    # the input coasts


# -- two frictions holding one motion (statically indeterminate) -------------------------

def test_two_bearings_on_one_shaft_start_at_their_total_break_away():
    """Two bearings (1 and 2 N*m) on one shaft, a torque ramping at 3 N*m/s:
    while both stick the split of the holding torque is not determined; the
    shaft starts when the torque exceeds their sum, t = 3/3 s, then J a =
    3 t - 3."""
    J, r = 0.5, 3.0
    model = Model()
    model.shaft = rot.Inertia(J=J, phi=0, w=0)
    model.b1 = rot.BearingFriction(tau_pos=[[0, 1.0]])
    model.b2 = rot.BearingFriction(tau_pos=[[0, 2.0]])
    model.motor = rot.Torque()
    model.ramp = Ramp(height=r * 10, duration=10)
    model.connect(model.motor.flange, model.shaft.flange_a)
    model.connect(model.shaft.flange_b, model.b1.flange_a, model.b2.flange_a)
    model.connect(model.ramp.y, model.motor.tau)
    res = compile_model(model).simulate(t_end=2.0, output_step=0.01, **TIGHT)
    t_s = 3.0 / r
    moving = res.t > t_s + 1e-9
    assert np.max(np.abs(res["shaft.phi"][res.t < t_s])) < 1e-15
    t = res.t[moving]
    assert np.max(np.abs(res["shaft.w"][moving] - (r / 2 * (t ** 2 - t_s ** 2) - 3 * (t - t_s))
                         / J)) < 1e-8
    # the holding torques always add up to the load; one of them is held
    stuck = res.t < t_s
    assert np.allclose(res["b1.tau"][stuck] + res["b2.tau"][stuck], r * res.t[stuck],
                       rtol=1e-10, atol=1e-12)


# -- lossy gear ----------------------------------------------------------------------------

def _gear_train(T, eta1=0.8, eta2=0.6, ratio=3.0, Ja=0.2, Jb=1.5, load=0.0):
    model = Model()
    model.a = rot.Inertia(J=Ja, phi=0, w=0)
    model.b = rot.Inertia(J=Jb, phi=0, w=0)
    model.gear = rot.LossyGear(ratio=ratio, lossTable=[[0, eta1, eta2, 0, 0]])
    model.motor = rot.Torque()
    model.drive = Constant(k=T)
    model.brake = rot.Torque()
    model.load = Constant(k=load)
    model.connect(model.motor.flange, model.a.flange_a)
    model.connect(model.drive.y, model.motor.tau)
    model.connect(model.a.flange_b, model.gear.flange_a)
    model.connect(model.gear.flange_b, model.b.flange_a)
    model.connect(model.brake.flange, model.b.flange_b)
    model.connect(model.load.y, model.brake.tau)
    return model


def test_lossy_gear_driving_side_a_with_mesh_efficiency():
    """flange_a drives: -flange_b.tau = i*eta1*flange_a.tau, so from rest
    w_b' = T/(Ja*i + Jb/(i*eta1))."""
    T, eta1, i, Ja, Jb = 2.0, 0.8, 3.0, 0.2, 1.5
    res = compile_model(_gear_train(T, eta1=eta1, ratio=i, Ja=Ja, Jb=Jb)).simulate(
        t_end=1.0, output_step=0.01, **TIGHT)
    acc = T / (Ja * i + Jb / (i * eta1))
    assert np.allclose(res["b.w"], acc * res.t, rtol=0, atol=1e-9)
    assert np.allclose(res["a.w"], i * acc * res.t, rtol=0, atol=1e-9)
    assert np.all(res["gear.mode"][res.t > 0] == 1)


@pytest.mark.parametrize("load", [-2.0, -4.0, -6.0])
def test_lossy_gear_sticks_between_its_two_efficiencies(load):
    """1 N*m drives flange_a (i = 3), a load torque on flange_b. flange_a
    drives the load only if i*eta1*T = 2.4 N*m exceeds it, flange_b drives
    back only if the load exceeds i*T/eta2 = 5 N*m; in between the gear
    stays stuck (load -4). Moving, from rest: forward w_b' = (i eta1 T +
    L)/(Jb + Ja i^2 eta1), backward w_b' = (i T/eta2 + L)/(Jb + Ja i^2/eta2)."""
    T, eta1, eta2, i, Ja, Jb = 1.0, 0.8, 0.6, 3.0, 0.2, 1.5
    res = compile_model(_gear_train(T, eta1=eta1, eta2=eta2, ratio=i, Ja=Ja, Jb=Jb,
                                    load=load)).simulate(t_end=1.0, output_step=0.01, **TIGHT)
    if load == -4.0:
        assert np.all(res["b.phi"] == 0.0) and np.all(res["gear.mode"] == 0)
        # the loss carries the difference: flange_b.tau = -i (flange_a.tau - tauLoss) = -L
        assert np.allclose(res["gear.tauLoss"], T + load / i, rtol=1e-12)
        return
    if load == -2.0:
        acc, mode = (i * eta1 * T + load) / (Jb + Ja * i ** 2 * eta1), 1
    else:
        acc, mode = (i * T / eta2 + load) / (Jb + Ja * i ** 2 / eta2), -1
    assert np.allclose(res["b.w"], acc * res.t, rtol=0, atol=1e-9)
    assert np.all(res["gear.mode"][res.t > 0] == mode)


def test_lossy_gear_ideal_table_is_an_ideal_gear():
    res = compile_model(_gear_train(2.0, eta1=1.0, eta2=1.0)).simulate(
        t_end=1.0, output_step=0.01, **TIGHT)
    assert np.all(res["gear.mode"] == 2) and np.all(res["gear.tauLoss"] == 0)
    assert np.allclose(res["b.w"], 2.0 / (0.2 * 3 + 1.5 / 3) * res.t, rtol=0, atol=1e-9)


def test_lossy_gear_negative_ratio_mirrors_the_motion():
    """A negative ratio is a reversing stage: the same losses, flange_b
    turning the other way."""
    pos = compile_model(_gear_train(2.0, ratio=3.0)).simulate(t_end=1.0, output_step=0.01,
                                                              **TIGHT)
    neg = compile_model(_gear_train(2.0, ratio=-3.0)).simulate(t_end=1.0, output_step=0.01,
                                                               **TIGHT)
    assert np.allclose(neg["b.w"], -pos["b.w"], rtol=0, atol=1e-12)
    assert np.allclose(neg["a.w"], pos["a.w"], rtol=0, atol=1e-12)


# -- a mass between hard stops -----------------------------------------------------------------

def test_mass_hits_the_stop_and_stays_until_pulled_back():
    """Coulomb friction only (F_prop = F_Stribeck = 0): from v0 the mass
    decelerates at F_Coulomb/m, reaches the right stop at the closed-form
    time, its velocity is reset to 0 there and it stays; pushed into the
    stop it stays; pulled back by more than f0_max it leaves."""
    m, Fc, v0, smax, L = 2.0, 1.0, 2.0, 1.0, 0.4
    model = Model()
    model.mass = tr.MassWithStopAndFriction(m=m, F_prop=0, F_Coulomb=Fc, F_Stribeck=0,
                                            fexp=0, smax=smax, smin=-5.0, L=L, s=0, v=v0)
    model.force = tr.Force()
    model.cmd = Step(height=-3.0, offset=1.5, startTime=3.0)     # +1.5 N, then -1.5 N
    model.connect(model.force.flange, model.mass.flange_a)
    model.connect(model.cmd.y, model.force.f)
    res = compile_model(model).simulate(t_end=5.0, output_step=0.01, **TIGHT)
    # m a = 1.5 - 1 (pushed, sliding forward): s = v0 t + a t^2/2 reaches smax - L/2
    a = (1.5 - Fc) / m
    t_hit = (-v0 + math.sqrt(v0 ** 2 + 2 * a * (smax - L / 2))) / a
    ev = _events(res, "mass")
    hit = [t for t, n in ev if n == "stop_at_smax"]
    assert len(hit) == 1 and abs(hit[0] - t_hit) < 1e-9
    at_stop = (res.t > hit[0]) & (res.t < 3.0)
    assert np.all(res["mass.v"][at_stop] == 0.0)
    assert np.allclose(res["mass.s"][at_stop], smax - L / 2, rtol=0, atol=1e-12)
    assert np.all(res["mass.stopped"][at_stop] == 1)
    # pulled back with 1.5 N > f0_max = 1.001 N from t = 3: leaves at once
    after = res.t > 3.0 + 1e-9
    a2 = (-1.5 + Fc) / m
    t = res.t[after] - 3.0
    assert np.max(np.abs(res["mass.v"][after] - a2 * t)) < 1e-9
    assert res.final()["mass.stopped"] == 0


def test_mass_starting_beyond_a_stop_is_one_clear_line():
    model = Model()
    model.m = tr.MassWithStopAndFriction(smax=1.0, smin=-1.0, L=0.5, s=0.9, v=0)
    with pytest.raises(InitializationError) as exc:
        compile_model(model).simulate(t_end=0.1)
    msg = str(exc.value)
    assert "\n" not in msg and "m:" in msg and "right stop" in msg


# -- free, tables, bad input ----------------------------------------------------------------

def test_brake_with_zero_normal_force_is_free():
    model = Model()
    model.J = rot.Inertia(J=1.0, phi=0, w=2.0)
    model.brake = rot.Brake(fn_max=100.0)
    model.zero = Constant(k=0.0)
    model.connect(model.J.flange_b, model.brake.flange_a)
    model.connect(model.zero.y, model.brake.f_normalized)
    res = compile_model(model).simulate(t_end=1.0, output_step=0.1, **TIGHT)
    assert np.all(res["brake.mode"] == 2) and np.all(res["brake.tau"] == 0)
    assert np.all(res["brake.free"] == 1) and np.all(res["J.w"] == 2.0)


def test_translational_brake_table_against_scipy():
    """A velocity-dependent friction coefficient (two table rows, linear
    extrapolation beyond them) decelerates a mass; scipy integrates the same
    law written out by hand."""
    from scipy.integrate import solve_ivp
    m, v0, fn = 1.0, 3.0, 10.0
    model = Model()
    model.mass = tr.Mass(m=m, s=0, v=v0)
    model.brake = tr.Brake(fn_max=fn, mu_pos=[[0, 0.3], [1, 0.4]])
    model.on = Constant(k=1.0)
    model.connect(model.mass.flange_b, model.brake.flange_a)
    model.connect(model.on.y, model.brake.f_normalized)
    res = compile_model(model).simulate(t_end=2.0, output_step=0.01, **TIGHT)

    def mu(v):                                   # MSL's interpolate, extrapolated
        return 0.3 + 0.1 * v

    stop = lambda t, y: y[1]                      # noqa: E731
    stop.terminal, stop.direction = True, -1
    ref = solve_ivp(lambda t, y: [y[1], -fn * mu(y[1]) / m], (0, 2.0), [0, v0],
                    events=stop, rtol=1e-12, atol=1e-14, dense_output=True)
    t_stop = ref.t_events[0][0]
    assert abs([t for t, n in _events(res, "brake") if n == "slide_stop"][0] - t_stop) < 1e-8
    sl = res.t < t_stop
    assert np.max(np.abs(res["mass.s"][sl] - ref.sol(res.t[sl])[0])) < 1e-8
    assert abs(res.final()["mass.s"] - ref.y[0, -1]) < 1e-8


def test_stribeck_table_is_msl_law():
    table = tr.stribeck_table(F_prop=1, F_Coulomb=5, F_Stribeck=10, fexp=2, v_max=12, n=50)
    assert len(table) == 50 and table[0] == (0.0, 15.0)
    v, f = table[7]
    assert v == 12 * 7 / 49 and f == 5 + v + 10 * math.exp(-2 * v)


def test_unconnected_normal_force_is_one_clear_line():
    model = Model()
    model.a = rot.Inertia(J=1.0, phi=0, w=1.0)
    model.b = rot.Inertia(J=1.0, phi=0, w=0.0)
    model.clutch = rot.Clutch(fn_max=10.0)
    model.connect(model.a.flange_b, model.clutch.flange_a)
    model.connect(model.clutch.flange_b, model.b.flange_a)
    with pytest.raises(ConnectionError_) as exc:
        compile_model(model)
    msg = str(exc.value)
    assert "\n" not in msg and "clutch.f_normalized" in msg and "not connected" in msg


@pytest.mark.parametrize("make, what", [
    (lambda: rot.Clutch(mu_pos=[[0, 0.5], [2, 0.4], [1, 0.3]]), r"mu_pos.*increase strictly"),
    (lambda: rot.BearingFriction(tau_pos=[[0, 1], [0, 2]]), r"tau_pos.*increase strictly"),
    (lambda: tr.SupportFriction(f_pos=[[0, 1, 2]]), r"f_pos.*row 1 has 3 numbers"),
    (lambda: tr.Brake(mu_pos=[]), r"mu_pos.*empty table"),
    (lambda: rot.Brake(peak=-2.0), r"peak = -2 .*>= 1"),
    (lambda: tr.SupportFriction(peak=0.5), r"peak = 0.5 .*>= 1"),
    (lambda: rot.OneWayClutch(fn_max=-1.0), r"fn_max = -1"),
    (lambda: rot.LossyGear(ratio=0), r"ratio = 0 .*non-zero"),
    (lambda: rot.LossyGear(lossTable=[[0, 1.2, 1, 0, 0]]), r"eta_mf1.*\(0, 1\]"),
    (lambda: rot.LossyGear(lossTable=[[0, 0.9, 0, 0, 0]]), r"eta_mf2.*\(0, 1\]"),
    (lambda: rot.IdealPlanetary(ratio=-1.5), r"ratio = -1.5 .*> 0"),
    (lambda: tr.MassWithStopAndFriction(fexp=-1), r"fexp = -1"),
])
def test_bad_parameters_are_one_clear_line(make, what):
    with pytest.raises(ParameterError, match=what) as exc:
        make()
    assert "\n" not in str(exc.value)


def test_stops_without_room_are_one_clear_line():
    model = Model()
    model.m = tr.MassWithStopAndFriction(smax=0.2, smin=-0.2, L=1.0, s=0, v=0)
    with pytest.raises(ParameterError, match=r"m: the stops leave no room") as exc:
        compile_model(model).simulate(t_end=0.1)
    assert "\n" not in str(exc.value)


def test_the_locked_test_from_numbers_is_the_sympy_condition():
    """The coupled-lock action reads "locked" from the event's numbers
    (``_locked_now``, run at every event of every element); it must agree
    with the mode machine's own sympy condition (``_locked_condition``) on
    every discrete state, including the start's Unknown and a start in
    progress."""
    from acausal.mechanics.frictionmodes import (BACKWARD, FORWARD, FREE, STUCK, UNKNOWN,
                                                 _true)
    m = Model()
    m.bf = rot.BearingFriction(tau_pos=[[0.0, 1.0]])
    el = m.bf
    for mode in (UNKNOWN, FREE, FORWARD, STUCK, BACKWARD):
        for sf in (0, 1):
            for sb in (0, 1):
                state = {el.mode: float(mode), el.startForward: float(sf),
                         el.startBackward: float(sb)}
                assert el._locked_now(state) == _true(state, el._locked_condition()), \
                    (mode, sf, sb)
