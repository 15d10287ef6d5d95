"""The model check (``acausal check MODEL``): compile a model and say what
it is made of, and what Modelica's rules filled in without an error.

An unconnected connector is no error (Modelica's rule: its through
variables, force or torque, are zero), but it is often a forgotten
``connect``: the check lists every one. Errors (a structurally singular
model, an input with no source) are raised as compiling raises them.
"""
from dataclasses import dataclass, field

from .pipeline import compile_model


@dataclass
class ModelCheck:
    """What :func:`check_model` found.

    ``unconnected``: paths of the connectors left unconnected (their force
    or torque is zero); ``states``: the integrator's states (empty for a
    fully prescribed motion); ``time_events``: the time switches and
    component time events, described; ``bound_inputs``: inputs set by an
    expression instead of a connection."""
    components: int
    equations: int
    unknowns: int
    states: list = field(default_factory=list)
    unconnected: list = field(default_factory=list)
    time_events: list = field(default_factory=list)
    bound_inputs: list = field(default_factory=list)

    def lines(self):
        """The check as lines of text."""
        out = [f"{self.components} components, {self.equations} equations and "
               f"{self.unknowns} unknowns after flattening; "
               + (f"{len(self.states)} states: " + ", ".join(self.states) if self.states
                  else "no states (every motion is prescribed)")]
        if self.unconnected:
            out.append(f"{len(self.unconnected)} unconnected connector(s), their force/torque "
                       "is zero: " + ", ".join(self.unconnected))
        else:
            out.append("every connector is connected")
        if self.time_events:
            out.append(f"{len(self.time_events)} time event source(s): "
                       + "; ".join(self.time_events))
        if self.bound_inputs:
            out.append("inputs bound to expressions: " + ", ".join(self.bound_inputs))
        return out

    def as_dict(self):
        return dict(components=self.components, equations=self.equations,
                    unknowns=self.unknowns, states=self.states, unconnected=self.unconnected,
                    time_events=self.time_events, bound_inputs=self.bound_inputs)


def check_model(model, cache=True, compiled=None):
    """Compile ``model`` (or take ``compiled``, its CompiledModel) and
    return a :class:`ModelCheck`."""
    cm = compiled if compiled is not None else compile_model(model, cache=cache)
    flat = cm.flat
    states = [s.name for s in cm.dae.y[:cm.dae.n_states]]
    events = [f"{sw.owner or 'model'}: {sw.text}" for sw in flat.time_switches]
    events += [f"{ev.owner}: {ev.name}" for ev in flat.time_events]
    bound = sorted(e.origin + "." + e.label.split()[-1] for e in flat.equations
                   if e.label.startswith("binding of input"))
    n_vars = sum(1 for v in flat.variables.values())
    return ModelCheck(sum(1 for path in flat.owners if path), len(flat.equations), n_vars, states,
                      sorted(flat.unconnected), events, bound)
