"""Connectors: the points where components meet.

Sign convention (the one place it is written; everything else refers here)
-------------------------------------------------------------------------
A connector carries one *across* variable (effort-like position, angle) and
one *through* variable (flow-like force, torque)::

             flange_a                      flange_b
                 |    +-------------+         |
     f_a  --->   o----|  component  |---------o   <---  f_b
                 |    +-------------+         |
        s_a                                        s_b       --> +s (positive axis)

* Across variables are absolute and measured along one positive axis
  (``s`` in m for translation, ``phi`` in rad for rotation, counter-clockwise
  or along the positive axis, as the model chooses once).
* Through variables are counted positive *into* the component at that
  connector: ``f_a`` is the force the outside applies on the component at
  ``flange_a``, along +s. A spring stretched between two flanges therefore has
  ``f_b = +c*(s_b - s_a - s0)`` (it pulls flange_b back: the outside must push
  +) and ``f_a = -f_b``.
* ``connect(a, b, c)`` makes a node: ``a.s = b.s = c.s`` and
  ``a.f + b.f + c.f = 0`` (what flows into one component flows out of the
  others).

Bond-graph view: the through variable (force, torque) is the *effort* e of a
bond and the rate of the across variable (velocity, angular velocity) is its
*flow* f; power e*f is positive into the component. A connection node is a
1-junction (common velocity, efforts sum to zero); a component between two
flanges that sees their relative motion sits on a 0-junction of velocity
difference, as in the report's contact module.

Planar frame (:class:`Frame`)
-----------------------------
A frame is a point with an orientation in the world's x-y plane: three
across variables ``x``, ``y`` [m] (world coordinates of the point) and
``phi`` [rad] (angle of the frame's own x axis from the world x axis,
counter-clockwise positive) and three through variables ``fx``, ``fy`` [N]
(world components of the force) and ``tau`` [N*m] (torque about the world z
axis, counter-clockwise positive), all counted positive *into* the
component at that frame, as for the 1-D flanges::

        y ^
          |              fy ^     x_f (frame's own x axis)
          |                 |    /
          |                 |   /  phi: angle of x_f from world x (ccw +)
          |          tau    |  /
          |        (ccw +)  | /
          |                 o------> fx        o = frame origin (x, y)
          |
          |   fx, fy, tau: what the OUTSIDE applies on the component here
          +---------------------------------------------> x
          z out of the page: phi and tau counter-clockwise positive

Power flowing into a component at a frame is
``fx*der(x) + fy*der(y) + tau*der(phi)``; a connection node makes the three
across variables equal and each of the three through variables sum to zero.

Mapping to the 1-D flanges (through the adaptors of
:mod:`acausal.mechanics.planar.adaptors`, never by a direct ``connect``):

* rotation: ``RotFlange.phi`` <-> ``Frame.phi`` and ``RotFlange.tau`` <->
  ``Frame.tau`` (same axis: world z, counter-clockwise positive);
* translation along a unit axis ``(ex, ey)`` of the world:
  ``Flange.s = ex*x + ey*y`` and ``frame.(fx, fy) = -flange.f * (ex, ey)``
  (the force that enters the adaptor at one side leaves it at the other);
* joints carry a 1-D flange in *relative* coordinates: a revolute's
  ``RotFlange`` has the joint angle ``frame_b.phi - frame_a.phi`` and a
  prismatic's ``Flange`` its stroke along the axis, so that 1-D springs,
  dampers, friction, stops and drives act across the joint (the 1-D
  ``Fixed`` on that side stands for the joint's frame_a).

Causal signals (:class:`RealInput`, :class:`RealOutput`)
--------------------------------------------------------
A signal connector is one real variable and no through part (MSL's
``Blocks.Interfaces.RealInput``/``RealOutput``): the connector *is* the
variable, named by the connector's path (``clutch.f_normalized``), and a
component uses it in its equations as it uses a symbol
(``Eq(self.f, self.f_max * self.f_normalized)``). ``connect(out, in1, in2)``
makes every input equal to the one output of its node; a node with two
outputs, or an input that is in no node with an output, is an error naming
them (``clutch.f_normalized: input not connected``). An unconnected output
is allowed (nobody reads it).
"""
import sympy as sp

from ..errors import ModelError


class Connector:
    """Declaration of a connector type on a component class.

    Subclasses name the across and through variables with their units; a
    connector with several (``pairs``: across, through) lists them all there.
    ``optional=True`` declares a connector that may stay unconnected: its
    through variables are then zero (Modelica's rule for unconnected flow
    variables), e.g. the 1-D flange of a planar joint that needs no drive.
    """

    across = ("s", "m", "absolute position")
    through = ("f", "N", "cut force, positive into the component")
    domain = "generic"

    def __init__(self, desc="", optional=False):
        self.desc = desc
        self.optional = optional
        self.name = None

    def make_port(self, owner, name):
        """The :class:`Port` of this connector on component ``owner``."""
        return Port(owner, name, self)

    @classmethod
    def pairs(cls):
        """((across name, unit, desc), (through name, unit, desc)) pairs."""
        return getattr(cls, "_pairs", None) or ((cls.across, cls.through),)

    def __set_name__(self, owner, name):
        self.name = name

    def __get__(self, obj, objtype=None):
        if obj is None:
            return self
        return obj.port(self.name)


class Flange(Connector):
    """Translational flange: position ``s`` [m], force ``f`` [N] (into the
    component)."""

    across = ("s", "m", "absolute position of the flange")
    through = ("f", "N", "cut force, positive into the component")
    domain = "translational"


class RotFlange(Connector):
    """Rotational flange: angle ``phi`` [rad], torque ``tau`` [N*m] (into the
    component)."""

    across = ("phi", "rad", "absolute rotation angle of the flange")
    through = ("tau", "N*m", "cut torque, positive into the component")
    domain = "rotational"


class Frame(Connector):
    """Planar frame: position ``x``, ``y`` [m], angle ``phi`` [rad]; force
    ``fx``, ``fy`` [N] and torque ``tau`` [N*m] into the component (see the
    picture in this module's docstring)."""

    _pairs = (
        (("x", "m", "world x of the frame origin"),
         ("fx", "N", "world x force, positive into the component")),
        (("y", "m", "world y of the frame origin"),
         ("fy", "N", "world y force, positive into the component")),
        (("phi", "rad", "angle of the frame x axis from world x, counter-clockwise"),
         ("tau", "N*m", "torque about world z, counter-clockwise, into the component")),
    )
    across = _pairs[0][0]
    through = _pairs[0][1]
    domain = "planar"


class RealSignal(Connector):
    """A causal signal connector: one real variable (unit ``unit``), no
    through part. Use :class:`RealInput` or :class:`RealOutput`. A signal
    given no unit is dimensionless for display but not checked (Modelica's
    ``unit = ""``, as a declaration without one: :mod:`acausal.compiler.units`),
    so a block's plain output may feed a force's input in N."""

    domain = "signal"
    causality = None     # "input" or "output"

    def __init__(self, desc="", unit=None):
        super().__init__(desc)
        self.unit_declared = unit is not None
        self.unit = "1" if unit is None else unit

    @classmethod
    def pairs(cls):
        """No across/through pairs: a signal is its own variable."""
        return ()

    def make_port(self, owner, name):
        return SignalPort(owner, name, self)


class RealInput(RealSignal):
    """Input signal (MSL ``RealInput``): set by the output it is connected to."""

    causality = "input"


class RealOutput(RealSignal):
    """Output signal (MSL ``RealOutput``): set by its component's equations."""

    causality = "output"


class Port:
    """A connector on one component instance. ``port.s`` / ``port.f`` (or the
    names of its type) are the sympy symbols of its two variables."""

    def __init__(self, owner, name, ctype):
        self.owner = owner
        self.name = name
        self.ctype = ctype

    @property
    def path(self):
        p = self.owner.path
        return f"{p}.{self.name}" if p else self.name

    def pairs(self):
        """[(across symbol, through symbol), ...] of this connector."""
        return [(sp.Symbol(f"{self.path}.{a[0]}"), sp.Symbol(f"{self.path}.{t[0]}"))
                for a, t in self.ctype.pairs()]

    def _single(self, k):
        if len(self.ctype.pairs()) != 1:
            raise ModelError(
                f"connector {self.path} ({type(self.ctype).__name__}) has several "
                f"across/through pairs: use .pairs() or the variable names")
        return self.pairs()[0][k]

    @property
    def across(self):
        return self._single(0)

    @property
    def through(self):
        return self._single(1)

    def __getattr__(self, item):
        ctype = self.__dict__.get("ctype")
        if ctype is not None:
            for a, t in ctype.pairs():
                if item == a[0]:
                    return sp.Symbol(f"{self.path}.{item}")
                if item == t[0]:
                    return sp.Symbol(f"{self.path}.{item}")
        raise AttributeError(
            f"connector {self.__dict__.get('name')} has no variable {item!r}")

    def __repr__(self):
        return f"<{type(self.ctype).__name__} {self.path}>"


def _sym(x):
    return x.symbol if isinstance(x, SignalPort) else x


class SignalPort(Port):
    """A signal connector on one component instance. It stands for its
    variable (the sympy symbol named by its path, :attr:`symbol`) wherever
    an expression is built: ``2 * port``, ``sp.sin(port)``, ``Eq(y, port)``."""

    @property
    def symbol(self):
        return sp.Symbol(self.path)

    @property
    def causality(self):
        return self.ctype.causality

    def pairs(self):
        return []

    def _sympy_(self):
        return self.symbol

    def __getattr__(self, item):
        raise AttributeError(f"signal connector {self.__dict__.get('name')} has no "
                             f"variable {item!r}: it is its own variable")

    def __neg__(self):
        return -self.symbol

    def __pos__(self):
        return self.symbol

    def __add__(self, o):
        return self.symbol + _sym(o)

    def __radd__(self, o):
        return _sym(o) + self.symbol

    def __sub__(self, o):
        return self.symbol - _sym(o)

    def __rsub__(self, o):
        return _sym(o) - self.symbol

    def __mul__(self, o):
        return self.symbol * _sym(o)

    def __rmul__(self, o):
        return _sym(o) * self.symbol

    def __truediv__(self, o):
        return self.symbol / _sym(o)

    def __rtruediv__(self, o):
        return _sym(o) / self.symbol

    def __pow__(self, o):
        return self.symbol ** _sym(o)

    def __rpow__(self, o):
        return _sym(o) ** self.symbol
