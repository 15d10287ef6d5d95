"""The planar world: the inertial frame and the uniform gravity field that
acts on every body of the model (Modelica MultiBody's ``World``, in the
plane).

How a body finds its world (Modelica's ``inner``/``outer``): each body asks
:meth:`acausal.lang.Component.outer` for the nearest :class:`World` that an
enclosing model declares -- one of its siblings, else one of its parent's
siblings, and so on. A world declared inside a sub-assembly therefore acts
on that sub-assembly's bodies only, and one model may not declare two.

**The default world (a deliberate choice):** a model that declares no
:class:`World` is *gravity-free*. Planar models written before the World
existed -- the breaker's mechanisms, whose plane is horizontal or whose
report neglects gravity -- keep their equations and results unchanged, and a
body's own ``g`` (``Body(g=9.81)``: along -y) still applies where it is
given. Modelica tools instead add a default world with standard gravity when
a model lacks one (with a warning); here the model says what it means:
``model.world = World()`` for standard gravity (what every MSL MultiBody
example declares as ``inner world``), nothing for none.

Sign convention of the frame: :mod:`acausal.lang.connectors` (``Frame``).
"""
from sympy import sqrt

from acausal.errors import ParameterError
from acausal.lang import Component, Eq, Frame, Parameter

__all__ = ["World", "STANDARD_GRAVITY", "gravity_of"]

STANDARD_GRAVITY = 9.80665    # [m/s^2] Modelica.Constants.g_n (CGPM 1901)


class World(Component):
    """The world frame and a uniform gravity field: every body of the
    enclosing model (and of its sub-assemblies that declare no world of
    their own) feels the acceleration ``g * n / |n|`` unless it gives its
    own ``g`` (see :mod:`.world` for the lookup and for models without a
    World). ``frame_b`` is the world's origin, fixed: a ground to connect
    joints to, as a :class:`~.parts.Fixed` at (0, 0, 0)::

        frame_b.x = 0,  frame_b.y = 0,  frame_b.phi = 0

    Gravity off: ``g = 0`` (MSL's ``NoGravity``). MSL's point gravity field
    is not offered (a planar mechanism lives in a uniform field).

    Parameters: ``g`` [m/s^2] magnitude of the gravity acceleration
    (default the standard gravity 9.80665, MSL's ``Modelica.Constants.g_n``),
    ``nx``, ``ny`` [1] its direction in the world (made unit length; default
    (0, -1): along -y). Connectors: ``frame_b`` (the world's origin;
    optional: a world that only gives gravity needs no connection).
    """

    loop_role = "ground"   # its frame is the world node of the kinematic graph
    frame_b = Frame("the world's origin, fixed (MSL's name)", optional=True)

    g = Parameter(STANDARD_GRAVITY, "m/s^2", "magnitude of the gravity acceleration")
    nx = Parameter(0.0, "1", "direction of gravity, world x (made unit length)")
    ny = Parameter(-1.0, "1", "direction of gravity, world y (made unit length)")

    def __init__(self, **kw):
        super().__init__(**kw)
        nx, ny = self.value("nx"), self.value("ny")
        if all(isinstance(c, (int, float)) for c in (nx, ny)) and nx * nx + ny * ny == 0:
            raise ParameterError("World: the gravity direction (nx, ny) is zero; give a "
                                 "direction, and g = 0 for no gravity", variable="nx")

    def direction(self):
        """(ux, uy): the unit direction of gravity, expressions of ``nx``, ``ny``."""
        n = sqrt(self.nx**2 + self.ny**2)
        return self.nx / n, self.ny / n

    def equations(self):
        fr = self.frame_b
        return [Eq(fr.x, 0), Eq(fr.y, 0), Eq(fr.phi, 0)]


def gravity_of(comp):
    """(magnitude, (ux, uy)) of the gravity field ``comp`` is in: its world's
    ``g`` symbol and unit direction, or (0, (0, -1)) when no enclosing model
    declares a :class:`World` (the gravity-free default world)."""
    w = comp.outer(World)
    if w is None:
        return 0.0, (0, -1)
    return w.g, w.direction()
