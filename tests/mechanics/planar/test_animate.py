"""``acausal animate``: the slider-crank's animation is written and, in the
drawn frames, the slider block sits where the crank puts it (closed form),
checked on the artists' data, not on pixels."""
import os

import numpy as np
import pytest
from click.testing import CliRunner
from PIL import Image

from acausal.viz.animate import Animator, draw_frame
from acausal.cli import main
from acausal.modelfile import compile_file

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(
    os.path.abspath(__file__)))))
CRANK = os.path.join(ROOT, "models", "examples", "slider_crank.py")
R, L = 0.05, 0.2          # the model file's crank and rod, written out here


@pytest.mark.slow
def test_animate_command_writes_gif_and_slider_follows_crank(tmp_path):
    out = tmp_path / "crank.gif"
    r = CliRunner().invoke(main, ["animate", CRANK, "--out", str(out), "--t-end", "0.4",
                                  "--frames", "12"])
    assert r.exit_code == 0, r.output
    with Image.open(out) as im:
        assert im.n_frames == 12
    _, cm = compile_file(CRANK)
    res = cm.simulate(t_end=0.4, rtol=1e-10, atol=1e-12, output_step=0.01)
    anim = Animator(res)
    items = {it.path: it for it in anim.scene.items}
    assert {"crank", "rod_half", "guide", "flywheel", "crank_pin", "ground"} <= set(items)
    xs = []
    for k in range(0, len(res.t), 5):
        anim.update(k)
        th = res["crank_pin.phi"][k]
        bx, by = items["guide"].artist.get_data()          # guide: frame_a -> block
        cx, cy = items["crank"].artist.get_data()          # crank: axis -> crank pin
        assert abs(cx[1] - R * np.cos(th)) < 1e-9 and abs(cy[1] - R * np.sin(th)) < 1e-9
        x_closed = R * np.cos(th) + np.sqrt(L**2 - (R * np.sin(th))**2)
        assert abs(bx[1] - x_closed) < 1e-9 and abs(by[1]) < 1e-12
        xs.append(bx[1])
    assert np.ptp(xs) > 1.5 * R            # the block travels the stroke (2 r)
    png = tmp_path / "frame.png"
    draw_frame(res, png, k=3)
    assert png.stat().st_size > 0


@pytest.mark.slow   # compiling a polyline contact takes several seconds
def test_a_polyline_profile_is_drawn_moving_with_its_body():
    """A polyline on a turning body: the drawn profile is its vertices in the
    body's frame at each output time."""
    from acausal import Model, compile_model
    from acausal.mechanics.planar.parts import Body, Fixed
    from acausal.mechanics.planar.joints import Revolute
    from acausal.mechanics.planar.polyline import CirclePolylineContact
    pts = ((-0.05, 0.01), (0.0, 0.0), (0.05, 0.02))
    m = Model()
    m.ground = Fixed()
    m.pin = Revolute(phi=0.0, w=2.0)
    m.cam = Body(m=1.0, I=1e-3)
    m.ball = Body(m=0.1, I=1e-5, x=0.0, y=0.2, vx=0.0, vy=0.0, phi=0.0, w=0.0)
    m.c = CirclePolylineContact(R=0.01, points=pts)
    m.connect(m.ground.frame, m.pin.frame_a)
    m.connect(m.pin.frame_b, m.cam.frame, m.c.frame_a)
    m.connect(m.c.frame_b, m.ball.frame)
    res = compile_model(m).simulate(t_end=0.5, rtol=1e-8, atol=1e-10, output_step=0.05)
    anim = Animator(res)
    prof = next(it for it in anim.scene.items if it.kind == "profile")
    for k in (0, 5, 10):
        anim.update(k)
        x, y = prof.artist.get_data()
        a = 2.0 * res.t[k]
        want = [(np.cos(a) * px - np.sin(a) * py, np.sin(a) * px + np.cos(a) * py)
                for px, py in pts]
        assert np.max(np.abs(np.column_stack([x, y]) - np.array(want))) < 1e-9
