"""A wheel driving a slider through a rigid lever, and a tip on a spring
beyond it (written as a user would, for tests/diagnose/test_kinematics.py)::

    wheel (J) --lever, arm ARM-- slider (m) --(k2, d2)-- tip (m)
                                    |
                                  k to ground

The slider's speed is ARM times the wheel's (closed form: the lever is
rigid), so the wheel and the slider are kinematically equivalent sites at a
rate ratio of ARM [m/rad]; the tip rings on its own spring (its own mode),
so it is tied to neither. The tip is released from ``x0`` with the rest at
rest; the first spring's stiffness is the free parameter."""
from acausal import Experiment, Model, guess
from acausal.mechanics.levers import IdealLever
from acausal.mechanics.rotational import Inertia
from acausal.mechanics.translational import Damper, Fixed, Mass, Spring

ARM = -0.05           # [m] lever arm: slider.s = ARM * wheel.phi

model = Model()
x0 = model.parameter("x0", 0.01, "m", "release offset of the tip")
model.ground = Fixed()
model.wheel = Inertia(J=2e-4, phi=0.0, w=0.0)
model.lever = IdealLever(arm=ARM)
model.slider = Mass(m=0.3, s=guess(0.0), v=guess(0.0))
model.k = Spring(c=500.0)
model.tip = Mass(m=0.1, s=x0, v=0.0)
model.k2 = Spring(c=300.0)
model.d2 = Damper(d=0.5)
model.connect(model.wheel.flange, model.lever.flange_r)
model.connect(model.lever.flange_t, model.slider.flange, model.k.flange_b, model.k2.flange_a,
              model.d2.flange_a)
model.connect(model.ground.flange, model.k.flange_a)
model.connect(model.k2.flange_b, model.d2.flange_b, model.tip.flange)

free_parameters = {"k.c": (200.0, 1000.0)}
conditions = {"x0": (0.004, 0.02, "m")}
experiment = Experiment(t_end=0.6, rtol=1e-9, atol=1e-12, output_step=1e-3)
