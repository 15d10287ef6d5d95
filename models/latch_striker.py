"""A solenoid striker tripping a spring-loaded latch: the smallest mechanism
with every kind of site the diagnosis looks at (two bodies, a spring, a
damper, an impact contact and a force source), and a second test bench for
it besides the breaker.

    frame --ret--[plunger]--contact--> [latch]--latch_spring-- frame
           coil pushes the plunger along +s     latch_damper to the frame

The coil pulls the plunger (0.04 kg) with ``F_coil`` against its return
spring; after 1 mm of travel the plunger strikes the latch (0.02 kg, a
Hunt-Crossley contact), which is held by a spring and a viscous damper and
trips when it has moved 2 mm (the run stops there, event ``trip``).
``F_coil`` plays the part of the breaker's impact velocity: an experimental
condition. Measures: ``trip_time`` (start to trip) and ``impact_velocity``.
The free parameters are the contact stiffness and the latch damping, the two
numbers a designer would calibrate.
"""
from acausal import Experiment, Measure, Model, Stop
from acausal.mechanics import contact as ct
from acausal.mechanics.contact import Contact
from acausal.mechanics.translational import Damper, Fixed, Force, Mass, Spring

GAP = 1e-3       # [m] plunger travel before it strikes the latch
TRIP = 2e-3      # [m] latch travel at which it trips

model = Model()
F_coil = model.parameter("F_coil", 30.0, "N", "coil force on the plunger", min=0.0)
model.frame = Fixed()
model.plunger = Mass(m=0.04, s=0.0, v=0.0)
model.coil = Force(f=F_coil)
model.ret = Spring(c=300.0, s_rel0=0.0, f0=-3.0)       # return spring, 3 N preload
model.contact = Contact(K=5e8, e=0.6, gamma=1.5, law="hunt_crossley", gap=0.0)
model.latch = Mass(m=0.02, s=GAP, v=0.0)
model.latch_spring = Spring(c=2000.0, s_rel0=GAP)
model.latch_damper = Damper(d=4.0)
model.latch_frame = Fixed(s0=0.0)
model.connect(model.frame.flange, model.ret.flange_a)
model.connect(model.ret.flange_b, model.plunger.flange, model.coil.flange,
              model.contact.flange_a)
model.connect(model.contact.flange_b, model.latch.flange, model.latch_spring.flange_b,
              model.latch_damper.flange_b)
model.connect(model.latch_frame.flange, model.latch_spring.flange_a,
              model.latch_damper.flange_a)

free_parameters = {"contact.K": (1e7, 1e10), "latch_damper.d": (0.0, 20.0)}

# output at the solver's steps and events (the measures are event-based and
# the same to round-off as on the 1e-5 s grid); plots, CSV files and trace
# comparisons get the grid (dense_step)
experiment = Experiment(t_end=0.05, rtol=1e-8, atol=1e-11, output_step=0, dense_step=1e-5,
                        stop=Stop("latch.s", ">=", GAP + TRIP, name="trip"))

measures = {
    "trip_time": Measure(lambda res: res.event_times("trip")[0], "s", display="ms"),
    "impact_velocity": Measure(lambda res: ct.impact_velocity(res, "contact"), "m/s"),
}
