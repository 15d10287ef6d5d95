"""Modelica.Mechanics.Translational.Examples.Friction (MSL 4.0.0), with the
library alone: three independent systems.

* stop1: a mass with Stribeck friction (F_prop 1, F_Coulomb 5, F_Stribeck
  10, fexp 2) driven by a sine force (25 N, 0.25 Hz), far from its stops;
* mass + supportFriction: the same physics with the friction as a
  50-point table of the Stribeck law (stribeck_table, MSL's
  GenerateStribeckFrictionTable);
* stop2: a mass on a spring starting at -5 m/s between hard stops at
  +-0.9 m (L = 1 m): it hits the left stop (velocity reset to 0), breaks
  away forward and oscillates with friction until it sticks.

Compared with the reference: mass.s, mass.v, stop1.s, stop1.v, stop2.s,
stop2.v and the modes and start flags of stop1, stop2 and supportFriction
(tests/msl/test_friction_examples.py).
"""
from acausal import Experiment, Model
from acausal.blocks.sources import Sine
from acausal.mechanics.translational import (Fixed, Force, Mass, MassWithStopAndFriction, Spring,
                                             SupportFriction, stribeck_table)

model = Model()
model.stop1 = MassWithStopAndFriction(L=1, s=0, v=0, smax=25, smin=-25, m=1, F_prop=1,
                                      F_Coulomb=5, F_Stribeck=10, fexp=2)
model.force = Force()
model.sineForce = Sine(amplitude=25, f=0.25)
model.stop2 = MassWithStopAndFriction(L=1, smax=0.9, smin=-0.9, F_Coulomb=3, F_Stribeck=5,
                                      s=0, m=1, F_prop=1, fexp=2, v=-5)
model.spring = Spring(s_rel0=1, c=500)
model.fixed2 = Fixed(s0=-1.75)
model.force2 = Force()
model.mass = Mass(m=1, L=1, s=0, v=0)
model.supportFriction = SupportFriction(f_pos=stribeck_table(
    F_prop=1, F_Coulomb=5, F_Stribeck=10, fexp=2, v_max=12, n=50))

model.connect(model.spring.flange_b, model.stop2.flange_a)
model.connect(model.sineForce.y, model.force.f)
model.connect(model.spring.flange_a, model.fixed2.flange)
model.connect(model.force.flange, model.stop1.flange_a)
model.connect(model.force2.flange, model.mass.flange_a)
model.connect(model.mass.flange_b, model.supportFriction.flange_a)
model.connect(model.sineForce.y, model.force2.f)

experiment = Experiment(t_end=5.0, rtol=1e-6, output_step=5e-4)
