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
"""
import sympy as sp


class Connector:
    """Declaration of a connector type on a component class.

    Subclasses name the across and through variables with their units.
    """

    across = ("s", "m", "absolute position")
    through = ("f", "N", "cut force, positive into the component")
    domain = "generic"

    def __init__(self, desc=""):
        self.desc = desc
        self.name = None

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

    @property
    def across(self):
        return sp.Symbol(f"{self.path}.{self.ctype.across[0]}")

    @property
    def through(self):
        return sp.Symbol(f"{self.path}.{self.ctype.through[0]}")

    def __getattr__(self, item):
        ctype = self.__dict__.get("ctype")
        if ctype is not None:
            if item == ctype.across[0]:
                return self.across
            if item == ctype.through[0]:
                return self.through
        raise AttributeError(
            f"connector {self.__dict__.get('name')} has no variable {item!r}")

    def __repr__(self):
        return f"<{type(self.ctype).__name__} {self.path}>"
