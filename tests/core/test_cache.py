"""The on-disk compiled-model cache (acausal.cache): a second compile of the
same model is a hit with identical results; any change to the model misses;
corrupt entries are rebuilt; the cache can be disabled."""
import numpy as np
import pytest

from acausal import Model, compile_model
from acausal.infra.store import cache_dir
from acausal.mechanics.translational import Damper, Fixed, Mass, Spring


def two_masses(c=200.0, damper=False, s0=0.05):
    """Two masses on springs (independent of the library's examples)."""
    m = Model()
    m.ground = Fixed()
    m.a = Mass(m=1.5, s=s0, v=0.0)
    m.b = Mass(m=0.5, s=0.0, v=0.0)
    m.k1 = Spring(c=c)
    m.k2 = Spring(c=80.0)
    m.connect(m.ground.flange, m.k1.flange_a)
    m.connect(m.k1.flange_b, m.a.flange, m.k2.flange_a)
    m.connect(m.k2.flange_b, m.b.flange)
    if damper:
        m.d = Damper(d=3.0)
        m.connect(m.ground.flange, m.d.flange_a)
        m.connect(m.d.flange_b, m.b.flange)
    return m


@pytest.fixture
def cache(tmp_path, monkeypatch):
    monkeypatch.setenv("ACAUSAL_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache"


def run(cm):
    return cm.simulate(t_end=0.5, rtol=1e-9, atol=1e-12, output_step=0.01)


def test_second_compile_is_a_hit_with_identical_results(cache):
    cm1 = compile_model(two_masses())
    assert not cm1.cache_hit and len(list(cache.glob("compile/*.pkl"))) == 1
    cm2 = compile_model(two_masses())
    assert cm2.cache_hit and cm2.source == cm1.source
    r1, r2 = run(cm1), run(cm2)
    assert np.array_equal(r1.t, r2.t) and np.array_equal(r1["b.s"], r2["b.s"])
    assert r1.stats["nfev"] == r2.stats["nfev"]
    # what the cache restores still answers questions about the model
    assert cm2.dae.n_states == cm1.dae.n_states
    assert [s.name for s in cm2.dae.y] == [s.name for s in cm1.dae.y]
    assert np.allclose(r2["k1.f"], 200.0 * r2["a.s"])   # an eliminated variable


def test_a_changed_model_misses(cache):
    compile_model(two_masses())
    assert not compile_model(two_masses(c=300.0)).cache_hit        # a parameter value
    assert not compile_model(two_masses(s0=0.06)).cache_hit        # a start value
    changed = compile_model(two_masses(damper=True))               # the structure
    assert not changed.cache_hit and len(list(cache.glob("compile/*.pkl"))) == 4
    # it is the damped model that runs, not the cached undamped one
    assert not np.allclose(run(changed)["b.s"], run(compile_model(two_masses()))["b.s"],
                           rtol=1e-3, atol=1e-6)


def test_corrupt_entry_is_rebuilt(cache):
    compile_model(two_masses())
    (entry,) = cache.glob("compile/*.pkl")
    entry.write_bytes(b"not a pickle")
    cm = compile_model(two_masses())
    assert not cm.cache_hit
    assert run(cm).status == "ok"
    assert compile_model(two_masses()).cache_hit                   # rewritten


def test_cache_can_be_disabled(tmp_path, monkeypatch):
    monkeypatch.setenv("ACAUSAL_CACHE", "off")
    assert cache_dir() is None
    assert not compile_model(two_masses()).cache_hit
    assert not compile_model(two_masses()).cache_hit
    monkeypatch.setenv("ACAUSAL_CACHE", str(tmp_path))
    compile_model(two_masses(), cache=False)
    assert not list(tmp_path.glob("**/*.pkl"))


def _entry(cm):
    from acausal.compiler import cache as compile_cache
    return compile_cache.load(cm.artefact.build.key)


def test_the_python_source_is_written_at_its_first_use_and_kept(cache):
    """A model the compiled backend runs never needs its generated Python
    (its callbacks are C): the source is written when a run first needs it,
    then kept in the store, and it is the source an eager compile writes."""
    from acausal.runtime.backends import compiled_available
    why = compiled_available()
    if why:
        pytest.skip(f"no compiled backend: {why}")
    cm = compile_model(two_masses(damper=True))
    assert _entry(cm).source is None
    rc = cm.simulate(t_end=0.5, rtol=1e-9, atol=1e-12, output_step=0.01, backend="compiled")
    assert rc.stats["backend"] == "compiled"
    assert _entry(cm).source is None           # the C run did not write it
    rs = cm.simulate(t_end=0.5, rtol=1e-9, atol=1e-12, output_step=0.01, backend="sundae")
    np.testing.assert_allclose(rs["b.s"], rc["b.s"], atol=1e-8)
    kept = _entry(cm).source
    assert kept is not None and kept == cm.source
    again = compile_model(two_masses(damper=True))
    assert again.cache_hit and again.source == kept
    fresh = compile_model(two_masses(damper=True), cache=False)
    assert fresh.source == kept                # written at once or later: one text


def test_identity_fixes_the_equations(cache):
    """The stores of what is derived from the equations (compiled libraries,
    sensitivity models) are keyed by the model's identity: the same model
    has one, another structure or parameter value another; without the
    store it is the digest of the generated source."""
    import hashlib
    a, b = compile_model(two_masses()), compile_model(two_masses())
    assert a.identity() == b.identity()
    assert compile_model(two_masses(c=300.0)).identity() != a.identity()
    assert compile_model(two_masses(damper=True)).identity() != a.identity()
    off = compile_model(two_masses(), cache=False)
    assert off.identity() == hashlib.sha256(off.source.encode()).hexdigest()
