"""Tolerance (Monte-Carlo) studies: how much a model's measures spread when
its parameters spread as drawn on the drawings.

A spec CSV gives each toleranced parameter a distribution, its two numbers
and their unit, one row per parameter (``#`` starts a comment; a first row
starting with ``name`` is a header)::

    # name,        distribution, a,       b,    unit
    contact.K,     normal,       6.17e8,  10%,  N/m^1.5
    hook.bh,       uniform,      0.20,    0.24, N*m*s/rad
    armature.ma,   normal,       nominal, 0.7%, kg

* ``normal, mean, std``: a Gaussian of that mean and standard deviation;
* ``uniform, low, high``: equally likely between ``low`` and ``high``;
* ``b`` written ``p%`` is relative to ``a``: a normal's standard deviation
  is p % of its mean, a uniform is ``a`` +- p % (a drawing's symmetric
  tolerance band);
* ``a`` written ``nominal`` is the model's own value of the parameter (a
  percentage then reads as "p % of the nominal value").

The unit is that of the numbers (``g`` for a mass in grams, ``1`` or ``-``
for a dimensionless one); it must have the dimension of the parameter's
declared unit (pint, :mod:`acausal.data.units`) and values are converted to
SI. Every bad row is reported, each on one line ``file:line: what``.

A study draws N sets by Latin hypercube or scrambled Sobol' sampling
(:mod:`scipy.stats.qmc`) in the unit cube and maps them through each
distribution's inverse CDF. With ``sampling="sobol"`` the design is
Saltelli's (two independent N x d matrices A and B from one 2d-dimensional
Sobol' sequence, and the d matrices AB_i = A with column i from B), so
first-order and total Sobol' indices are estimated (Saltelli 2010 and
Jansen estimators); that takes N (d + 2) simulations, N a power of 2 (the
balance properties of the Sobol' sequence hold for powers of 2 only).
With ``sampling="lhs"`` the N sets are simulated and each parameter's share
of the variance is estimated by its correlation ratio (the variance of the
measure's conditional mean over equal-count bins of the parameter, bias
corrected) and by standardised regression coefficients, with the R^2 of
the linear fit saying how far those can be trusted.

The sets run on the compiled backend in chunks: each chunk is one task on
an :mod:`acausal.infra.executor` (local processes or Dask) that calls
:meth:`CompiledModel.simulate_batch` in its worker, and each finished chunk
is appended to a :class:`~acausal.infra.checkpoint.Checkpoint`, so a study
killed at any moment and started again with the same inputs runs only the
chunks that had not finished. A set that fails (solver failure, a measure
that cannot be computed, a drawn value outside the parameter's bounds) is
recorded as failed with its reason, counted and reported; the statistics
use the sets that succeeded.
"""
from __future__ import annotations

import csv
import json
import math
import os
import re
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Mapping, Sequence

import numpy as np

from ..errors import AcausalError, DataError, UsageError

__all__ = ["Dist", "SpecError", "parse_spec", "draw", "Design", "run_tolerance",
           "ToleranceResult", "summarize", "sobol_indices", "correlation_ratios",
           "regression_shares", "plot_histograms", "plot_tornado", "PERCENTILES"]

PERCENTILES = (1, 5, 50, 95, 99)
SAMPLINGS = ("lhs", "sobol")
CHUNK = 64          # sets per executor task (a chunk is journaled as one record)


# ---------------------------------------------------------------------------
# The spec
# ---------------------------------------------------------------------------


class SpecError(UsageError):
    """Bad rows of a tolerance spec: one line ``file:line: what`` per row."""

    def __init__(self, lines: Sequence[str]):
        self.lines = list(lines)
        super().__init__("\n".join(self.lines))

    def __str__(self):
        return "\n".join(self.lines)


@dataclass(frozen=True)
class Dist:
    """One toleranced parameter: ``kind`` 'normal' (a = mean, b = standard
    deviation) or 'uniform' (a = low, b = high), in SI; ``unit`` the SI unit
    (for labels), ``given`` the row as written."""

    name: str
    kind: str
    a: float
    b: float
    unit: str = ""
    given: str = ""

    def ppf(self, u: np.ndarray) -> np.ndarray:
        """The inverse CDF at ``u`` in (0, 1)."""
        if self.kind == "normal":
            from scipy.special import ndtri
            return self.a + self.b * ndtri(u)
        return self.a + (self.b - self.a) * np.asarray(u, dtype=float)

    @property
    def mean(self) -> float:
        return self.a if self.kind == "normal" else 0.5 * (self.a + self.b)

    @property
    def std(self) -> float:
        return self.b if self.kind == "normal" else (self.b - self.a) / math.sqrt(12.0)


_NUMBER = re.compile(r"^[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")


def _declared_unit(cm, name):
    """The unit text declared for parameter (or fixed start value) ``name``."""
    free = {e.name: e for e in cm.params}
    return free[name].unit if name in free else cm.flat.variables[name].unit


def _model_unit(cm, name):
    """The declared unit of parameter (or fixed start value) ``name``, with a
    symbolic exponent such as ``N/m^gamma`` resolved from the sibling
    parameter's value (``contact.gamma`` = 1.5 -> ``N/m^1.5``)."""
    unit = _declared_unit(cm, name)
    if not unit:
        return unit
    from ..data.units import parse_unit
    try:
        parse_unit(unit)
        return unit
    except Exception:   # noqa: BLE001 - pint cannot read it: resolve symbolic exponents
        pass
    scope = name.rsplit(".", 1)[0] + "." if "." in name else ""
    free = {e.name: e for e in cm.params}

    def value(m):
        e = free.get(scope + m.group(0))
        return repr(float(e.default)) if e is not None else m.group(0)
    return re.sub(r"[A-Za-z_]\w*", value, unit)


def _nominal(cm, name):
    """The model's value of ``name`` in SI (a parameter's default, or a fixed
    start value)."""
    free = {e.name: e for e in cm.params}
    if name in free:
        return float(free[name].default)
    return float(cm.flat.variables[name].start)


def _check_name(cm, name):
    """Raise an AcausalError unless ``name`` is a free parameter or a fixed
    start value of ``cm``."""
    params, _ = cm.split_overrides({name: 0.0})
    if name in params:
        cm.param_index(name)


def _to_si(cm, name, unit_text, where):
    """(factor, offset) taking values in ``unit_text`` to the SI unit of
    ``name``; a DataError if the dimension is wrong."""
    from ..data.units import converter
    declared = _declared_unit(cm, name)
    if declared and unit_text.strip() == declared.strip():
        return 1.0, 0.0        # the declared unit itself ('N/m^gamma', as listed)
    expected = _model_unit(cm, name)
    conv = converter(unit_text if unit_text not in ("",) else "1", expected,
                     f"{name} [{unit_text}]", name, where)
    zero = float(np.asarray(conv(np.array([0.0])))[0])
    return float(np.asarray(conv(np.array([1.0])))[0]) - zero, zero


def _read_number(text, what):
    if not _NUMBER.match(text):
        raise UsageError(f"{what} {text!r} is not a number")
    value = float(text)
    if not math.isfinite(value):
        raise UsageError(f"{what} {text!r} is not finite")
    return value


def _parse_row(cm, cells, path, line):
    """A Dist from one row's cells, or an AcausalError (UsageError, DataError) saying why not."""
    if len(cells) != 5:
        raise UsageError(f"expected 5 fields 'name, distribution, a, b, unit', got {len(cells)}")
    name, kind, a_text, b_text, unit = cells
    _check_name(cm, name)
    kind = kind.lower()
    if kind not in ("normal", "uniform"):
        raise UsageError(f"{name}: distribution {kind!r} is not 'normal' or 'uniform'")
    scale, offset = _to_si(cm, name, unit, (str(path), line, None))
    if a_text.lower() == "nominal":
        a = (_nominal(cm, name) - offset) / scale       # in the row's unit
    else:
        a = _read_number(a_text, f"{name}: {'mean' if kind == 'normal' else 'low'}")
    if b_text.endswith("%"):
        p = _read_number(b_text[:-1].strip(), f"{name}: percentage") / 100.0
        if p < 0:
            raise UsageError(f"{name}: a negative percentage {b_text!r}")
        a, b = (a, abs(a) * p) if kind == "normal" else (a - abs(a) * p, a + abs(a) * p)
    else:
        b = _read_number(b_text, f"{name}: {'standard deviation' if kind == 'normal' else 'high'}")
    if kind == "normal":
        if b < 0:
            raise UsageError(f"{name}: a negative standard deviation {b_text} [{unit}]")
        if b == 0:
            raise UsageError(f"{name}: a standard deviation of 0 (a fixed value: leave the row out)")
        return Dist(name, kind, a * scale + offset, b * abs(scale), _model_unit(cm, name) or "1",
                    ", ".join(cells))
    if not b > a:
        raise UsageError(f"{name}: an empty range: high {b:g} is not above low {a:g} [{unit}]")
    lo, hi = sorted((a * scale + offset, b * scale + offset))
    e = {p.name: p for p in cm.params}.get(name)
    if e is not None:
        for v in (lo, hi):
            e.decl.check_bounds(v, name)
    return Dist(name, kind, lo, hi, _model_unit(cm, name) or "1", ", ".join(cells))


def _separator(lines):
    """The spec's field separator: ',' unless its first row reads as the 5
    fields with ';' (a spreadsheet's export in a locale with decimal
    commas) or a tab and not with ','."""
    for text in lines:
        if not text.strip() or text.lstrip().startswith("#"):
            continue
        for sep in (",", ";", "\t"):
            if len(next(csv.reader([text], delimiter=sep))) == 5:
                return sep
        return ","
    return ","


def _hint(cells, sep):
    """What a row that does not read probably means."""
    if sep == "," and len(cells) > 5 and any(";" in c for c in cells):
        return " (';' between rows? put each row on its own line)"
    if sep != "," and any(re.fullmatch(r"[-+]?\d+,\d+", c) for c in cells):
        return " (a decimal comma? write numbers with a point: 1.5)"
    if len(cells) == 1:
        return " (fields are separated by commas: 'k.c, normal, 100, 5, N/m')"
    return ""


def parse_spec(path: str | os.PathLike, cm) -> list[Dist]:
    """The distributions of spec CSV ``path`` for compiled model ``cm``.

    Raises :class:`SpecError` listing every bad row, one line each
    (``tol.csv:3: contact.Kx: the model has no parameter 'contact.Kx'``): a
    parameter the model does not have (or has twice in the spec), an
    unknown distribution, a number that is not one, a negative or zero
    standard deviation, an empty range, a range outside the parameter's
    bounds, a unit of the wrong dimension.
    """
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        why = (getattr(exc, "strerror", None) or "not UTF-8 text"
               if not isinstance(exc, FileNotFoundError) else "no such file")
        raise UsageError(f"{path}: cannot read the tolerance spec: {why}") from None
    dists, bad, seen = [], [], {}
    lines = text.splitlines()
    sep = _separator(lines)
    for line, row in enumerate(csv.reader(lines, delimiter=sep), start=1):
        cells = [c.strip() for c in row]
        if not cells or not any(cells) or cells[0].startswith("#"):
            continue
        if cells[0].lower() == "name" and not dists and not bad:
            continue                                      # a header
        try:
            dist = _parse_row(cm, cells, path, line)
        except AcausalError as exc:
            msg = exc.message if isinstance(exc, AcausalError) else str(exc)
            if isinstance(exc, DataError):
                msg = f"{cells[0]}: {msg}"
            bad.append((line, " ".join(msg.split()) + _hint(cells, sep)))
            continue
        if dist.name in seen:
            bad.append((line, f"{dist.name}: already given on line {seen[dist.name]}"))
            continue
        seen[dist.name] = line
        dists.append(dist)
    # rows wrong in the same way (a file whose every row has one field) are
    # one line naming them all; other bad rows one line each
    grouped = {}
    for line, msg in bad:
        grouped.setdefault(msg, []).append(line)
    bad = [f"{path}:{','.join(map(str, ls))}: {msg}" for msg, ls in grouped.items()]
    if bad:
        raise SpecError(bad)
    if not dists:
        raise SpecError([f"{path}: no parameter rows (expected 'name, normal|uniform, a, b, unit')"])
    return dists


# ---------------------------------------------------------------------------
# Sampling
# ---------------------------------------------------------------------------


@dataclass
class Design:
    """The drawn sets: ``X`` (runs x d, SI), ``names``, ``sampling``, ``n``
    (the base sample size) and, for Saltelli's design, the row blocks
    A = X[:n], B = X[n:2n], AB_i = X[(2+i)n:(3+i)n]."""

    X: np.ndarray
    names: tuple
    sampling: str
    n: int
    seed: int | None

    @property
    def saltelli(self) -> bool:
        return self.sampling == "sobol"


def check_n(n: int, sampling: str) -> None:
    """Refuse a sample size the sampling cannot use (one line)."""
    if sampling not in SAMPLINGS:
        raise UsageError(f"sampling {sampling!r}: expected one of {', '.join(SAMPLINGS)}")
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)) or n < 2:
        raise UsageError(f"-n {n!r}: the number of sets must be an integer >= 2")
    if sampling == "sobol" and n & (n - 1):
        lo = 1 << (int(n).bit_length() - 1)
        raise UsageError(f"-n {n}: Sobol' sampling needs a power of 2 (its balance properties "
                         f"hold only then): use {lo} or {2 * lo}, or --sampling lhs")


def draw(dists: Sequence[Dist], n: int, sampling: str = "lhs", seed: int | None = 0) -> Design:
    """N sets of the parameters of ``dists`` (SI): Latin hypercube (n rows)
    or Saltelli's design on a scrambled Sobol' sequence (n (d + 2) rows)."""
    from scipy.stats import qmc
    check_n(n, sampling)
    d = len(dists)
    if sampling == "lhs":
        U = qmc.LatinHypercube(d, seed=seed).random(n)
    else:
        AB = qmc.Sobol(2 * d, scramble=True, seed=seed).random(n)
        A, B = AB[:, :d], AB[:, d:]
        blocks = [A, B]
        for i in range(d):
            M = A.copy()
            M[:, i] = B[:, i]
            blocks.append(M)
        U = np.vstack(blocks)
    X = np.column_stack([dist.ppf(U[:, i]) for i, dist in enumerate(dists)])
    return Design(X, tuple(dd.name for dd in dists), sampling, int(n), seed)


# ---------------------------------------------------------------------------
# Variance shares
# ---------------------------------------------------------------------------


def sobol_indices(y: np.ndarray, n: int, d: int) -> dict:
    """First-order (Saltelli 2010) and total (Jansen 1999) Sobol' indices from
    the outputs ``y`` of Saltelli's design (blocks A, B, AB_1..AB_d of n rows).
    A base row j whose A, B or AB_i output is NaN (a failed set) is left out
    of index i. Returns {'S1', 'ST' (arrays of d), 'used' (rows per index)}."""
    y = np.asarray(y, dtype=float).reshape(d + 2, n)
    fA, fB = y[0], y[1]
    S1, ST, used = np.full(d, np.nan), np.full(d, np.nan), np.zeros(d, dtype=int)
    both = np.concatenate([fA, fB])
    V = np.nanvar(both, ddof=1)
    for i in range(d):
        fABi = y[2 + i]
        ok = np.isfinite(fA) & np.isfinite(fB) & np.isfinite(fABi)
        used[i] = int(ok.sum())
        if used[i] < 2 or not V > 0:
            continue
        S1[i] = np.mean(fB[ok] * (fABi[ok] - fA[ok])) / V
        ST[i] = 0.5 * np.mean((fA[ok] - fABi[ok]) ** 2) / V
    return {"S1": S1, "ST": ST, "used": used}


def correlation_ratios(X: np.ndarray, y: np.ndarray, bins: int | None = None) -> np.ndarray:
    """Each column's correlation ratio with ``y`` (a given-data estimate of the
    first-order Sobol' index): the sets are split into ``bins`` equal-count
    bins of the parameter (default ~ sqrt(N)/2, at least 4), and the
    between-bin variance of y is corrected for its bias as epsilon^2 =
    (SS_between - (k-1) MS_within) / SS_total. NaN outputs are left out."""
    X, y = np.asarray(X, dtype=float), np.asarray(y, dtype=float)
    ok = np.isfinite(y)
    X, y = X[ok], y[ok]
    N = len(y)
    out = np.full(X.shape[1], np.nan)
    if N < 8:
        return out
    k = bins or max(4, int(round(math.sqrt(N) / 2)))
    ss_total = np.sum((y - y.mean()) ** 2)
    if not ss_total > 0:
        return out
    for i in range(X.shape[1]):
        order = np.argsort(X[:, i], kind="stable")
        groups = np.array_split(y[order], k)
        ss_between = sum(len(g) * (g.mean() - y.mean()) ** 2 for g in groups if len(g))
        ms_within = (ss_total - ss_between) / (N - k)
        out[i] = (ss_between - (k - 1) * ms_within) / ss_total
    return out


def regression_shares(X: np.ndarray, y: np.ndarray) -> dict:
    """Standardised regression coefficients of y on the columns of X (least
    squares with an intercept; NaN outputs left out): ``src`` (dy/dx_i
    std(x_i)/std(y)), ``slope`` (dy/dx_i in SI), ``r2`` (the linear fit's
    coefficient of determination; SRC_i^2 are variance shares only when it
    is near 1 and the inputs are independent)."""
    X, y = np.asarray(X, dtype=float), np.asarray(y, dtype=float)
    ok = np.isfinite(y)
    X, y = X[ok], y[ok]
    d = X.shape[1]
    nan = np.full(d, np.nan)
    if len(y) < d + 2 or not np.std(y) > 0:
        return {"src": nan, "slope": nan, "r2": math.nan}
    mx, sx = X.mean(axis=0), X.std(axis=0, ddof=1)
    sx = np.where(sx > 0, sx, 1.0)
    Z = (X - mx) / sx
    A = np.column_stack([np.ones(len(y)), Z])
    coef, *_ = np.linalg.lstsq(A, y, rcond=None)
    resid = y - A @ coef
    r2 = 1.0 - np.sum(resid ** 2) / np.sum((y - y.mean()) ** 2)
    return {"src": coef[1:] / np.std(y, ddof=1), "slope": coef[1:] / sx, "r2": float(r2)}


# ---------------------------------------------------------------------------
# Statistics
# ---------------------------------------------------------------------------


def summarize(design: Design, values: Mapping[str, np.ndarray], status: np.ndarray) -> dict:
    """Per measure: n_ok, n_failed, mean, std, percentiles, and the variance
    shares (see the module doc). ``values[m]``: one value per row of
    ``design.X`` (NaN where the set failed or the measure had no value)."""
    out = {}
    d = design.X.shape[1]
    for m, y in values.items():
        y = np.asarray(y, dtype=float)
        ok = (status == "ok") & np.isfinite(y)
        yo = y[ok]
        s = {"n": int(len(y)), "n_ok": int(ok.sum()), "n_failed": int(len(y) - ok.sum()),
             "mean": float(np.mean(yo)) if len(yo) else math.nan,
             "std": float(np.std(yo, ddof=1)) if len(yo) > 1 else math.nan,
             "percentiles": {p: float(np.percentile(yo, p)) if len(yo) else math.nan
                             for p in PERCENTILES}}
        yy = np.where(ok, y, np.nan)
        # Saltelli's AB_i rows repeat A's and B's columns: the given-data
        # estimates use the independent rows only (A and B)
        rows = slice(0, 2 * design.n) if design.saltelli else slice(None)
        reg = regression_shares(design.X[rows], yy[rows])
        s.update(src=reg["src"], slope=reg["slope"], r2=reg["r2"],
                 eta2=correlation_ratios(design.X[rows], yy[rows]))
        if design.saltelli:
            idx = sobol_indices(yy, design.n, d)
            s.update(S1=idx["S1"], ST=idx["ST"], used=idx["used"])
        out[m] = s
    return out


# ---------------------------------------------------------------------------
# Running (chunks on an executor, journaled)
# ---------------------------------------------------------------------------


def run_chunk(model_path: str, names: Sequence[str], rows: Sequence[tuple[int, Sequence[float]]],
              measures: Sequence[str], max_memory: float | None = None,
              backend: str | None = "compiled") -> list[dict]:
    """One chunk, on a worker: the model file compiled once per process, the
    chunk's sets simulated by :meth:`CompiledModel.simulate_batch` in this
    process. Returns one record per set: index, status ('ok'/'failed'),
    values (measure -> float, NaN if missing), error (one line, empty if ok).
    Module-level, so picklable."""
    from functools import partial

    from ..modelfile import compile_file
    mf, cm = compile_file(model_path)
    opts = mf.experiment.run_options()
    if max_memory is not None:
        opts["max_memory"] = max_memory
    if backend is not None:
        opts["backend"] = backend
    out, todo = [], []
    for index, values in rows:
        params = dict(zip(names, map(float, values)))
        try:
            p, _ = cm.split_overrides(params)
            cm.param_vector(p)                   # out of bounds: this set fails, not the chunk
        except AcausalError as exc:
            out.append(_record(index, "failed", {}, exc))
            continue
        todo.append((index, params))
    results = cm.simulate_batch([p for _, p in todo], workers=1, errors="return",
                                reduce=partial(_measures, mf, tuple(measures)), **opts)
    for (index, _), res in zip(todo, results):
        if isinstance(res, Exception):
            out.append(_record(index, "failed", {}, res))
        else:
            values, missing = res
            status = "failed" if missing else "ok"
            why = "; ".join(f"{m}: {r}" for m, r in missing.items())
            out.append(_record(index, status, values, why))
    return sorted(out, key=lambda r: r["index"])


def _measures(mf, measures, result):
    """(values, missing) of the chosen measures of one result (in the worker)."""
    from ..modelfile import measure_values
    values, missing = measure_values(mf, result)
    return ({m: values[m] for m in measures}, {m: missing[m] for m in measures if m in missing})


def _record(index, status, values, error):
    if isinstance(error, BaseException):
        error = f"{type(error).__name__}: {error}" if not isinstance(error, AcausalError) \
            else str(error)
    text = " ".join(str(error or "").split())
    return {"index": int(index), "status": status,
            "values": {k: float(v) for k, v in values.items()}, "error": text[:300]}


@dataclass
class ToleranceResult:
    """A finished study: the design, each measure's values (NaN where the
    set failed), each set's status and error, the summary, and the units."""

    design: Design
    dists: list
    measures: tuple
    values: dict
    status: np.ndarray
    errors: list
    summary: dict
    resumed: int = 0
    wall_s: float = 0.0
    measure_units: dict = field(default_factory=dict)   # measure -> (factor, display unit)

    @property
    def n_failed(self) -> int:
        return int(np.sum(self.status != "ok"))


@dataclass(frozen=True)
class Sampling:
    """How the sets are drawn: ``kind`` 'lhs' (Latin hypercube) or 'sobol'
    (Saltelli's design), with ``seed``."""

    kind: str = "lhs"
    seed: int | None = 0


@dataclass(frozen=True)
class StudyRun:
    """How the sets run: ``chunk`` sets per task, ``max_memory`` bytes each
    worker's simulation may store, the integrator ``backend`` ('compiled',
    the default: generated C; None: the library's default),
    ``on_resume(done, total)`` when sets were already done, and a
    ``progress`` bar."""

    chunk: int = CHUNK
    max_memory: float | None = None
    backend: str | None = "compiled"
    on_resume: Callable[[int, int], None] | None = None
    progress: bool = False


def run_tolerance(model_path: str | os.PathLike, dists: Sequence[Dist], n: int, *,
                  executor, measures: Sequence[str], sampling: Sampling = Sampling(),
                  out_csv: str | os.PathLike | None = None,
                  run: StudyRun = StudyRun()) -> ToleranceResult:
    """Run a tolerance study of the model file ``model_path`` (see the module
    doc). ``executor``: from :func:`acausal.infra.executor.open_executor`.
    Finished chunks are journaled in ``<out_csv>.partial/`` (or, without
    ``out_csv``, ``tolerance.partial/`` beside the model file) and the study
    resumes from them. ``out_csv`` receives one row per set (its parameters
    in SI, its measures, status and error). ``sampling``: :class:`Sampling`;
    ``run``: :class:`StudyRun`."""
    seed = sampling.seed
    chunk, max_memory, backend = run.chunk, run.max_memory, run.backend
    on_resume, progress = run.on_resume, run.progress
    sampling = sampling.kind
    from ..infra.checkpoint import Checkpoint, input_key, source_files
    t0 = time.perf_counter()
    measures = tuple(measures)
    design = draw(dists, n, sampling, seed)
    runs = len(design.X)
    folder = (Path(str(out_csv) + ".partial") if out_csv is not None
              else Path(model_path).with_name("tolerance.partial"))
    key = input_key(*source_files(model_path), design.X.tobytes(), list(design.names),
                    list(measures), int(chunk))
    store = Checkpoint(folder, key)
    done = {}
    for k, recs in store.load().items():
        for r in recs if isinstance(recs, list) else []:
            if isinstance(r, dict) and r.get("index") is not None:
                done[int(r["index"])] = r
    if done and on_resume is not None:
        on_resume(len(done), runs)
    starts = [s for s in range(0, runs, chunk)
              if not all(i in done for i in range(s, min(s + chunk, runs)))]
    submit = lambda s: executor.submit(              # noqa: E731
        run_chunk, os.path.abspath(model_path), design.names,
        [(i, design.X[i].tolist()) for i in range(s, min(s + chunk, runs)) if i not in done],
        measures, max_memory, backend)
    resumed = len(done)
    bar = _bar(runs, len(done), progress)
    futures = {}
    try:
        window = max(4, 4 * (getattr(executor, "workers", None) or 4))
        pending = list(starts)
        while pending or futures:
            while pending and len(futures) < window:
                s = pending.pop(0)
                futures[submit(s)] = s
            fut = next(iter(executor.as_completed(list(futures))))
            s = futures.pop(fut)
            recs = fut.result()
            store.append(str(s), recs)
            for r in recs:
                done[r["index"]] = r
            bar.update(len(recs))
    except BaseException:
        executor.cancel(list(futures))
        raise
    finally:
        bar.close()
    status = np.array([done[i]["status"] for i in range(runs)], dtype=object)
    values = {m: np.array([done[i]["values"].get(m, math.nan) for i in range(runs)], dtype=float)
              for m in measures}
    errors = [done[i]["error"] for i in range(runs)]
    res = ToleranceResult(design, list(dists), measures, values, status, errors,
                          summarize(design, values, status), resumed=resumed,
                          wall_s=time.perf_counter() - t0)
    if out_csv is not None:
        _write_sets(Path(out_csv), res)
    store.discard()
    return res


def _bar(total, initial, enabled):
    import sys

    from tqdm import tqdm
    return tqdm(total=total, initial=initial, disable=not enabled, file=sys.stderr,
                desc="tolerance", unit="set")


def _write_sets(path: Path, res: ToleranceResult) -> None:
    """One row per set: its index, parameters (SI, unit in the header),
    measures, status and error; written to a temporary file then renamed."""
    from .sweep import column_label
    units = {d.name: d.unit for d in res.dists}
    header = ["set", *res.design.names, *res.measures, "status", "error"]
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    with open(tmp, "w", newline="", encoding="utf-8") as f:
        w = csv.writer(f, lineterminator="\n")
        w.writerow([column_label(c, units) for c in header])
        for i in range(len(res.design.X)):
            w.writerow([i, *map(repr, map(float, res.design.X[i])),
                        *(repr(float(res.values[m][i])) for m in res.measures),
                        res.status[i], res.errors[i]])
    os.replace(tmp, path)


# ---------------------------------------------------------------------------
# Report and plots
# ---------------------------------------------------------------------------


def shares(s: Mapping) -> tuple[np.ndarray, str]:
    """The variance shares to rank parameters by, and what they are."""
    if "S1" in s:
        return s["ST"], "total Sobol' index"
    return s["eta2"], "correlation ratio"


def report_lines(res: ToleranceResult, show: Callable[[str, float], str] | None = None) -> list[str]:
    """The study's summary as text lines; ``show(measure, value)`` formats a
    value in the measure's display unit."""
    show = show or (lambda m, v: f"{v:.6g}")
    d = res.design
    lines = [f"{len(d.X)} sets ({d.sampling}"
             + (f", Saltelli design: N = {d.n} x (d + 2 = {len(d.names) + 2})" if d.saltelli else "")
             + f", seed {d.seed}), {res.n_failed} failed"]
    for m in res.measures:
        s = res.summary[m]
        pct = ", ".join(f"p{p} {show(m, v)}" for p, v in s["percentiles"].items())
        lines.append(f"{m}: mean {show(m, s['mean'])}, std {show(m, s['std'])} "
                     f"({s['n_ok']} ok, {s['n_failed']} failed)")
        lines.append(f"  {pct}")
        head = "S1      ST      " if "S1" in s else ""
        lines.append(f"  {'parameter':28s} {head}eta^2   SRC     SRC^2   (linear fit R^2 = "
                     f"{s['r2']:.3f})")
        order = np.argsort(-np.nan_to_num(shares(s)[0], nan=-1.0))
        for i in order:
            cols = f"{s['S1'][i]:6.3f}  {s['ST'][i]:6.3f}  " if "S1" in s else ""
            lines.append(f"  {d.names[i]:28s} {cols}{s['eta2'][i]:6.3f}  {s['src'][i]:+6.3f}  "
                         f"{s['src'][i] ** 2:6.3f}")
    failed = [(i, e) for i, e in enumerate(res.errors) if res.status[i] != "ok"]
    for i, e in failed[:5]:
        lines.append(f"failed set {i}: {e}")
    if len(failed) > 5:
        lines.append(f"... and {len(failed) - 5} more failed sets (see the CSV)")
    return lines


def plot_histograms(res: ToleranceResult, prefix: str | os.PathLike,
                    display: Mapping[str, tuple[float, str]] | None = None) -> list[Path]:
    """One histogram per measure, ``<prefix>_<measure>_hist.png``, values in
    the measure's display unit (``display[m]`` = (factor from SI, unit)),
    with the mean and the 1st/99th percentiles marked."""
    from matplotlib.figure import Figure
    paths = []
    for m in res.measures:
        f, unit = (display or {}).get(m, (1.0, ""))
        s = res.summary[m]
        y = res.values[m][(res.status == "ok") & np.isfinite(res.values[m])] * f
        fig = Figure(figsize=(6.4, 4.2), layout="constrained")
        ax = fig.add_subplot()
        ax.hist(y, bins=max(10, int(math.sqrt(len(y)))), color="0.6", edgecolor="0.3")
        ax.axvline(s["mean"] * f, color="C0", label=f"mean {s['mean'] * f:.4g}")
        for p in (1, 99):
            ax.axvline(s["percentiles"][p] * f, color="C3", ls="--",
                       label=f"p{p} {s['percentiles'][p] * f:.4g}")
        ax.set_xlabel(f"{m} [{unit}]" if unit else m)
        ax.set_ylabel("sets")
        ax.set_title(f"{m}: {s['n_ok']} sets, {s['n_failed']} failed", fontsize="medium")
        ax.legend(fontsize="small")
        path = Path(f"{prefix}_{m}_hist.png")
        fig.savefig(path, dpi=120)
        paths.append(path)
    return paths


def plot_tornado(res: ToleranceResult, prefix: str | os.PathLike,
                 display: Mapping[str, tuple[float, str]] | None = None) -> list[Path]:
    """One tornado plot per measure, ``<prefix>_<measure>_tornado.png``: for
    each parameter, the change of the measure (display unit) when the
    parameter goes from its 5th to its 95th percentile with the others at
    their means (the linear fit's slope), labelled with its variance share;
    sorted by the share."""
    from matplotlib.figure import Figure
    paths = []
    q = np.array([[dd.ppf(0.05), dd.ppf(0.95)] for dd in res.dists])
    for m in res.measures:
        f, unit = (display or {}).get(m, (1.0, ""))
        s = res.summary[m]
        share, what = shares(s)
        order = np.argsort(np.nan_to_num(share, nan=-1.0))
        lo = s["slope"] * (q[:, 0] - np.array([dd.mean for dd in res.dists])) * f
        hi = s["slope"] * (q[:, 1] - np.array([dd.mean for dd in res.dists])) * f
        fig = Figure(figsize=(6.8, 0.9 + 0.38 * len(order)), layout="constrained")
        ax = fig.add_subplot()
        names = [res.design.names[i] for i in order]
        ax.barh(names, lo[order], color="C0", label="parameter at its 5th percentile")
        ax.barh(names, hi[order], color="C3", label="parameter at its 95th percentile")
        ax.axvline(0.0, color="0.2", lw=0.8)
        for k, i in enumerate(order):
            ax.annotate(f"{100 * share[i]:.1f} %", (max(lo[i], hi[i]), k),
                        xytext=(4, 0), textcoords="offset points", va="center", fontsize="small")
        ax.set_xlabel(f"change of {m} from its mean [{unit}]" if unit else f"change of {m}")
        ax.set_title(f"{m}: labels = {what} (linear fit R^2 = {s['r2']:.3f})", fontsize="medium")
        ax.legend(fontsize="small", loc="lower right")
        ax.margins(x=0.25)
        path = Path(f"{prefix}_{m}_tornado.png")
        fig.savefig(path, dpi=120)
        paths.append(path)
    return paths


def summary_json(res: ToleranceResult) -> dict:
    """The summary as JSON-able data (arrays as lists keyed by parameter)."""
    out = {}
    for m, s in res.summary.items():
        row = {k: s[k] for k in ("n", "n_ok", "n_failed", "mean", "std", "r2")}
        row["percentiles"] = {str(p): v for p, v in s["percentiles"].items()}
        for k in ("S1", "ST", "eta2", "src"):
            if k in s:
                row[k] = dict(zip(res.design.names, map(float, s[k])))
        out[m] = row
    return json.loads(json.dumps(out, default=float))
