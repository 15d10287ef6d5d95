"""Components: parameters, variables, connectors and equations.

A component class declares its parameters, variables and connectors as class
attributes and returns its equations from ``equations()``. Equations are
inherited the Modelica way: every class in the hierarchy that defines
``equations`` contributes its own, so a partial base (two flanges and their
relative motion) owns the connector equations and a leaf only adds its law.
Components never compile or solve anything.
"""
import math
import numbers

import sympy as sp

from .connectors import Connector, Port
from .declare import Declaration, Discrete, Parameter, Start, Variable, check_nominal
from ..errors import ModelError, ParameterError


def _collect(cls, kind):
    out = {}
    for klass in reversed(cls.__mro__):
        for name, val in vars(klass).items():
            if isinstance(val, kind):
                out[name] = val
    return out


def _check_start(value, label, unit):
    """A ParameterError unless a start value is a finite number or an
    expression of parameters."""
    if isinstance(value, sp.Basic) and not value.is_number:
        return
    ok = not isinstance(value, bool) and isinstance(value, (numbers.Real, sp.Basic))
    try:
        ok = ok and math.isfinite(float(value))
    except (TypeError, ValueError):  # a sympy number that is not real
        ok = False
    if not ok:
        raise ParameterError(f"start value {label} = {value!r} [{unit}] is not a finite "
                             "number", variable=label)


def _binding(value, label):
    """An input's binding: a number or a sympy expression (of time and
    parameters), else a ParameterError."""
    try:
        expr = sp.sympify(value, strict=True)
    except (sp.SympifyError, TypeError):
        expr = None
    if isinstance(value, bool) or not isinstance(expr, sp.Basic):
        raise ParameterError(f"input {label} can be bound to a number or a sympy expression "
                             f"of time and parameters, got {value!r}", variable=label)
    return expr


class Component:
    """Base of every component and model. Keyword arguments set parameter
    values (numbers, or sympy expressions of other parameters) and start
    values of variables (a number means a fixed start; ``guess(x)`` or
    ``Start(x, fixed=False)`` a guess)."""

    def __init__(self, **kw):
        object.__setattr__(self, "_parent", None)
        object.__setattr__(self, "_name", None)
        object.__setattr__(self, "_extra", {})
        object.__setattr__(self, "_ports", {})
        object.__setattr__(self, "_values", {})
        object.__setattr__(self, "_starts", {})
        object.__setattr__(self, "_bindings", {})
        object.__setattr__(self, "_nominals", {})
        for name, d in self.declarations().items():
            if isinstance(d, Parameter):
                self._values[name] = d.default
            elif isinstance(d, (Variable,)):
                self._starts[name] = d.start
            elif isinstance(d, Discrete):
                self._starts[name] = Start(d.start, True)
        self.set(**kw)

    # -- declarations ------------------------------------------------------
    def declarations(self):
        """Name -> declaration (parameters, variables, discrete values)."""
        decl = _collect(type(self), Declaration)
        decl.update(self._extra)
        return decl

    def connectors(self):
        """Name -> connector declaration."""
        return _collect(type(self), Connector)

    def set(self, **kw):
        """Set parameter values and start values; checks bounds. A value
        given for an input connector (``Position(s_ref=0.1*sin(2*pi*time))``) binds
        that input to the expression, as a Modelica modifier does: it is
        then set by it instead of by a connection."""
        decls = self.declarations()
        for key, value in kw.items():
            d = decls.get(key)
            if d is None and getattr(self.connectors().get(key), "causality", None) == "input":
                self._bindings[key] = _binding(value, f"{self.path or type(self).__name__}.{key}")
                continue
            if d is None:
                valid = ", ".join(n for n, x in decls.items() if not isinstance(x, Discrete))
                raise ParameterError(
                    f"{type(self).__name__} {self.path or '(top)'} has no parameter or "
                    f"variable {key!r}; it has: {valid}", component=self.path, variable=key)
            if isinstance(d, Parameter):
                if d.final:
                    raise ParameterError(
                        f"{type(self).__name__} {self.path or ''}: parameter {key!r} is "
                        f"computed ({d.desc}); set the parameters it is computed from",
                        component=self.path, variable=key)
                self._values[key] = d.check(value, self.path or type(self).__name__)
            elif isinstance(d, Variable):
                start = value if isinstance(value, Start) else Start(value, True)
                _check_start(start.value, f"{self.path or type(self).__name__}.{key}", d.unit)
                self._starts[key] = start
            else:
                raise ParameterError(f"{key!r} of {self.path} is discrete; it cannot be set",
                                     component=self.path, variable=key)
        return self

    def with_nominal(self, **values):
        """Set the nominal values of variables of this instance (Modelica's
        ``inertia(w(nominal=1e-3))``): ``Inertia(J=2).with_nominal(w=1e-3)``.
        Returns the component."""
        decls = self.declarations()
        for key, value in values.items():
            if not isinstance(decls.get(key), Variable):
                raise ParameterError(f"with_nominal: {type(self).__name__} "
                                     f"{self.path or '(top)'} has no variable {key!r}",
                                     component=self.path, variable=key)
            self._nominals[key] = check_nominal(value, f"{self.path or type(self).__name__}."
                                                f"{key}")
        return self

    def nominal(self, name):
        """The nominal value of variable ``name`` (None when not given)."""
        if name in self._nominals:
            return self._nominals[name]
        return getattr(self.declarations().get(name), "nominal", None)

    def value(self, name):
        """The value given to a parameter (number, expression or choice).
        A parameter left at a default that is a function of the component
        (``Parameter(lambda c: ..., ...)``: a derived parameter, or one
        taken from an :meth:`outer` component) is that function's value now;
        the compiler asks when it flattens the model, when every path is
        final."""
        v = self._values[name]
        if callable(v) and not isinstance(v, sp.Basic):
            v = v(self)
        return v

    def outer(self, kind):
        """The component of class ``kind`` that an enclosing model declares,
        as Modelica's ``inner``/``outer``: the nearest one (among this
        component's siblings, then its parent's siblings, ...), or None when
        no enclosing model has one. Two in one model is a
        :class:`~acausal.errors.ModelError` (which one is meant?)."""
        node = self._parent
        while node is not None:
            hits = [c for c in node._children.values() if isinstance(c, kind) and c is not self]
            if len(hits) > 1:
                raise ModelError(
                    f"{node.path or 'the model'} has {len(hits)} {kind.__name__} components "
                    f"({', '.join(c.path for c in hits)}); {self.path} needs exactly one",
                    component=self.path)
            if hits:
                return hits[0]
            node = node._parent
        return None

    def start(self, name):
        return self._starts[name]

    # -- naming --------------------------------------------------------------
    @property
    def path(self):
        if self._parent is None:
            return ""
        pp = self._parent.path
        return f"{pp}.{self._name}" if pp else self._name

    def symbol(self, name):
        p = self.path
        return sp.Symbol(f"{p}.{name}" if p else name)

    def port(self, name):
        port = self._ports.get(name)
        if port is None:
            ctype = self.connectors()[name]
            port = self._ports[name] = ctype.make_port(self, name)
        return port

    # -- behaviour (overridden by subclasses) --------------------------------
    def equations(self):
        """Equations of this class only (sympy ``Eq`` or expressions = 0)."""
        return []

    def initial_equations(self):
        """Equations of this class that hold at the start only (Modelica's
        ``initial equation``, e.g. a filter starting at its input)."""
        return []

    def events(self):
        """Events of this class only (see :class:`acausal.declare.Event`)."""
        return []

    def assertions(self):
        """Conditions that must stay true (see :class:`acausal.declare.Assertion`)."""
        return []

    def gather(self, method):
        """All items that every class in the hierarchy returns from ``method``."""
        out = []
        for klass in reversed(type(self).__mro__):
            fn = vars(klass).get(method)
            if fn is not None:
                out.extend(fn(self))
        return out

    def __repr__(self):
        return f"<{type(self).__name__} {self.path or '(top)'}>"


class Model(Component):
    """A component made of named sub-components and connections.

    Sub-components are added by attribute (``model.mass = Mass(m=1)``) or with
    :meth:`add`; connectors are joined with :meth:`connect`. A model can carry
    its own parameters (:meth:`parameter`), equations (:meth:`equation`),
    events and connectors of its sub-components it exposes (:meth:`expose`),
    so that sub-assemblies compose hierarchically.
    """

    def __init__(self, **kw):
        object.__setattr__(self, "_children", {})
        object.__setattr__(self, "_connections", [])
        object.__setattr__(self, "_exposed", {})
        object.__setattr__(self, "_own_eqs", [])
        object.__setattr__(self, "_own_events", [])
        super().__init__(**kw)

    # -- building --------------------------------------------------------------
    def add(self, name, comp):
        if not isinstance(comp, Component):
            raise ModelError(f"{name}: {comp!r} is not a component")
        if "." in name or not name.isidentifier():
            raise ModelError(f"invalid component name {name!r}")
        if name in self._children or name in self.declarations():
            raise ModelError(f"{self.path or 'model'} already has a member named {name!r}")
        if comp._parent is not None:
            raise ModelError(f"component {comp.path} is already part of a model")
        object.__setattr__(comp, "_parent", self)
        object.__setattr__(comp, "_name", name)
        self._children[name] = comp
        return comp

    def __setattr__(self, name, value):
        if isinstance(value, Component):
            self.add(name, value)
        elif isinstance(value, Port):
            self.expose(name, value)
        else:
            object.__setattr__(self, name, value)

    def __getattr__(self, name):
        d = self.__dict__
        if name in d.get("_children", {}):
            return d["_children"][name]
        if name in d.get("_exposed", {}):
            return d["_exposed"][name]
        if name in d.get("_extra", {}):
            return d["_extra"][name].__get__(self)
        raise AttributeError(f"{type(self).__name__} has no member {name!r}")

    def children(self):
        return dict(self._children)

    def connect(self, *ports):
        """Join connectors into one node (across equal, through sum to 0)."""
        if len(ports) < 2:
            raise ModelError("connect() needs at least two connectors")
        for p in ports:
            if not isinstance(p, Port):
                raise ModelError(f"connect(): {p!r} is not a connector")
        self._connections.append(tuple(ports))

    def disconnect(self, port):
        """Take ``port`` out of every connection made in this model or its
        sub-models, keeping the other connectors of its node joined to each
        other (what was connected only through ``port`` stays connected).
        Returns the connectors ``port`` was joined to (one node, by path);
        afterwards ``port`` is unconnected. Connectors exposed under another
        name are the same object, so a connection made through the exposed
        name is removed too."""
        if not isinstance(port, Port):
            raise ModelError(f"disconnect(): {port!r} is not a connector")
        neighbours, reps = {}, []
        for m in self.walk():
            if not isinstance(m, Model):
                continue
            kept = []
            for group in m._connections:
                if not any(p is port for p in group):
                    kept.append(group)
                    continue
                rest = tuple(p for p in group if p is not port)
                for p in rest:
                    neighbours[id(p)] = p
                if rest:
                    reps.append(rest[0])
                if len(rest) >= 2:
                    kept.append(rest)
            m._connections[:] = kept
        if len(reps) >= 2:       # the groups were joined through port: keep them joined
            self._connections.append(tuple(reps))
        return sorted(neighbours.values(), key=lambda p: p.path)

    def expose(self, name, port):
        """Make a sub-component's connector a connector of this model."""
        if not isinstance(port, Port):
            raise ModelError(f"expose({name!r}): {port!r} is not a connector")
        self._exposed[name] = port

    def parameter(self, name, default, unit=None, desc="", **bounds):
        """Declare a parameter of this model; returns its symbol."""
        p = Parameter(default, unit, desc, **bounds)
        p.name = name
        self._extra[name] = p
        self._values[name] = p.check(default, self.path)
        return self.symbol(name)

    def variable(self, name, start=0.0, unit=None, desc="", fixed=False, nominal=None):
        """Declare a variable of this model; returns its symbol."""
        if isinstance(start, Start):
            start, fixed = start.value, start.fixed
        v = Variable(start, unit, desc, fixed=fixed, nominal=nominal)
        v.name = name
        self._extra[name] = v
        self._starts[name] = v.start
        return self.symbol(name)

    def equation(self, eq):
        self._own_eqs.append(eq)

    def event(self, ev):
        self._own_events.append(ev)

    def equations(self):
        return list(self._own_eqs)

    def events(self):
        return list(self._own_events)

    def walk(self):
        """This model and every sub-component, depth first."""
        yield self
        for c in self._children.values():
            if isinstance(c, Model):
                yield from c.walk()
            else:
                yield c

    def find(self, path):
        """The sub-component at a dotted path (``'hook'``, ``'sub.lever'``)."""
        obj = self
        for part in path.split("."):
            if not isinstance(obj, Model) or part not in obj._children:
                raise ModelError(f"no component {path!r} in the model")
            obj = obj._children[part]
        return obj
