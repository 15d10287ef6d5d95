"""A segment's output times (``hybrid._tspan``), found by bisection in the
sorted grid, are those the masks over the whole grid select: the times after
``t`` (beyond IDA's smallest step), up to a time event, a watch's window or
the end."""
import numpy as np

from acausal.runtime.hybrid import SAME_INSTANT, _tspan


def masks(t, tout, t_end, horizon, t_event=np.inf):
    """The span as written with boolean masks (the reference)."""
    after = t + SAME_INSTANT * max(abs(t), abs(t_end))
    if t_event < t_end and (horizon is None or t_event <= horizon):
        return np.concatenate([[t], tout[(tout > after) & (tout < t_event)], [t_event]])
    later = tout[tout > after]
    if horizon is not None and horizon < t_end:
        cut = later[later <= horizon]
        if len(cut) == 0:
            cut = later[:1] if len(later) else np.array([horizon])
        return np.concatenate([[t], cut])
    return np.concatenate([[t], later if len(later) and later[-1] >= t_end
                           else np.append(later, t_end)])


def test_the_bisection_gives_the_masks_spans():
    rng = np.random.default_rng(7)
    for _ in range(5000):
        t_end = float(rng.choice([1.0, 2.5, 1e-3]))
        n = int(rng.integers(0, 25))
        grid = np.linspace(0.0, t_end, 17)
        tout = np.sort(rng.choice(grid, size=n) if rng.random() < 0.5
                       else rng.uniform(0.0, t_end, n))     # repeats and grid points
        if n and rng.random() < 0.3:
            tout = np.append(tout, t_end)
        t = float(rng.choice(np.concatenate([tout, [0.0, t_end * rng.random()]])))
        if rng.random() < 0.2:      # an output time exactly at the span's first limit
            tout = np.sort(np.append(tout, t + SAME_INSTANT * max(abs(t), abs(t_end))))
        horizon = None if rng.random() < 0.5 else t + float(rng.choice([0.0, 1e-3, 0.1, 10.0]))
        t_event = float(rng.choice([np.inf, t_end * rng.random(), t + 1e-17, t, t_end]
                                   + list(tout[-3:])))     # a time event at an output time
        got = _tspan(t, tout, t_end, horizon, t_event)
        want = masks(t, tout, t_end, horizon, t_event)
        assert np.array_equal(got, want), (t, tout, t_end, horizon, t_event, got, want)
