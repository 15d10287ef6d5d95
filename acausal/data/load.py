"""load_dataset: a dataset folder read into SI values, every problem located."""
from __future__ import annotations

import math
import re
from pathlib import Path
from typing import Iterable, Mapping, Optional, Union

import numpy as np

from .records import DataError, Dataset, Instrument, MeasuredExperiment, Trace
from .table import Table, number, read_numeric_table, read_table
from .units import converter

EXPERIMENTS = "experiments.csv"
INSTRUMENT = "instrument.csv"
_RESERVED = {"experiments", "instrument"}
_FIELDS = ("resolution", "noise_std")
USE_COLUMN = "use"
USES = ("calibrate", "validate")
Units = Union[Mapping[str, Optional[str]], Iterable[str]]


def _as_units(names: Optional[Units]) -> Optional[dict[str, Optional[str]]]:
    """Normalise a mapping name -> unit, or an iterable of names (unit None)."""
    if names is None or isinstance(names, Mapping):
        return None if names is None else dict(names)
    return {name: None for name in names}


def _role(name: str, parameters, measures, where: tuple) -> str:
    """'condition' or 'measure' for column ``name`` (see the module doc)."""
    if measures is not None and name in measures:
        return "measure"
    if parameters is not None and name in parameters:
        return "condition"
    if measures is None:
        return "measure"
    if parameters is None:
        return "condition"
    raise DataError(f"unknown parameter or measure '{name}'", *where)


def _experiment_names(table: Table) -> list[str]:
    """The ``name`` column, checked: non-empty, unique, usable as a file name."""
    k, first = table.column("name"), {}
    for line, cells in table.rows:
        name, where = cells[k], (table.file, line, "name")
        if not name and line == table.rows[0][0] and _looks_like_units(cells, k):
            raise DataError("a row of units under the header: write each unit in its "
                            "header, in brackets ('F [N]')", *where)
        if not name or name in _RESERVED or re.search(r"[/\\]", name):
            raise DataError(f"bad experiment name {name!r}", *where)
        if name in first:
            raise DataError(f"duplicate experiment {name!r} (first on line "
                            f"{first[name]})", *where)
        first[name] = line
    return list(first)


def _looks_like_units(cells, k) -> bool:
    """Whether a row (but its name cell) holds words, none a number: units
    written on their own line, as spreadsheets often do."""
    others = [c.strip() for i, c in enumerate(cells) if i != k and c.strip()]
    if not others:
        return False
    for c in others:
        try:
            float(c)
            return False
        except ValueError:
            pass
    return True


def _experiment_uses(table: Table) -> list[str]:
    """The optional ``use`` column: 'calibrate' (default, also an empty cell)
    or 'validate' for every row."""
    k = table.column(USE_COLUMN, False)
    if k is None:
        return ["calibrate"] * len(table.rows)
    if table.units[k] is not None:
        raise DataError("the use column takes no unit", table.file, table.header_line,
                        USE_COLUMN)
    uses = []
    for line, cells in table.rows:
        use = cells[k] or "calibrate"
        if use not in USES:
            raise DataError(f"use {cells[k]!r}: expected 'calibrate' or 'validate'",
                            table.file, line, USE_COLUMN)
        uses.append(use)
    return uses


def _check_conditions(table: Table, columns, conditions) -> None:
    """A DataError unless the columns set one of ``conditions`` (if any)."""
    given = {name for name, role, _, _ in columns if role == "condition"}
    if conditions and not given & set(conditions):
        raise DataError("sets none of the model's conditions (" + ", ".join(conditions)
                        + "): every experiment would run at the model's default; add a "
                        f"column such as '{conditions[0]} [unit]'", table.file,
                        table.header_line)


def _read_experiments(folder: Path, parameters, measures, conditions=()
                      ) -> list[MeasuredExperiment]:
    """Experiments of ``experiments.csv``, values in SI, no traces yet."""
    table = read_table(folder / EXPERIMENTS)
    if not table.rows:   # (calibrate said "every experiment is marked 'validate'")
        raise DataError("no experiments: a header and no rows under it", table.file,
                        table.header_line)
    names = _experiment_names(table)
    uses = _experiment_uses(table)
    columns = []  # (name, role, converter, index); headers checked first
    for k, name in enumerate(table.names):
        if name not in ("name", USE_COLUMN):
            where = (table.file, table.header_line, name)
            role = _role(name, parameters, measures, where)
            expected = (measures if role == "measure" else parameters) or {}
            convert = converter(table.units[k], expected.get(name),
                                table.header(k), name, where)
            columns.append((name, role, convert, k))
    _check_conditions(table, columns, list(conditions or ()))
    values = {name: convert(table.numbers(k, role == "condition"))
              for name, role, convert, k in columns}
    return [MeasuredExperiment(names[i], _row(columns, values, i, "condition"),
                               _row(columns, values, i, "measure"), None, line, uses[i])
            for i, (line, _) in enumerate(table.rows)]


def _row(columns, values, i: int, role: str) -> dict[str, float]:
    """Row ``i`` of the columns of ``role``, empty cells left out."""
    return {n: float(values[n][i]) for n, r, _, _ in columns
            if r == role and not math.isnan(values[n][i])}


def _read_trace(path: Path, variables) -> Trace:
    """A trace file: ``time`` strictly increasing, signals in SI (a large
    file through numpy's reader: :func:`.table.read_numeric_table`)."""
    table, values = read_numeric_table(path)
    table.column("time")
    if not len(values):
        raise DataError("no samples", path, table.header_line)
    converters = []
    for k, name in enumerate(table.names):
        where = (path, table.header_line, name)
        if name != "time" and variables is not None and name not in variables:
            raise DataError(f"unknown variable '{name}'", *where)
        expected = "s" if name == "time" else (variables or {}).get(name)
        converters.append(converter(table.units[k], expected, table.header(k),
                                    name, where))
    data = {n: c(values[:, k]) for k, (n, c) in enumerate(zip(table.names, converters))}
    time = data.pop("time")
    bad = np.flatnonzero(np.diff(time) <= 0)
    if bad.size:
        i = bad[0] + 1
        raise DataError(f"time does not increase ({time[i]:g} s after "
                        f"{time[i - 1]:g} s)", path, table.line_of(i), "time")
    return Trace(time, data, path)


def _attach_traces(folder: Path, experiments: list[MeasuredExperiment], variables) -> None:
    """Read ``<name>.csv`` traces into ``experiments``; error on orphans."""
    by_name = {e.name: e for e in experiments}
    for path in sorted(folder.glob("*.csv")):
        if path.name in (EXPERIMENTS, INSTRUMENT):
            continue
        if path.stem not in by_name:
            raise DataError(f"trace of unknown experiment '{path.stem}' (not in "
                            f"{EXPERIMENTS})", path)
        by_name[path.stem].trace = _read_trace(path, variables)


def _read_instrument(folder: Path, known: set, units: dict) -> dict[str, Instrument]:
    """``instrument.csv`` if present, values in SI; ``units`` name -> SI unit."""
    path = folder / INSTRUMENT
    if not path.exists():
        return {}
    table = read_table(path)
    for name in table.names:
        if name not in ("signal", "unit") + _FIELDS:
            raise DataError("unknown column (expected signal, resolution, "
                            "noise_std, unit)", path, table.header_line, name)
    k_signal, k_unit = table.column("signal"), table.column("unit", False)
    if k_unit is not None and any(table.units[table.names.index(f)] is not None
                                  for f in _FIELDS if f in table.names):
        raise DataError("give units in the 'unit' column or in the headers, not "
                        "both", path, table.header_line, "unit")
    instrument = {}
    for line, cells in table.rows:
        signal, where = cells[k_signal], (path, line, "signal")
        if signal not in known:
            raise DataError(f"unknown signal {signal!r}", *where)
        if signal in instrument:
            raise DataError(f"duplicate signal {signal!r}", *where)
        instrument[signal] = _instrument_row(table, line, cells, units.get(signal))
    return instrument


def _instrument_row(table: Table, line: int, cells: list[str],
                    expected: Optional[str]) -> Instrument:
    """One row of instrument.csv; empty or absent values are 0."""
    signal, k_unit = cells[table.column("signal")], table.column("unit", False)
    values = {}
    for f in _FIELDS:
        k = table.column(f, False)
        if k is None:
            continue
        if k_unit is None:
            unit, label, where = table.units[k], table.header(k), (table.file, line, f)
        else:
            unit = cells[k_unit] or None
            label, where = unit, (table.file, line, "unit")
        convert = converter(unit, expected, label, signal, where)
        value = number(cells[k], False, (table.file, line, f))
        if value < 0:
            raise DataError(f"negative {f}: {cells[k]}", table.file, line, f)
        values[f] = 0.0 if math.isnan(value) else float(convert(value))
    return Instrument(signal, **values)


def load_dataset(folder, *, parameters: Optional[Units] = None,
                 measures: Optional[Units] = None,
                 variables: Optional[Units] = None,
                 conditions: Iterable[str] = ()) -> Dataset:
    """Load a dataset folder (format: module docstring); values in SI.

    ``parameters``, ``measures`` and ``variables`` map names to the SI unit the
    model expects (``{"v_impact": "m/s"}``; a unit None, or a plain list of
    names, skips the unit check).  Given both ``parameters`` and ``measures``,
    any other column of experiments.csv is an error; given ``variables``, any
    other trace column is.  Given ``conditions`` (parameter names), the
    dataset must set at least one of them.  Raises :class:`DataError` on any
    problem.
    """
    folder = Path(folder)
    parameters, measures = _as_units(parameters), _as_units(measures)
    variables = _as_units(variables)
    experiments = _read_experiments(folder, parameters, measures, conditions)
    _attach_traces(folder, experiments, variables)
    units = {**(variables or {}), **(measures or {})}
    known = set(units).union(*(e.measures for e in experiments),
                             *(e.trace.signals for e in experiments if e.trace))
    instrument = _read_instrument(folder, known, units)
    return Dataset(folder, experiments, instrument)
