"""The flat model: the data :mod:`.flatten` produces and the later stages
read (parameters, variables and discrete values under dotted paths, the
equations with the component each came from, events, assertions, the
unconnected connectors and the time switches)."""
from dataclasses import dataclass, field

import sympy as sp

from ..lang.declare import Parameter, Start
from ..lang.symbols import base_and_order


@dataclass
class ParamInfo:
    symbol: sp.Symbol
    value: object          # number, sympy expression (bound) or a choice
    decl: Parameter
    owner: str

    @property
    def bound(self):
        return isinstance(self.value, sp.Basic) and not self.value.is_number


@dataclass
class VarInfo:
    symbol: sp.Symbol
    start: Start
    unit: str
    desc: str
    owner: str
    port: bool = False     # a connector variable
    unit_declared: bool = True   # False: no unit was given (not checked)
    internal: bool = False  # made by the compiler (a time switch), not declared
    nominal: float = None   # Modelica's nominal value (scales the absolute tolerance)


@dataclass
class Equation:
    expr: sp.Expr           # residual: expr = 0
    origin: str             # component path (or 'connect(...)')
    label: str = ""

    def describe(self):
        return f"{self.label or 'equation'} of {self.origin or 'the model'}: {self.expr} = 0"


@dataclass
class Flat:
    params: dict = field(default_factory=dict)      # path -> ParamInfo
    variables: dict = field(default_factory=dict)   # path -> VarInfo
    discretes: dict = field(default_factory=dict)   # path -> VarInfo (start value)
    equations: list = field(default_factory=list)
    events: list = field(default_factory=list)
    assertions: list = field(default_factory=list)
    unconnected: list = field(default_factory=list)  # port paths
    owners: dict = field(default_factory=dict)      # component path -> class name
    time_switches: list = field(default_factory=list)  # compiler/timeevents.TimeSwitch
    time_events: list = field(default_factory=list)    # lang.declare.TimeEvent

    def owner_of(self, sym):
        """Component path owning a variable/parameter symbol."""
        base, _ = base_and_order(sym)
        info = self.variables.get(base.name) or self.params.get(base.name) \
            or self.discretes.get(base.name)
        return info.owner if info else ""
