"""Event actions read parameters that are bound to other parameters."""
from acausal import Component, Discrete, Eq, Event, Flange, Model, Parameter, compile_model
from acausal.mechanics.translational import Mass


class Marker(Component):
    """Records the value of parameter ``level`` when the flange passes it."""
    flange = Flange("watched flange")
    level = Parameter(0.0, "m", "position that triggers the event")
    seen = Discrete(0.0, "m", "level read by the action")

    def equations(self):
        return [Eq(self.flange.f, 0)]

    def events(self):
        def act(s):
            s[self.seen] = s[self.level]
        return [Event("pass", self.flange.s - self.level, +1, act)]


def test_event_action_reads_a_bound_parameter():
    m = Model()
    x = m.parameter("x", 0.25, "m", "shared level")
    m.mass = Mass(m=1.0, s=0.0, v=1.0)
    m.marker = Marker(level=2 * x)
    m.connect(m.mass.flange, m.marker.flange)
    cm = compile_model(m)
    assert "marker.level" in cm.bound
    res = cm.simulate(t_end=1.0, params={"x": 0.3}, rtol=1e-9, atol=1e-12)
    (t, name), = res.events
    assert abs(t - 0.6) < 1e-8
    assert res.final()["marker.seen"] == 0.6
