"""A spring-returned planar slider-crank, written as a user would: crank,
connecting rod and slider of planar bodies and joints (one closed loop),
the slider pulled back by a return spring on the guide's axis into an end
stop, a small drive torque on the crank's axis. Released at rest from the
crank angle ``theta0`` (a condition of the experiment), so the loop's start
guesses are sympy expressions of ``theta0`` (docs/planar.md).

    crank r, rod l, slider on the x axis (no offset):
    x = r cos(theta) + sqrt(l^2 - r^2 sin(theta)^2)

Sites of every kind: joints ``crank_pin``, ``rod_pin``, ``wrist``,
``guide``; the spring ``spring``; the contact ``stop``; the source
``drive``. Used by tests/diagnose/test_planar_every_site.py (every
hypothesis and the located term compile at every site)."""
import sympy as sp

from acausal import Experiment, Model, guess
from acausal.mechanics.contact import EndStop
from acausal.mechanics.planar.joints import Prismatic, Revolute
from acausal.mechanics.planar.parts import Body, Fixed, FixedTranslation
from acausal.mechanics.rotational import Torque
from acausal.mechanics.translational import Fixed as Anchor
from acausal.mechanics.translational import Spring

R, L = 0.05, 0.2                       # crank and rod [m]

model = Model()
theta0 = model.parameter("theta0", 1.0, "rad", "release angle of the crank")
beta = sp.asin(R * sp.sin(theta0) / L)  # the rod's angle below the x axis at the release
model.ground = Fixed()
model.crank_pin = Revolute(phi=theta0, w=0.0)
model.flywheel = Body(m=1.0, I=2e-3)
model.crank = FixedTranslation(rx=R, ry=0.0)
model.rod_pin = Revolute(phi=guess(-theta0 - beta))
model.rod_half = FixedTranslation(rx=L / 2, ry=0.0)
model.rod_body = Body(m=0.3, I=1.2e-3)
model.rod_end = FixedTranslation(rx=L / 2, ry=0.0)
model.wrist = Revolute(phi=guess(beta))
model.slider = Body(m=0.5, I=1e-4)
model.guide = Prismatic(ex=1.0, ey=0.0,
                        s=guess(R * sp.cos(theta0) + sp.sqrt(L**2 - (R * sp.sin(theta0))**2)))
model.anchor = Anchor()
model.spring = Spring(c=400.0, s_rel0=0.10)
model.stop = EndStop(s_limit=0.16, side="lower", K=1e7, e=0.5)
model.drive = Torque(tau=0.5)
model.connect(model.ground.frame, model.crank_pin.frame_a, model.guide.frame_a)
model.connect(model.crank_pin.frame_b, model.flywheel.frame, model.crank.frame_a)
model.connect(model.crank.frame_b, model.rod_pin.frame_a)
model.connect(model.rod_pin.frame_b, model.rod_half.frame_a)
model.connect(model.rod_half.frame_b, model.rod_body.frame, model.rod_end.frame_a)
model.connect(model.rod_end.frame_b, model.wrist.frame_a)
model.connect(model.wrist.frame_b, model.slider.frame, model.guide.frame_b)
model.connect(model.anchor.flange, model.spring.flange_a)
model.connect(model.spring.flange_b, model.guide.axis, model.stop.flange)
model.connect(model.drive.flange, model.crank_pin.axis)

free_parameters = {"spring.c": (200.0, 800.0)}
conditions = {"theta0": (0.6, 1.4, "rad")}
experiment = Experiment(t_end=0.15, rtol=1e-8, atol=1e-10, atol_algebraic=1e-2,
                        output_step=5e-4)
