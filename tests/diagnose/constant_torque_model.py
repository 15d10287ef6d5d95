"""A spring-held inertia driven by an MSL ConstantTorque (its value is the
tau variable of PartialTorque, no ``quantity``): for the hypotheses that
read a source's value (tests/diagnose/test_hypotheses.py)."""
from acausal import Experiment, Model
from acausal.mechanics.rotational import Fixed, Inertia, ConstantTorque, Spring
model = Model()
tq = model.parameter("tq", 2.0, "N*m", "drive torque")
model.frame = Fixed()
model.body = Inertia(J=0.01, phi=0.0, w=0.0)
model.spring = Spring(c=50.0, phi_rel0=0.0)
model.drive = ConstantTorque(tau_constant=tq)
model.connect(model.frame.flange, model.spring.flange_a)
model.connect(model.spring.flange_b, model.body.flange)
model.connect(model.drive.flange, model.body.flange)
experiment = Experiment(t_end=0.2, rtol=1e-8, atol=1e-11, output_step=1e-3)
free_parameters = {"spring.c": (10.0, 200.0)}
conditions = {"tq": (0.5, 5.0, "N*m")}
