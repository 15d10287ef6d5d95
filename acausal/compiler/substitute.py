"""Substitution of symbols in expressions, remembered across the models one
process compiles.

A diagnosis compiles dozens of models that differ from one nominal model by
one added component: most of their event conditions, observed variables and
residuals are the nominal's, and so are the substitutions the compiler makes
in them (parameter bindings, aliases and explicit solutions:
:class:`~acausal.compiler.artefact.Resolver`; the generated code's names:
:class:`~acausal.compiler.codegen.Names`). Rebuilding an expression after a
substitution evaluates every new node, and each new node asks sympy's
assumption system about itself: on the planar breaker's candidates that was
most of a model's code generation (the event conditions' square roots and
relations), and 88 % of the resolved and 91 % of the renamed expressions of
twelve candidates were ones an earlier candidate had already substituted
with the same values.

:func:`substitute` gives what ``expr.xreplace(mapping)`` gives (each distinct
sub-expression rebuilt once: :func:`replace_shared`) and remembers it under
``expr`` and the mapping's entries for the symbols of ``expr``, which are all
that the result depends on when every key is a symbol
(:class:`Substitution`). The same expression object is returned for the
same input, so what is generated from it is the same text.
"""
from collections import OrderedDict
import os
import threading

import sympy as sp

MEMO_SIZE = 40_000    # remembered substitutions per process (least recently used dropped)
_memo = OrderedDict()
_lock = threading.Lock()


def _new_lock_in_child():
    # a lock copied by fork while another thread held it would stay locked
    global _lock
    _lock = threading.Lock()


os.register_at_fork(after_in_child=_new_lock_in_child)


class Substitution:
    """A mapping of symbols to expressions (``items``: a dict), and whether
    every key is a :class:`sympy.Symbol` (``by_symbol``): only then is a
    substitution remembered across models (a compound key could match a
    sub-tree whose symbols do not show it)."""

    __slots__ = ("items", "by_symbol")

    def __init__(self, items, by_symbol=None):
        self.items = items           # (not copied: read at each substitution)
        self.by_symbol = (all(isinstance(k, sp.Symbol) for k in items)
                          if by_symbol is None else by_symbol)


def replace_shared(expr, mapping, memo=None):
    """``expr.xreplace(mapping)`` that rebuilds each distinct sub-expression
    once (``memo``: node -> its replacement, shared across calls). sympy's
    xreplace walks the tree, so a sub-expression shared by many parents
    (the chain rule's products in sensitivity equations) is rebuilt once
    per path to it: 1.2 million rebuilds for the breaker's observed
    variables with three parameters' sensitivities."""
    memo = {} if memo is None else memo

    def walk(e):
        hit = memo.get(e)
        if hit is not None:
            return hit
        if e in mapping:
            out = mapping[e]
        elif not e.args:
            out = e
        else:
            args = [walk(a) for a in e.args]
            out = e.func(*args) if any(a is not b for a, b in zip(args, e.args)) else e
        memo[e] = out
        return out
    return walk(expr)


def substitute(expr, sub, memo=None):
    """``expr.xreplace(sub.items)`` (:class:`Substitution` ``sub``), remembered
    across calls and models by ``expr`` and the entries of ``sub`` for its
    symbols; ``memo`` as :func:`replace_shared`'s (within one batch)."""
    if not sub.items:
        return expr
    if not sub.by_symbol:
        return replace_shared(expr, sub.items, memo)
    items = sub.items
    used = frozenset((s, items[s]) for s in expr.atoms(sp.Symbol) if s in items)
    if not used:
        return expr
    key = (expr, used)
    with _lock:
        out = _memo.get(key)
        if out is not None:
            _memo.move_to_end(key)
            return out
    out = replace_shared(expr, items, memo)
    with _lock:
        _memo[key] = out
        if len(_memo) > MEMO_SIZE:
            _memo.popitem(last=False)
    return out
