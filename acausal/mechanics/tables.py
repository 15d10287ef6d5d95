"""Tables of a law (a friction characteristic, a gear's losses) as
parameters, and their linear interpolation.

:class:`Table` is a structural parameter holding rows of numbers whose
first column (the abscissa, e.g. a speed) increases strictly; it is checked
when the component is built. :func:`interpolate` turns a table column into
a piecewise linear sympy expression of a variable, as MSL's
``Modelica.Math.Vectors.interpolate`` does: linear between rows, linear
extrapolation beyond the first and the last row with their end intervals,
the constant value of a one-row table.
"""
import math
import numbers

import sympy as sp

from acausal.errors import ParameterError
from acausal.lang import Parameter

__all__ = ["Table", "interpolate"]


class Table(Parameter):
    """A table parameter: rows of ``columns`` numbers, the first column
    strictly increasing (structural: changing it recompiles).

    ``units`` names the unit of each column (used in messages); the value
    may be a list of rows, a tuple of rows or a 2-D numpy array, and is
    kept as a tuple of tuples of floats.
    """

    def __init__(self, default, columns, units, desc=""):
        super().__init__(default, "/".join(units), desc, structural=True)
        self.columns = columns
        self.units = tuple(units)

    def check(self, value, where):
        label = f"{where}.{self.name}" if where else self.name
        rows = _rows(value, label, self.columns)
        for k, row in enumerate(rows):
            for j, x in enumerate(row):
                if not math.isfinite(x):
                    raise ParameterError(f"parameter {label}: row {k + 1}, column {j + 1} is "
                                         f"{x}, not a finite number", variable=label)
        for k in range(1, len(rows)):
            if not rows[k][0] > rows[k - 1][0]:
                raise ParameterError(
                    f"parameter {label}: the first column ({self.units[0]}) must increase "
                    f"strictly, but row {k + 1} has {rows[k][0]:g} after {rows[k - 1][0]:g}",
                    variable=label)
        return rows


def _rows(value, label, columns):
    """``value`` as a tuple of rows of ``columns`` floats, or a ParameterError."""
    try:
        rows = [list(r) for r in (value.tolist() if hasattr(value, "tolist") else value)]
    except TypeError:
        raise ParameterError(f"parameter {label} must be a table (rows of {columns} numbers), "
                             f"got {value!r}", variable=label) from None
    if not rows:
        raise ParameterError(f"parameter {label} is an empty table; it needs at least one "
                             f"row of {columns} numbers", variable=label)
    out = []
    for k, row in enumerate(rows):
        if len(row) != columns:
            raise ParameterError(f"parameter {label}: row {k + 1} has {len(row)} numbers, a "
                                 f"row must have {columns}", variable=label)
        if any(isinstance(x, bool) or not isinstance(x, (numbers.Real, sp.Number))
               for x in row):
            raise ParameterError(f"parameter {label}: row {k + 1} = {row} is not all "
                                 "numbers", variable=label)
        out.append(tuple(float(x) for x in row))
    return tuple(out)


def interpolate(table, column, x):
    """The table's ``column`` (0-based; column 0 is the abscissa) at ``x``,
    linearly interpolated, extrapolated linearly with the end intervals
    (MSL ``Vectors.interpolate``): a sympy expression of ``x``."""
    xs = [r[0] for r in table]
    ys = [r[column] for r in table]
    if len(xs) == 1:
        return sp.Float(ys[0])
    pieces = []
    for i in range(len(xs) - 1):
        slope = (ys[i + 1] - ys[i]) / (xs[i + 1] - xs[i])
        line = sp.Float(ys[i]) + sp.Float(slope) * (x - sp.Float(xs[i]))
        last = i == len(xs) - 2
        pieces.append((line, True if last else x < sp.Float(xs[i + 1])))
    return sp.Piecewise(*pieces)
