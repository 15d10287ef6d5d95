"""Picklable task functions for the sweep tests (imported by worker processes)."""

import json
import os
import uuid
from pathlib import Path

from acausal.infra.executor import worker_cache


def square(point):
    """y = x**2 (+ k if present)."""
    return {"y": point["x"] ** 2 + point.get("k", 0.0)}


def logged(point, *, log_dir, fail_x=(), interrupt_x=None):
    """Leave one marker file per call in ``log_dir``, then behave like ``square``.

    Raises ValueError for x in ``fail_x`` and KeyboardInterrupt for x == ``interrupt_x``.
    """
    marker = Path(log_dir) / f"{os.getpid()}-{uuid.uuid4().hex}.call"
    marker.write_text(json.dumps(point))
    if point["x"] == interrupt_x:
        raise KeyboardInterrupt
    if point["x"] in fail_x:
        raise ValueError(f"bad point\nx={point['x']}")
    return {"y": point["x"] ** 2, "tag": f"x{point['x']:g}"}


def calls(log_dir):
    """Points passed to ``logged`` so far (one dict per call)."""
    return [json.loads(p.read_text()) for p in Path(log_dir).glob("*.call")]


def _make_token(log_dir):
    (Path(log_dir) / f"{os.getpid()}-{uuid.uuid4().hex}.factory").write_text("")
    return uuid.uuid4().hex


def cached_token(point, *, log_dir):
    """Return a per-process token built once by ``worker_cache``."""
    token = worker_cache(("token", str(log_dir)), lambda: _make_token(log_dir))
    return {"token": token, "pid": os.getpid()}
