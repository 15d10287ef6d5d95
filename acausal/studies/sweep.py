"""Parameter sweeps: parse ranges, build a grid, run it in parallel, resume, plot.

A sweep maps each point of a grid (a dict ``{param_name: float}``) through a
``task(point) -> {measure_name: value}`` on an executor from
:func:`acausal.executor.open_executor`. Every finished point is appended at
once to a checkpoint beside the CSV (``<csv>.partial/``, one checksummed line
per point, see :mod:`acausal.checkpoint`) and the CSV is replaced atomically
every few seconds, so a sweep killed at any moment loses no finished work and
leaves no corrupt row, and running it again with the same CSV computes only
the missing points::

    params = [parse_param("v_impact=3:5:21"), parse_param("contact.K=1e5,1e6")]
    with open_executor(workers=2) as ex:
        rows = run_sweep(task, grid(params), "out/sweep.csv",
                         executor=ex, measures=["peak_force", "rebound"])
    plot_sweep(rows, "v_impact", "peak_force", "out/peak_force.png")

CSV columns: the parameter names, the measure names, ``status`` (``ok`` or
``failed``), ``error`` (``ExceptionType: message`` on one line, empty when ok)
and ``wall_s`` (task run time measured where it ran). Parameters and measures
are written with ``repr`` of Python floats, which round-trips exactly; points
are matched between runs by these values.
"""

from __future__ import annotations

import csv
import dataclasses
import itertools
import json
import math
import os
import pickle
import re
import sys
import time
import warnings
from collections.abc import Callable, Iterable, Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from ..infra.checkpoint import Checkpoint, input_key
from ..errors import UsageError

__all__ = ["parse_param", "grid", "Grid", "run_sweep", "Journal", "plot_sweep", "SweepRows", "SweepAborted"]

RESERVED = ("status", "error", "wall_s")
_NAME = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*(\.[A-Za-z_][A-Za-z0-9_]*)*$")
_MAX_ERROR_CHARS = 500


class ResumeWarning(RuntimeWarning):
    """What resuming a sweep left out of a previous run's files (a cut last
    line, malformed rows, damaged checkpoint records): the command line
    prints each as its own line, not among the numerical libraries'."""

    said_alone = True


class SweepAborted(RuntimeError):
    """The executor failed (not the task); finished points are saved in the CSV."""


class SweepRows(list):
    """A list of row dicts that also records which columns are parameters/measures."""

    def __init__(self, rows: Iterable[dict], params: Sequence[str], measures: Sequence[str]):
        super().__init__(rows)
        self.params = tuple(params)
        self.measures = tuple(measures)


# ---------------------------------------------------------------------------
# Parameter specs and grids
# ---------------------------------------------------------------------------


def _number(text: str, spec: str, what: str) -> float:
    """Parse one finite float of ``spec`` or raise a ValueError naming it."""
    try:
        value = float(text)
    except ValueError:
        raise UsageError(f"bad parameter spec {spec!r}: {what} {text.strip()!r} is not a number") from None
    if not math.isfinite(value):
        raise UsageError(f"bad parameter spec {spec!r}: {what} must be finite, got {text.strip()!r}")
    return value


def _range_values(text: str, spec: str, max_count: int | None = None) -> np.ndarray:
    """Values of ``start:stop:count`` (inclusive linspace); a count above
    ``max_count`` is refused before any value is made."""
    parts = text.split(":")
    if len(parts) != 3:
        raise UsageError(f"bad parameter spec {spec!r}: a range is start:stop:count, e.g. 'x=3.0:5.0:21'")
    start = _number(parts[0], spec, "start")
    stop = _number(parts[1], spec, "stop")
    try:
        count = float(parts[2].strip().replace("_", ""))
    except ValueError:
        count = math.nan
    if not (math.isfinite(count) and count == int(count)):
        raise UsageError(f"bad parameter spec {spec!r}: count {parts[2].strip()!r} must be an integer >= 1")
    count = int(count)
    if max_count is not None and count > max_count:
        from ..errors import BudgetError
        raise BudgetError(f"bad parameter spec {spec!r}: {count:,} points, more than the "
                          f"sweep's limit of {max_count:,} points (--max-points)")
    if count < 1:
        raise UsageError(f"bad parameter spec {spec!r}: count must be an integer >= 1, got {count}")
    if count == 1 and start != stop:
        raise UsageError(f"bad parameter spec {spec!r}: count 1 is only allowed with start == stop")
    return np.linspace(start, stop, count)


def parse_param(spec: str, max_count: int | None = None) -> tuple[str, np.ndarray]:
    """Parse ``"name=values"`` into ``(name, float array)``.

    Values are ``start:stop:count`` (inclusive linspace, e.g. ``"v=3.0:5.0:21"``;
    a count above ``max_count`` is refused before the values are made),
    a comma list (``"k=1,2,5"``) or one number (``"k=3"``). Names are dotted
    identifiers such as ``contact.K``. Raises ValueError naming ``spec`` if it is
    malformed, has non-finite or repeated values, or a count that is not an
    integer >= 1.
    """
    if not isinstance(spec, str) or "=" not in spec:
        raise UsageError(f"bad parameter spec {spec!r}: expected name=values, e.g. 'contact.K=1e5,1e6'")
    name, text = (part.strip() for part in spec.split("=", 1))
    if not _NAME.match(name):
        raise UsageError(f"bad parameter spec {spec!r}: {name!r} is not a (dotted) parameter name")
    if not text:
        raise UsageError(f"bad parameter spec {spec!r}: no values after '='")
    if ":" in text:
        values = _range_values(text, spec, max_count)
    else:
        values = np.array([_number(item, spec, "value") for item in text.split(",")], dtype=float)
    if len(np.unique(values)) != len(values):
        raise UsageError(f"bad parameter spec {spec!r}: values repeat")
    return name, values


class Grid(Sequence):
    """The Cartesian product of parameter values, held as one array per
    parameter: point ``i`` (a dict ``{name: float}``) is made when asked
    for. A 1e6-point grid of two parameters is two arrays of 1,000 values,
    not a million dicts (2.9 s to make and prepare, 4.75 GB estimated). The last parameter
    varies fastest (nested loops in the order given); compares equal to the
    list of its points."""

    def __init__(self, params: Sequence[tuple[str, Iterable[float]]]):
        names = [name for name, _ in params]
        if len(set(names)) != len(names):
            raise UsageError(f"parameter names repeat: {names}")
        self.names = tuple(names)
        self.axes = [np.asarray(values, dtype=float).ravel() for _, values in params]
        self.shape = tuple(len(a) for a in self.axes)
        self._size = math.prod(self.shape)
        self._values = [[float(v) for v in a] for a in self.axes]
        self._reprs = [[repr(v) for v in a] for a in self._values]
        self._places = None      # per axis: repr -> position (made when first needed)

    def __len__(self) -> int:
        return self._size

    def _index(self, i: int) -> tuple[int, ...]:
        i = int(i)
        if i < 0:
            i += self._size
        if not 0 <= i < self._size:
            raise IndexError("grid index out of range")
        out = []
        for n in reversed(self.shape):
            i, j = divmod(i, n)
            out.append(j)
        return tuple(reversed(out))

    def __getitem__(self, i):
        if isinstance(i, slice):
            return [self[j] for j in range(*i.indices(self._size))]
        return dict(zip(self.names, (v[j] for v, j in zip(self._values, self._index(i)))))

    def __iter__(self):
        for combo in itertools.product(*self._values):
            yield dict(zip(self.names, combo))

    def __eq__(self, other):
        if isinstance(other, Grid):
            return self.names == other.names and all(
                np.array_equal(a, b) for a, b in zip(self.axes, other.axes))
        if isinstance(other, Sequence) and not isinstance(other, str):
            return len(other) == len(self) and all(a == b for a, b in zip(self, other))
        return NotImplemented

    __hash__ = None

    def key(self, i: int) -> tuple[str, ...]:
        """Point ``i``'s identity in the CSV and the checkpoint (:func:`_key`)."""
        return tuple(r[j] for r, j in zip(self._reprs, self._index(i)))

    def place(self, key: tuple[str, ...]) -> int | None:
        """The index of the point of ``key``, None if it is not in the grid."""
        if self._places is None:
            self._places = [{r: j for j, r in enumerate(reprs)} for reprs in self._reprs]
        if len(key) != len(self.shape):
            return None
        i = 0
        for places, n, text in zip(self._places, self.shape, key):
            j = places.get(text)
            if j is None:
                return None
            i = i * n + j
        return i


def grid(params: Sequence[tuple[str, Iterable[float]]]) -> Grid:
    """Cartesian product of ``[(name, values), ...]``: a :class:`Grid`, a
    sequence of point dicts made on demand.

    Order is deterministic: the last parameter varies fastest (like nested
    loops in the order given). Values become Python floats.
    """
    return Grid(params)


class _Points(Sequence):
    """The points of ``grid`` at ``indices`` (the ones still to run), made
    one by one as they are submitted."""

    def __init__(self, grid: Grid, indices: np.ndarray):
        self.grid, self.indices = grid, indices

    def __len__(self) -> int:
        return len(self.indices)

    def __getitem__(self, i):
        return self.grid[int(self.indices[i])]


# ---------------------------------------------------------------------------
# Running one point (executes on a worker)
# ---------------------------------------------------------------------------


def _one_line(exc: BaseException) -> str:
    """``"Type: message"`` on one line, capped in length."""
    message = " ".join(str(exc).split())
    text = f"{type(exc).__name__}: {message}" if message else type(exc).__name__
    return text if len(text) <= _MAX_ERROR_CHARS else text[: _MAX_ERROR_CHARS - 3] + "..."


def _scalar(name: str, value: Any) -> float | str:
    """A measure value as float (numbers, None -> nan) or str."""
    if value is None:
        return math.nan
    if isinstance(value, str):
        return value
    arr = np.asarray(value)
    if arr.shape == () and arr.dtype.kind in "biuf":
        return float(arr)
    raise TypeError(f"measure {name!r} must be a real scalar or a string, got {type(value).__name__}")


def _measure_values(result: Any, measures: Sequence[str]) -> dict[str, float | str]:
    """Pick and convert the measures from a task result."""
    if not isinstance(result, Mapping):
        raise TypeError(f"task must return a dict of measures, got {type(result).__name__}")
    missing = [m for m in measures if m not in result]
    if missing:
        raise UsageError(f"task result lacks measures {missing}")
    return {m: _scalar(m, result[m]) for m in measures}


def _run_point(task: Callable[[dict], Mapping], point: dict, measures: Sequence[str]) -> dict:
    """Run ``task(point)``; task Exceptions become a ``failed`` record.

    Runs on the worker, so only plain data (floats, strings) travels back.
    BaseExceptions such as KeyboardInterrupt propagate and stop the sweep.
    A dict under ``"__missing__"`` in the task's result (measure -> why it has
    no value) goes into the error column of the ``ok`` row, for the
    measures asked for.
    """
    start = time.perf_counter()
    try:
        result = task(dict(point))
        values = _measure_values(result, measures)
    except Exception as exc:
        return {"status": "failed", "error": _one_line(exc), "values": {}, "wall_s": time.perf_counter() - start}
    missing = result.get("__missing__")
    missing = missing if isinstance(missing, Mapping) else {}
    note = "; ".join(f"{m} missing: {' '.join(str(missing[m]).split())}" for m in measures
                     if m in missing)[:_MAX_ERROR_CHARS]
    return {"status": "ok", "error": note, "values": values, "wall_s": time.perf_counter() - start}


# ---------------------------------------------------------------------------
# CSV cells and rows
# ---------------------------------------------------------------------------


def _key(values: Mapping, params: Sequence[str]) -> tuple[str, ...]:
    """Identity of a point: repr-exact floats of its parameters."""
    return tuple(repr(float(values[p])) for p in params)


def _keys(points: Sequence[Mapping], params: Sequence[str]) -> list[tuple[str, ...]]:
    """``_key`` of every point, each distinct value's repr made once (a grid
    of 1e6 points has a few thousand distinct values: 6e6 reprs took most of
    the 14 s before a 1e6-point sweep's first point)."""
    memo: dict = {}

    def text(v):
        v = float(v)
        if v == 0.0:          # 0.0 and -0.0 are one dict key, two reprs
            return repr(v)
        hit = memo.get(v)
        if hit is None:
            hit = memo[v] = repr(v)
        return hit
    return [tuple(text(p[name]) for name in params) for p in points]


def _cell(value: float | str) -> str:
    return repr(float(value)) if isinstance(value, float) else str(value)


def _format_cells(point: Mapping, record: dict, params: Sequence[str], measures: Sequence[str]) -> dict[str, str]:
    cells = {p: repr(float(point[p])) for p in params}
    cells.update({m: _cell(record["values"][m]) if m in record["values"] else "" for m in measures})
    cells.update(status=record["status"], error=record["error"], wall_s=f"{record['wall_s']:.6f}")
    return cells


def _parse_measure(text: str) -> float | str:
    if text == "":
        return math.nan
    try:
        return float(text)
    except ValueError:
        return text


def _parse_row(cells: Mapping[str, str], params: Sequence[str], measures: Sequence[str]) -> dict:
    """Row dict (params, measures, status, error, wall_s) from CSV cells."""
    row: dict[str, Any] = {p: float(cells[p]) for p in params}
    row.update({m: _parse_measure(cells[m]) for m in measures})
    wall = cells["wall_s"]
    row.update(status=cells["status"], error=cells["error"], wall_s=float(wall) if wall else math.nan)
    return row


# ---------------------------------------------------------------------------
# CSV file: load for resume, append as points finish
# ---------------------------------------------------------------------------


def _repair_tail(path: Path) -> None:
    """Cut a partial last line (left by a crash mid-write) so appends stay aligned."""
    with open(path, "rb+") as f:
        data = f.read()
        if data and not data.endswith(b"\n"):
            f.truncate(data.rfind(b"\n") + 1)
            warnings.warn(f"{path}: dropped an incomplete last line (a run killed while "
                          "writing it); that point will be recomputed", ResumeWarning, stacklevel=3)


def column_label(name: str, units: Mapping[str, str] | None) -> str:
    """The CSV header of column ``name``: ``"name [unit]"`` when its unit is
    known (the data folders' convention, :mod:`acausal.data`), else ``name``."""
    unit = (units or {}).get(name)
    return f"{name} [{unit}]" if unit else name


def _column_name(label: str) -> str:
    """``"thrt [s]"`` -> ``"thrt"``: the column's name without its unit."""
    m = re.fullmatch(r"(.*\S)\s*\[[^\[\]]*\]", label.strip())
    return m.group(1) if m else label.strip()


def read_rows(path: str | Path) -> list[dict[str, str]]:
    """A sweep CSV's rows as dicts keyed by column name (units stripped from
    the ``"name [unit]"`` header), cells as written."""
    with open(path, newline="", encoding="utf-8") as f:
        reader = csv.reader(f)
        names = [_column_name(h) for h in next(reader, [])]
        return [dict(zip(names, line)) for line in reader]


def _check_header(path: Path, header: list[str], columns: Sequence[str]) -> None:
    if len(set(header)) != len(header) or set(header) != set(columns):
        raise UsageError(
            f"{path} holds a sweep with columns {header}, but this sweep writes {list(columns)}; "
            "use another out_csv (or delete it) instead of mixing sweeps"
        )


def _load_cells(path: Path, params: Sequence[str], measures: Sequence[str]) -> tuple[list[str] | None, dict]:
    """A previous run's CSV cells keyed by point; ``(None, {})`` if there is none."""
    if not path.exists() or path.stat().st_size == 0:
        return None, {}
    _repair_tail(path)
    try:
        return _read_cells(path, params, measures)
    except (UnicodeDecodeError, csv.Error) as exc:   # not a CSV this sweep wrote
        raise UsageError(f"{path} is not a sweep's CSV ({_one_line(exc)}); use another "
                         "out_csv (or delete it)") from None


def _read_cells(path: Path, params: Sequence[str], measures: Sequence[str]):
    with open(path, newline="", encoding="utf-8") as f:
        reader = csv.reader(f)
        header = next(reader, None)
        if header is None:
            return None, {}
        header = [_column_name(h) for h in header]
        _check_header(path, header, [*params, *measures, *RESERVED])
        cells_by_key, bad = {}, 0
        for line in reader:
            cells = dict(zip(header, line))
            try:
                if len(line) != len(header) or cells["status"] not in ("ok", "failed"):
                    raise ValueError  # internal: control flow, caught just below
                _parse_row(cells, params, measures)
                cells_by_key[_key(cells, params)] = cells
            except ValueError:
                bad += 1
    if bad:
        warnings.warn(f"{path}: ignored {bad} malformed line(s); those points will be recomputed",
                      ResumeWarning, stacklevel=3)
    return header, cells_by_key


def _write_csv(path: Path, header: Sequence[str], rows: Iterable[Mapping[str, str]],
               units: Mapping[str, str] | None = None) -> None:
    """Write the whole CSV to a temporary file, then rename it over ``path``:
    a reader (or a kill) never sees a half-written file. The header labels
    carry ``units`` (:func:`column_label`)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    with open(tmp, "w", newline="", encoding="utf-8") as f:
        writer = csv.writer(f, lineterminator="\n")
        writer.writerow([column_label(c, units) for c in header])
        writer.writerows([row.get(c, "") for c in header] for row in rows)
    os.replace(tmp, path)


class _Journal:
    """The sweep's finished points: a :class:`~acausal.checkpoint.Checkpoint`
    (each point one checksummed line, written as it finishes) plus the CSV,
    rewritten atomically at most every ``CSV_EVERY_S`` seconds and at the end."""

    CSV_EVERY_S = 2.0

    def __init__(self, out_csv: Path, store: Checkpoint | None, header: Sequence[str], cells: dict,
                 units: Mapping[str, str] | None = None):
        self.out_csv, self.store, self.header, self.cells = out_csv, store, list(header), cells
        self.units = dict(units or {})
        self.written = time.monotonic()
        self.every = self.CSV_EVERY_S
        # point key -> its place in the grid, None if not in it (rows are written so)
        self.place: Callable[[tuple], int | None] = lambda key: None

    def add(self, key: tuple, cells: dict[str, str]) -> None:
        if self.store is not None:
            self.store.append(json.dumps(key), cells)
        self.cells[key] = cells
        if time.monotonic() - self.written > self.every:
            self.write_csv()

    def write_csv(self) -> None:
        """The CSV, rows in grid order (points of other grids kept after
        them). A write that takes long (a million rows) is made rarer: at
        most a tenth of the time goes into rewriting the CSV (the checkpoint
        keeps every point meanwhile)."""
        start = time.monotonic()
        last = math.inf

        def place(k):
            i = self.place(k)
            return last if i is None else i
        keys = sorted(self.cells, key=place)
        _write_csv(self.out_csv, self.header, (self.cells[k] for k in keys), self.units)
        self.written = time.monotonic()
        self.every = max(self.CSV_EVERY_S, 10 * (self.written - start))


def _open_journal(out_csv: Path, params, measures, checkpoint, inputs, units=None) -> _Journal:
    """The CSV's rows merged with the checkpoint's (a run killed before its
    last CSV write left points only there)."""
    header, cells = _load_cells(out_csv, params, measures)
    store = None
    if checkpoint is not False:
        folder = Path(checkpoint) if checkpoint else out_csv.with_name(out_csv.name + ".partial")
        store = Checkpoint(folder, input_key(list(params), sorted(measures), *inputs))
        for key, saved in store.load().items():
            try:
                cells.setdefault(tuple(json.loads(key)), _parse_cells(saved, params, measures))
            except (ValueError, KeyError, TypeError):
                store.ignored += 1
        if store.ignored:
            warnings.warn(f"{store.path}: ignored {store.ignored} damaged record(s); those points "
                          "will be recomputed", ResumeWarning, stacklevel=3)
    return _Journal(out_csv, store, header or [*params, *measures, *RESERVED], cells, units)


def _parse_cells(saved: Any, params: Sequence[str], measures: Sequence[str]) -> dict[str, str]:
    """Checkpointed cells, checked like a CSV row."""
    if not isinstance(saved, dict) or saved.get("status") not in ("ok", "failed"):
        raise ValueError("not a sweep row")  # internal: control flow, the caller skips the record
    cells = {c: str(saved[c]) for c in [*params, *measures, *RESERVED]}
    _parse_row(cells, params, measures)
    return cells


# ---------------------------------------------------------------------------
# run_sweep
# ---------------------------------------------------------------------------


def _param_names(points: Sequence[Mapping]) -> tuple[str, ...]:
    if not points:
        raise UsageError("run_sweep needs at least one point")
    names = tuple(points[0])
    for point in points:
        if tuple(point) != names:
            raise UsageError(f"all points must have the same parameters {list(names)}, got {list(point)}")
    clash = [n for n in names if n in RESERVED]
    if clash:
        raise UsageError(f"parameter names {clash} are reserved CSV columns")
    return names


def _check_measures(measures: Sequence[str], params: Sequence[str]) -> tuple[str, ...]:
    measures = (measures,) if isinstance(measures, str) else tuple(measures)
    if not measures or not all(isinstance(m, str) and m for m in measures):
        raise UsageError(f"measures must be a non-empty list of names, got {measures!r}")
    if len(set(measures)) != len(measures):
        raise UsageError(f"measure names repeat: {list(measures)}")
    clash = [m for m in measures if m in RESERVED or m in params]
    if clash:
        raise UsageError(f"measure names {clash} clash with parameters or reserved columns")
    return measures


def _check_picklable(task: Callable) -> None:
    try:
        pickle.dumps(task)
    except Exception as exc:
        raise TypeError(
            "the sweep task must be picklable for a process pool: use a module-level "
            f"function or a functools.partial of one ({_one_line(exc)})"
        ) from exc


def _result(future: Any) -> dict:
    """The record of a finished future; executor failures abort the sweep."""
    try:
        return future.result()
    except Exception as exc:  # task errors are caught on the worker, so this is the executor's
        raise SweepAborted(
            f"sweep stopped by an executor failure ({_one_line(exc)}); finished points are "
            "saved, rerun with the same out_csv to resume"
        ) from exc


def _progress_bar(total: int, initial: int, enabled: bool):
    from tqdm import tqdm

    return tqdm(total=total, initial=initial, disable=not enabled, file=sys.stderr, desc="sweep", unit="pt")


def _window(executor) -> int:
    """Points in flight at once: enough to keep every worker busy."""
    return max(16, 4 * (getattr(executor, "workers", None) or 16))


def _wait_any(executor, futures: list) -> list:
    """The finished ones among ``futures`` (at least one): the executor's
    ``wait_any``, else the first its ``as_completed`` yields."""
    if hasattr(executor, "wait_any"):
        return executor.wait_any(futures)
    return [next(iter(executor.as_completed(futures)))]


def _collect_windowed(executor, todo: list, submit: Callable, on_row: Callable[[dict, dict], None],
                      bar, window: int) -> None:
    """Submit ``todo`` in order, at most ``window`` unfinished at a time;
    record each as it finishes; cancel the rest if anything goes wrong."""
    from ..infra.executor import check_interrupted
    inflight: dict = {}
    nxt = 0
    failed = 0
    try:
        while nxt < len(todo) or inflight:
            check_interrupted()
            while nxt < len(todo) and len(inflight) < window:
                inflight[submit(todo[nxt])] = todo[nxt]
                nxt += 1
            for future in _wait_any(executor, list(inflight)):
                point = inflight.pop(future)
                record = _result(future)
                on_row(point, record)
                failed += record["status"] == "failed"
                if failed:
                    bar.set_postfix(failed=failed, refresh=False)
                bar.update(1)
    except BaseException:
        _keep_finished(inflight, on_row)
        executor.cancel(list(inflight))
        raise
    finally:
        bar.close()


def _keep_finished(inflight: dict, on_row: Callable[[dict, dict], None]) -> None:
    """On an interruption: record the points whose results have arrived but
    were not yet taken (they would be computed again on resume)."""
    for future, point in list(inflight.items()):
        try:
            if future.done() and not future.cancelled() and future.exception() is None:
                on_row(point, future.result())
                inflight.pop(future)
        except BaseException:  # noqa: BLE001 - best effort while unwinding an interruption
            return


@dataclasses.dataclass(frozen=True)
class Journal:
    """Where a sweep keeps its finished points and how it resumes (see
    :func:`run_sweep`): ``checkpoint`` folder (default ``<out_csv>.partial``;
    False: none), the ``inputs`` the results depend on, the CSV header's
    ``units`` (column -> unit), ``on_resume(done, total)``, and ``window``,
    the most points submitted and not yet finished."""

    checkpoint: Any = None
    inputs: Sequence[Any] = ()
    units: Mapping[str, str] | None = None
    on_resume: Callable[[int, int], None] | None = None
    window: int | None = None


def run_sweep(
    task: Callable[[dict], Mapping],
    points: Sequence[Mapping[str, float]],
    out_csv: str | Path,
    *,
    executor,
    measures: Sequence[str],
    progress: bool = True,
    journal: Journal = Journal(),
) -> SweepRows:
    """Run ``task(point)`` for every point not already in ``out_csv``.

    Args:
        task: ``task(point) -> {measure: value}``; for a process pool it must be
            picklable (a module-level function or ``functools.partial`` of one).
            Expensive set-up belongs in :func:`acausal.executor.worker_cache`.
        points: dicts ``{param: float}`` with the same keys, e.g. from :func:`grid`.
        out_csv: results file. Points already in it (or in the checkpoint) (status ok *or* failed) are not rerun; to
            retry failures, delete their lines. A file from a sweep with other
            parameter/measure columns is refused (ValueError).
        executor: an :class:`acausal.executor.Executor` (from ``open_executor``).
        measures: names to take from each task result (numbers or strings).
        progress: show a tqdm progress bar on stderr.
        checkpoint: folder of the checkpoint (default ``<out_csv>.partial``;
            ``False``: none). Each finished point is appended there at once as
            a checksummed line (:mod:`acausal.checkpoint`), and ``out_csv`` is
            rewritten atomically (temporary file, then rename) every few
            seconds and at the end, so a sweep killed at any moment (even by
            SIGKILL) loses no finished point and leaves no corrupt row. When
            the sweep completes, the checkpoint is deleted.
        inputs: what else the points' results depend on (e.g. the model
            file as a :class:`~pathlib.Path`, options), hashed into the
            checkpoint's name: a checkpoint of other inputs is not reused.
        units: column name -> unit, written into the header as
            ``"name [unit]"``. A resumed file's
            header is read with or without units.
        on_resume: called as ``on_resume(done, total)`` before the run when
            points were already done (the command line says "resumed: ...").
        window: most points submitted and not yet finished (default
            :func:`_window`): the executor holds a bounded number of tasks
            whatever the grid's size (all of a 1e9-point grid's were
            submitted at once).

    Returns:
        :class:`SweepRows` (a list) with one row per point, in ``points`` order:
        ``{param: float, measure: float|str (nan if failed), status, error, wall_s}``.
        Rows in ``out_csv`` for points not in ``points`` are kept in the file but
        not returned.

    A task exception marks only its point failed. KeyboardInterrupt (also one
    raised in a process-pool worker) stops the sweep and propagates; a broken
    executor raises :class:`SweepAborted`. Either way finished points are saved.
    """
    checkpoint, inputs, units = journal.checkpoint, journal.inputs, journal.units
    on_resume, window = journal.on_resume, journal.window
    if not isinstance(points, Grid):
        points = [dict(p) for p in points]
    params = points.names if isinstance(points, Grid) else _param_names(points)
    measures = _check_measures(measures, params)
    out_csv = Path(out_csv)
    journal = _open_journal(out_csv, params, measures, checkpoint, inputs, units)
    if isinstance(points, Grid):
        if not len(points):
            raise UsageError("run_sweep needs at least one point")
        clash = [n for n in params if n in RESERVED]
        if clash:
            raise UsageError(f"parameter names {clash} are reserved CSV columns")
        journal.place = points.place
        done = np.zeros(len(points), dtype=bool)
        for key in journal.cells:
            i = points.place(key)
            if i is not None:
                done[i] = True
        todo = _Points(points, np.flatnonzero(~done))
        n_unique, key_of = len(points), points.key
    else:
        keys = _keys(points, params)
        order: dict = {}
        for k in keys:
            order.setdefault(k, len(order))
        journal.place = order.get
        todo = list({k: p for k, p in zip(keys, points) if k not in journal.cells}.values())
        n_unique, key_of = len(order), keys.__getitem__
    if len(todo) and executor.needs_pickle:
        _check_picklable(task)

    def on_row(point: dict, record: dict) -> None:
        journal.add(_key(point, params), _format_cells(point, record, params, measures))

    if n_unique > len(todo) and on_resume is not None:
        on_resume(n_unique - len(todo), n_unique)
    bar = _progress_bar(n_unique, n_unique - len(todo), progress)
    try:
        _collect_windowed(executor, todo, lambda p: executor.submit(_run_point, task, p, measures),
                          on_row, bar, window or _window(executor))
    finally:
        journal.write_csv()
    if journal.store is not None:
        journal.store.discard()  # everything is in the CSV now
    cells = journal.cells
    return SweepRows((_parse_row(cells[key_of(i)], params, measures) for i in range(len(points))),
                     params, measures)


# ---------------------------------------------------------------------------
# Plot
# ---------------------------------------------------------------------------


def _series_param(rows: Sequence[Mapping], x: str, by: str | None) -> str | None:
    """The parameter that splits rows into lines (explicit, or inferred from SweepRows)."""
    if by is not None or not isinstance(rows, SweepRows):
        return by
    others = [p for p in rows.params if p != x and len({r[p] for r in rows}) > 1]
    if len(others) > 1:
        raise UsageError(f"rows vary in {others} besides {x!r}; pass by= and rows with the others fixed")
    return others[0] if others else None


def _series(rows: Sequence[Mapping], x: str, by: str | None) -> list[tuple[Any, list[Mapping]]]:
    """Rows grouped by ``by`` value (one group if None), each sorted by ``x``."""
    groups: dict[Any, list[Mapping]] = {}
    for row in rows:
        groups.setdefault(row[by] if by else None, []).append(row)
    series = []
    for value, group in groups.items():
        xs = [r[x] for r in group]
        if len(set(xs)) != len(xs):
            raise UsageError(f"several rows share one {x!r} value in a line; pass by= (or fix other parameters)")
        series.append((value, sorted(group, key=lambda r: r[x])))
    return series


def _plot_series(ax, group: list[Mapping], x: str, measure: str, label: str | None,
                 factor: float = 1.0) -> bool:
    """One line (failed points are gaps, marked by an x at the bottom); True if any failed."""
    xs = [r[x] for r in group]
    ys = [factor * float(r[measure]) if r["status"] == "ok" else math.nan for r in group]
    (line,) = ax.plot(xs, ys, "o-", ms=3, label=label)
    failed = [r[x] for r in group if r["status"] != "ok"]
    if failed:
        ax.plot(failed, [0.03] * len(failed), "x", color=line.get_color(), ms=8, mew=2,
                transform=ax.get_xaxis_transform(), clip_on=False)
    return bool(failed)


def plot_sweep(rows: Sequence[Mapping], x: str, measure: str, path: str | Path, *, by: str | None = None,
               x_unit: str | None = None, y_unit: str | None = None, y_factor: float = 1.0) -> Path:
    """Save a line plot of ``measure`` against parameter ``x`` to ``path``.

    One line per value of ``by``; with rows from :func:`run_sweep` of a 2-D grid,
    ``by`` defaults to the other parameter. Failed points leave a gap in their
    line and are marked with an ``x`` at the bottom of the axes. The axes are
    labelled ``name [unit]`` with ``x_unit`` and ``y_unit`` (the measure's
    values multiplied by ``y_factor``, e.g. 1e3 for a time shown in ms). Uses a bare
    matplotlib ``Figure`` (Agg), so no pyplot state or backend is touched.
    """
    from matplotlib.figure import Figure
    from matplotlib.lines import Line2D

    by = _series_param(rows, x, by)
    fig = Figure(figsize=(6.4, 4.2), layout="constrained")
    ax = fig.add_subplot()
    any_failed = False
    for value, group in _series(rows, x, by):
        label = f"{by} = {value:g}" if by else None
        any_failed |= _plot_series(ax, group, x, measure, label, y_factor)
    handles, _ = ax.get_legend_handles_labels()
    if any_failed:
        handles.append(Line2D([], [], ls="", marker="x", color="0.3", mew=2, label="failed"))
    if handles:
        ax.legend(handles=handles, fontsize="small")
    ax.set_xlabel(column_label(x, {x: x_unit} if x_unit else None))
    ax.set_ylabel(column_label(measure, {measure: y_unit} if y_unit else None))
    ax.grid(alpha=0.3)
    fig.savefig(path, dpi=120)
    return Path(path)
