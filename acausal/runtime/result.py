"""Simulation results: every variable by dotted path, events, statistics;
variables the solver does not integrate are evaluated from the stored rows
by the generated observe callback, once per mode."""
from typing import NamedTuple

import numpy as np

from ..errors import UnknownNameError
from .observe import observed_column, observed_rows


class Rows(NamedTuple):
    """The stored output rows of a run: times ``t``, unknowns ``y`` and
    their derivatives ``yp`` (rows x unknowns), discrete values ``d``
    (rows x discrete values)."""
    t: np.ndarray
    y: np.ndarray
    yp: np.ndarray
    d: np.ndarray


BLOCK_ROWS = 200_000    # rows of one block of a large result's CSV or scan
# observed variables read one by one from a result before the whole matrix is
# computed instead: a fit reads one or two (each alone is 10x cheaper than
# all of them), a comparison against a reference reads every one (the whole
# matrix once is cheaper than a generated expression and a check per name)
ALONE = 4


class Result:
    """What a simulation produced.

    ``res["hook.phi"]`` is the time series of any variable (including those
    eliminated as aliases), discrete value or parameter; ``res.t`` the time
    points (requested output times plus both sides of every event);
    ``res.events`` a list of ``(t, name)``; ``res.stats`` solver statistics;
    ``res.sensitivities`` the :class:`acausal.runtime.sensitivity_run.Sensitivities`
    of a run that asked for them (else None).
    """

    def __init__(self, cm, p, rows, events, stats, status="ok", message="",
                 sensitivities=None):
        self.model = cm
        self.p = np.asarray(p, dtype=float)
        self.t = np.asarray(rows.t, dtype=float)
        self.y = np.asarray(rows.y, dtype=float)
        self.yp = np.asarray(rows.yp, dtype=float)
        self.d = np.asarray(rows.d, dtype=float)
        self.events = events
        self.stats = stats
        self.status = status
        self.message = message
        self._obs = None
        self._columns = {}    # variable index -> its column (observed_column), read alone
        self.sensitivities = sensitivities

    # -- access ----------------------------------------------------------------
    @property
    def names(self):
        cm = self.model   # (not the compiler's time switches and initial equations)
        flat = cm.flat
        return [n for n in cm.var_names if not flat.variables[n].internal] + \
            [d.symbol.name for d in cm.discretes if not d.internal]

    def _observed(self):
        if self._obs is None:
            self._obs = self._observed_rows(0, len(self.t))
        return self._obs

    def _observed_rows(self, k0, k1):
        """Every variable (``var_names``' order) at rows ``k0:k1``: from the
        cache when the whole matrix was computed, else computed for these
        rows only (a block of a large result, or its last row)."""
        if self._obs is not None:
            return self._obs[k0:k1]
        return observed_rows(self.model, self.p, self.t[k0:k1], self.y[k0:k1],
                             self.yp[k0:k1], self.d[k0:k1] if self.d.size else self.d)

    def _block(self, names, k0, k1):
        """Columns ``names`` at rows ``k0:k1`` (as ``self[name][k0:k1]``,
        observed variables computed for these rows only)."""
        cm, obs, out = getattr(self, "model", None), None, []
        for name in names:
            k = cm.var_names.index(name) if cm is not None and name in cm.var_names else None
            j = cm.y_column(name) if k is not None and self._obs is None and \
                self.y.ndim == 2 else None
            if k is None:
                out.append(np.asarray(self[name][k0:k1], dtype=float))
            elif j is not None:
                out.append(self.y[k0:k1, j])
            else:
                obs = self._observed_rows(k0, k1) if obs is None else obs
                out.append(obs[:, k])
        return out

    def blocks(self, names=None, rows=None):
        """``(t, columns)`` of ``names`` (default: every variable and discrete
        value) by blocks of ``rows`` rows: what a large result's CSV or scan
        needs, without the whole matrix of observed variables (writing 8.9 M
        rows took 5.4 GB at once, past the command's 4 GB limit)."""
        names, rows = names or self.names, rows or BLOCK_ROWS
        for k0 in range(0, len(self.t), rows):
            k1 = min(k0 + rows, len(self.t))
            yield self.t[k0:k1], self._block(names, k0, k1)

    def nonfinite(self, names=None):
        """``(name, t, value)`` of the earliest NaN or infinite value among
        ``names`` (default: every variable), or None; read by blocks."""
        names = names or self.names
        for t, cols in self.blocks(names):
            hits = [(int(np.flatnonzero(~np.isfinite(c))[0]), n, c) for n, c in
                    zip(names, cols) if not np.all(np.isfinite(c))]
            if hits:
                i, name, col = min(hits, key=lambda h: h[0])
                return name, float(t[i]), float(col[i])
        return None

    def __getitem__(self, name):
        cm = self.model
        if name in ("time", "t"):
            return self.t
        try:
            k = cm.var_names.index(name)
        except ValueError:
            k = None
        if k is not None:
            j = cm.y_column(name) if self._obs is None and self.y.ndim == 2 else None
            if j is not None:
                return self.y[:, j]
            return self._observed()[:, k] if self._obs is not None else self._column(k)
        for j, dsc in enumerate(cm.discretes):
            if dsc.symbol.name == name:
                return self.d[:, j]
        for j, prm in enumerate(cm.params):
            if prm.name == name:
                return np.full(len(self.t), self.p[j])
        raise UnknownNameError(f"no variable {name!r} in the result; try one of: "
                       + ", ".join(self.names[:12]) + (" ..." if len(self.names) > 12 else ""))

    def _column(self, k):
        """Observed variable ``k`` alone (:func:`.observe.observed_column`),
        or from the whole matrix when it cannot be vectorised."""
        col = self._columns.get(k)
        if col is None and len(self._columns) >= ALONE:
            return self._observed()[:, k]      # many names read: the whole matrix, once
        if col is None:
            col = observed_column(self.model, k, self.p, self.t, self.y, self.yp,
                                  self.d)
            if col is None:
                return self._observed()[:, k]
            self._columns[k] = col
        return col

    def __contains__(self, name):
        try:
            self[name]
            return True
        except KeyError:
            return False

    def final(self):
        """Every variable's value at the last time point (SI units)."""
        obs = self._observed_rows(len(self.t) - 1, len(self.t))[0]
        out = {n: float(v) for n, v in zip(self.model.var_names, obs)}
        for j, dsc in enumerate(self.model.discretes):
            out[dsc.symbol.name] = float(self.d[-1, j])
        return out

    def sensitivity(self, name, param):
        """d(``name``)/d(``param``) at every ``res.t``: the forward sensitivity of
        a variable (state, algebraic unknown or any observed variable) with
        respect to a parameter named in ``simulate(sensitivities=[...])``, in
        the variable's unit per the parameter's unit."""
        return self._sens().of(name, param)

    def event_sensitivity(self, param, name=None):
        """d(event time)/d(``param``) of the events called ``name`` (all if
        None), in the order of :meth:`event_times` (NaN for an event whose
        time is not differentiable, a grazing root)."""
        e = self._sens().event(param)
        return np.array([v for (_, n), v in zip(self.events, e) if name is None or n == name])

    def measure_sensitivity(self, fn, param):
        """d fn(res) / d(``param``) of a measure ``fn`` (a function of a
        result, as a model file's measures), from the sensitivities, with no
        further simulation (:meth:`acausal.runtime.sensitivity_run.Sensitivities.measure`)."""
        return self._sens().measure(self, fn, param)

    def _sens(self):
        if self.sensitivities is None:
            from ..errors import UsageError
            raise UsageError("this result has no sensitivities: simulate with "
                             "sensitivities=[parameter names]")
        return self.sensitivities

    def event_times(self, name=None):
        """Times of the events called ``name`` (all events if None)."""
        return [t for t, n in self.events if name is None or n == name]

    def at(self, name, t):
        """Linear interpolation of a variable at time ``t``."""
        return float(np.interp(t, self.t, self[name]))

    def unit(self, name):
        """The declared unit of a variable, discrete value or parameter
        (``"s"`` for time); the values in the result are in this unit."""
        cm = self.model
        if name in ("time", "t"):
            return "s"
        info = cm.flat.variables.get(name)
        if info is not None:
            return info.unit
        for dsc in cm.discretes:
            if dsc.symbol.name == name:
                return dsc.unit
        for prm in cm.params:
            if prm.name == name:
                return prm.unit
        raise UnknownNameError(f"no variable {name!r} in the result", variable=name)

    # -- export --------------------------------------------------------------------
    def to_csv(self, path, names=None):
        """Write ``names`` (default: every variable and discrete value) as
        columns after ``time``; headers carry units: ``hook.phi [rad]``."""
        import polars   # Rust's shortest round-trip float formatting (ryu)
        names = names or self.names
        header = ["time [s]"] + [f"{n} [{self.unit(n)}]" for n in names]
        # Every value reads back bit for bit. Measured on 1 M rows x 15 values:
        # 2 s, against 13 s for Python's repr joined by blocks and 27 s for
        # pandas (a million rows of an interrupted run are written while the
        # user waits). Written by blocks: the memory of one block, not of a
        # copy of the whole result.
        with open(path, "wb") as f:
            for k, (t, cols) in enumerate(self.blocks(names)):
                frame = polars.DataFrame(dict(zip(header, [np.asarray(t, dtype=float)] + cols)))
                frame.write_csv(f, include_header=(k == 0))
            if not len(self.t):
                f.write((",".join(header) + "\n").encode())
        return path

    def plot(self, names=None, path=None, title=None):
        """Stacked panels, one per variable (default: the states), labelled
        with their units. Returns the figure."""
        from ..viz.plot import plot_result, state_variables
        return plot_result(self, names or state_variables(self.model), path, title)

    def __repr__(self):
        return (f"<Result {len(self.t)} points, t = {self.t[0]:g}..{self.t[-1]:g}, "
                f"{len(self.events)} events, {self.status}>")
