"""Hertz impact: a 0.1 kg mass hits a rigid wall at 1 m/s through an
undamped Hertz contact (K = 1e9 N/m^1.5, gamma = 1.5, restitution 1).

Exact: the contact lasts t_c = 2.94328 * delta_max / v0 with
delta_max = (5 m v0^2 / (4 K))^(2/5) (t_c = 0.321807 ms here; the constant is
(4/5) B(2/5, 1/2)); the mass leaves at -1 m/s; the peak force is
K delta_max^1.5 = 1143.26 N. The mass starts 0.1 mm from the wall.
"""
from acausal import Experiment, Measure, Model
from acausal.mechanics.contact import Contact, contact_period, peak_force, restitution
from acausal.mechanics.translational import Fixed, Mass

model = Model()
model.mass = Mass(m=0.1, s=-1e-4, v=1.0)
model.wall = Fixed(s0=0.0)
model.contact = Contact(K=1e9, gamma=1.5, e=1.0, gap=0.0)
model.connect(model.mass.flange, model.contact.flange_a)
model.connect(model.contact.flange_b, model.wall.flange)

experiment = Experiment(t_end=6e-4, rtol=1e-10, atol=1e-14, output_step=1e-6)

measures = {
    "contact_period": Measure(lambda res: contact_period(res, "contact"), "s", display="ms"),
    "rebound_velocity": Measure(lambda res: -res.final()["mass.v"], "m/s"),
    "restitution": Measure(lambda res: restitution(res, "contact"), "1"),
    "peak_force": Measure(lambda res: peak_force(res, "contact"), "N"),
}
