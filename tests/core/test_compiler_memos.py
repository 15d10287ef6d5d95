"""The compiler's per-process memos (compiler/substitute.py, the derivative
memo of lang/fastdiff.py, codegen.PrintMemo) return exactly what the
computation would: a remembered result is never reused where the inputs that
shape it differ."""
import random

import sympy as sp

from acausal.compiler.codegen import PrintMemo, repeated_subexpressions
from acausal.compiler.codegen_c import _Printer as CPrinter
from acausal.compiler.substitute import Substitution, substitute
from acausal.lang.fastdiff import diff

x, y, z, w = sp.symbols("x y z w", real=True)


def _random_expr(rng, depth=3):
    if depth == 0:
        return rng.choice([x, y, z, w, sp.Integer(rng.randint(1, 4)), sp.Rational(1, 3)])
    a, b = _random_expr(rng, depth - 1), _random_expr(rng, depth - 1)
    op = rng.choice(["add", "mul", "pow", "sin", "sqrt", "pw"])
    if op == "add":
        return a + b
    if op == "mul":
        return a * b
    if op == "pow":
        return a ** rng.randint(2, 3)
    if op == "sin":
        return sp.sin(a)
    if op == "sqrt":
        return sp.sqrt(a ** 2 + 1)
    return sp.Piecewise((a, b > 0), (b, True))


def test_substitute_is_xreplace_and_keyed_by_the_values_used():
    rng = random.Random(7)
    for _ in range(60):
        e = _random_expr(rng)
        for m in ({x: y + 1}, {x: y + 2}, {x: w, z: 3 * y}, {w: x}, {}):
            assert substitute(e, Substitution(m)) == e.xreplace(m)
    # the same expression again under a mapping that differs only in an
    # entry it uses: a new result, not the remembered one
    e = sp.sin(x) + z
    assert substitute(e, Substitution({x: y})) == sp.sin(y) + z
    assert substitute(e, Substitution({x: 2 * y})) == sp.sin(2 * y) + z
    # an entry for a symbol the expression lacks does not matter
    assert substitute(e, Substitution({x: y, w: 5})) == sp.sin(y) + z


def test_a_compound_key_is_substituted_without_the_memo():
    e = sp.sin(x) * y + sp.sin(x)
    sub = Substitution({sp.sin(x): w})
    assert not sub.by_symbol
    assert substitute(e, sub) == e.xreplace({sp.sin(x): w}) == w * y + w


def test_remembered_derivatives_are_sympys():
    rng = random.Random(3)
    for _ in range(60):
        e = _random_expr(rng)
        for s in (x, y):
            first, again = diff(e, s), diff(e, s)
            assert again is first
            assert sp.simplify(first - sp.diff(e, s)) == 0


def _c_body(exprs, memo):
    """(lines, printed) as codegen_c._body writes them, through ``memo``."""
    repeated = repeated_subexpressions(exprs)
    names = {e: f"c_{k}" for k, e in enumerate(repeated)}
    printer = CPrinter(names)
    return ([memo.definition(printer, e) for e in repeated],
            [memo.definition(printer, e) for e in exprs])


def _fresh_c_body(exprs):
    repeated = repeated_subexpressions(exprs)
    names = {e: f"c_{k}" for k, e in enumerate(repeated)}
    printer = CPrinter(names)
    return ([printer.definition(e) for e in repeated], [printer.definition(e) for e in exprs])


def test_a_printed_definition_is_reused_only_under_the_same_names():
    shared = sp.sqrt(x ** 2 + y ** 2)
    target = sp.sin(shared) * shared + z
    memo = PrintMemo()
    # one model: the shared square root is c_0
    a = _c_body([target, shared * w], memo)
    assert a == _fresh_c_body([target, shared * w])
    # another model where an earlier expression shifts the names: the
    # remembered text of ``target`` (naming c_0) must not be reused
    other = sp.cos(z) * sp.cos(z) ** 2 + sp.cos(z)
    b = _c_body([other, target, shared * w], memo)
    assert b == _fresh_c_body([other, target, shared * w])
    assert a[1][0] != b[1][1]                     # target's text changed with its names
    # and with no common sub-expression at all
    c = _c_body([target], memo)
    assert c == _fresh_c_body([target])


def test_printed_definitions_match_fresh_printing_on_random_systems():
    rng = random.Random(11)
    memo = PrintMemo()
    for _ in range(40):
        exprs = [_random_expr(rng) for _ in range(rng.randint(2, 6))]
        exprs = [e for e in exprs if not e.is_Atom] or [x + y]
        assert _c_body(exprs, memo) == _fresh_c_body(exprs)


def test_a_forked_worker_does_not_inherit_a_held_memo_lock():
    """A pool forks its workers while another thread of the parent may hold
    a memo's lock: the child gets fresh locks (else its first compile would
    wait forever)."""
    import os
    import sys
    if not hasattr(os, "fork"):
        import pytest
        pytest.skip("no fork here")
    from acausal.compiler import substitute as S
    from acausal.compiler.codegen_c import _PRINTED
    S._lock.acquire()
    _PRINTED._lock.acquire()
    try:
        pid = os.fork()
        if pid == 0:
            free = S._lock.acquire(timeout=2) and _PRINTED._lock.acquire(timeout=2)
            sys.stdout.flush()
            os._exit(0 if free else 1)
        _, status = os.waitpid(pid, 0)
    finally:
        S._lock.release()
        _PRINTED._lock.release()
    assert os.waitstatus_to_exitcode(status) == 0
