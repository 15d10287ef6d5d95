"""The constant-pivot elimination's trigsimp is asked only about entries
that could be parameters-only (acausal.causalize._moves)."""
import sympy as sp

from acausal import causalize as C


def _setup():
    I, m, r, e = sp.symbols("I m r e", positive=True)
    phi, th = sp.symbols("phi th")
    params = {I, m, r, e}
    values = {I: 0.02, m: 1.5, r: 0.1, e: 0.03, phi: 0.4, th: -0.2}
    return I, m, r, e, phi, th, params, values


def test_identity_in_disguise_does_not_move():
    I, m, r, _, phi, _, params, values = _setup()
    a = I + m * r**2 * (sp.sin(phi)**2 + sp.cos(phi)**2)
    assert not C._moves(a, params, values)


def test_entry_of_a_linkage_moves():
    _, _, _, e, phi, th, params, values = _setup()
    a = e**2 * sp.sin(th + phi) * sp.cos(phi)
    assert C._moves(a, params, values)


def test_unknown_value_is_not_judged():
    _, _, _, e, phi, _, params, values = _setup()
    psi = sp.Symbol("psi")            # no start value: cannot be evaluated
    assert not C._moves(e * sp.sin(psi + phi), params, values)


def test_simplified_pivot_skips_trigsimp_for_moving_entries(monkeypatch):
    I, m, r, e, phi, th, params, values = _setup()
    M = sp.Matrix([[e**2 * sp.sin(th + phi) * sp.cos(phi), 1],
                   [1, I + m * r**2 * (sp.sin(phi)**2 + sp.cos(phi)**2)]])
    asked = []
    real = sp.trigsimp
    monkeypatch.setattr(C.sp, "trigsimp", lambda a: asked.append(a) or real(a))
    best = C._simplified_pivot(M, 0, params, values)
    assert len(asked) == 1                       # only the (1, 1) entry
    assert best is not None and best[1:] == (1, 1)
    assert sp.simplify(M[1, 1] - (I + m * r**2)) == 0
