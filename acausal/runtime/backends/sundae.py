"""The reference backend: scikit-sundae's IDA (SUNDIALS) calling the
generated Python callbacks. The only module that imports ``sksundae``.

What it relies on (checked by ``tests/backends/test_sundae_contract.py``):

* ``IDA(resfn, jacfn=, eventsfn=, num_events=, algebraic_idx=, rtol=, atol=,
  max_step=, max_num_steps=)`` and ``IDA.solve(tspan, y0, yp0)``; a
  two-point ``tspan`` reports every internal step;
* the events function's ``terminal`` and ``direction`` attributes, as
  documented: a terminal root stops ``solve`` (status 2, the root the last
  row), a non-terminal one does not and is still reported;
* the public result fields ``t, y, yp, status, message, i_events, t_events,
  y_events, yp_events, nfev, njev``.

One private thing, unavoidable: scikit-sundae keeps the located roots and
the per-event counts that decide when to stop on the events function
(``_i, _t, _y, _yp, _i_cnt``), for the life of the IDA object, and a
terminal event that fired once would stop every later ``solve`` at any
root. Creating an IDA object per segment costs more than a segment of a
short contact, so one object serves a run and the log is cleared before
each segment (:func:`_clear_event_log`); the public ``*_events`` fields then
hold exactly the segment's roots.

scikit-sundae's error handler ``print``s SUNDIALS' message (``[IDASolve,
Error: -22] At t = ... mxstep steps taken``) to ``sys.stdout`` before
``solve`` returns a failed status. That line is caught here
(:func:`_caught_prints`) and carried in the segment's message, so that a
failed run says it once, in its own error line, and the many fits of a
diagnosis or a sweep whose trial points fail print nothing.
"""
import contextlib
import io
import re
import sys
import threading

import numpy as np
from sksundae.ida import IDA

from . import Root, Segment, SegmentSolver

_EVENT_LOG = ("_i", "_t", "_y", "_yp")


class SundaeSolver(SegmentSolver):
    """One scikit-sundae IDA object per run; its callbacks dispatch to the
    current mode's generated functions, so a mode change only swaps them."""
    name = "sundae"
    detail = "scikit-sundae IDA, generated Python callbacks"

    def __init__(self, cm, p, opts):
        self.cm = cm
        self.cb = None
        kw = dict(rtol=opts["rtol"], atol=opts["atol"], max_step=opts.get("max_step") or 0.0,
                  max_num_steps=opts["max_num_steps"])
        alg = list(range(cm.dae.n_states, len(cm.dae.y)))
        if alg:
            kw["algebraic_idx"] = alg
        # dense, band or sparse, from the iteration matrix's structure
        lin = cm.linear_solver(opts.get("linsolver", "auto"))
        kw.update(lin.options)

        def res(t, y, yp, r):
            self.cb.res(t, y, yp, r)

        def jac(t, y, yp, r, cj, J):
            self.cb[lin.jac_index](t, y, yp, r, cj, J)
        self.roots = None
        if cm.n_roots:
            def roots(t, y, yp, g):
                self.cb.roots(t, y, yp, g)
            roots.terminal = [not e.observer for e in cm.events] + [True] * len(cm.assertions)
            roots.direction = [e.direction for e in cm.events] + [-1] * len(cm.assertions)
            self.roots = roots
            kw.update(eventsfn=roots, num_events=cm.n_roots)
        self.ida = IDA(res, jacfn=jac, **kw)
        self.solved = False

    def solve(self, cb, d, t, y, yp, tout, every_step):
        self.cb = cb
        tspan = np.concatenate([[t], np.asarray(tout, float)])
        _clear_event_log(self.roots, self.solved)
        self.solved = True
        cb.count[0] = 0
        with _caught_prints() as said:
            sol = self.ida.solve(tspan, y, yp)
        message = str(sol.message)
        lines = _sundials_lines(said.getvalue())
        if lines and int(sol.status) < 0:
            message += " (SUNDIALS: " + "; ".join(dict.fromkeys(lines)) + ")"
        st, sy, syp = np.atleast_1d(sol.t), np.atleast_2d(sol.y), np.atleast_2d(sol.yp)
        if len(tspan) == 2 and not every_step and len(st) > 2:
            keep = np.r_[0, len(st) - 1]   # IDA reported every internal step
            st, sy, syp = st[keep], sy[keep], syp[keep]
        roots = []
        if sol.t_events is not None:
            for flags, te, ye, ype in zip(sol.i_events, sol.t_events, sol.y_events,
                                          sol.yp_events):
                roots.append(Root(float(te), np.array(ye), np.array(ype),
                                  [i for i, s in enumerate(flags) if s != 0]))
        return Segment(st, sy, syp, int(sol.status), message, roots,
                       int(sol.nfev), int(sol.njev), int(cb.count[0]))


def _clear_event_log(roots, solved):
    """Forget the roots located in earlier segments (see the module doc).
    Before the first solve there is no log yet; after it, a missing log means
    a scikit-sundae this adapter does not support."""
    if roots is None or not (solved or hasattr(roots, "_i_cnt")):
        return
    missing = [n for n in _EVENT_LOG + ("_i_cnt",) if not hasattr(roots, n)]
    if missing:
        import sksundae
        raise RuntimeError(f"scikit-sundae {getattr(sksundae, '__version__', '?')} keeps no "
                           f"event log {missing} on the events function; acausal supports "
                           "the versions pinned in pyproject.toml")
    for name in _EVENT_LOG:
        getattr(roots, name).clear()
    roots._i_cnt[:] = 0


_SUNDIALS_LINE = re.compile(r"^\[\w+, Error: -?\d+\]")


def _sundials_lines(text):
    """SUNDIALS' lines in what a solve printed (``[IDASolve, Error: -22]
    ...``); anything else (a model file's own ``print`` in a force law) is
    written on to ``sys.stdout`` as it would have been."""
    ours, other = [], []
    for ln in text.splitlines(keepends=True):
        (ours if _SUNDIALS_LINE.match(ln.strip()) else other).append(ln)
    rest = "".join(other)
    if rest.strip():
        sys.stdout.write(rest)
    return [ln.strip() for ln in ours]


class _Routed:
    """``sys.stdout`` while a solve runs: what a thread inside
    :func:`_caught_prints` writes goes to that thread's buffer, everything
    else to the stream it replaced (Dask threads solving in one process
    each catch their own lines; another thread's output is untouched)."""

    def __init__(self, stream):
        self.stream = stream
        self.local = threading.local()

    def write(self, text):
        buf = getattr(self.local, "buf", None)
        return (buf if buf is not None else self.stream).write(text)

    def flush(self):
        if getattr(self.local, "buf", None) is None:
            self.stream.flush()

    def __getattr__(self, name):          # encoding, isatty, fileno, buffer, ... of the stream
        return getattr(self.stream, name)


_ROUTE_LOCK = threading.Lock()
_ROUTE = {"routed": None, "users": 0}


@contextlib.contextmanager
def _caught_prints():
    """Python-level writes to ``sys.stdout`` by this thread go to the
    returned buffer until the block ends. The router is installed by the
    first thread in and removed by the last one out, unless someone replaced
    ``sys.stdout`` meanwhile (then it is left to them)."""
    buf = io.StringIO()
    with _ROUTE_LOCK:
        routed = _ROUTE["routed"]
        if routed is None or sys.stdout is not routed:
            routed = _Routed(sys.stdout)
            sys.stdout = routed
            _ROUTE.update(routed=routed, users=0)
        _ROUTE["users"] += 1
    routed.local.buf = buf
    try:
        yield buf
    finally:
        routed.local.buf = None
        with _ROUTE_LOCK:
            if _ROUTE["routed"] is routed:
                _ROUTE["users"] -= 1
                if _ROUTE["users"] <= 0:
                    if sys.stdout is routed:
                        sys.stdout = routed.stream
                    _ROUTE.update(routed=None, users=0)
