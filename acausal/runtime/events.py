"""What an event action sees (:class:`EventState`): the hybrid loop
(:mod:`acausal.simulate`) and the sensitivity jumps (:mod:`acausal.sensitivity`)
build one at each event instant."""
from ..errors import ModelError


class EventState:
    """What an event action sees: ``state[symbol]`` reads a variable, a
    discrete value or a parameter at the event; ``state[discrete] = v`` sets a
    discrete value."""

    def __init__(self, cm, p, d, t, obs):
        self.cm, self.p, self.d, self.t, self._obs = cm, p, d, t, obs
        self.changed = False

    def _find(self, sym):
        name = getattr(sym, "name", sym)
        hit = _names(self.cm).get(name)
        if hit is None:
            raise ModelError(f"event action asked for {name!r}, which is not in the model")
        return hit

    def __getitem__(self, sym):
        kind, j = self._find(sym)
        if kind == "b":
            return float(j.xreplace(dict(zip(self.cm.param_syms, self.p))))
        return {"d": self.d, "v": self._obs, "p": self.p}[kind][j]

    def __setitem__(self, sym, value):
        kind, j = self._find(sym)
        if kind != "d":
            raise ModelError(f"event actions may only set discrete values, not {sym}")
        if self.d[j] != value:
            self.d[j] = float(value)
            self.changed = True


def _names(cm):
    """name -> ("d", discrete index) | ("v", index in var_names) | ("p",
    parameter index) | ("b", expression of a parameter bound to others),
    made once per model; a name in several kinds resolves in that order."""
    index = cm.__dict__.get("_event_names")
    if index is None:
        index = {}
        for s, expr in cm._subs.items():
            index[s.name] = ("b", expr)
        for j, prm in enumerate(cm.params):
            index[prm.name] = ("p", j)
        for k, n in enumerate(cm.var_names):
            index[n] = ("v", k)
        for j, dsc in enumerate(cm.discretes):
            index[dsc.symbol.name] = ("d", j)
        cm._event_names = index
    return index
