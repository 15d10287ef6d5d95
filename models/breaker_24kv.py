"""The 24 kV circuit-breaker driving mechanism of the research report
(Yu, Wang and Hsu, NSC 99-2221-E-011-015), composed from the component
library following the report's five sub-models (section 2, Figs. 3 and 4):

  armature --contact--> hook (lever s3) --four-bar (cam/roller)--> main shaft
     |                    |  reset spring kh at s4, friction bh     |  open spring ko at s1,
     Fe, reset spring ka  |                                         |  wipe spring kw at s2

Sign convention (docs/breaker_model.md section 1, the report's own): the
armature moves along -s, pushes the hook's contact point (s = s3*phi) along
-s, so the hook angle ``hook.phi`` decreases from 0 to -Ra at release.
Parameters from Table 1 (data/report/table1_parameters.csv); the values the
report leaves out (main-shaft inertia, spring preloads, initial angles) are
documented with their effect on the response time in docs/breaker_model.md.

The run starts 1 um before first contact (so the contact's onset is a real
event) and stops when the hook reaches its release angle. Measures:
``thrt`` (first contact to release), ``contact_period`` (first impact),
``peak_force``, ``impact_velocity``.
"""
import math

from acausal import Experiment, Measure, Model, Stop, guess
from acausal.mechanics import contact as ct
from acausal.mechanics.contact import Contact
from acausal.mechanics.fourbar import FourBar, fourbar_angles
from acausal.mechanics.levers import IdealLever
from acausal.mechanics.rotational import Fixed as RotFixed
from acausal.mechanics.rotational import Inertia, RotationalDamper
from acausal.mechanics.translational import Fixed, Force, Mass, Spring

GAP0 = 1e-6          # [m] armature-hook distance at t = 0 (first contact at ~0.26 us)
THETA1_0 = 0.0       # [rad] hook angle at first contact (report's figures start at 0)


class Armature(Model):
    """Solenoid armature (Fig. 4a): mass ``ma``, reset spring ``ka``, constant
    electromagnetic force ``Fe`` along -s. Connector: ``flange``."""

    def __init__(self, v0, **kw):
        super().__init__(**kw)
        ma = self.parameter("ma", 0.22, "kg", "armature mass", min=0.0, min_open=True)
        ka = self.parameter("ka", 0.013, "N/m", "armature reset-spring stiffness", min=0.0)
        Fe = self.parameter("Fe", 160.0, "N", "electromagnetic force during impact", min=0.0)
        self.mass = Mass(m=ma, s=GAP0, v=-v0)
        self.coil = Force(f=-Fe)
        self.reset = Spring(c=ka, s_rel0=GAP0)
        self.frame = Fixed()
        self.connect(self.frame.flange, self.reset.flange_a)
        self.connect(self.reset.flange_b, self.mass.flange, self.coil.flange)
        self.flange = self.mass.flange


class TriggerHook(Model):
    """Trigger hook (Fig. 4c): inertia ``Jh``, contact point at arm ``s3``,
    reset spring ``kh`` at arm ``s4``, viscous shaft friction ``bh``.
    Connectors: ``point`` (translational, the armature's contact point),
    ``shaft`` (rotational, to the cam). Variable ``phi`` [rad]."""

    def __init__(self, **kw):
        super().__init__(**kw)
        Jh = self.parameter("Jh", 0.00044, "kg*m^2", "hook moment of inertia", min=0.0,
                            min_open=True)
        bh = self.parameter("bh", 0.219, "N*m*s/rad", "hook friction coefficient", min=0.0)
        s3 = self.parameter("s3", 0.055, "m", "arm of the armature contact point", min=0.0,
                            min_open=True)
        s4 = self.parameter("s4", 0.058, "m", "arm of the hook reset spring", min=0.0,
                            min_open=True)
        kh = self.parameter("kh", 714.0, "N/m", "hook reset-spring stiffness", min=0.0)
        self.body = Inertia(J=Jh, phi=THETA1_0, w=0.0)
        self.friction = RotationalDamper(d=bh)
        self.arm3 = IdealLever(arm=s3)
        self.arm4 = IdealLever(arm=s4)
        self.reset = Spring(c=kh)
        self.frame = RotFixed()
        self.ground = Fixed()
        self.connect(self.frame.flange, self.friction.flange_a)
        self.connect(self.body.flange, self.friction.flange_b, self.arm3.flange_r,
                     self.arm4.flange_r)
        self.connect(self.arm4.flange_t, self.reset.flange_b)
        self.connect(self.reset.flange_a, self.ground.flange)
        self.point = self.arm3.flange_t
        self.shaft = self.body.flange
        phi = self.variable("phi", 0.0, "rad", "hook angle (decreases when tripped)")
        self.equation(phi - self.body.phi)


class MainShaft(Model):
    """Main shaft (Fig. 4e): inertia ``Js``, open spring ``ko`` at arm ``s1``
    and wipe spring ``kw`` at arm ``s2``, preloaded with ``Fo0``/``Fw0`` at the
    closed position ``theta0``. Connector: ``shaft``."""

    def __init__(self, theta0, **kw):
        super().__init__(**kw)
        Js = self.parameter("Js", 0.05, "kg*m^2", "main-shaft inertia (assumed)", min=0.0,
                            min_open=True)
        ko = self.parameter("ko", 7.0e4, "N/m", "open-spring stiffness", min=0.0)
        kw = self.parameter("kw", 2.4e5, "N/m", "wipe-spring stiffness", min=0.0)
        s1 = self.parameter("s1", 0.091, "m", "open-spring arm", min=0.0, min_open=True)
        s2 = self.parameter("s2", 0.091, "m", "wipe-spring arm", min=0.0, min_open=True)
        Fo0 = self.parameter("Fo0", 5600.0, "N", "open-spring force when closed (assumed)")
        Fw0 = self.parameter("Fw0", 9000.0, "N", "wipe-spring force when closed (assumed)")
        self.body = Inertia(J=Js, phi=guess(theta0), w=guess(0.0))
        self.arm1 = IdealLever(arm=s1)
        self.arm2 = IdealLever(arm=s2)
        self.open_spring = Spring(c=ko, s_rel0=s1 * theta0, f0=Fo0)
        self.wipe_spring = Spring(c=kw, s_rel0=s2 * theta0, f0=Fw0)
        self.ground = Fixed()
        self.connect(self.body.flange, self.arm1.flange_r, self.arm2.flange_r)
        self.connect(self.arm1.flange_t, self.open_spring.flange_b)
        self.connect(self.arm2.flange_t, self.wipe_spring.flange_b)
        self.connect(self.ground.flange, self.open_spring.flange_a, self.wipe_spring.flange_a)
        self.shaft = self.body.flange


def build(v_impact=3.8, K=8.3e9, bh=0.219):
    """The breaker model (defaults: the report's calibrated bh, K from eq. 3)."""
    m = Model()
    v = m.parameter("v_impact", v_impact, "m/s", "armature speed at first contact",
                    min=0.0, min_open=True)
    Ra = m.parameter("Ra", math.radians(5.0), "rad", "release angle of the trigger hook",
                     min=0.0, min_open=True)
    theta3_0 = fourbar_angles(THETA1_0)[1]
    m.armature = Armature(v)
    m.hook = TriggerHook()
    m.hook.set(bh=bh)
    m.contact = Contact(K=K, e=0.74, gamma=1.5, law="lankarani_nikravesh")
    m.cam = FourBar(theta1=guess(THETA1_0))
    m.main_shaft = MainShaft(theta3_0)
    m.connect(m.hook.point, m.contact.flange_a)
    m.connect(m.contact.flange_b, m.armature.flange)
    m.connect(m.hook.shaft, m.cam.flange_a)
    m.connect(m.cam.flange_b, m.main_shaft.shaft)
    m.Ra_sym = Ra
    return m


# the project's calibration to the measured 110 V figures (docs/calibration.md;
# the report found K = 6.25e8, bh = 0.219 with its 20-sim model); the
# variants in this folder use the same values
K_CAL, BH_CAL = 6.17e8, 0.219
model = build(K=K_CAL, bh=BH_CAL)
# what calibration and diagnosis fit when not told otherwise (the report's two)
FREE_PARAMETERS = {"contact.K": (1e8, 1e10), "hook.bh": (0.0, 1.0)}


def release_experiment(model, **options):
    """The run of this file and its variants: from first contact until the
    hook reaches its release angle Ra (the terminal event ``release``);
    ``options`` add to or override the Experiment's settings.

    Output at the solver's internal steps and both sides of every event
    (``output_step=0``): the measures are event times and event-located
    values, which the output times do not change (the same THRT and contact
    period to round-off as on a 2 us grid, tests/models/
    test_breaker_output.py), at about half the cost. A plot or a CSV gets
    the 2 us grid (``dense_step``). The absolute tolerance stays 1e-11 on
    every unknown: per-variable tolerances (benchmarks/breaker_speed.py) are
    faster still but move THRT by up to 5e-7 ms."""
    settings = dict(t_end=0.02, rtol=1e-8, atol=1e-11, output_step=0, dense_step=2e-6,
                    stop=Stop(model.hook.phi, "<=", -model.Ra_sym, name="release"))
    settings.update(options)
    return Experiment(**settings)


def t_first_contact(res):
    imps = ct.impacts(res, "contact")
    if not imps:
        raise ValueError(f"the armature never touched the hook by t = {res.t[-1]:.6g} s")
    return imps[0].t_onset


def t_release(res):
    """The release time; a run that ends without it says where the hook got to."""
    times = res.event_times("release")
    if not len(times):
        raise ValueError(f"the hook did not reach its release angle: the run ended at "
                         f"t = {res.t[-1]:.6g} s with hook.phi = {res['hook.phi'][-1]:.6g} rad")
    return times[0]


# the measures of this file; the variants add their own to these
MEASURES = {
    "thrt": Measure(lambda res: t_release(res) - t_first_contact(res),
                    "s", display="ms", desc="trigger hook response time"),
    "contact_period": Measure(lambda res: ct.contact_period(res, "contact"), "s",
                              display="ms", desc="duration of the first impact"),
    "peak_force": Measure(lambda res: ct.peak_force(res, "contact"), "N",
                          desc="largest contact force of the first impact (>= 0)"),
    "impact_velocity": Measure(lambda res: ct.impact_velocity(res, "contact"), "m/s",
                               desc="approach speed at the first contact"),
}

# the conditions an experiment sets, with the range the report's drive covers
# (Table 2: 3.3-4.5 m/s): a dataset must set at least one of them (else every
# experiment would silently run at the default v_impact), and acausal.design
# searches this range for the next experiment
CONDITIONS = {"v_impact": (3.0, 5.0, "m/s")}

free_parameters = dict(FREE_PARAMETERS)
experiment = release_experiment(model)
measures = dict(MEASURES)
conditions = dict(CONDITIONS)


def plot(res, path):
    """The report's Fig. 7/10: impact force, hook angle, hook velocity and
    armature velocity, with the contact period and THRT marked.

    The force is the contact force ``contact.fc`` >= 0, the value the
    ``peak_force`` measure reports (acausal/mechanics/contact.py: it pushes
    the bodies apart). The report's figures draw it negative (the force on
    the hook points along -s, docs/breaker_model.md section 1); the
    velocities and the angle keep the report's signs, since they are signed
    coordinates, not magnitudes."""
    import numpy as np
    from acausal.viz.plot import plot_result
    t0 = t_first_contact(res)
    imp = ct.impacts(res, "contact")[0]
    t_rel = t_release(res)
    s3 = float(res["hook.s3"][0])
    return plot_result(
        res, ["contact.fc", "hook.phi", "hook.body.w", "armature.mass.v"], path,
        title=f"24 kV breaker, v_impact = {ct.impact_velocity(res, 'contact'):.2f} m/s: contact "
              f"{(imp.t_release - t0) * 1e3:.3f} ms, THRT {(t_rel - t0) * 1e3:.3f} ms",
        scales={"hook.phi": 180 / np.pi, "hook.body.w": s3},
        labels={"contact.fc": "contact force\n(>= 0) [N]", "hook.phi": "hook angle [deg]",
                "hook.body.w": "hook velocity\nat s3 [m/s]",
                "armature.mass.v": "armature\nvelocity [m/s]"},
        marks=[(imp.t_release, "contact end"), (t_rel, "release (THRT)")])
