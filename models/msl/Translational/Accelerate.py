"""Modelica.Mechanics.Translational.Examples.Accelerate (MSL 4.0.0), with the
library alone: a Constant signal (k = 1 m/s2) drives a Sources.Accelerate,
which moves a 1 kg Mass of length 1 m by its flange_a (flange_b is
unconnected: no force there). Accelerate's s and v start fixed at 0.

Compared with the reference: accelerate.s and accelerate.v
(tests/msl/test_signals_examples.py).
"""
from acausal import Experiment, Model
from acausal.blocks import Constant
from acausal.mechanics.translational import Accelerate, Mass

model = Model()
model.accelerate = Accelerate()
model.mass = Mass(L=1, m=1)
model.constantAcc = Constant(k=1)

model.connect(model.accelerate.flange, model.mass.flange_a)
model.connect(model.constantAcc.y, model.accelerate.a_ref)

experiment = Experiment(t_end=1.0, rtol=1e-6, output_step=5e-4)
