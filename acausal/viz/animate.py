"""Drawing planar mechanisms from a result: one frame (a figure) or an
animation (GIF with Pillow, MP4 where ffmpeg exists), with matplotlib.

What is drawn comes from the model's planar components (their frame
positions in the result; :mod:`acausal.connectors` for the frame):

* ``FixedTranslation`` (a rigid link) and the two-frame bodies
  (``BodyShape``, ``BodyBox``, ``BodyCylinder``): a thick line frame_a -> frame_b;
* ``Body``: a disc at its centre of mass with a tick along its x axis;
* ``Revolute``: a small ring at the pin; ``Prismatic``: its guide line and a
  square block at frame_b; ``Fixed``: a triangle (ground);
* line forces (``Spring``, ``Damper``, ``SpringDamper``): a dashed line;
* a contact that defines ``drawing_points(result)``: its points; one that
  defines ``drawing_profile(result)`` (a polyline, a circle on a body): that
  profile as a line moving with its body.
"""
from dataclasses import dataclass

import matplotlib

matplotlib.use("Agg", force=False)
import numpy as np  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402

from ..errors import ModelError  # noqa: E402


@dataclass
class Item:
    """One drawn element: kind, component path and its matplotlib artist."""

    kind: str
    path: str
    artist: object = None


def _kinds():
    from ..mechanics.planar import bodies, forces, joints, parts
    return [(parts.FixedTranslation, "link"), (parts.FixedRotation, "link"),
            (bodies.BodyShape, "link"),
            (parts.Body, "body"), (joints.Revolute, "pin"),
            (joints.Prismatic, "slider"), (parts.Fixed, "ground"),
            (forces.Spring, "force"), (forces.Damper, "force"), (forces.SpringDamper, "force")]


def scene_items(model):
    """The drawable planar components of ``model`` (a list of :class:`Item`)."""
    kinds = _kinds()
    out = []
    for comp in model.walk():
        for cls, kind in kinds:
            if isinstance(comp, cls):
                out.append(Item(kind, comp.path))
                break
        else:
            if hasattr(comp, "drawing_profile"):
                out.append(Item("profile", comp.path))
            if hasattr(comp, "drawing_points"):
                out.append(Item("contact", comp.path))
    if not out:
        raise ModelError("nothing to draw: the model has no planar components "
                         "(acausal.mechanics.planar)")
    return out


class Scene:
    """Positions of every drawn element along a result."""

    def __init__(self, res):
        self.res = res
        self.items = scene_items(res.model.model)

    def _xy(self, path, k):
        r = self.res
        return np.array([r[f"{path}.x"][k], r[f"{path}.y"][k]])

    def geometry(self, item, k):
        """Points [[x, y], ...] of ``item`` at output index ``k``."""
        p = item.path
        if item.kind in ("link", "force", "slider"):
            return np.array([self._xy(f"{p}.frame_a", k), self._xy(f"{p}.frame_b", k)])
        if item.kind == "body":
            c = self._xy(f"{p}.frame", k)
            phi = self.res[f"{p}.frame.phi"][k]
            return np.array([c, c + 0.08 * self.size * np.array([np.cos(phi), np.sin(phi)])])
        if item.kind == "pin":
            return np.array([self._xy(f"{p}.frame_a", k)])
        if item.kind == "ground":
            return np.array([self._xy(f"{p}.frame", k)])
        comp = self.res.model.model.find(p)
        pts = (comp.drawing_profile if item.kind == "profile" else comp.drawing_points)(self.res)
        return np.atleast_2d(np.asarray(pts)[k])

    @property
    def size(self):
        lo, hi = self.limits
        return float(max(hi - lo))

    @property
    def limits(self):
        if not hasattr(self, "_limits"):
            pts = []
            for it in self.items:
                if it.kind in ("link", "force", "slider", "pin", "ground"):
                    for k in (0, len(self.res.t) // 2, len(self.res.t) - 1):
                        pts.append(self.geometry_raw(it, k))
                elif it.kind == "body":
                    pts.append(np.column_stack([self.res[f"{it.path}.frame.x"],
                                                self.res[f"{it.path}.frame.y"]]))
            allp = np.vstack(pts)
            lo, hi = allp.min(axis=0), allp.max(axis=0)
            pad = 0.1 * max(float(max(hi - lo)), 1e-6)
            self._limits = (lo - pad, hi + pad)
        return self._limits

    def geometry_raw(self, item, k):
        p = item.path
        if item.kind in ("pin", "ground"):
            return np.array([self._xy(f"{p}.frame_a" if item.kind == "pin" else f"{p}.frame", k)])
        return np.array([self._xy(f"{p}.frame_a", k), self._xy(f"{p}.frame_b", k)])


_STYLE = {
    "link": dict(color="tab:blue", lw=4, solid_capstyle="round", zorder=2),
    "force": dict(color="tab:green", lw=1.5, ls="--", zorder=1),
    "slider": dict(color="0.5", lw=1, marker="s", markevery=[1], ms=12, mfc="tab:orange",
                   zorder=3),
    "body": dict(color="k", lw=1.5, marker="o", markevery=[0], ms=10, mfc="tab:red", zorder=4),
    "pin": dict(ls="none", marker="o", ms=7, mfc="white", mec="k", zorder=5),
    "ground": dict(ls="none", marker="^", ms=11, mfc="0.6", mec="k", zorder=0),
    "contact": dict(ls="none", marker="x", ms=8, color="tab:purple", zorder=6),
    "profile": dict(color="tab:brown", lw=2, zorder=1),
}


class Animator:
    """A figure of the mechanism whose artists :meth:`update` moves to an
    output index of the result."""

    def __init__(self, res, title=None, figsize=(6, 5)):
        self.scene = Scene(res)
        self.fig = Figure(figsize=figsize)
        ax = self.ax = self.fig.add_subplot(1, 1, 1)
        lo, hi = self.scene.limits
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.grid(alpha=0.3)
        for it in self.scene.items:
            it.artist, = ax.plot([], [], **_STYLE[it.kind])
        self.label = ax.text(0.02, 0.97, "", transform=ax.transAxes, va="top", fontsize=9)
        if title:
            ax.set_title(title, fontsize=10)
        self.fig.tight_layout()

    def update(self, k):
        for it in self.scene.items:
            pts = self.scene.geometry(it, k)
            it.artist.set_data(pts[:, 0], pts[:, 1])
        self.label.set_text(f"t = {self.scene.res.t[k]:.4g} s")
        return [it.artist for it in self.scene.items] + [self.label]


def frame_indices(res, max_frames=150):
    """Output indices of the animation's frames, evenly spaced in time."""
    t = res.t
    times = np.linspace(t[0], t[-1], min(max_frames, len(t)))
    return np.unique(np.searchsorted(t, times).clip(0, len(t) - 1))


def animate(res, path, fps=25, max_frames=150, title=None):
    """Write an animation of the result to ``path`` (``.gif``: Pillow,
    ``.mp4``: ffmpeg). Returns the output indices drawn."""
    from matplotlib.animation import FFMpegWriter, FuncAnimation, PillowWriter
    anim = Animator(res, title=title)
    ks = frame_indices(res, max_frames)
    if str(path).lower().endswith(".mp4"):
        if not FFMpegWriter.isAvailable():
            raise ModelError(f"{path}: writing MP4 needs ffmpeg, which is not installed; "
                             "write a .gif instead")
        writer = FFMpegWriter(fps=fps)
    else:
        writer = PillowWriter(fps=fps)
    FuncAnimation(anim.fig, anim.update, frames=ks, blit=False).save(str(path),
                                                                     writer=writer)
    return ks


def draw_frame(res, path, k=0, title=None):
    """One picture of the mechanism at output index ``k`` written to ``path``."""
    anim = Animator(res, title=title)
    anim.update(k)
    anim.fig.savefig(path, dpi=110)
    return anim


def plot_with_mechanism(res, path, title=None):
    """A model file's ``plot`` (``acausal simulate --plot``): the mechanism
    at the end of the run."""
    return draw_frame(res, path, k=len(res.t) - 1, title=title)
