"""What a model file may declare besides its model: how to run it.

``experiment = Experiment(t_end=..., stop=Stop("hook.phi", ">=", "Ra"))``
"""
from dataclasses import dataclass, field

import sympy as sp

from .declare import Event
from .errors import ModelError

_OPS = {">=": 1, ">": 1, "<=": -1, "<": -1}


class Stop:
    """A terminal condition: ``Stop("hook.phi", ">=", "Ra")`` stops the run
    when ``hook.phi - Ra`` rises through zero. The sides are dotted names,
    numbers or sympy expressions of model symbols; the event is called
    ``name`` (default ``"stop"``) in the result."""

    def __init__(self, lhs, op, rhs, name="stop"):
        if op not in _OPS:
            raise ModelError(f"Stop: operator must be one of {list(_OPS)}, got {op!r}")
        self.lhs, self.op, self.rhs, self.name = lhs, op, rhs, name

    def event(self, model):
        """The terminal :class:`Event` for ``model``."""
        names = {}
        for comp in model.walk():
            for dname in comp.declarations():
                s = comp.symbol(dname)
                names[s.name] = s
            for pname in comp.connectors():
                for pair in comp.port(pname).pairs():
                    names.update((s.name, s) for s in pair)

        def conv(side):
            if isinstance(side, str):
                if side not in names:
                    raise ModelError(f"Stop: {side!r} is not a variable or parameter "
                                     "of the model")
                return names[side]
            return sp.sympify(side)

        expr = conv(self.lhs) - conv(self.rhs)
        return Event(self.name, expr, _OPS[self.op], terminal=True)


@dataclass
class Experiment:
    """How to simulate a model: time span, tolerances, output step, and an
    optional terminal :class:`Stop` condition."""

    t_end: float = 1.0
    t0: float = 0.0
    rtol: float = 1e-6
    atol: float = 1e-8
    output_step: float = None
    max_step: float = None
    atol_algebraic: float = None   # see acausal.simulate.simulate
    stop: Stop = None
    options: dict = field(default_factory=dict)

    def run_options(self):
        return dict(t_end=self.t_end, t0=self.t0, rtol=self.rtol, atol=self.atol,
                    output_step=self.output_step, max_step=self.max_step,
                    **({} if self.atol_algebraic is None
                       else {"atol_algebraic": self.atol_algebraic}))
