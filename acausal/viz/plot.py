"""Plots of results: stacked panels against time, events marked."""
import matplotlib

matplotlib.use("Agg", force=False)
from matplotlib.figure import Figure  # noqa: E402


MAX_PANELS = 8


def state_variables(cm, limit=MAX_PANELS):
    """Names of the model's states as the user declared them: for each state
    slot of the solver the first variable that is (up to sign) that slot
    (``armature.mass.v`` for the slot ``der(armature.mass.s)``), at most
    ``limit`` of them."""
    names = []
    for slot in cm.slot_names()[:cm.dae.n_states]:
        declared = [n for n in slot if n in cm.flat.variables]
        if declared:
            names.append(declared[0])
    return names[:limit]


def plot_result(res, names, path=None, title=None, scales=None, labels=None, marks=None):
    """One panel per variable in ``names`` (time in ms when the run is
    shorter than 0.1 s). ``scales``: name -> factor (e.g. rad -> deg);
    ``labels``: name -> axis label; ``marks``: list of (t, text) drawn as
    vertical lines. A panel without a label is labelled with the variable's
    name and unit. Returns the figure; writes it to ``path`` if given."""
    t = res.t
    ms = (t[-1] - t[0]) < 0.1
    tt = t * 1e3 if ms else t
    fig = Figure(figsize=(7, 1.9 * len(names) + 0.6))
    axes = fig.subplots(len(names), 1, sharex=True, squeeze=False)[:, 0]
    for ax, name in zip(axes, names):
        y = res[name] * (scales or {}).get(name, 1.0)
        ax.plot(tt, y, lw=1.2)
        ax.set_ylabel((labels or {}).get(name) or _label(res, name, (scales or {}).get(name)),
                      fontsize=8)
        ax.grid(alpha=0.3)
        for tm, text in marks or []:
            x = tm * 1e3 if ms else tm
            ax.axvline(x, color="tab:red", lw=0.8, ls="--")
        if ax is axes[0]:
            for tm, text in marks or []:
                x = tm * 1e3 if ms else tm
                ax.annotate(text, (x, 1.0), xycoords=("data", "axes fraction"),
                            fontsize=7, color="tab:red", rotation=0, va="bottom", ha="center")
    axes[-1].set_xlabel("time [ms]" if ms else "time [s]")
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    if path:
        fig.savefig(path, dpi=120)
    return fig


def _label(res, name, scale):
    """``name [unit]`` (``name [unit x scale]`` when the panel is scaled)."""
    try:
        unit = res.unit(name)
    except KeyError:
        return name
    return f"{name} [{unit}]" if scale in (None, 1.0) else f"{name} [{unit} x {scale:g}]"
