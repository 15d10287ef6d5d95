"""Modelica.Mechanics.Translational.Examples.SignConvention (MSL 4.0.0),
with the library alone: the same +1 N applied three ways, at a mass's
flange_a, at its flange_b, and by a force whose support is grounded
(useSupport=False): every mass moves with s = t^2/2.

MSL's file also connects fixed.flange to force3.support although force3
has no support (useSupport=false); Modelica drops a connection to a
disabled connector. Here that connector does not exist and reaching for
it is an error that names the flag, so the connection is not written;
the ground it would have given is force3's internal one either way.

Compared with the reference: mass1.s, mass1.v, mass2.s, mass2.v,
mass3.s, mass3.v (tests/msl/test_parts_examples.py).
"""
from acausal import Experiment, Model
from acausal.blocks import Constant
from acausal.mechanics.translational import Fixed, Force, Mass

model = Model()
model.mass1 = Mass(L=1, s=0, v=0, m=1)
model.force1 = Force()
model.constant1 = Constant(k=1)
model.mass2 = Mass(L=1, s=0, v=0, m=1)
model.force2 = Force()
model.constant2 = Constant(k=1)
model.mass3 = Mass(L=1, s=0, v=0, m=1)
model.force3 = Force(useSupport=False)
model.constant3 = Constant(k=1)
model.fixed = Fixed()

model.connect(model.constant1.y, model.force1.f)
model.connect(model.constant2.y, model.force2.f)
model.connect(model.constant3.y, model.force3.f)
model.connect(model.force1.flange, model.mass1.flange_a)
model.connect(model.force2.flange, model.mass2.flange_b)
model.connect(model.mass3.flange_b, model.force3.flange)

experiment = Experiment(t_end=1.0, rtol=1e-6, output_step=5e-4)
