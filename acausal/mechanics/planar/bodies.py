"""Rigid bodies with two frames and shapes, in the plane (Modelica
MultiBody's ``Parts.BodyShape``, ``BodyBox`` and ``BodyCylinder``, with
the motion confined to the world's x-y plane):

* :class:`BodyShape`: a body of given mass ``m``, inertia ``I`` about its
  centre of mass and centre of mass ``r_CM``, with ``frame_b`` at ``r``
  from ``frame_a`` (both in frame_a's axes);
* :class:`BodyBox` and :class:`BodyCylinder`: the mass, the planar moment
  of inertia and the centre of mass computed from the dimensions and the
  density, as MSL computes them (density 7700 kg/m^3, steel, by default).

The plane of motion is the world's x-y plane and the rotation axis is z.
A box's ``length`` runs along ``lengthDirection`` in the plane, its
``width`` across it in the plane and its ``height`` along z (out of the
plane); a cylinder's axis runs along ``lengthDirection`` in the plane. The
inertia that matters is the one about z through the centre of mass::

    box:      m = density length (width height - innerWidth innerHeight)
              I = (mo (length^2 + width^2) - mi (length^2 + innerWidth^2)) / 12
    cylinder: m = density pi length (r^2 - ri^2)     (r, ri: the radii)
              I = (mo (length^2 + 3 r^2) - mi (length^2 + 3 ri^2)) / 12

with ``mo``, ``mi`` the masses of the full outer shape and of the hole
(MSL's ``I[3,3]`` of the box and ``I22`` of the cylinder, whose length
direction lies in the plane). The centre of mass is half-way along the
length: ``r_CM = r_shape + lengthDirection/|lengthDirection| length/2``.
Gravity and the Newton-Euler law: :class:`~.partials.PartialBody`.
"""
import sympy as sp
from sympy import pi, sqrt

from acausal.errors import ParameterError
from acausal.lang import Frame, Parameter

from .partials import PartialBody

__all__ = ["BodyShape", "BodyBox", "BodyCylinder"]

DENSITY = 7700.0              # [kg/m^3] MSL's default density (steel: 7700 .. 7900)
DEFAULT_WIDTH_FRACTION = 20   # MSL world.defaultWidthFraction: width = length / 20


class BodyShape(PartialBody):
    """A rigid body with two frames: ``frame_b`` sits at ``(rx, ry)`` from
    ``frame_a`` and the centre of mass at ``(r_CM_x, r_CM_y)`` from
    ``frame_a``, both in the body's (frame_a's) axes; both frames turn with
    the body::

        frame_a = c - R(phi) r_CM,  frame_b = c - R(phi) (r_CM - r),
        frame_a.phi = frame_b.phi = phi           (c = (x, y), the centre of mass)
        m der(v) = frame_a.f + frame_b.f + m g u,
        I der(w) = frame_a.tau + frame_b.tau + sum of the frame forces' moments about c

    Either frame may stay unconnected (it then carries no force: a body
    hanging from frame_a). In a kinematic loop it is a rigid link between
    its frames (:mod:`.loops`).

    Parameters: ``rx``, ``ry`` [m] frame_b from frame_a, ``r_CM_x``,
    ``r_CM_y`` [m] centre of mass from frame_a (frame_a's axes), ``m``
    [kg] (> 0), ``I`` [kg*m^2] about the centre of mass (> 0), ``g``
    [m/s^2] gravity on the body (default the world's; see
    :class:`~.partials.PartialBody`). States: ``x``, ``y`` [m] centre of
    mass, ``phi`` [rad], ``vx``, ``vy`` [m/s], ``w`` [rad/s].
    Connectors: ``frame_a``, ``frame_b`` (both optional).
    """

    loop_role = "link"   # a rigid edge between its frames in the kinematic graph

    frame_a = Frame("first frame of the body", optional=True)
    frame_b = Frame("second frame, at r from frame_a", optional=True)

    rx = Parameter(0.1, "m", "frame_b from frame_a, x in frame_a's axes")
    ry = Parameter(0.0, "m", "frame_b from frame_a, y in frame_a's axes")
    r_CM_x = Parameter(0.0, "m", "centre of mass from frame_a, x in frame_a's axes")
    r_CM_y = Parameter(0.0, "m", "centre of mass from frame_a, y in frame_a's axes")

    def frames(self):
        cx, cy = self.r_CM_x, self.r_CM_y
        return [(self.frame_a, (-cx, -cy)), (self.frame_b, (self.rx - cx, self.ry - cy))]


def _length(c):
    return sqrt((c.rx - c.r_shape_x)**2 + (c.ry - c.r_shape_y)**2)


def _centre(c, k):
    """x (k = 0) or y (k = 1) of r_shape + unit(lengthDirection) length / 2."""
    ux, uy = c.lengthDirection_x, c.lengthDirection_y
    n = sqrt(ux**2 + uy**2)
    return ((c.r_shape_x, c.r_shape_y)[k] + (ux, uy)[k] / n * c.length / 2)


class _ShapedBody(BodyShape):
    """What a box and a cylinder share: the shape's origin, length direction
    and length, the density, and the checks of the dimensions when the model
    is built (on the values given as numbers)."""

    r_shape_x = Parameter(0.0, "m", "origin of the shape from frame_a, x in frame_a's axes")
    r_shape_y = Parameter(0.0, "m", "origin of the shape from frame_a, y in frame_a's axes")
    lengthDirection_x = Parameter(lambda c: c.rx - c.r_shape_x, "1",
                                  "length direction, x in frame_a's axes (default r - r_shape)")
    lengthDirection_y = Parameter(lambda c: c.ry - c.r_shape_y, "1",
                                  "length direction, y in frame_a's axes (default r - r_shape)")
    length = Parameter(_length, "m", "length (default |r - r_shape|)", min=0.0, min_open=True)
    density = Parameter(DENSITY, "kg/m^3", "density (steel 7700 .. 7900, wood 400 .. 800)",
                        min=0.0, min_open=True)
    r_CM_x = Parameter(lambda c: _centre(c, 0), "m", "centre of mass from frame_a, x "
                       "(r_shape + half the length along lengthDirection)", final=True)
    r_CM_y = Parameter(lambda c: _centre(c, 1), "m", "centre of mass from frame_a, y "
                       "(r_shape + half the length along lengthDirection)", final=True)

    # (outer dimension, inner dimension) pairs that equations() checks
    _nested = ()

    def number(self, name):
        """The value of parameter ``name`` as a float when it follows from
        numbers given to this component, else None (an expression of the
        enclosing model's parameters)."""
        own = {self.symbol(n): n for n, d in self.declarations().items()
               if isinstance(d, Parameter)}
        value = sp.sympify(self.value(name))
        for _ in range(len(own)):       # defaults refer to defaults (height -> width -> length)
            hits = {s: sp.sympify(self.value(own[s])) for s in value.free_symbols if s in own}
            if not hits:
                break
            value = value.xreplace(hits)
        return float(value) if value.is_number else None

    def equations(self):
        where = f"{type(self).__name__} {self.path}"
        length = self.number("length")
        if length is not None and not length > 0:
            raise ParameterError(f"{where}: its length is 0 (r = r_shape): give r (rx, ry) "
                                 "or length", component=self.path, variable="length")
        dx, dy = self.number("lengthDirection_x"), self.number("lengthDirection_y")
        if dx == 0 and dy == 0:
            raise ParameterError(f"{where}: lengthDirection is zero", component=self.path,
                                 variable="lengthDirection_x")
        for outer, inner in self._nested:
            a, b = self.number(outer), self.number(inner)
            if a is not None and b is not None and not b < a:
                raise ParameterError(f"{where}: {inner} = {b:g} m must be less than {outer} = "
                                     f"{a:g} m", component=self.path, variable=inner)
        return []


class BodyBox(_ShapedBody):
    """A rigid box between ``frame_a`` and ``frame_b`` (MSL's ``BodyBox``):
    ``length`` along ``lengthDirection`` from ``r_shape``, ``width`` across
    it in the plane, ``height`` out of the plane, optionally hollow (an
    inner box ``innerWidth`` x ``innerHeight`` along the whole length); the
    mass, the moment of inertia about z and the centre of mass follow from
    them and the density (module docstring). By default the box runs from
    frame_a to frame_b: ``length = |r|``, ``width = height = length/20``.

    Parameters: ``rx``, ``ry`` [m] frame_b from frame_a; ``r_shape_x``,
    ``r_shape_y`` [m] the box's origin from frame_a; ``lengthDirection_x``,
    ``lengthDirection_y`` [1] (default ``r - r_shape``); ``length`` [m]
    (default ``|r - r_shape|``); ``width`` [m] (default ``length/20``);
    ``height`` [m] (default ``width``); ``innerWidth`` [m] (default 0,
    < width), ``innerHeight`` [m] (default ``innerWidth``, < height);
    ``density`` [kg/m^3] (default 7700); ``g`` [m/s^2] (default the
    world's). Computed (final): ``m`` [kg], ``I`` [kg*m^2], ``r_CM_x``,
    ``r_CM_y`` [m]. States: ``x``, ``y`` [m] centre of mass, ``phi``
    [rad], ``vx``, ``vy`` [m/s], ``w`` [rad/s].
    Connectors: ``frame_a``, ``frame_b`` (both optional).
    """

    width = Parameter(lambda c: c.length / DEFAULT_WIDTH_FRACTION, "m",
                      "width, in the plane (default length/20)", min=0.0, min_open=True)
    height = Parameter(lambda c: c.width, "m", "height, out of the plane (default width)",
                       min=0.0, min_open=True)
    innerWidth = Parameter(0.0, "m", "width of the hole (0: solid)", min=0.0)
    innerHeight = Parameter(lambda c: c.innerWidth, "m",
                            "height of the hole (default innerWidth)", min=0.0)
    m = Parameter(lambda c: c.density * c.length * (c.width * c.height
                                                    - c.innerWidth * c.innerHeight),
                  "kg", "mass: density length (width height - innerWidth innerHeight)",
                  final=True)
    I = Parameter(lambda c: c.density * c.length * (  # noqa: E741
        c.width * c.height * (c.length**2 + c.width**2)
        - c.innerWidth * c.innerHeight * (c.length**2 + c.innerWidth**2)) / 12,
        "kg*m^2", "moment of inertia about z through the centre of mass", final=True)

    _nested = (("width", "innerWidth"), ("height", "innerHeight"))


class BodyCylinder(_ShapedBody):
    """A rigid cylinder between ``frame_a`` and ``frame_b`` (MSL's
    ``BodyCylinder``): its axis of ``length`` along ``lengthDirection`` from
    ``r_shape`` in the plane, outer ``diameter``, optionally a tube (an
    ``innerDiameter``); the mass, the moment of inertia about z (about a
    diameter through the centre of mass) and the centre of mass follow from
    them and the density (module docstring). By default the cylinder runs
    from frame_a to frame_b: ``length = |r|``, ``diameter = length/20``.

    Parameters: ``rx``, ``ry`` [m] frame_b from frame_a; ``r_shape_x``,
    ``r_shape_y`` [m] the centre of the cylinder's first end from frame_a;
    ``lengthDirection_x``, ``lengthDirection_y`` [1] (default
    ``r - r_shape``); ``length`` [m] (default ``|r - r_shape|``);
    ``diameter`` [m] (default ``length/20``); ``innerDiameter`` [m]
    (default 0, < diameter); ``density`` [kg/m^3] (default 7700); ``g``
    [m/s^2] (default the world's). Computed (final): ``m`` [kg], ``I``
    [kg*m^2], ``r_CM_x``, ``r_CM_y`` [m]. States: ``x``, ``y`` [m] centre of
    mass, ``phi`` [rad], ``vx``, ``vy`` [m/s], ``w`` [rad/s].
    Connectors: ``frame_a``, ``frame_b`` (both optional).
    """

    diameter = Parameter(lambda c: c.length / DEFAULT_WIDTH_FRACTION, "m",
                         "outer diameter (default length/20)", min=0.0, min_open=True)
    innerDiameter = Parameter(0.0, "m", "inner diameter (0: solid)", min=0.0)
    m = Parameter(lambda c: c.density * pi * c.length * (c.diameter**2
                                                         - c.innerDiameter**2) / 4,
                  "kg", "mass: density pi length (diameter^2 - innerDiameter^2)/4", final=True)
    I = Parameter(lambda c: c.density * pi * c.length / 4 * (  # noqa: E741
        c.diameter**2 * (c.length**2 + 3 * c.diameter**2 / 4)
        - c.innerDiameter**2 * (c.length**2 + 3 * c.innerDiameter**2 / 4)) / 12,
        "kg*m^2", "moment of inertia about z (a diameter) through the centre of mass",
        final=True)

    _nested = (("diameter", "innerDiameter"),)
