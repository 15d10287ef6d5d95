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
    if not path.is_file():
        raise DataError("file not found", path)
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
