"""The constant-pivot elimination's trigsimp is asked only about entries
that could be parameters-only (acausal.causalize._moves)."""
import sympy as sp

from acausal.compiler import causalize as C


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


def _velocity_block():
    """A four-bar's velocity block: pin C's rates (vx, vy) and the rocker's
    and coupler's (ws, wc), the crank's rate w given; rocker r1 at angle ps,
    coupler L at angle pc. Its determinant is r1*L*sin(pc - ps)."""
    r1, L, w = sp.symbols("r1 L w")
    ps, pc = sp.symbols("ps pc")
    vx, vy, ws, wc = sp.symbols("vx vy ws wc")
    exprs = [vx + r1 * sp.sin(ps) * ws, vy - r1 * sp.cos(ps) * ws,
             vx - L * sp.sin(pc) * wc + w, vy + L * sp.cos(pc) * wc - 2 * w]
    return exprs, [vx, vy, ws, wc], {r1, L}, (r1, L, w, ps, pc)


def test_velocity_block_divides_only_by_its_determinant():
    """Pivots chosen at the start values (here the rocker at -0.5 rad) made
    r1*cos(ps) a divisor, zero with the rocker vertical although the block is
    regular there; eliminated on the constant pivots and solved by Cramer's
    rule, the solution is finite there and solves the block."""
    exprs, us, params, (r1, L, w, ps, pc) = _velocity_block()
    start = {r1: 0.08, L: 0.09, w: 1.0, ps: -0.5, pc: 0.6}
    x = C._solve_linear_block(exprs, us, params, start)
    vertical = {**start, ps: -sp.pi / 2}
    for e in exprs:
        assert abs(float(e.xreplace(dict(zip(us, x))).xreplace(vertical))) < 1e-12
    for xi in x:
        den = sp.denom(sp.together(xi))
        assert sp.simplify(den.xreplace(vertical)) != 0
        # every divisor is (a multiple of) the determinant r1*L*sin(pc - ps)
        ratio = sp.simplify(sp.expand_trig(den / (r1 * L * sp.sin(pc - ps))))
        assert ratio.free_symbols <= params


def test_a_parameter_pivot_keeps_the_start_values_pivots():
    """After a pivot that is a parameter (a hook's inertia, 1e-30 kg m^2 in a
    test) the rest is not solved by Cramer's rule: None, and the caller
    falls back to the start values' pivots."""
    J = sp.Symbol("J", positive=True)
    a, b, c = sp.symbols("a b c")
    A = sp.Matrix([[J, 1, 0], [1, sp.sin(a), sp.cos(b)], [0, sp.cos(a), sp.sin(b)]])
    rhs = sp.Matrix([1, 0, c])
    values = {J: 1.0, a: 0.3, b: 0.4, c: 1.0}
    assert C._constant_pivot_solve(A, rhs, {J}, values) is None


def test_semi_explicit_replaces_a_derivative_link_in_the_other_rows():
    q, w, a, f = sp.symbols("q w a f")
    qp, wp = sp.symbols("__yp__q wp")          # wp: the derivative of the state w
    dae = C.DAE(y=[q, w, a], yp=[qp, wp, None], n_states=2,
                residuals=[qp - w, wp - a, 2 * wp + q - f], origins=[None] * 3, explicit={})
    out = C.semi_explicit(dae)
    assert out.residuals == [qp - w, wp - a, 2 * a + q - f]
    assert dae.residuals[2] == 2 * wp + q - f            # the input is left as it was
    # a derivative given as an expression stays where it is
    dae2 = C.DAE(y=[q, w, a], yp=[qp, wp, None], n_states=2,
                 residuals=[qp - w, wp - q**2, 2 * wp + a - f], origins=[None] * 3, explicit={})
    assert C.semi_explicit(dae2) is dae2
