"""The compiled backend against the reference (scikit-sundae): every
simulation-test model, run with its file's options on both, must give the
same events in the same order, event times and measures within the solver
tolerance, and the same traces at the requested output times.

Both backends run the same IDA algorithm with the same settings; they differ
only in the round-off of the generated residual (C against Python), which
can change a Newton iteration or a step and so moves the solution by at most
IDA's global error: a multiple of the local tolerance. On the examples the
two agree to round-off or within ``AGREE = 20`` times ``rtol`` (relative to
each trace's largest value, or to the event time). The breaker's THRT
carries a global error of up to ~40 rtol on either backend (measured against
rtol 1e-11 over 41 impact speeds), so there the event times and measures are
checked for equal accuracy against a high-accuracy solution instead. Which backend ran is asserted, not assumed: without
a C compiler the compiled backend must say it fell back.
"""
import os

import numpy as np
import pytest

from acausal.backends import compiled_available
from acausal.modelfile import compile_file, evaluate_measures

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
AGREE = 20.0
_cache = {}


def _compiled(path):
    if path not in _cache:
        _cache[path] = compile_file(os.path.join(ROOT, path))
    return _cache[path]


def _check_agreement(path, params=None, times=True):
    mf, cm = _compiled(path)
    opts = mf.experiment.run_options()
    rtol = opts.get("rtol", 1e-6)
    a = cm.simulate(params=params, backend="sundae", **opts)
    b = cm.simulate(params=params, backend="compiled", **opts)
    assert a.stats["backend"] == "sundae"
    why = compiled_available()
    if why is None:
        assert b.stats["backend"] == "compiled", b.stats
    else:   # the fallback must be visible; the agreement then holds trivially
        assert b.stats["backend"] == "sundae" and why in b.stats["backend_fallback"]
    assert [n for _, n in a.events] == [n for _, n in b.events]
    span = a.t[-1] - a.t[0]
    ma, mb = evaluate_measures(mf, a), evaluate_measures(mf, b)
    assert ma.keys() == mb.keys()
    for (ta, name), (tb, _) in zip(a.events, b.events):
        assert not times or abs(ta - tb) <= AGREE * rtol * max(abs(ta), span), (name, ta, tb)
    for k in ma:
        assert not times or mb[k] == pytest.approx(ma[k], rel=AGREE * rtol, abs=1e-300), k
    # traces at the requested output times (rows at events sit at slightly
    # different instants on the two backends)
    events = {t for t, _ in a.events} | {t for t, _ in b.events}
    rows = np.array([t not in events for t in a.t])
    assert len(a.t) == len(b.t)
    np.testing.assert_allclose(a.t[rows], b.t[rows], rtol=0, atol=1e-12 * max(span, 1.0))
    for names in cm.slot_names()[:cm.dae.n_states]:
        xa, xb = a[names[-1]][rows], b[names[-1]][rows]
        scale = np.max(np.abs(a[names[-1]]))
        assert np.max(np.abs(xa - xb)) <= AGREE * rtol * scale + 1e-300, names[-1]
    return a, b


@pytest.mark.parametrize("model", ["oscillator", "hertz_impact", "stick_slip"])
def test_examples_agree(model):
    _check_agreement(f"models/examples/{model}.py")


@pytest.mark.slow
@pytest.mark.parametrize("model", ["newtons_cradle", "fourbar", "lever_masses"])
def test_larger_examples_agree(model):
    _check_agreement(f"models/examples/{model}.py")


@pytest.mark.slow
@pytest.mark.parametrize("v", [3.3, 3.8, 4.2, 4.5])
def test_breaker_agrees_at_several_impact_speeds(v):
    """Events in the same order and traces within 20 rtol; event times and
    measures: see the next test (the breaker's THRT carries a global error
    of up to ~40 rtol on either backend, so a fixed multiple of rtol between
    the two is no criterion)."""
    a, b = _check_agreement("models/breaker_24kv.py", {"v_impact": v}, times=False)
    assert a.event_times("release") and b.event_times("release")


@pytest.mark.slow
def test_breaker_backends_are_equally_accurate():
    """Against an independent high-accuracy solution (the reference backend
    at rtol 1e-11, atol 1e-14), over impact speeds 3-5 m/s, the compiled
    backend's largest error in each measure is at most twice the reference
    backend's (plus one rtol), and the other way round: both carry the
    method's global error at the file's tolerance, neither more."""
    mf, cm = _compiled("models/breaker_24kv.py")
    opts = mf.experiment.run_options()
    rtol = opts["rtol"]
    tight = dict(opts, rtol=1e-11, atol=1e-14)
    names = ("thrt", "contact_period", "peak_force")
    worst = {b: dict.fromkeys(names, 0.0) for b in ("sundae", "compiled")}
    for v in np.linspace(3.0, 5.0, 11):
        params = {"v_impact": float(v)}
        ref = evaluate_measures(mf, cm.simulate(params=params, backend="sundae", **tight))
        for backend in worst:
            m = evaluate_measures(mf, cm.simulate(params=params, backend=backend, **opts))
            for k in names:
                worst[backend][k] = max(worst[backend][k], abs(m[k] / ref[k] - 1))
    for k in names:
        s, c = worst["sundae"][k], worst["compiled"][k]
        assert c <= 2 * s + rtol and s <= 2 * c + rtol, (k, s, c)
        assert max(s, c) < 1e-5, (k, s, c)   # and both are accurate


def test_missing_compiler_falls_back_to_the_reference(monkeypatch, tmp_path):
    """No C compiler (CC names none, empty cache): the run completes on
    scikit-sundae and says why."""
    import weakref

    from acausal.backends import compiled
    monkeypatch.setattr(compiled, "_loaded", weakref.WeakKeyDictionary())  # nothing loaded
    monkeypatch.setenv("CC", str(tmp_path / "no-such-cc"))
    monkeypatch.setenv("ACAUSAL_CACHE_DIR", str(tmp_path))
    _, cm = compile_file(os.path.join(ROOT, "models/examples/oscillator.py"))
    res = cm.simulate(t_end=0.05, backend="compiled")
    assert res.stats["backend"] == "sundae"
    assert "no C compiler" in res.stats["backend_fallback"]
    assert res.status == "ok" and res.t[-1] == pytest.approx(0.05)
