"""Checkpoints of long commands: finished work survives a kill.

A :class:`Checkpoint` is an append-only JSON-lines file of finished units of
work (one sweep point, one candidate fit). The file is named by a hash of
the command's inputs (:func:`input_key`: model file contents, data, options),
so a run with other inputs never picks up a stale result, and a run killed at
any moment and started again with the same command finds every unit that
had finished::

    store = Checkpoint("out.csv.partial", input_key(Path("model.py"), {"t_end": 1.0}))
    done = store.load()                       # key -> value of finished units
    for key in todo:
        store.append(key, compute(key))       # one line, flushed at once
    store.discard()                           # the command finished: forget it

Line format: ``<16 hex digits> <json>``, the digits the BLAKE2b checksum of
the JSON text. A line whose checksum does not match (a truncated last line
left by a kill mid-write, or any damaged line) is ignored and its unit is
recomputed; a partial last line is cut off before the next append, so the
records that follow stay intact. Each append is flushed to the operating
system, which keeps it through a kill of the process (not through a power
cut: no fsync).

Values are JSON with tags for what JSON lacks: numpy arrays, tuples,
non-finite floats (JSON's ``NaN``/``Infinity``) and dataclasses of the
``types`` the store is given (decoded only into those types, never by name
lookup of arbitrary classes).
"""
from __future__ import annotations

import dataclasses
import hashlib
import json
import os
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["Checkpoint", "input_key", "source_files"]

_DIGITS = 16


# ---------------------------------------------------------------------------
# The inputs' hash
# ---------------------------------------------------------------------------


def _feed(h, part: Any) -> None:
    """Add one input to the hash: a file or folder by content, else canonical JSON."""
    if isinstance(part, Path):
        if part.is_dir():
            for f in sorted(p for p in part.rglob("*") if p.is_file()):
                h.update(f.relative_to(part).as_posix().encode() + b"\0")
                h.update(f.read_bytes() + b"\0")
        elif part.is_file():
            h.update(part.name.encode() + b"\0" + part.read_bytes() + b"\0")
        else:
            h.update(f"missing:{part}".encode() + b"\0")
        return
    if isinstance(part, bytes):
        h.update(part + b"\0")
        return
    h.update(json.dumps(part, sort_keys=True, default=repr).encode() + b"\0")


def input_key(*parts: Any) -> str:
    """A short hex hash identifying a command's inputs.

    ``parts``: :class:`~pathlib.Path` objects (a file counts by name and
    content, a folder by every file in it), bytes, or JSON-able values
    (options; keys sorted). The acausal version is included, so results of
    another version are not reused.
    """
    from importlib import metadata

    h = hashlib.blake2b(digest_size=12)
    try:
        h.update(metadata.version("acausal").encode() + b"\0")
    except metadata.PackageNotFoundError:  # running from a source tree
        pass
    for part in parts:
        _feed(h, part)
    return h.hexdigest()


def source_files(model_path: str | os.PathLike) -> list[Path]:
    """The model file and the Python files beside it (a model file may import
    its neighbours, e.g. a breaker variant its base file), sorted."""
    path = Path(model_path).resolve()
    return [path] + sorted(p for p in path.parent.glob("*.py") if p != path)


# ---------------------------------------------------------------------------
# Values <-> JSON
# ---------------------------------------------------------------------------


def _encode(obj: Any, types: dict) -> Any:
    if dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        name = type(obj).__name__
        if types.get(name) is not type(obj):
            raise TypeError(f"checkpoint: dataclass {name} is not among the store's types")
        return {"__dataclass__": name, "fields": {
            f.name: _encode(getattr(obj, f.name), types) for f in dataclasses.fields(obj)}}
    if isinstance(obj, np.ndarray):
        return {"__ndarray__": _encode(obj.tolist(), types), "dtype": obj.dtype.str}
    if isinstance(obj, dict):
        if not all(isinstance(k, str) for k in obj):
            return {"__items__": [[_encode(k, types), _encode(v, types)] for k, v in obj.items()]}
        return {k: _encode(v, types) for k, v in obj.items()}
    if isinstance(obj, tuple):
        return {"__tuple__": [_encode(v, types) for v in obj]}
    if isinstance(obj, list):
        return [_encode(v, types) for v in obj]
    if isinstance(obj, (np.bool_, bool)):
        return bool(obj)
    if isinstance(obj, (np.integer, int)):
        return int(obj)
    if isinstance(obj, (np.floating, float)):
        return float(obj)
    if obj is None or isinstance(obj, str):
        return obj
    raise TypeError(f"checkpoint: cannot store a {type(obj).__name__}")


def _decode(obj: Any, types: dict) -> Any:
    if isinstance(obj, list):
        return [_decode(v, types) for v in obj]
    if not isinstance(obj, dict):
        return obj
    if "__dataclass__" in obj:
        cls = types[obj["__dataclass__"]]  # KeyError: a type this store does not know
        return cls(**{k: _decode(v, types) for k, v in obj["fields"].items()})
    if "__ndarray__" in obj:
        return np.array(_decode(obj["__ndarray__"], types), dtype=np.dtype(obj["dtype"]))
    if "__tuple__" in obj:
        return tuple(_decode(v, types) for v in obj["__tuple__"])
    if "__items__" in obj:
        return {_decode(k, types): _decode(v, types) for k, v in obj["__items__"]}
    return {k: _decode(v, types) for k, v in obj.items()}


def _digest(text: bytes) -> str:
    return hashlib.blake2b(text, digest_size=_DIGITS // 2).hexdigest()


# ---------------------------------------------------------------------------
# The store
# ---------------------------------------------------------------------------


class Checkpoint:
    """Append-only store of finished units of work under ``folder/<key>.jsonl``.

    ``key``: from :func:`input_key`. ``types``: the dataclasses values may
    contain. Attributes: ``path`` (the file), ``ignored`` (lines skipped by
    the last :meth:`load` because their checksum or JSON was bad).
    """

    def __init__(self, folder: str | os.PathLike, key: str, types: Iterable[type] = ()):
        self.folder = Path(folder)
        self.path = self.folder / f"{key}.jsonl"
        self.types = {t.__name__: t for t in types}
        self.ignored = 0

    def load(self) -> dict[str, Any]:
        """Unit key -> value of every intact record (the last one wins)."""
        self.ignored = 0
        if not self.path.exists():
            return {}
        out = {}
        for line in self.path.read_bytes().split(b"\n"):
            if not line:
                continue
            record = self._parse(line)
            if record is None:
                self.ignored += 1
            else:
                out[record[0]] = record[1]
        return out

    def _parse(self, line: bytes) -> tuple[str, Any] | None:
        digest, _, text = line.partition(b" ")
        if digest.decode("ascii", "replace") != _digest(text):
            return None
        try:
            data = json.loads(text)
            return str(data["key"]), _decode(data["value"], self.types)
        except (ValueError, KeyError, TypeError):
            return None

    def append(self, key: str, value: Any) -> None:
        """Add one record and flush it (a partial last line is cut off first)."""
        text = json.dumps({"key": key, "value": _encode(value, self.types)},
                          separators=(",", ":")).encode()
        line = _digest(text).encode() + b" " + text + b"\n"
        self.folder.mkdir(parents=True, exist_ok=True)
        self._cut_partial_line()
        with open(self.path, "ab") as f:
            f.write(line)
            f.flush()

    def _cut_partial_line(self) -> None:
        if not self.path.exists():
            return
        with open(self.path, "rb+") as f:
            size = f.seek(0, os.SEEK_END)
            if size == 0:
                return
            f.seek(size - 1)
            if f.read(1) == b"\n":
                return
            f.seek(0)
            data = f.read()
            f.truncate(data.rfind(b"\n") + 1)

    def discard(self) -> None:
        """Forget the store (the work is complete and saved elsewhere); the
        folder goes too when nothing else is in it."""
        self.path.unlink(missing_ok=True)
        try:
            self.folder.rmdir()
        except OSError:  # not empty (another command's store) or absent
            pass
