"""write_dataset: a Dataset written in the folder format load_dataset reads."""
from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Mapping, Optional

import numpy as np

from .load import EXPERIMENTS, INSTRUMENT
from .records import DataError, Dataset
from .units import from_si


def _cells(values, unit: Optional[str]) -> list[str]:
    """Format SI values for a column in ``unit``; NaN (not measured) -> ''."""
    values = np.asarray(values, dtype=float)
    shown = from_si(values, unit)
    text = (lambda v: f"{v:.15g}") if unit is not None else (lambda v: repr(float(v)))
    return ["" if math.isnan(v) else text(v) for v in shown]


def _write_csv(path: Path, header: list[str], columns: list[list[str]]) -> None:
    """Write columns of cells under ``header``."""
    with path.open("w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow(header)
        writer.writerows(zip(*columns))


def _head(name: str, units: Mapping[str, str]) -> str:
    return f"{name} [{units[name]}]" if name in units else name


def write_dataset(folder, dataset: Dataset, units: Optional[Mapping[str, str]] = None
                  ) -> Path:
    """Write ``dataset`` to ``folder`` in the format :func:`load_dataset` reads.

    ``units`` maps a condition, measure, trace variable or ``"time"`` to the
    unit to write it in (``{"thrt": "ms", "hook.phi": "deg"}``); others are
    written in SI without a bracket.  Files of the same name are overwritten.
    Returns the folder.
    """
    folder, units = Path(folder), dict(units or {})
    folder.mkdir(parents=True, exist_ok=True)
    names = dataset.condition_names + dataset.measure_names
    for e in dataset.experiments:
        if set(e.conditions) != set(dataset.condition_names):
            raise DataError(f"experiment {e.name!r} lacks a condition value")
    columns = [[e.name for e in dataset.experiments]]
    for n in names:
        values = [{**e.measures, **e.conditions}.get(n, math.nan)
                  for e in dataset.experiments]
        columns.append(_cells(values, units.get(n)))
    header = ["name"] + [_head(n, units) for n in names]
    if any(e.use != "calibrate" for e in dataset.experiments):
        header.append("use")
        columns.append([e.use for e in dataset.experiments])
    _write_csv(folder / EXPERIMENTS, header, columns)
    if dataset.instrument:
        rows = list(dataset.instrument.values())
        unit = [units.get(i.signal) for i in rows]
        columns = [[i.signal for i in rows], [u or "" for u in unit]]
        for f in ("resolution", "noise_std"):
            columns.append([_cells([getattr(i, f)], u)[0] for i, u in zip(rows, unit)])
        _write_csv(folder / INSTRUMENT, ["signal", "unit", "resolution", "noise_std"],
                   columns)
    for e in dataset.experiments:
        if e.trace is not None:
            names = ["time", *e.trace.signals]
            data = [e.trace.time, *e.trace.signals.values()]
            _write_csv(folder / f"{e.name}.csv", [_head(n, units) for n in names],
                       [_cells(d, units.get(n)) for n, d in zip(names, data)])
    return folder
