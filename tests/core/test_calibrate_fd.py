"""The finite differences of the least squares (acausal.calibrate.ForwardDifferences)."""
import numpy as np
import pytest

from acausal.studies.calibrate import ForwardDifferences


def test_forward_differences_absolute_step_and_reuse():
    calls = []

    def fun(z):
        calls.append(np.array(z))
        return np.array([z[0] ** 2, 3.0 * z[1], z[0] * z[1]])

    fd = ForwardDifferences(fun, 1e-3, hi=[np.inf, 1.0])
    z = np.array([0.0, 1.0])            # at 0 the step is still 1e-3, not 1e-3 * |z|
    fd(z)
    J = fd.jac(z)
    assert len(calls) == 3                # the residual at z reused: one call per variable
    assert calls[1][0] == pytest.approx(1e-3)          # forward in z0
    assert calls[2][1] == pytest.approx(1.0 - 1e-3)    # backward at the upper bound of z1
    np.testing.assert_allclose(J, [[1e-3, 0.0], [0.0, 3.0], [1.0, 0.0]], atol=1e-12)


@pytest.mark.slow   # 4 s; the breaker's 110 V intervals also in test_breaker_calibration
def test_breaker_110V_intervals_from_the_right_jacobian():
    """At 110 V the contact period fixes K to within the reading step: its
    sensitivity to log K is -0.4 x 0.3 ms = -4.3 floors, so the 95 % interval
    of log K is about +-1.96 / 4.3 = +-0.46 (a relative step that shrinks with
    |log(K/K0)| gave +-0.023)."""
    import os

    from acausal.studies import calibrate as cal
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    model = os.path.join(root, "models", "breaker_24kv.py")
    ds, _ = cal.split(cal.model_dataset(model, os.path.join(root, "data", "report_24kv")))
    out = cal.least_squares(model, ds, ["contact.K", "hook.bh"])
    K = out.values["contact.K"]
    lo, hi = out.ci95["contact.K"]
    assert np.log(hi / K) == pytest.approx(1.96 / 4.3, rel=0.05)
    assert np.log(K / lo) == pytest.approx(1.96 / 4.3, rel=0.05)
    assert abs(out.correlation[0, 1]) < 0.3
