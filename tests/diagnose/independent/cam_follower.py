"""A cam follower, written as a user would with the library: a free-running
eccentric cam (inertia ``J`` on a bearing with a viscous loss) lifts a
flat-faced follower (mass ``m``) that a preloaded spring presses onto it.
The cam is spun up to the speed ``w0`` (the experiment's condition) and
left to run down: fast runs turn it over the top many times, slow ones
leave it rocking in the profile's valley. The cam's profile is known: the
follower's lift is ``e * (1 - cos(phi))`` (an eccentric disc of
eccentricity ``e`` under a flat face), so the follower stays in contact as
long as the spring's force exceeds its inertia's (checked by the truth
simulator, ``cam_truth.py``).

The follower spring's rate and the cam bearing's viscous coefficient are
the free parameters a user would calibrate. Measured: the cam angle
(encoder) and the follower's lift (a displacement probe). Used by the
independent blind cases (``tests/diagnose/independent/``) with data from
a scipy simulator that shares no code with the library."""
from sympy import cos, sin

from acausal import Component, Eq, Experiment, Flange, Model, Parameter, RotFlange, guess
from acausal.mechanics.rotational import Fixed as RotFixed
from acausal.mechanics.rotational import Inertia, RotationalDamper
from acausal.mechanics.translational import Fixed, Mass, Spring


class EccentricCam(Component):
    """A massless eccentric cam under a flat-faced follower: the follower's
    lift is ``flange_t.s = e * (1 - cos(phi))`` with ``phi =
    flange_r.phi``, and power is conserved, ``flange_r.tau = -e * sin(phi)
    * flange_t.f`` (the follower's force acts on the cam through the lever
    arm ``ds/dphi``). The cam's inertia is an Inertia on ``flange_r``, the
    follower's mass a Mass on ``flange_t``.

    Parameters: ``e`` [m] eccentricity (the lift is 0 .. 2e).
    Connectors: ``flange_r`` (the cam shaft), ``flange_t`` (the follower).
    """

    flange_r = RotFlange("the cam shaft")
    flange_t = Flange("the follower's face")
    e = Parameter(5e-3, "m", "eccentricity of the cam (lift 0 .. 2e)", min=0.0, min_open=True)

    def equations(self):
        phi = self.flange_r.phi
        return [Eq(self.flange_t.s, self.e * (1 - cos(phi))),
                Eq(self.flange_r.tau, -self.e * sin(phi) * self.flange_t.f)]


model = Model()
w0 = model.parameter("w0", 35.0, "rad/s", "speed the cam is spun up to")
model.frame = RotFixed()
model.ground = Fixed()
model.cam = Inertia(J=1e-3, phi=0.0, w=w0)
model.bearing = RotationalDamper(d=2e-5)
model.profile = EccentricCam(e=5e-3)
model.follower = Mass(m=0.2, s=guess(0.0), v=guess(0.0))
# the spring pushes the follower down onto the cam with 20 N at zero lift
model.spring = Spring(c=2000.0, s_rel0=-0.01)
model.connect(model.frame.flange, model.bearing.flange_a)
model.connect(model.bearing.flange_b, model.cam.flange, model.profile.flange_r)
model.connect(model.profile.flange_t, model.follower.flange, model.spring.flange_b)
model.connect(model.ground.flange, model.spring.flange_a)

free_parameters = {"spring.c": (1000.0, 4000.0), "bearing.d": (0.0, 2e-4)}
conditions = {"w0": (10.0, 40.0, "rad/s")}

experiment = Experiment(t_end=2.0, rtol=1e-8, atol=1e-10, output_step=1e-3)
