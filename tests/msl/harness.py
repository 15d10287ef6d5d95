"""Compare a simulated MSL example with the Modelica Association's reference.

For the porters of issue #23: a test of an example is ::

    from tests.msl.harness import assert_matches, settings

    def test_oscillator():
        cm = compile_model(load_model("models/msl/translational/oscillator.py"))
        s = settings("Translational.Oscillator")       # StopTime, output interval, ...
        res = cm.simulate(t_end=s.stop_time, ...)
        assert_matches("Translational.Oscillator", res,
                       {"damper1.s_rel": "damper1.s_rel", "mass1.s": "mass1.s"})

* ``name``: ``"Translational.Friction"`` (or ``"Translational/Friction"``,
  or a bare example name where it is unique: ``"Oscillator"``).
* ``result``: an :class:`acausal.result.Result`, or anything with
  ``result["time"]`` and ``result[variable]`` giving arrays (a dict will do).
* ``names``: the compared Modelica signal -> what to read from the result:
  an acausal variable name (``"mass.s"``), or a function of the result
  returning the array (``lambda r: -r["x"]``). A compared signal that is not
  in ``names`` is read under its Modelica name.
* ``skip``: compared signals left out on purpose, each with its reason (they
  are listed in the message; a skip is never silent).

Every compared signal (experiments.csv's ``compared`` column, which is the
reference file's header) runs through :func:`acausal.data.tube.tube_compare`
with ``tol`` = 1e-3 of the reference's span in time and of its range in value
(issue #23). A signal missing from the result fails (csv-compare would only
warn). ``compare`` returns an :class:`ExampleComparison`; ``assert_matches``
raises ``AssertionError`` with one line per failing signal: the signal, the
time of its worst point, its value there and the tube's bounds.

Where the reference files are (the first that has the file):
``$ACAUSAL_MSL_REFERENCE``, this repository's ``data/msl_reference/``, and
``shared/data/msl_reference/`` in any folder above the repository (the
workplace's shared folder). A test that needs a missing file is skipped with
the reason (:func:`reference_or_skip`).
"""
from __future__ import annotations

import csv
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Mapping, Optional, Union

import numpy as np

from acausal.data.tube import TubeResult, tube_compare

ENV = "ACAUSAL_MSL_REFERENCE"
REPO = Path(__file__).resolve().parents[2]
LIBRARIES = ("Translational", "Rotational", "MultiBody")
Source = Union[str, Callable[[object], np.ndarray]]


def reference_dirs():
    """The folders searched for reference files, in order."""
    out = []
    if os.environ.get(ENV):
        out.append(Path(os.environ[ENV]))
    out.append(REPO / "data" / "msl_reference")
    for parent in REPO.parents:
        out.append(parent / "shared" / "data" / "msl_reference")
    return out


def _find(relative):
    for d in reference_dirs():
        p = d / relative
        if p.is_file():
            return p
    return None


@dataclass(frozen=True)
class Settings:
    """An example's experiment: the MSL annotation and the reference run's.

    ``stop_time``, ``start_time``: the annotation's (StartTime 0 when absent);
    ``interval``: the annotation's Interval (None when absent);
    ``tolerance``: the annotation's Tolerance (None: none of these examples
    gives one); ``ref_interval``, ``ref_tolerance``, ``ref_method``: what the
    reference run used (Dymola, DASSL, rtol 1e-6, half the annotated interval);
    ``compared``: the compared signals, in the reference file's order.
    """
    name: str
    model: str
    start_time: float
    stop_time: float
    interval: Optional[float]
    tolerance: Optional[float]
    ref_interval: float
    ref_tolerance: float
    ref_method: str
    compared: tuple
    reference: str
    msl_source: str


def _float(text):
    return float(text) if text.strip() else None


def experiments():
    """Every example of experiments.csv, by ``"Library.Example"``."""
    path = _find("experiments.csv")
    if path is None:
        raise FileNotFoundError("no msl_reference/experiments.csv in "
                                + ", ".join(map(str, reference_dirs())))
    out = {}
    with open(path, newline="") as fh:
        for row in csv.DictReader(fh):
            key = f"{row['library']}.{row['example']}"
            out[key] = Settings(
                name=key, model=row["model"],
                start_time=_float(row["StartTime"]) or 0.0,
                stop_time=float(row["StopTime"]), interval=_float(row["Interval"]),
                tolerance=_float(row["Tolerance"]),
                ref_interval=float(row["ref_Interval"]), ref_tolerance=float(row["ref_Tolerance"]),
                ref_method=row["ref_method"], compared=tuple(row["compared"].split()),
                reference=row["reference"], msl_source=row["msl_source"])
    return out


def canonical(name):
    """``"Translational.Friction"`` from that, ``"Translational/Friction"`` or a
    bare example name that only one library has."""
    table = experiments()
    key = name.replace("/", ".")
    if key in table:
        return key
    hits = [k for k in table if k.split(".", 1)[1] == key]
    if len(hits) == 1:
        return hits[0]
    if hits:
        raise KeyError(f"{name!r} is in several libraries: {', '.join(hits)}")
    raise KeyError(f"no MSL example {name!r}; known: {', '.join(table)}")


def settings(name):
    """The :class:`Settings` of an example."""
    return experiments()[canonical(name)]


def reference_path(name):
    """The reference CSV of an example, or None when no folder has it."""
    return _find(settings(name).reference)


def reference_or_skip(name):
    """The reference CSV's path; skips the calling test when it is missing."""
    path = reference_path(name)
    if path is None:
        import pytest
        pytest.skip(f"the MSL reference file {settings(name).reference} is in none of "
                    + ", ".join(map(str, reference_dirs())))
    return path


def load_reference(name):
    """``(t, {signal: values})`` of an example's reference file."""
    path = reference_path(name)
    if path is None:
        raise FileNotFoundError(f"the MSL reference file {settings(name).reference} is "
                                "in none of " + ", ".join(map(str, reference_dirs())))
    with open(path, newline="") as fh:
        header = next(csv.reader(fh))
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    if header[0] != "time" or data.shape[1] != len(header):
        raise ValueError(f"{path}: expected 'time' and {len(header) - 1} signals")
    return data[:, 0], {h: data[:, j] for j, h in enumerate(header[1:], start=1)}


@dataclass
class ExampleComparison:
    """The tube test of every compared signal of one example.

    ``results``: signal -> :class:`TubeResult`; ``missing``: signal -> why it
    could not be read from the result; ``skipped``: signal -> the caller's
    reason. ``passed`` when no signal failed or is missing.
    """
    name: str
    results: dict = field(default_factory=dict)
    missing: dict = field(default_factory=dict)
    skipped: dict = field(default_factory=dict)
    source: dict = field(default_factory=dict)
    status: str = ""

    @property
    def passed(self):
        return not self.missing and all(r.passed for r in self.results.values())

    @property
    def failed(self):
        return [s for s, r in self.results.items() if not r.passed]

    def __bool__(self):
        return self.passed

    def message(self):
        """Readable lines: a verdict, then one line per failing, missing or
        skipped signal (with where it was read from the result)."""
        n = len(self.results) + len(self.missing)
        bad = len(self.failed) + len(self.missing)
        head = (f"{self.name}: {n - bad} of {n} compared signals inside the tube"
                + (f" ({len(self.skipped)} skipped)" if self.skipped else ""))
        if self.status:
            head += f"; the simulation ended {self.status}"
        lines = [head]
        for s in self.failed:
            src = self.source.get(s, s)
            label = s if src == s else f"{s} (read as {src})"
            lines.append("  " + self.results[s].describe(label))
        for s, why in self.missing.items():
            lines.append(f"  {s}: missing from the result: {why}")
        for s, why in self.skipped.items():
            lines.append(f"  {s}: skipped: {why}")
        return "\n".join(lines)


def _read(result, source):
    if callable(source):
        return np.asarray(source(result), dtype=float)
    return np.asarray(result[source], dtype=float)


def compare(name, result, names: Optional[Mapping[str, Source]] = None, *, tol=1e-3,
            nominal=1e-3, skip: Optional[Mapping[str, str]] = None,
            require_coverage=True) -> ExampleComparison:
    """Run the tube on every compared signal of example ``name`` (see the
    module's docstring). ``names`` maps Modelica signal names to acausal names
    or functions of the result; ``skip`` maps signals to leave out to the
    reason. ``tol``, ``nominal``, ``require_coverage``: as
    :func:`acausal.data.tube.tube_compare`."""
    key = canonical(name)
    compared = settings(key).compared
    names = dict(names or {})
    skip = dict(skip or {})
    unknown = sorted(set(names) - set(compared)) + sorted(set(skip) - set(compared))
    if unknown:
        raise KeyError(f"{key} compares {', '.join(compared)}; not "
                       + ", ".join(repr(u) for u in unknown))
    t_ref, ref = load_reference(key)
    out = ExampleComparison(key, skipped=skip)
    status = getattr(result, "status", "ok")
    if status != "ok":
        out.status = f"{status}: {getattr(result, 'message', '')}".rstrip(": ")
    t = np.asarray(result["time"], dtype=float)
    for sig in compared:
        if sig in skip:
            continue
        source = names.get(sig, sig)
        out.source[sig] = source if isinstance(source, str) else getattr(
            source, "__name__", "a function")
        try:
            y = _read(result, source)
        except Exception as exc:          # an unknown name, or the function failed
            out.missing[sig] = f"{type(exc).__name__}: {exc}"
            continue
        if y.shape != t.shape:
            out.missing[sig] = f"{y.size} values for {t.size} time points"
            continue
        out.results[sig] = tube_compare(t_ref, ref[sig], t, y, tol, nominal=nominal,
                                        require_coverage=require_coverage)
    return out


def assert_matches(name, result, names=None, **kw) -> ExampleComparison:
    """:func:`compare`, raising ``AssertionError`` with its message when any
    compared signal fails or is missing; returns the comparison."""
    cmp = compare(name, result, names, **kw)
    if not cmp.passed:
        raise AssertionError(cmp.message())
    return cmp
