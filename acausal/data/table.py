"""Reading CSV tables: comments, unit brackets in headers, located numeric cells."""
from __future__ import annotations

import csv
import io
import math
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Optional

import numpy as np

from .records import DataError

_HEADER = re.compile(r"^(?P<name>[^\[\]]*?)\s*(?:\[(?P<unit>[^\[\]]*)\])?$")


@dataclass
class Table:
    """A CSV file read as text: header names and units, rows with line numbers."""

    file: Path
    header_line: int
    names: list[str]
    units: list[Optional[str]]
    rows: list[tuple[int, list[str]]]

    def column(self, name: str, required: bool = True) -> Optional[int]:
        """Index of column ``name``; DataError if required and absent."""
        if name in self.names:
            return self.names.index(name)
        if required:
            raise DataError("missing column", self.file, self.header_line, name)
        return None

    def header(self, k: int) -> str:
        """The header text of column ``k`` as written (``'thrt [ms]'``)."""
        unit = self.units[k]
        return self.names[k] if unit is None else f"{self.names[k]} [{unit}]"

    def line_of(self, i: int) -> Optional[int]:
        """The file line of data row ``i`` (a table read by
        :func:`read_numeric_table` keeps no rows: the file is scanned)."""
        if self.rows:
            return self.rows[i][0]
        seen = -1
        with open(self.file, encoding="utf-8-sig", errors="replace") as f:
            for line, raw in enumerate(f, start=1):
                if line <= self.header_line or not raw.strip() or raw.lstrip().startswith("#"):
                    continue
                seen += 1
                if seen == i:
                    return line
        return None

    def numbers(self, k: int, required: bool) -> np.ndarray:
        """Column ``k`` as floats, NaN for empty cells (error if ``required``)."""
        out = np.empty(len(self.rows))
        for i, (line, cells) in enumerate(self.rows):
            out[i] = number(cells[k], required, (self.file, line, self.names[k]))
        return out


def number(cell: str, required: bool, where: tuple) -> float:
    """One cell as a finite float; NaN if empty and not ``required``."""
    if not cell:
        if required:
            raise DataError("missing value", *where)
        return math.nan
    try:
        value = float(cell)
    except ValueError:
        raise DataError(f"not a number: {cell!r}", *where) from None
    if not math.isfinite(value):
        raise DataError(f"{cell!r} is not a finite number", *where)
    return value


def _text(path: Path) -> str:
    """The file's text (UTF-8, a BOM allowed); a DataError naming the line
    and column of the first byte that is not UTF-8, or of a NUL byte."""
    if not path.is_file():   # (a folder or a pipe there was 'file not found')
        what = ("a folder, not a file" if path.is_dir() else
                "not a regular file (a CSV file is expected)" if path.exists() else
                "file not found")
        raise DataError(what, path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise DataError(f"cannot read: {exc.strerror or exc}", path) from None
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):
        raise DataError("the file is UTF-16 (save it as UTF-8)", path, 1)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        col = exc.start - (data.rfind(b"\n", 0, exc.start) + 1) + 1
        raise DataError(f"byte 0x{data[exc.start]:02x} (byte {col} of the line) is not UTF-8 "
                        "(save the file as UTF-8)", path, line) from None
    if "\0" in text:
        raise DataError("NUL byte (not a text file?)", path,
                        text.count("\n", 0, text.index("\0")) + 1)
    return text


def _rows(path: Path, text: str) -> list[tuple[int, list[str]]]:
    """(line, cells) of the non-blank, non-comment lines of ``text``."""
    rows = []
    for line, raw in enumerate(io.StringIO(text, newline=""), start=1):
        if raw.strip() and not raw.lstrip().startswith("#"):
            try:
                cells = next(csv.reader([raw], strict=True))
            except csv.Error as exc:
                raise DataError(f"cannot read the row as CSV: {exc}", path, line) from None
            rows.append((line, [c.strip() for c in cells]))
    return rows


def _header(path: Path, line: int, header: list[str]) -> tuple[list[str], list]:
    """Names and units of a header row."""
    if len(header) == 1 and ";" in header[0]:
        raise DataError("the header is separated by ';': acausal reads comma-separated "
                        "files (decimal point '.')", path, line)
    names, units = [], []
    for text in header:
        match = _HEADER.match(text)
        if match is None or not match["name"]:
            raise DataError(f"cannot read header {text!r}: expected 'name' or "
                            "'name [unit]'", path, line, text)
        if match["name"] in names:
            raise DataError("duplicate column", path, line, match["name"])
        names.append(match["name"])
        units.append(match["unit"])
    return names, units


def read_table(path: Path) -> Table:
    """Read a CSV file: header, unit brackets, rows of the header's width."""
    rows = _rows(path, _text(path))
    if not rows:
        raise DataError("no header row (empty file)", path)
    (line, header), rows = rows[0], rows[1:]
    names, units = _header(path, line, header)
    for row_line, cells in rows:
        if len(cells) != len(names):
            column = names[len(cells)] if len(cells) < len(names) else None
            raise DataError(f"row has {len(cells)} cell{'s' * (len(cells) != 1)}, header "
                            f"has {len(names)}",
                            path, row_line, column)
    return Table(path, line, names, units, rows)


FAST_MIN_BYTES = 2_000_000   # files larger than this are parsed by pandas (or numpy) in C
CHUNK_LINES = 200_000        # lines per chunk (a progress-bar step; a failed chunk is re-read exactly)
PROGRESS_MIN_BYTES = 20_000_000   # a file this large shows a progress bar on stderr


def read_numeric_table(path: Path, progress: bool = True) -> tuple[Table, np.ndarray]:
    """A table whose every cell is a required finite number (a trace), as
    (Table without its rows, values: rows x columns). Small files go
    through :func:`read_table`; larger ones are parsed in chunks by
    pandas' C parser (:func:`_read_pandas`), else numpy's (a 5 M-row,
    120 MB trace: 47-128 s and 2.3 GB through the exact reader, 10 s and
    0.36 GB with numpy, 2 s of parsing with pandas), with a progress bar on
    stderr above ``PROGRESS_MIN_BYTES``. Every error is located as by the
    exact reader: a file pandas finds irregular goes to numpy, and a chunk
    that numpy cannot read, or that holds a non-finite value, is read again
    line by line."""
    path = Path(path)
    if not path.is_file() or path.stat().st_size < FAST_MIN_BYTES:
        table = read_table(path)
        values = np.column_stack([table.numbers(k, True) for k in range(len(table.names))]) \
            if table.rows else np.zeros((0, len(table.names)))
        return table, values
    head = _text_head(path)
    rows = _rows(path, head)
    if not rows:
        raise DataError("no header row (empty file)", path)
    header_line, header = rows[0]
    names, units = _header(path, header_line, header)
    table = Table(path, header_line, names, units, [])
    size = path.stat().st_size
    bar = None
    if progress and size >= PROGRESS_MIN_BYTES:
        import sys

        from tqdm import tqdm
        bar = tqdm(total=size, unit="B", unit_scale=True, desc=f"reading {path.name}",
                   file=sys.stderr, leave=False, delay=0.5)
    try:
        values = _read_pandas(path, header_line, len(names), bar)
        if values is not None:
            return table, values
        blocks = []
        if bar is not None:
            bar.reset()
        with open(path, "rb") as f:
            line_no = 0
            while True:
                raw = f.readlines(CHUNK_LINES * 24)
                if not raw:
                    break
                first = line_no + 1
                line_no += len(raw)
                if bar is not None:
                    bar.update(sum(len(r) for r in raw))
                lines = _decode(path, raw, first)
                if first <= header_line:        # the header and what precedes it
                    lines = [ln if k + first > header_line else "#"
                             for k, ln in enumerate(lines)]
                blocks.append(_chunk(path, lines, first, names))
    finally:
        if bar is not None:
            bar.close()
    values = np.concatenate(blocks) if blocks else np.zeros((0, len(names)))
    return table, values


PANDAS_CHUNK = 1_000_000   # rows per pandas chunk (a progress-bar step)


def _read_pandas(path: Path, header_line: int, width: int, bar) -> Optional[np.ndarray]:
    """The body after the header line read by pandas' C parser (3.3x
    faster than numpy's loadtxt on a 5 M-row trace: 1.9 against 6.2 s), or
    None when pandas is missing or finds anything irregular (a cell that is
    not a finite number, a ragged row, bytes that are not UTF-8): the
    exact reader then says where."""
    try:
        import pandas as pd
    except ImportError:
        return None
    blocks = []
    try:
        with open(path, "rb") as f:
            reader = pd.read_csv(f, header=None, names=list(range(width)), skiprows=header_line,
                                 comment="#", dtype=float, engine="c", encoding="utf-8",
                                 skip_blank_lines=True, chunksize=PANDAS_CHUNK,
                                 skipinitialspace=True)
            for chunk in reader:
                blocks.append(chunk.to_numpy(dtype=float))
                if bar is not None:
                    bar.update(max(f.tell() - bar.n, 0))
    except (ValueError, UnicodeDecodeError, pd.errors.ParserError, OverflowError):
        return None
    values = np.concatenate(blocks) if blocks else np.zeros((0, width))
    if values.ndim != 2 or values.shape[1] != width or not np.all(np.isfinite(values)):
        return None
    return values


def _text_head(path: Path, limit: int = 1 << 16) -> str:
    """The first bytes of a file as text, up to a whole line (for its header)."""
    with open(path, "rb") as f:
        data = f.read(limit)
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):
        raise DataError("the file is UTF-16 (save it as UTF-8)", path, 1)
    cut = data.rfind(b"\n")
    data = data[:cut + 1] if cut >= 0 else data
    return _decode(path, [data], 1)[0]


def _decode(path: Path, raw: list, first: int) -> list:
    """Lines as text; a DataError at the first byte that is not UTF-8 or is NUL."""
    out = []
    for k, b in enumerate(raw):
        if k == 0 and first == 1 and b.startswith(b"\xef\xbb\xbf"):
            b = b[3:]
        try:
            text = b.decode("utf-8")
        except UnicodeDecodeError as exc:
            line = first + k + b.count(b"\n", 0, exc.start)
            col = exc.start - (b.rfind(b"\n", 0, exc.start) + 1) + 1
            raise DataError(f"byte 0x{b[exc.start]:02x} (byte {col} of the line) is "
                            "not UTF-8 (save the file as UTF-8)", path, line) from None
        if "\0" in text:
            raise DataError("NUL byte (not a text file?)", path,
                            first + k + text.count("\n", 0, text.index("\0")))
        out.append(text)
    return out


def _holds_data(raw: str) -> bool:
    """Whether a line of a trace holds values (not blank, not a comment)."""
    return bool(raw.strip()) and not raw.lstrip().startswith("#")


def _chunk(path: Path, lines: list, first: int, names: list) -> np.ndarray:
    """The numbers of ``lines`` (file lines from ``first``), read by numpy;
    on any doubt, line by line, so that the error names its line and column."""
    if not any(_holds_data(raw) for raw in lines):
        return np.empty((0, len(names)))      # (numpy warns on a chunk with no data)
    try:
        with np.errstate(all="ignore"):
            values = np.loadtxt(lines, delimiter=",", comments="#", ndmin=2, dtype=float)
        if values.size == 0:
            values = values.reshape(0, len(names))
        if values.shape[1] == len(names) and np.all(np.isfinite(values)):
            return values
    except ValueError:
        pass
    out = []
    for k, raw in enumerate(lines):
        line = first + k
        if not _holds_data(raw):
            continue
        try:
            cells = next(csv.reader([raw], strict=True))
        except csv.Error as exc:
            raise DataError(f"cannot read the row as CSV: {exc}", path, line) from None
        cells = [c.strip() for c in cells]
        if len(cells) != len(names):
            column = names[len(cells)] if len(cells) < len(names) else None
            raise DataError(f"row has {len(cells)} cell{'s' * (len(cells) != 1)}, header "
                            f"has {len(names)}", path, line, column)
        out.append([number(c, True, (path, line, n)) for c, n in zip(cells, names)])
    return np.array(out, dtype=float).reshape(len(out), len(names))
