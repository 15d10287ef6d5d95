"""What an event action sees (:class:`EventState`): the hybrid loop
(:mod:`acausal.simulate`) and the sensitivity jumps (:mod:`acausal.sensitivity`)
build one at each event instant."""
from .errors import ModelError


class EventState:
    """What an event action sees: ``state[symbol]`` reads a variable, a
    discrete value or a parameter at the event; ``state[discrete] = v`` sets a
    discrete value."""

    def __init__(self, cm, p, d, t, obs):
        self.cm, self.p, self.d, self.t, self._obs = cm, p, d, t, obs
        self.changed = False

    def _find(self, sym):
        name = getattr(sym, "name", sym)
        for j, dsc in enumerate(self.cm.discretes):
            if dsc.symbol.name == name:
                return "d", j
        if name in self._index():
            return "v", self._index()[name]
        for j, prm in enumerate(self.cm.params):
            if prm.name == name:
                return "p", j
        for s, expr in self.cm._subs.items():   # a parameter bound to others
            if s.name == name:
                return "b", expr
        raise ModelError(f"event action asked for {name!r}, which is not in the model")

    def _index(self):
        idx = getattr(self, "_idx", None)
        if idx is None:
            idx = self._idx = {n: k for k, n in enumerate(self.cm.var_names)}
        return idx

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
