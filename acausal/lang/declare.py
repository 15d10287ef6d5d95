"""Declarations a component makes as class attributes: parameters, variables
and discrete values. Each carries a unit and a one-line description.

Reading a declaration on a component *instance* gives the sympy symbol named
by the instance's dotted path (``hook.Jh``), ready for use in equations.
"""
import math
import numbers

import sympy as sp

from ..errors import ModelError, ParameterError


class Declaration:
    """Common part: a name (set by ``__set_name__``), a unit, a description."""

    kind = "declaration"

    def __init__(self, unit=None, desc=""):
        # a unit not given is dimensionless for display and data ("1"), but
        # unchecked (Modelica's unit = ""): acausal.compiler.units skips it
        self.unit_declared = unit is not None
        self.unit = "1" if unit is None else unit
        self.desc = desc
        self.name = None

    def __set_name__(self, owner, name):
        self.name = name

    def __get__(self, obj, objtype=None):
        if obj is None:
            return self
        return obj.symbol(self.name)


class Parameter(Declaration):
    """A constant of the model, changeable between runs without recompiling.

    ``min``/``max`` are checked when the component is built (``min_open`` /
    ``max_open`` make a bound strict). A ``structural`` parameter (a choice of
    law, a flag) is baked into the generated code: changing it recompiles.
    Its value is read as a plain Python value, not a symbol.

    ``default`` may be a function of the component, evaluated when the
    model is flattened (:meth:`acausal.lang.Component.value`): a derived
    parameter (a body's mass from its dimensions and density) or one taken
    from an enclosing component (a body's gravity from the world's,
    :meth:`acausal.lang.Component.outer`). Its value is then an expression
    of other parameters, which a run cannot set on its own. ``final``: a
    derived parameter that cannot be given a value (Modelica's ``final``).
    """

    kind = "parameter"

    def __init__(self, default, unit=None, desc="", *, min=None, max=None,
                 min_open=False, max_open=False, structural=False, choices=None,
                 final=False):
        super().__init__(unit, desc)
        self.final = final
        self.default = default
        self.min, self.max = min, max
        self.min_open, self.max_open = min_open, max_open
        self.structural = structural
        self.choices = choices

    def __get__(self, obj, objtype=None):
        if obj is None:
            return self
        if self.structural:
            return obj._values[self.name]
        return obj.symbol(self.name)

    def check(self, value, where):
        """Validate ``value`` for the component at path ``where``."""
        label = f"{where}.{self.name}" if where else self.name
        if self.structural:
            if self.choices is not None and value not in self.choices:
                raise ParameterError(
                    f"parameter {label} = {value!r} is not one of {list(self.choices)}")
            return value
        if isinstance(value, sp.Basic) and not value.is_number:
            return value  # bound to an expression of other parameters
        if isinstance(value, bool) or not isinstance(value, (numbers.Real, sp.Basic)):
            raise ParameterError(
                f"parameter {label} must be a number [{self.unit}], got {value!r}",
                variable=label)
        try:
            v = float(value)
        except (TypeError, ValueError):  # a sympy number that is not real (zoo, I)
            raise ParameterError(f"parameter {label} = {value} is not a real number",
                                 variable=label) from None
        if not math.isfinite(v):
            raise ParameterError(f"parameter {label} = {v} is not a finite number",
                                 variable=label)
        self.check_bounds(v, label)
        return value

    def check_bounds(self, v, label):
        if self.min is not None and (v < self.min or (self.min_open and v == self.min)):
            rel = ">" if self.min_open else ">="
            raise ParameterError(
                f"parameter {label} = {v:g} [{self.unit}] must be {rel} {self.min:g} ({self.desc})",
                variable=label)
        if self.max is not None and (v > self.max or (self.max_open and v == self.max)):
            rel = "<" if self.max_open else "<="
            raise ParameterError(
                f"parameter {label} = {v:g} [{self.unit}] must be {rel} {self.max:g} ({self.desc})",
                variable=label)


class Start:
    """A start value: ``fixed=True`` means the initial value is imposed,
    ``fixed=False`` that it is only a guess for the initialisation."""

    def __init__(self, value, fixed=True):
        self.value = value
        self.fixed = fixed

    def __repr__(self):
        return f"Start({self.value!r}, fixed={self.fixed})"


def guess(value):
    """A start value that is only a guess (``Start(value, fixed=False)``)."""
    return Start(value, fixed=False)


class Variable(Declaration):
    """A time-varying unknown. ``start`` is a guess unless ``fixed``.

    ``nominal`` (Modelica's attribute, in the variable's unit): its order
    of magnitude. The integrator's absolute tolerance on it is then
    ``rtol * |nominal|`` (the Modelica Specification's recommendation,
    section 4.8.7: tolerance ``rtol*(|nominal| + |x|)``; OpenModelica's
    rule), instead of the run's ``atol``: a 1e-3-scale angle or velocity is
    integrated to the relative accuracy asked, and a kilonewton force is
    not held to 1e-8 N. ``Component.with_nominal(w=1e-3)`` sets it on one
    instance."""

    kind = "variable"

    def __init__(self, start=0.0, unit=None, desc="", *, fixed=False, nominal=None):
        super().__init__(unit, desc)
        self.start = Start(start, fixed)
        self.nominal = check_nominal(nominal, desc)


def check_nominal(value, where):
    """``value`` as a positive finite float (None stays None), else a
    ParameterError naming ``where``."""
    if value is None:
        return None
    ok = isinstance(value, numbers.Real) and not isinstance(value, bool)
    if not ok or not math.isfinite(float(value)) or float(value) == 0.0:
        raise ParameterError(f"nominal value of {where} must be a non-zero finite number, "
                             f"got {value!r}", variable=str(where))
    return abs(float(value))


class Discrete(Declaration):
    """A value that only changes at events (a contact mode, the impact
    velocity captured at contact onset). Constant between events."""

    kind = "discrete"

    def __init__(self, start=0.0, unit=None, desc=""):
        super().__init__(unit, desc)
        self.start = start


class Event:
    """A zero crossing of ``expr`` that a component reacts to.

    ``direction`` +1 fires when ``expr`` rises through zero, -1 when it falls,
    0 both ways. ``action(state)`` may change discrete values
    (``state[self.mode] = 1``); ``terminal=True`` stops the simulation.
    With ``recheck=True`` the condition is also tested right after any other
    event re-initialised the model (an event iteration, as Modelica does), so
    a mode that is not valid at the new point is left at once.
    ``observer=True`` marks an event whose action only records values
    (discrete values that no equation uses, such as a peak force): IDA does
    not stop for it, the action runs on the state IDA located, and the
    integration goes on undisturbed. ``log=False`` leaves the event out of
    ``res.events`` (bookkeeping that is no physical event, such as a
    planar joint deciding at the start whether it drives its loop).
    """

    def __init__(self, name, expr, direction=0, action=None, *, terminal=False,
                 recheck=False, observer=False, log=True):
        if direction not in (-1, 0, 1):
            raise ModelError(f"event {name}: direction must be -1, 0 or +1")
        self.name = name
        self.expr = sp.sympify(expr)
        self.direction = direction
        self.action = action
        self.terminal = terminal
        self.recheck = recheck
        self.observer = observer
        self.log = log
        self.owner = None  # set by flattening: the component path


class TimeEvent:
    r"""Events at instants known without integrating (a table's breakpoints,
    a clock), which a component returns from ``events()`` beside its
    :class:`Event`\ s. The integrator stops exactly at each one (IDA's stop
    time, not a root search) and the hybrid loop runs ``action``.

    ``next_time(state)``: the first instant of this event strictly after
    ``state.t`` [s] (``math.inf`` for none); it may read parameters and
    discrete values (``state[symbol]``), not variables.
    ``action(state)``: sets the discrete values (``state[d] = v``) for the
    interval that begins at ``state.t``; it runs at the start of a run (to
    set them for the first interval; variables cannot be read there) and
    at each of this event's instants (recorded in ``res.events`` under
    ``name`` unless ``log=False``).
    """

    def __init__(self, name, next_time, action, *, log=True):
        if not callable(next_time) or not callable(action):
            raise ModelError(f"time event {name}: next_time and action must be functions")
        self.name = name
        self.next_time = next_time
        self.action = action
        self.log = log
        self.owner = None  # set by flattening: the component path


class Assertion:
    """A condition ``expr > 0`` that must hold while simulating; when it is
    crossed the run stops with ``message`` naming the component."""

    def __init__(self, expr, message):
        self.expr = sp.sympify(expr)
        self.message = message
        self.owner = None
