"""Segment solvers: what the hybrid loop (:mod:`acausal.simulate`) asks of an
integrator.

A *segment* is a stretch of integration in one mode (one set of discrete
values) from a consistent point ``(t, y, y')``: the backend integrates it
over the requested output times until the first terminal root or the end,
and reports every root it located on the way (observer roots, which did not
stop it, and the terminal one), in time order. Everything hybrid (event
actions, re-initialisation, event iteration, the chattering guard) stays in
the loop, so a second backend only has to implement :class:`SegmentSolver`.

Backends:

``"sundae"``
    scikit-sundae's IDA calling the generated Python callbacks (the
    reference); :mod:`acausal.backends.sundae`.
``"compiled"``
    SUNDIALS IDA (the library the scikit-sundae wheel ships) calling
    generated C compiled with the system's C compiler, with no Python call
    per residual, Jacobian or root evaluation; :mod:`acausal.backends.compiled`.
    Without a C compiler it falls back to ``"sundae"`` and says so in
    ``res.stats["backend_fallback"]``.
"""
from dataclasses import dataclass, field

import numpy as np

from ...errors import AcausalError, UsageError

BAND_MIN_SIZE = 40        # unknowns from which a narrow band beats the dense solver
BAND_MAX_FRACTION = 0.25  # a band at most this fraction of n wide counts as narrow


@dataclass
class LinearSolver:
    """IDA's linear solver for a model: its ``kind``, the keyword ``options``
    for ``sksundae.ida.IDA`` and ``jac_index``, the position in
    :meth:`acausal.compile.CompiledModel.callbacks` of the Jacobian callback that fills the
    storage this solver uses (1: 2-D array, 6: CSC array)."""
    kind: str
    options: dict
    jac_index: int


BACKENDS = ("sundae", "compiled")


@dataclass
class Root:
    """A located root: time, point and the indices of the root functions
    that crossed zero there (events first, then assertions)."""
    t: float
    y: np.ndarray
    yp: np.ndarray
    fired: list


@dataclass
class Segment:
    """What a segment solve produced. ``t, y, yp``: output rows, the first
    being the start point; ``status``: 0 reached the end, 2 stopped at a
    terminal root (the last row), < 0 failed (``message`` says why);
    ``roots``: every located root in time order."""
    t: np.ndarray
    y: np.ndarray
    yp: np.ndarray
    status: int
    message: str
    roots: list = field(default_factory=list)
    nfev: int = 0
    njev: int = 0
    steps: int = 0


class SegmentSolver:
    """Interface of a backend. ``solve(cb, d, t, y, yp, tout, every_step)``
    integrates from the consistent point ``(t, y, yp)`` in the mode given by
    the discrete values ``d`` (``cb``: that mode's generated Python
    callbacks, which a compiled backend may ignore) over the output times
    ``tout`` (increasing, all > t, the last one the end of the segment),
    with a row at every internal step as well when ``every_step``, and
    returns a :class:`Segment`."""
    name = "?"
    detail = ""
    fallback = None   # why another backend runs in place of the one asked for
    # guard(steps): called by a backend that does not call the Python residual
    # (compiled) whenever its output buffer fills, with the steps of the call
    # so far; returns True to end the call (past a limit, or a stop request),
    # the segment then being the rows computed so far
    guard = None

    def solve(self, cb, d, t, y, yp, tout, every_step):
        raise NotImplementedError

    def serve(self, model, p, d):
        """The callbacks the hybrid loop uses between segments
        (initialisation, event actions, re-initialisation) in mode ``d``:
        those of ``model`` (this solver's, or one run beside it:
        a sensitivity run's base model, :mod:`acausal.sensitivity`) with
        parameters ``p``: the generated Python callbacks, or a backend's faster
        equivalent of them (same tuple, same results)."""
        return model.callbacks(p, d)


class BackendError(AcausalError):
    """A backend was asked for that does not exist or cannot run here."""


def make_solver(name, cm, p, opts):
    """A :class:`SegmentSolver` of backend ``name`` for model ``cm`` with
    parameter vector ``p`` and options ``opts`` (rtol, atol, max_step,
    max_num_steps). A model with no states gets an
    :class:`~acausal.runtime.backends.algebraic.AlgebraicSolver` on that
    backend's callbacks (there is nothing for IDA to integrate)."""
    if cm.dae.n_states == 0:
        return _stateless(name, cm, p, opts)
    if name in (None, "sundae"):
        from .sundae import SundaeSolver
        return SundaeSolver(cm, p, opts)
    if name == "compiled":
        from .compiled import CompiledSolver, Unavailable
        try:
            return CompiledSolver(cm, p, opts)
        except Unavailable as exc:
            from .sundae import SundaeSolver
            solver = SundaeSolver(cm, p, opts)
            solver.fallback = f"compiled backend unavailable: {exc}"
            return solver
    raise BackendError(f"unknown backend {name!r}; choose one of: {', '.join(BACKENDS)}")


def _stateless(name, cm, p, opts):
    from .algebraic import AlgebraicSolver
    if name == "compiled":
        from .compiled import CCallbacks, Unavailable, library
        try:
            library(cm)
        except Unavailable as exc:
            solver = AlgebraicSolver(cm, p, opts, "sundae",
                                     lambda model, q, d: model.callbacks(q, d))
            solver.fallback = f"compiled backend unavailable: {exc}"
            return solver

        def serve(model, q, d):
            return CCallbacks(library(model), model, q, d, lambda: model.callbacks(q, d))
        return AlgebraicSolver(cm, p, opts, "compiled", serve)
    if name in (None, "sundae"):
        return AlgebraicSolver(cm, p, opts, "sundae", lambda model, q, d: model.callbacks(q, d))
    raise BackendError(f"unknown backend {name!r}; choose one of: {', '.join(BACKENDS)}")


def compiled_available():
    """None when the compiled backend can run here, else the reason."""
    from .compiled import Unavailable, _compiler, _sundials_libs
    try:
        _compiler()
        _sundials_libs()
    except Unavailable as exc:
        return str(exc)
    return None


def choose_linear_solver(sparsity, kind="auto"):
    """IDA's linear solver for an iteration matrix of pattern ``sparsity``
    (:class:`acausal.codegen.Sparsity`): ``"dense"``, ``"band"`` (bandwidths
    from the pattern), ``"sparse"`` (SuperLU_MT on the CSC pattern) or
    ``"auto"``: dense below :data:`BAND_MIN_SIZE` unknowns or when the band
    is not narrow, else band. Raises UsageError for another ``kind``."""
    n = sparsity.n
    if kind == "auto":
        narrow = sparsity.lband + sparsity.uband + 1 <= BAND_MAX_FRACTION * n
        kind = "band" if n >= BAND_MIN_SIZE and narrow else "dense"
    if kind == "dense":
        return LinearSolver("dense", {}, 1)
    if kind == "band":
        return LinearSolver("band", dict(linsolver="band", lband=int(sparsity.lband),
                                         uband=int(sparsity.uband)), 1)
    if kind == "sparse":
        return LinearSolver("sparse", dict(linsolver="sparse", sparsity=sparsity.matrix()), 6)
    raise UsageError(f"linear solver {kind!r}: choose 'auto', 'dense', 'band' or 'sparse'")
