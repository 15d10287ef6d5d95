"""What an event action sees (:class:`EventState`): the hybrid loop
(:mod:`.hybrid`) and the sensitivity jumps (:mod:`.sensitivity_run`) build
one at each event instant. Names are looked up in the compiled model's
table of what an action may read
(:meth:`acausal.compiler.artefact.Artefact.readable`)."""
from ..errors import ModelError


class EventState:
    """What an event action sees: ``state[symbol]`` reads a variable, a
    discrete value or a parameter at the event; ``state[discrete] = v`` sets a
    discrete value. ``observed``: every variable's value at the event (in
    the order of ``cm.var_names``); ``changed``: whether a discrete value
    was set to a new value."""

    def __init__(self, cm, p, d, t, observed):
        self.cm, self.p, self.d, self.t, self.observed = cm, p, d, t, observed
        self.changed = False

    def _find(self, sym):
        name = getattr(sym, "name", sym)
        hit = self.cm.artefact.readable(name)
        if hit is None:
            raise ModelError(f"event action asked for {name!r}, which is not in the model")
        return hit

    def __getitem__(self, sym):
        kind, j = self._find(sym)
        if kind == "b":
            return float(j.xreplace(dict(zip(self.cm.param_syms, self.p))))
        return {"d": self.d, "v": self.observed, "p": self.p}[kind][j]

    def __setitem__(self, sym, value):
        kind, j = self._find(sym)
        if kind != "d":
            raise ModelError(f"event actions may only set discrete values, not {sym}")
        if self.d[j] != value:
            self.d[j] = float(value)
            self.changed = True
