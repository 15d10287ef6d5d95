"""The reference files against answers known without acausal: closed forms
and an independent scipy integration of the planar pendulum. These check
the vendored data, the harness and docs/msl_laws.md's reading of the
examples (signs, initial conditions, World's gravity) together; they are
skipped where the reference files are absent."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from tests.msl.harness import assert_matches, compare, reference_or_skip


def with_events(t_end, n, events):
    """A grid with both sides of every event time."""
    t = np.linspace(0.0, t_end, n)
    return np.sort(np.concatenate([t, events, events]))


def after(t, t_event):
    """True at the points after an event (the second of its pair on)."""
    k = int(np.searchsorted(t, t_event, side="left"))
    out = t > t_event
    out[k + 1:] = True
    return out


def test_accelerate_is_half_t_squared():
    reference_or_skip("Translational.Accelerate")
    t = np.linspace(0.0, 1.0, 1001)
    assert_matches("Translational.Accelerate", {"time": t, "accelerate.s": t * t / 2,
                                                "accelerate.v": t})


def test_sign_convention_pushes_every_mass_forward():
    reference_or_skip("Translational.SignConvention")
    t = np.linspace(0.0, 1.0, 1001)
    res = {"time": t}
    for m in ("mass1", "mass2", "mass3"):
        res[m + ".s"], res[m + ".v"] = t * t / 2, t
    assert_matches("Translational.SignConvention", res)
    res["mass2.v"] = -t                        # a sign error is caught
    assert not compare("Translational.SignConvention", res).passed


def test_brake_stops_the_masses_at_1_1_s_with_modes_free_forward_stuck():
    reference_or_skip("Translational.Brake")
    t = with_events(2.0, 2001, [0.1, 1.1])
    on, stuck = after(t, 0.1), after(t, 1.1)
    v = np.where(stuck, 0.0, np.where(on, 1.0 - (t - 0.1), 1.0))
    s = np.where(stuck, 0.6, np.where(on, 0.1 + (t - 0.1) - (t - 0.1) ** 2 / 2, t))
    mode = np.where(stuck, 0.0, np.where(on, 1.0, 2.0))
    zero = np.zeros(t.size)
    res = {"time": t}
    for m, b in (("mass1", "brake"), ("mass2", "brake1")):
        res.update({m + ".s": s, m + ".v": v, b + ".mode": mode,
                    b + ".startForward": zero, b + ".startBackward": zero})
    assert_matches("Translational.Brake", res)
    late = dict(res, **{"brake.mode": np.where(t > 1.11, 0.0, np.where(t > 0.1, 1.0, 2.0))})
    cmp = compare("Translational.Brake", late)
    assert cmp.failed == ["brake.mode"]


@pytest.mark.parametrize("g, ok", [(9.80665, True), (9.81, False)])
def test_pendulum_planar_law_with_worlds_gravity(g, ok):
    reference_or_skip("MultiBody.Pendulum")
    m, r, d = 1.0, 0.5, 0.1
    J = 0.001 + m * r * r                      # Body's default I_33 plus m r^2

    def rhs(_, x):
        return [x[1], (-m * g * r * np.cos(x[0]) - d * x[1]) / J]

    t = np.linspace(0.0, 5.0, 2501)
    sol = solve_ivp(rhs, (0.0, 5.0), [0.0, 0.0], t_eval=t, rtol=1e-10, atol=1e-12)
    cmp = compare("MultiBody.Pendulum", {"time": t, "rev.phi": sol.y[0], "rev.w": sol.y[1]},
                  tol=1e-4)                    # ten times tighter than issue #23's tube
    assert cmp.passed is ok, cmp.message()
