"""Slider-crank with a flywheel, built from planar bodies and joints: one
closed kinematic loop (ground - crank - connecting rod - slider - ground),
closed at position level by the index reduction.

    y ^        crank r        rod l
      |     o=========o-----------------o[slider]      --> x (guide on y = 0)
      |  (flywheel, pin A)  pin B              pin C

* crank: revolute at the origin, turning the flywheel (a Body, mass m_f,
  inertia J_f, centre on the axis) and carrying the crank pin B at r;
* connecting rod: length l from B to C, a Body of mass m_r and inertia J_r
  at its middle;
* slider: a Body of mass m_s at C, on a prismatic guide along world x.

Closed-form kinematics (no offset): with the crank angle theta,
``x_C = r cos(theta) + sqrt(l^2 - r^2 sin(theta)^2)`` and
``v_C = -r w sin(theta) (1 + r cos(theta) / sqrt(l^2 - r^2 sin(theta)^2))``.
No losses and no gravity: the kinetic energy stays constant.
"""
import math

from acausal import Experiment, Model, guess
from acausal.mechanics.planar.joints import Prismatic, Revolute
from acausal.mechanics.planar.parts import Body, Fixed, FixedTranslation

R, L = 0.05, 0.2                       # crank and rod [m]
M_F, J_F = 2.0, 5e-3                   # flywheel [kg], [kg m^2]
M_R, J_R = 0.3, 1.2e-3                 # rod [kg], [kg m^2] about its centre
M_S = 0.5                              # slider [kg]
THETA0, W0 = 0.3, 20.0                 # crank start [rad], [rad/s]


def slider_x(theta, r=R, l=L):
    """Closed-form slider position [m] at crank angle ``theta`` [rad]."""
    return r * math.cos(theta) + math.sqrt(l**2 - (r * math.sin(theta))**2)


def build(theta0=THETA0, w0=W0, r=R, l=L):
    """The slider-crank model with the crank at ``theta0`` turning at ``w0``."""
    beta = math.asin(r * math.sin(theta0) / l)       # rod angle below the x axis
    m = Model()
    m.ground = Fixed()
    m.crank_pin = Revolute(phi=theta0, w=w0)          # A: ground -> crank
    m.flywheel = Body(m=M_F, I=J_F)
    m.crank = FixedTranslation(rx=r, ry=0.0)
    m.rod_pin = Revolute(phi=guess(-theta0 - beta))   # B: crank -> rod
    m.rod_half = FixedTranslation(rx=l / 2, ry=0.0)
    m.rod_body = Body(m=M_R, I=J_R)
    m.rod_end = FixedTranslation(rx=l / 2, ry=0.0)
    m.wrist = Revolute(phi=guess(beta))               # C: rod -> slider
    m.slider = Body(m=M_S, I=1e-4)
    m.guide = Prismatic(ex=1.0, ey=0.0, s=guess(slider_x(theta0, r, l)))
    m.connect(m.ground.frame, m.crank_pin.frame_a, m.guide.frame_a)
    m.connect(m.crank_pin.frame_b, m.flywheel.frame, m.crank.frame_a)
    m.connect(m.crank.frame_b, m.rod_pin.frame_a)
    m.connect(m.rod_pin.frame_b, m.rod_half.frame_a)
    m.connect(m.rod_half.frame_b, m.rod_body.frame, m.rod_end.frame_a)
    m.connect(m.rod_end.frame_b, m.wrist.frame_a)
    m.connect(m.wrist.frame_b, m.slider.frame, m.guide.frame_b)
    return m


model = build()
experiment = Experiment(t_end=1.0, rtol=1e-10, atol=1e-12, output_step=2e-3)


def kinetic_energy(res):
    """Total kinetic energy [J] along the result."""
    E = 0.5 * J_F * res["flywheel.w"]**2 + 0.5 * M_S * res["slider.vx"]**2
    E = E + 0.5 * M_R * (res["rod_body.vx"]**2 + res["rod_body.vy"]**2) \
        + 0.5 * J_R * res["rod_body.w"]**2
    return E + 0.5 * M_F * (res["flywheel.vx"]**2 + res["flywheel.vy"]**2) \
        + 0.5 * 1e-4 * res["slider.w"]**2


measures = {
    "turns": lambda res: (res["crank_pin.phi"][-1] - res["crank_pin.phi"][0]) / (2 * math.pi),
    "max_slider_x_error_m": lambda res: max(
        abs(x - slider_x(th)) for x, th in zip(res["slider.x"], res["crank_pin.phi"])),
    "energy_drift": lambda res: float(max(abs(kinetic_energy(res) / kinetic_energy(res)[0] - 1))),
}


def plot(res, path):
    """``acausal simulate --plot``: the mechanism at the end of the run."""
    from acausal.viz.animate import plot_with_mechanism
    plot_with_mechanism(res, path, title="slider-crank")
