"""The planar World (gravity acting on every body unless a body overrides
it, found as Modelica's inner/outer) and the bodies whose mass and inertia
follow from dimensions and density (BodyBox, BodyCylinder), against closed
forms and independent scipy solutions written here from first principles."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from acausal import Model, compile_model
from acausal.errors import ModelError, ParameterError
from acausal.mechanics import rotational as rot
from acausal.mechanics.planar import (Body, BodyBox, BodyCylinder, BodyShape, Fixed,
                                      Revolute, SpringDamper, World)

TOL = dict(rtol=1e-10, atol=1e-12)
SWING = dict(rtol=1e-12, atol=1e-14)   # pendulums swinging over the top for 1.5-2 s
Y0 = 0.4      # the free bodies start at (x0, 0.4), off the fixed point of their links
G_N = 9.80665


def _free_bodies(world=None, **bodies):
    """A model of free bodies (each on a slack line force to a fixed point,
    so that the model has a frame graph), with an optional World."""
    m = Model()
    if world is not None:
        m.world = world
    m.ground = Fixed()
    for name, body in bodies.items():
        setattr(m, name, body)
        link = SpringDamper(c=0.0, d=0.0)
        setattr(m, f"link_{name}", link)
        m.connect(m.ground.frame, link.frame_a)
        m.connect(link.frame_b, body.frame)
    return m


def _start(**kw):
    base = dict(x=0.3, y=Y0, vx=1.0, vy=2.0, phi=0.0, w=0.0)
    base.update(kw)
    return base


def test_world_gravity_acts_on_every_body_unless_overridden():
    """Standard gravity along -y on every body; a body's own g overrides it
    (0: no gravity on that body) and keeps the world's direction."""
    m = _free_bodies(World(), a=Body(m=0.5, I=0.1, **_start()),
                     b=Body(m=2.0, I=0.1, **_start(x=1.0)),
                     c=Body(m=1.0, I=0.1, g=0.0, **_start()),
                     d=Body(m=1.0, I=0.1, g=3.0, **_start()))
    cm = compile_model(m)
    res = cm.simulate(t_end=1.0, output_step=0.1, **TOL)
    t = res.t
    for name, g in (("a", G_N), ("b", G_N), ("c", 0.0), ("d", 3.0)):
        assert np.max(np.abs(res[f"{name}.y"] - (Y0 + 2.0 * t - 0.5 * g * t**2))) < 1e-9, name
    assert np.max(np.abs(res["b.x"] - (1.0 + t))) < 1e-9
    # world.g is one runtime parameter for every body that takes the world's
    res2 = cm.simulate(t_end=1.0, output_step=0.1, params={"world.g": 1.5}, **TOL)
    assert np.max(np.abs(res2["a.y"] - (Y0 + 2.0 * res2.t - 0.75 * res2.t**2))) < 1e-9
    assert np.max(np.abs(res2["d.y"] - (Y0 + 2.0 * res2.t - 1.5 * res2.t**2))) < 1e-9
    # a body's own g (given) is its own runtime parameter; one that takes the
    # world's cannot be set alone: one line saying what to set instead
    res3 = cm.simulate(t_end=1.0, output_step=0.1, params={"d.g": 0.0}, **TOL)
    assert np.max(np.abs(res3["d.y"] - Y0 - 2.0 * res3.t)) < 1e-9
    with pytest.raises(ParameterError, match=r"a\.g is bound to world\.g"):
        cm.simulate(t_end=0.1, params={"a.g": 1.0})


def test_world_direction_and_magnitude():
    """g along an arbitrary direction (nx, ny), made unit length."""
    m = _free_bodies(World(g=2.0, nx=3.0, ny=4.0), b=Body(m=1.3, I=0.2, **_start()))
    res = compile_model(m).simulate(t_end=1.0, output_step=0.1, **TOL)
    t = res.t
    assert np.max(np.abs(res["b.x"] - (0.3 + t + 0.5 * 1.2 * t**2))) < 1e-9
    assert np.max(np.abs(res["b.y"] - (Y0 + 2.0 * t + 0.5 * 1.6 * t**2))) < 1e-9


def test_no_world_is_gravity_free_and_own_g_still_acts_along_minus_y():
    """The default world (none declared) is gravity-free: models written
    before the World keep their equations; Body(g=...) acts along -y."""
    m = _free_bodies(None, a=Body(m=1.0, I=0.1, **_start()),
                     b=Body(m=1.0, I=0.1, g=9.81, **_start()))
    cm = compile_model(m)
    res = cm.simulate(t_end=1.0, output_step=0.1, **TOL)
    t = res.t
    assert np.max(np.abs(res["a.y"] - Y0 - 2.0 * t)) < 1e-9
    assert np.max(np.abs(res["b.y"] - (Y0 + 2.0 * t - 0.5 * 9.81 * t**2))) < 1e-9
    assert cm.params[cm.param_index("a.g")].default == 0.0   # a free parameter, as before


def test_the_nearest_enclosing_world_acts():
    """A sub-assembly with its own World: its bodies feel that one, the
    others the top-level world (Modelica's inner/outer: nearest scope)."""
    sub = Model()
    sub.world = World(g=1.0)
    sub.body = Body(m=1.0, I=0.1, **_start())
    sub.deep = Model()
    sub.deep.body = Body(m=1.0, I=0.1, **_start())
    m = _free_bodies(World(), top=Body(m=1.0, I=0.1, **_start()))
    m.sub = sub
    for path, b in (("s1", sub.body), ("s2", sub.deep.body)):
        link = SpringDamper(c=0.0, d=0.0)
        setattr(m, path, link)
        m.connect(m.ground.frame, link.frame_a)
        m.connect(link.frame_b, b.frame)
    res = compile_model(m).simulate(t_end=1.0, output_step=0.1, **TOL)
    t = res.t
    assert np.max(np.abs(res["top.y"] - (Y0 + 2.0 * t - 0.5 * G_N * t**2))) < 1e-9
    for name in ("sub.body.y", "sub.deep.body.y"):
        assert np.max(np.abs(res[name] - (Y0 + 2.0 * t - 0.5 * t**2))) < 1e-9


def test_two_worlds_in_one_model_is_one_clear_error():
    m = _free_bodies(World(), b=Body(**_start()))
    m.world2 = World(g=1.0)
    with pytest.raises(ModelError) as err:
        compile_model(m, cache=False)
    text = str(err.value)
    assert "\n" not in text and "world, world2" in text and "b" in text


def test_world_frame_is_a_fixed_ground():
    """world.frame_b is the origin, fixed: a pendulum hung from it swings
    as from a Fixed at (0, 0, 0) (closed form of the compound pendulum:
    (I + m L^2) th'' = -m g L cos(th), th from the x axis)."""
    mass, Ic, L = 0.7, 0.01, 0.3
    m = Model()
    m.world = World()
    m.pin = Revolute(phi=0.2, w=0.0)
    m.body = BodyShape(m=mass, I=Ic, r_CM_x=L, rx=2 * L)
    m.connect(m.world.frame_b, m.pin.frame_a)
    m.connect(m.pin.frame_b, m.body.frame_a)
    ts = np.linspace(0.0, 2.0, 201)
    res = compile_model(m).simulate(t_end=2.0, output_times=ts, **SWING)
    J = Ic + mass * L**2
    ref = solve_ivp(lambda t, z: [z[1], -mass * G_N * L * np.cos(z[0]) / J], [0, 2.0],
                    [0.2, 0.0], t_eval=ts, rtol=1e-12, atol=1e-14, method="DOP853")
    assert np.max(np.abs(res["pin.phi"] - ref.y[0])) < 1e-8
    th = res["pin.phi"]
    assert np.max(np.abs(res["body.x"] - L * np.cos(th))) < 1e-10
    assert np.max(np.abs(res["body.frame_b.y"] - 2 * L * np.sin(th))) < 1e-10
    assert np.max(np.abs(res["world.frame_b.fy"] + res["pin.frame_a.fy"])) < 1e-9


def _hanging(body, phi0=0.3, damper=None):
    """``body`` on a revolute at the world's origin, released at ``phi0``."""
    m = Model()
    m.world = World()
    m.pin = Revolute(phi=phi0, w=0.0)
    m.body = body
    m.connect(m.world.frame_b, m.pin.frame_a)
    m.connect(m.pin.frame_b, m.body.frame_a)
    if damper is not None:
        m.damper = rot.Damper(d=damper)
        m.connect(m.pin.support, m.damper.flange_a)
        m.connect(m.damper.flange_b, m.pin.axis)
    return m


def _pendulum_reference(mass, I_pivot, d_cm, alpha, phi0, ts, d=0.0):
    """th'' = (-m g |d| cos(th + alpha) - d th') / I_pivot, the centre of
    mass at distance |d| and angle alpha from the joint's x axis."""
    rhs = lambda t, z: [z[1], (-mass * G_N * d_cm * np.cos(z[0] + alpha) - d * z[1]) / I_pivot]
    return solve_ivp(rhs, [ts[0], ts[-1]], [phi0, 0.0], t_eval=ts, rtol=1e-12, atol=1e-14,
                     method="DOP853").y[0]


@pytest.mark.parametrize("case", ["solid", "hollow", "shifted"])
def test_body_box_mass_inertia_and_centre_from_dimensions(case):
    """MSL's BodyBox: m = rho L (W H - Wi Hi), I_z = (mo (L^2 + W^2) - mi (L^2 + Wi^2))/12,
    centre of mass half-way along the length from r_shape; checked through
    the motion of the box hung from frame_a (and the default width L/20)."""
    rho = 7700.0
    if case == "solid":
        box, L, W, H, Wi, Hi, cm_ = BodyBox(rx=0.5), 0.5, 0.025, 0.025, 0.0, 0.0, (0.25, 0.0)
    elif case == "hollow":
        box = BodyBox(rx=0.4, ry=0.3, width=0.08, height=0.05, innerWidth=0.06,
                      innerHeight=0.03, density=2700.0)
        L, W, H, Wi, Hi, rho, cm_ = 0.5, 0.08, 0.05, 0.06, 0.03, 2700.0, (0.2, 0.15)
    else:   # the box from r_shape along a direction of its own, a given length
        box = BodyBox(rx=0.6, r_shape_x=0.1, r_shape_y=-0.05, lengthDirection_x=0.0,
                      lengthDirection_y=1.0, length=0.3, width=0.04)
        L, W, H, Wi, Hi, cm_ = 0.3, 0.04, 0.04, 0.0, 0.0, (0.1, 0.1)
    mo, mi = rho * L * W * H, rho * L * Wi * Hi
    mass = mo - mi
    Ic = (mo * (L**2 + W**2) - mi * (L**2 + Wi**2)) / 12
    d_cm, alpha = math.hypot(*cm_), math.atan2(cm_[1], cm_[0])
    ts = np.linspace(0.0, 1.5, 151)
    res = compile_model(_hanging(box)).simulate(t_end=1.5, output_times=ts, **SWING)
    ref = _pendulum_reference(mass, Ic + mass * d_cm**2, d_cm, alpha, 0.3, ts)
    assert np.max(np.abs(res["pin.phi"] - ref)) < 1e-8
    assert np.ptp(res["pin.phi"]) > 0.5
    # the pin carries the box's weight at rest-free release: the vertical
    # force balance m (y_cm'' + g) = f on the box at frame_a
    yc = res["body.y"]
    assert np.max(np.abs(yc - d_cm * np.sin(res["pin.phi"] + alpha))) < 1e-10


@pytest.mark.parametrize("case", ["solid", "tube"])
def test_body_cylinder_mass_and_inertia_from_dimensions(case):
    """MSL's BodyCylinder: m = rho pi L (r^2 - ri^2), I about a diameter
    through the centre = (mo (L^2 + 3 r^2) - mi (L^2 + 3 ri^2))/12, default
    diameter L/20; with a damper on the pin's axis (via its support)."""
    rho = 7700.0
    if case == "solid":
        cyl, L, D, Di = BodyCylinder(rx=0.0, ry=-0.4), 0.4, 0.02, 0.0
    else:
        cyl, L, D, Di = BodyCylinder(rx=0.3, diameter=0.1, innerDiameter=0.08), 0.3, 0.1, 0.08
    mo, mi = rho * math.pi * L * D**2 / 4, rho * math.pi * L * Di**2 / 4
    mass = mo - mi
    Ic = (mo * (L**2 + 3 * D**2 / 4) - mi * (L**2 + 3 * Di**2 / 4)) / 12
    alpha = -math.pi / 2 if case == "solid" else 0.0
    ts = np.linspace(0.0, 1.5, 151)
    res = compile_model(_hanging(cyl, phi0=0.4, damper=0.05)).simulate(
        t_end=1.5, output_times=ts, **SWING)
    ref = _pendulum_reference(mass, Ic + mass * (L / 2)**2, L / 2, alpha, 0.4, ts, d=0.05)
    assert np.max(np.abs(res["pin.phi"] - ref)) < 1e-8
    assert np.ptp(res["pin.phi"]) > 0.3


def test_support_flange_equals_a_fixed_on_the_axis():
    """A damper between the revolute's support and axis acts as one from a
    rotational Fixed to the axis: the same motion to round-off."""
    def build(with_support):
        m = _hanging(BodyShape(m=1.0, I=0.001, r_CM_x=0.5), phi0=0.0)
        m.damper = rot.Damper(d=0.3)
        if with_support:
            m.connect(m.pin.support, m.damper.flange_a)
        else:
            m.housing = rot.Fixed()
            m.connect(m.housing.flange, m.damper.flange_a)
        m.connect(m.damper.flange_b, m.pin.axis)
        return m
    ts = np.linspace(0.0, 2.0, 101)
    a = compile_model(build(True)).simulate(t_end=2.0, output_times=ts, **SWING)
    b = compile_model(build(False)).simulate(t_end=2.0, output_times=ts, **SWING)
    assert np.max(np.abs(a["pin.phi"] - b["pin.phi"])) < 1e-10
    ref = _pendulum_reference(1.0, 0.001 + 0.25, 0.5, 0.0, 0.0, ts, d=0.3)
    assert np.max(np.abs(a["pin.phi"] - ref)) < 1e-8


@pytest.mark.parametrize("make, words", [
    (lambda: BodyBox(rx=0.5, width=0.05, innerWidth=0.05),
     "innerWidth = 0.05 m must be less than width"),
    (lambda: BodyBox(rx=0.5, width=0.05, height=0.02, innerHeight=0.03), "innerHeight"),
    (lambda: BodyCylinder(rx=0.5, diameter=0.02, innerDiameter=0.03), "innerDiameter"),
    (lambda: BodyBox(rx=0.0, ry=0.0), "its length is 0"),
])
def test_bad_dimensions_get_one_line_naming_the_body(make, words):
    m = _hanging(make())
    with pytest.raises(ParameterError) as err:
        compile_model(m, cache=False)
    text = str(err.value)
    assert "\n" not in text and "body" in text and words in text


def test_computed_parameters_cannot_be_given_and_zero_gravity_direction_is_refused():
    with pytest.raises(ParameterError, match="'m' is computed"):
        BodyBox(rx=0.5, m=3.0)
    with pytest.raises(ParameterError, match="gravity direction"):
        World(nx=0.0, ny=0.0)


def test_fixed_rotation_turns_frame_b():
    """A body hung from a pin through a FixedRotation (frame_b turned by
    angle a, offset r): the same motion as the body at the rotated offset,
    with its own angle shifted by a (the pendulum's closed form)."""
    from acausal.mechanics.planar import FixedRotation
    a, L = 0.7, 0.4
    m = Model()
    m.world = World()
    m.pin = Revolute(phi=0.0, w=0.0)
    m.turn = FixedRotation(rx=0.1, ry=0.0, angle=a)
    m.body = BodyShape(m=2.0, I=0.01, r_CM_x=L, rx=2 * L)
    m.connect(m.world.frame_b, m.pin.frame_a)
    m.connect(m.pin.frame_b, m.turn.frame_a)
    m.connect(m.turn.frame_b, m.body.frame_a)
    ts = np.linspace(0.0, 1.0, 101)
    res = compile_model(m).simulate(t_end=1.0, output_times=ts, **SWING)
    # the centre of mass from the pin: (0.1, 0) + L (cos a, sin a) in the pin's axes
    cx, cy = 0.1 + L * math.cos(a), L * math.sin(a)
    ref = _pendulum_reference(2.0, 0.01 + 2.0 * (cx**2 + cy**2), math.hypot(cx, cy),
                              math.atan2(cy, cx), 0.0, ts)
    assert np.max(np.abs(res["pin.phi"] - ref)) < 1e-8
    assert np.max(np.abs(res["body.phi"] - (res["pin.phi"] + a))) < 1e-12
