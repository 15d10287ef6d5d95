"""Modelica.Mechanics.Rotational.Examples.ElasticBearing (MSL 4.0.0), with
the library alone: a gearbox whose housing is not fixed to the ground but
held by a stiff spring-damper, so that the housing's small oscillation can
be examined (MSL's example of a support flange).

    ramp -> torque -> shaft -> idealGear(3) -> spring -> load
                       support: housing -> multiSensor -> springDamper -> fixed

The torque ramps to 100 N*m over 5 s. ``springDamper.w_rel`` carries MSL's
``nominal = 1e-4`` rad/s (it stays below 1e-3 rad/s): its absolute
tolerance is rtol*1e-4, not the run's atol.

Compared with the reference: load.phi, load.w, shaft.phi, shaft.w,
springDamper.phi_rel, springDamper.w_rel (tests/msl/test_unlisted_examples.py).
"""
from acausal import Experiment, Model
from acausal.blocks.sources import Ramp
from acausal.mechanics.rotational import (Fixed, IdealGear, Inertia, MultiSensor, Spring,
                                          SpringDamper, Torque)

model = Model()
model.shaft = Inertia(J=1, phi=0, w=0)
model.load = Inertia(J=50, w=0)
model.spring = Spring(c=1e3, phi_rel=0)
model.fixed = Fixed()
model.springDamper = SpringDamper(c=1e5, d=5, phi_rel=0, w_rel=0).with_nominal(w_rel=1e-4)
model.torque = Torque(useSupport=True)
model.ramp = Ramp(duration=5, height=100)
model.idealGear = IdealGear(ratio=3, useSupport=True)
model.housing = Inertia(J=5)
model.multiSensor = MultiSensor()

model.connect(model.torque.flange, model.shaft.flange_a)
model.connect(model.spring.flange_b, model.load.flange_a)
model.connect(model.springDamper.flange_a, model.fixed.flange)
model.connect(model.shaft.flange_b, model.idealGear.flange_a)
model.connect(model.idealGear.flange_b, model.spring.flange_a)
model.connect(model.idealGear.support, model.housing.flange_b)
model.connect(model.ramp.y, model.torque.tau)
model.connect(model.fixed.flange, model.torque.support)
model.connect(model.housing.flange_a, model.multiSensor.flange_b)
model.connect(model.multiSensor.flange_a, model.springDamper.flange_b)

experiment = Experiment(t_end=10.0, rtol=1e-6, output_step=5e-3)
