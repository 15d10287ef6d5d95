"""Time tables (MSL ``Modelica.Blocks.Sources.CombiTimeTable``).

:class:`CombiTimeTable` interpolates columns of a table (an array, or a CSV
file) in time. Between two breakpoints every output is a polynomial of
time whose coefficients are discrete values; a time event at every
breakpoint sets them for the next interval (linear segments: the value
and slope of the segment; constant segments: the value), so IDA
integrates a smooth input between events and stops exactly at each
breakpoint.

The table's first column is the time ``T`` (in units of ``timeScale``
seconds, relative to ``shiftTime``): a breakpoint is at model time
``shiftTime + timeScale*T``. It increases; a time may appear twice in a
row (MSL's rule), for a jump. Outside ``[T_first, T_last]`` the
``extrapolation`` rule applies; before ``startTime`` the output is
``offset``.
"""
import csv
import math
from pathlib import Path

import numpy as np
import sympy as sp

from acausal.errors import DataError, ModelError, ParameterError
from acausal.lang import Component, Discrete, Eq, Parameter, Start, TimeEvent, time
from acausal.lang.connectors import RealOutput

__all__ = ["CombiTimeTable", "read_table_file", "check_table"]

SMOOTHNESS = ("LinearSegments", "ConstantSegments")
EXTRAPOLATION = ("LastTwoPoints", "HoldLastPoint", "Periodic", "NoExtrapolation")


def read_table_file(path):
    """(array rows x columns, header names or None, line number of each row)
    of a CSV table: comma-separated numbers, one row per line; blank lines
    and lines starting with ``#`` are skipped; a first row that is not all
    numbers is a header (column names). A DataError naming file and line
    for a missing file, a row of another width or a cell that is not a
    finite number."""
    path = Path(path)
    if not path.is_file():
        raise DataError("table file not found", path)
    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError) as exc:
        raise DataError(f"cannot read the table file: {exc}", path) from None
    rows, lines, header = [], [], None
    for line, raw in enumerate(text.splitlines(), start=1):
        if not raw.strip() or raw.lstrip().startswith("#"):
            continue
        cells = [c.strip() for c in next(csv.reader([raw]))]
        values = [_number(c) for c in cells]
        if header is None and not rows and any(v is None for v in values):
            header = cells
            width = len(cells)
            continue
        width = len(header) if header is not None else (len(rows[0]) if rows else len(cells))
        if len(cells) != width:
            raise DataError(f"row has {len(cells)} values, expected {width} (as the "
                            f"{'header' if header is not None else 'first row'})", path, line)
        for k, (c, v) in enumerate(zip(cells, values)):
            if v is None or not math.isfinite(v):
                col = header[k] if header is not None else f"column {k + 1}"
                raise DataError(f"{col}: {c!r} is not a finite number", path, line)
        rows.append(values)
        lines.append(line)
    if not rows:
        raise DataError("the table file has no rows of numbers", path)
    return np.array(rows, dtype=float), header, lines


def _number(cell):
    try:
        return float(cell)
    except ValueError:
        return None


def check_table(T, where):
    """A ModelError unless the times ``T`` increase (a time may repeat once,
    for a jump); ``where(i)`` names row ``i`` (file and line, or the row of
    an array)."""
    for i in range(1, len(T)):
        if T[i] < T[i - 1]:
            raise _located(where(i), f"time {T[i]:g} is less than the time {T[i - 1]:g} of "
                           "the row before: the first column must increase")
        if i >= 2 and T[i] == T[i - 1] == T[i - 2]:
            raise _located(where(i), f"time {T[i]:g} appears three times in a row (twice "
                           "makes a jump; a third is not allowed)")


def _located(where, reason):
    file, line, text = where
    if file is not None:
        return DataError(reason, file, line)
    return ModelError(f"{text}: {reason}")


class CombiTimeTable(Component):
    """Table look-up in time (MSL ``CombiTimeTable``).

    ``CombiTimeTable(table=[[0, 0], [1, 2], [2, 2]])`` or
    ``CombiTimeTable(fileName="force.csv", columns=(2, 3))``: the first
    column is time, ``columns`` (1-based, as MSL's, or header names of a
    file with a header) the columns interpolated, one output each:
    ``y1``, ``y2``, ... (``table.y`` is the tuple of them).

    ``y_i = offset_i + f_i((time - shiftTime)/timeScale)`` for time >=
    ``startTime``, ``offset_i`` before it. ``smoothness``:
    ``"LinearSegments"`` (linear interpolation) or ``"ConstantSegments"``
    (each row's value held until the next row). ``extrapolation`` outside
    the table: ``"LastTwoPoints"`` (the line through the first/last two
    rows; MSL's default), ``"HoldLastPoint"``, ``"Periodic"`` (the table
    repeats with period T_last - T_first) or ``"NoExtrapolation"`` (an
    error when time leaves the table). Time events at every breakpoint
    (MSL's ``timeEvents = Always``) and at ``startTime``.

    Parameters: ``timeScale`` [s] (> 0), ``shiftTime`` [s] (default
    ``startTime``), ``startTime`` [s], ``offset_1..n`` [1] (``offset``: one
    number for all, or one per column); ``smoothness``, ``extrapolation``
    (structural). Discrete values: ``c0_i``, ``c1_i`` (the value and slope
    per table time unit of output i on the current interval), ``T_k``
    (the interval's start in table time). Connectors: ``y1``..``yn``
    (RealOutput).
    """

    timeScale = Parameter(1.0, "s", "time scale of the first table column", min=0.0,
                          min_open=True)
    startTime = Parameter(0.0, "s", "output = offset for time < startTime")
    shiftTime = Parameter(0.0, "s", "shift time of the first table column")
    smoothness = Parameter("LinearSegments", "1", "interpolation", structural=True,
                           choices=SMOOTHNESS)
    extrapolation = Parameter("LastTwoPoints", "1", "extrapolation outside the table",
                              structural=True, choices=EXTRAPOLATION)
    T_k = Discrete(0.0, "1", "start of the current interval, in table time")

    def __init__(self, table=None, fileName=None, columns=None, offset=0.0, **kw):
        kw.setdefault("shiftTime", kw.get("startTime", 0.0))
        super().__init__(**kw)
        label = type(self).__name__
        if (table is None) == (fileName is None):
            raise ParameterError(f"{label}: give either table= (an array) or fileName= (a "
                                 "CSV file), not both or neither")
        if fileName is not None:
            data, header, lines = read_table_file(fileName)
            where = (lambda i: (Path(fileName), lines[i], None))
        else:
            data = self._array(table, label)
            header = None
            where = (lambda i: (None, None, f"{label} table row {i + 1}"))
        check_table(data[:, 0], where)
        cols = self._columns(columns, data, header, fileName, label)
        offsets = self._offsets(offset, len(cols), label)
        object.__setattr__(self, "_T", data[:, 0].copy())
        object.__setattr__(self, "_Y", data[:, [c - 1 for c in cols]].copy())
        object.__setattr__(self, "_outputs", {})
        for i, c in enumerate(cols, start=1):
            what = header[c - 1] if header is not None else f"column {c}"
            self._outputs[f"y{i}"] = _named(RealOutput(f"interpolated {what}"), f"y{i}")
            self._declare(Parameter(offsets[i - 1], None, f"offset of output y{i}"),
                          f"offset_{i}", offsets[i - 1])
            self._declare(Discrete(0.0, None, f"value of y{i} at T_k (table)"), f"c0_{i}")
            self._declare(Discrete(0.0, None, f"slope of y{i} per table time unit"), f"c1_{i}")

    # -- construction helpers ----------------------------------------------------
    @staticmethod
    def _array(table, label):
        try:
            data = np.array(table, dtype=float)
        except (TypeError, ValueError):
            raise ParameterError(f"{label}: table must be a 2-D array of numbers") from None
        if data.ndim != 2 or data.shape[0] < 1 or data.shape[1] < 2:
            raise ParameterError(f"{label}: table must be a 2-D array with a time column and "
                                 f"at least one data column, got shape {data.shape}")
        bad = np.argwhere(~np.isfinite(data))
        if len(bad):
            i, k = bad[0]
            raise ParameterError(f"{label} table row {i + 1}, column {k + 1}: "
                                 f"{data[i, k]} is not a finite number")
        return data

    @staticmethod
    def _columns(columns, data, header, fileName, label):
        m = data.shape[1]
        if columns is None:
            return list(range(2, m + 1))
        if isinstance(columns, (int, str)):
            columns = (columns,)
        out = []
        for c in columns:
            if isinstance(c, str):
                if header is None or c not in header:
                    raise ParameterError(f"{label}.columns: no column named {c!r} in "
                                         f"{fileName or 'the table'}"
                                         + (f" (it has: {', '.join(header)})" if header else
                                            " (it has no header row)"))
                c = header.index(c) + 1
            if isinstance(c, bool) or not isinstance(c, (int, np.integer)) or not 2 <= c <= m:
                raise ParameterError(f"{label}.columns: {c!r} is not a data column of "
                                     f"{fileName or 'the table'} (1-based, 2..{m}; column 1 "
                                     "is time)")
            out.append(int(c))
        if not out:
            raise ParameterError(f"{label}.columns: no column chosen")
        return out

    @staticmethod
    def _offsets(offset, n, label):
        vals = list(offset) if np.ndim(offset) == 1 else [offset] * n
        if len(vals) == 1:
            vals = vals * n
        if len(vals) != n:
            raise ParameterError(f"{label}.offset: {len(vals)} offsets for {n} columns")
        return [float(v) for v in vals]

    def _declare(self, decl, name, value=None):
        decl.name = name
        self._extra[name] = decl
        if isinstance(decl, Parameter):
            self._values[name] = decl.check(value, self.path)
        else:
            self._starts[name] = Start(decl.start, True)

    def connectors(self):
        out = super().connectors()
        out.update(self.__dict__.get("_outputs", {}))
        return out

    def __getattr__(self, name):
        outs = self.__dict__.get("_outputs", {})
        if name in outs:
            return self.port(name)
        extra = self.__dict__.get("_extra", {})
        if name in extra:
            return self.symbol(name)
        raise AttributeError(f"{type(self).__name__} has no member {name!r}")

    @property
    def y(self):
        """The outputs, one per chosen column (``y1``, ``y2``, ...)."""
        return tuple(self.port(f"y{i}") for i in range(1, len(self._outputs) + 1))

    # -- behaviour ---------------------------------------------------------------
    def equations(self):
        tau = (time - self.shiftTime) / self.timeScale
        out = []
        for i in range(1, len(self._outputs) + 1):
            law = self.symbol(f"c0_{i}") + self.symbol(f"c1_{i}") * (tau - self.T_k)
            out.append(Eq(self.port(f"y{i}"), self.symbol(f"offset_{i}")
                          + sp.Piecewise((0, time < self.startTime), (law, True))))
        return out

    def events(self):
        return [TimeEvent(f"{self.path}.breakpoint", self._next_time, self._set_interval)]

    def _breaks(self, state):
        """The breakpoints in model time: shiftTime + timeScale*T."""
        shift, scale = state[self.shiftTime], state[self.timeScale]
        return shift + scale * self._T, scale

    def _tol(self, t, tb):
        return 64 * np.finfo(float).eps * max(abs(t), float(np.max(np.abs(tb))), 1.0)

    def _period(self, state):
        """(number of periods m before the one containing t, period) of a
        periodic table (m = 0 otherwise)."""
        tb, scale = self._breaks(state)
        P = tb[-1] - tb[0]
        if self.extrapolation != "Periodic" or P <= 0:
            return 0, 0.0
        x = (state.t - tb[0]) / P
        m = round(x)
        if abs(x - m) > 1e-12 * max(1.0, abs(x)):
            m = math.floor(x)
        return m, P

    def _next_time(self, state):
        tb, _ = self._breaks(state)
        m, P = self._period(state)
        t = state.t - m * P
        tol = self._tol(state.t, tb)
        k = int(np.searchsorted(tb, t + tol, side="right"))
        if k < len(tb):
            return m * P + tb[k]
        if P > 0:   # (round-off put t past the period's end: the next period)
            return (m + 1) * P + tb[int(np.searchsorted(tb, tb[0] + tol, side="right"))]
        return math.inf

    def _set_interval(self, state):
        T, Y = self._T, self._Y
        tb, _ = self._breaks(state)
        m, P = self._period(state)
        t = state.t - m * P
        tol = self._tol(state.t, tb)
        n = len(T)
        k = int(np.searchsorted(tb, t + tol, side="right")) - 1   # interval [T_k, T_k+1)
        if P > 0:
            k = min(max(k, 0), n - 2)
        const = self.smoothness == "ConstantSegments"
        if n == 1:
            c0, c1, tk = Y[0], np.zeros(Y.shape[1]), T[0]
        elif k < 0 or k >= n - 1:
            if self.extrapolation == "NoExtrapolation":
                # (right limit: at the last row the run is about to leave the table)
                raise ModelError(
                    f"{self.path}: at time {state.t:.9g} s the run leaves the table's range "
                    f"[{tb[0]:.9g}, {tb[-1]:.9g}] s (extrapolation='NoExtrapolation')",
                    component=self.path)
            a, b = (0, 1) if k < 0 else (n - 2, n - 1)
            end = 0 if k < 0 else n - 1
            if self.extrapolation == "HoldLastPoint" or T[b] == T[a] or \
                    self.extrapolation == "NoExtrapolation":
                c1 = np.zeros(Y.shape[1])
            else:
                c1 = (Y[b] - Y[a]) / (T[b] - T[a])
            c0, tk = Y[end], T[end]
        else:
            c0, tk = Y[k], T[k]
            c1 = np.zeros(Y.shape[1]) if const else (Y[k + 1] - Y[k]) / (T[k + 1] - T[k])
        if P > 0:   # the interval's start in table time, periods included
            tk = tk + m * P / state[self.timeScale]
        state[self.T_k] = float(tk)
        for i in range(Y.shape[1]):
            state[self.symbol(f"c0_{i + 1}")] = float(c0[i])
            state[self.symbol(f"c1_{i + 1}")] = float(c1[i])


def _named(connector, name):
    connector.name = name
    return connector
