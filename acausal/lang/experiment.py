"""What a model file may declare besides its model: how to run it, and
what to measure.

``experiment = Experiment(t_end=..., stop=Stop("hook.phi", ">=", "Ra"))``
``measures = {"thrt": Measure(lambda res: ..., "s", display="ms")}``
"""
from dataclasses import dataclass, field
from typing import Callable, Optional

import sympy as sp

from .declare import Event
from ..errors import ModelError

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
    """How to simulate a model: time span, tolerances, output step (0: the
    solver's internal steps and events; None: 500 intervals), the output
    step of runs that need a dense time series (``dense_step``, see
    :meth:`run_options`), and an optional terminal :class:`Stop` condition.

    ``atol`` applies to every unknown; ``atol_algebraic``, when given, to the
    algebraic ones instead (accelerations, joint forces, Lagrange-like
    reactions: whatever is not a state). In a planar loop those are large
    (joint forces of 100s of N, accelerations of 100s of rad/s^2), and an
    absolute tolerance far below their rounding makes IDA take tiny steps
    or fail. Measured on the spring-returned planar slider-crank
    (tests/diagnose/planar_slider_crank.py, 0.6 s, compiled backend):
    rtol 1e-9 with atol 1e-12 stopped at t = 0.28 s ("maximum number of
    steps"); with ``atol_algebraic=1e-4`` it took 4069 steps, 3.6e-8 of the
    range from a reference at rtol 1e-11, and with 1e-2 3574 steps, 1.3e-7.
    The states keep ``atol``, so the positions and speeds a trace compares
    are held to it. See docs/planar.md, "Writing a planar model file"."""

    t_end: float = 1.0
    t0: float = 0.0
    rtol: float = 1e-6
    atol: float = 1e-8
    output_step: float = None
    max_step: float = None
    atol_algebraic: float = None   # absolute tolerance of the algebraic unknowns (class doc)
    stop: Stop = None
    options: dict = field(default_factory=dict)
    dense_step: float = None

    def run_options(self, dense=False):
        """Keyword arguments of ``simulate``. ``output_step`` gives the output
        of every run (0: the solver's internal steps plus both sides of every
        event, all that event-based measures need); ``dense_step``, when set,
        is the output grid of a run that needs a dense time series (a plot, a
        CSV, samples compared with a measured trace): ``dense=True``. The
        output times never change the solution (IDA interpolates them), only
        the cost and what is stored."""
        step = self.dense_step if dense and self.dense_step is not None else self.output_step
        return dict(t_end=self.t_end, t0=self.t0, rtol=self.rtol, atol=self.atol,
                    output_step=step, max_step=self.max_step,
                    **({} if self.atol_algebraic is None
                       else {"atol_algebraic": self.atol_algebraic}))


@dataclass(frozen=True)
class Measure:
    """A scalar computed from a result, with its unit: ``fn(result)`` returns
    the value in the SI unit ``unit``; ``display`` is the unit it is printed
    in (default: ``unit``), e.g. ``Measure(thrt, "s", display="ms")``.
    A model file's ``measures`` may also hold plain functions (no unit)."""

    fn: Callable
    unit: str = "1"
    display: Optional[str] = None
    desc: str = ""

    def __call__(self, result):
        return self.fn(result)

    def shown(self, value):
        """(value in the display unit, display unit)."""
        if not self.display or self.display == self.unit:
            return value, self.unit
        return value * unit_factor(self.unit, self.display), self.display


def unit_factor(unit, target):
    """The factor taking a value in ``unit`` to ``target`` (pint; raises a
    ModelError naming both when the dimensions differ)."""
    from ..data.units import parse_unit
    try:
        return float((1.0 * parse_unit(unit)).to(parse_unit(target)).magnitude)
    except Exception as exc:   # pint: undefined unit, dimensionality error
        raise ModelError(f"cannot show a value in [{unit}] in [{target}]: {exc}") from None
