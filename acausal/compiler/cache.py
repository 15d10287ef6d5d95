"""The compile namespace of the on-disk store (:mod:`acausal.infra.store`):
compiled models, keyed by the model's structure.

Compiling (aliases, Pantelides, dummy derivatives, causalization, code
generation) depends only on the flattened model: its equations, declarations
(names, start values, parameter values: the state selection evaluates
Jacobians at them), events and assertions, and on the compiler itself. The
key is a SHA-256 of all of these, the source of the compiler's modules and
the versions of Python, sympy and numpy, so a second ``acausal simulate``,
``calibrate`` or ``diagnose`` of the same file reads the compiled stages
back instead of computing them; any change to the model, the compiler or
those libraries gives another key.

What is stored is an :class:`Entry` of the compile stages' outputs (sympy
expressions pickle) and the generated source *text*, which is compiled
again on load (generated functions themselves do not pickle). Entries that
cannot be read (corrupt, truncated, from another format) are ignored and
rebuilt. ``compile_model(model, cache=False)`` or ``ACAUSAL_CACHE=off``
bypass it.
"""
import hashlib
import pickle
import platform
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import sympy as sp

from ..infra import store

FORMAT = 4    # 4: the Python source may be absent (written at its first use)
NAMESPACE = "compile"
_COMPILER_MODULES = ("compiler/flatten", "compiler/aliases", "compiler/structure",
                     "compiler/causalize", "compiler/codegen", "compiler/pipeline",
                     "compiler/artefact", "compiler/cache", "compiler/units", "compiler/substitute",
                     "lang/fastdiff",
                     "lang/symbols", "lang/declare")
_source_hash = []


@dataclass
class Entry:
    """The outputs of the compile stages after flattening."""
    key: str
    reduced: object
    graph: object
    root_starts: dict
    dae: object
    source: str | None   # the generated Python source; None until a run needs it
    sparsity: object
    root_via: dict = None   # root -> (alias name, sign, offset): start values set per run
    propagated: dict = None  # guesses of frame positions/angles from the start values
    format: int = FORMAT


def _compiler_hash():
    if not _source_hash:
        h = hashlib.sha256()
        here = Path(__file__).resolve().parent.parent   # the acausal package
        for name in _COMPILER_MODULES:
            h.update((here / f"{name}.py").read_bytes())
        _source_hash.append(h.hexdigest())
    return _source_hash[0]


def _value(v):
    if isinstance(v, sp.Basic):
        return _serial(v)
    return repr(v)


def _walker(finish):
    """A memoised walk of a sympy tree that is the same in every process:
    the class of every node and its arguments' results in sympy's stored
    (canonical, name-sorted) order, atoms by ``srepr`` (a Float with all its
    digits, a Symbol with its assumptions); ``finish`` maps each node's text
    to its result."""
    memo = {}

    def walk(e):
        out = memo.get(e)
        if out is None:
            if e.is_Atom or not e.args:
                text = sp.srepr(e)
            else:
                text = type(e).__name__ + "(" + ",".join(walk(a) for a in e.args) + ")"
            out = memo[e] = finish(text)
        return out
    return walk


def _serial(expr):
    """An exact text of a sympy expression that is the same in every
    process (:func:`_walker`). ``srepr`` of the whole tree gives the same
    information but sorts every sum's terms for printing; it took a third of
    compiling a 100-mass chain."""
    return _walker(lambda text: text)(expr)


def digest(exprs):
    """SHA-256 (hex) of sympy expressions, the same in every process: the
    walk of :func:`_serial` with each node's text replaced by its hash, so
    that a tree with much sharing (the sensitivity residuals) costs its
    number of distinct nodes, not the length of its printed form."""
    walk = _walker(lambda text: hashlib.sha256(text.encode()).hexdigest()[:32])
    h = hashlib.sha256()
    for e in exprs:
        h.update((walk(e) if isinstance(e, sp.Basic) else repr(e)).encode())
        h.update(b"\x1f")
    return h.hexdigest()


def model_key(flat):
    """SHA-256 (hex) of everything compilation depends on in ``flat``, of the
    compiler's source and of the library versions."""
    h = hashlib.sha256()

    def put(*parts):
        for p in parts:
            h.update(str(p).encode())
            h.update(b"\x1f")
        h.update(b"\x1e")

    put("acausal-cache", FORMAT, _compiler_hash(), sys.version, platform.machine(),
        sp.__version__, np.__version__)
    for name, info in flat.params.items():
        d = info.decl
        put("P", name, _value(info.value), d.structural, d.unit, info.owner)
    for name, info in flat.variables.items():
        put("V", name, _value(info.start.value), info.start.fixed, info.port, info.owner)
    for name, info in flat.discretes.items():
        put("D", name, _value(info.start.value), info.owner)
    for eq in flat.equations:
        put("E", _serial(eq.expr), eq.origin, eq.label)
    for ev in flat.events:
        put("Ev", ev.name, _serial(ev.expr), ev.owner)
    for a in flat.assertions:
        put("A", _serial(a.expr), a.owner)
    put("U", *flat.unconnected)
    return h.hexdigest()


def load(key):
    """The :class:`Entry` stored under ``key``, or None (missing, disabled,
    unreadable or not matching)."""
    data = store.read_bytes(NAMESPACE, f"{key}.pkl")
    if data is None:
        return None
    try:
        entry = pickle.loads(data)
    except Exception:     # corrupt or from an incompatible version: rebuild
        return None
    if not isinstance(entry, Entry) or entry.format != FORMAT or entry.key != key:
        return None
    return entry


def save(entry):
    """Write ``entry`` (atomically); True when written. A model whose
    compiled form does not pickle (a user-defined sympy function), or a
    store that cannot be written, is not cached."""
    try:
        data = pickle.dumps(entry, protocol=pickle.HIGHEST_PROTOCOL)
    except Exception:
        return False
    return store.write_bytes(NAMESPACE, f"{entry.key}.pkl", data)
