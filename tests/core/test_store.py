"""The one on-disk store (acausal/infra/store.py): namespaces under one
variable, $ACAUSAL_CACHE; off disables all but what must live in a file;
the old $ACAUSAL_CACHE_DIR is read with a DeprecationWarning; writes are
atomic; compiled models and sensitivity models land in their namespaces
and are read back with identical results."""
from pathlib import Path

import numpy as np
import pytest

from acausal import Model, compile_model
from acausal.infra import store
from acausal.mechanics.translational import Fixed, Mass, Spring


@pytest.fixture
def root(tmp_path, monkeypatch):
    monkeypatch.setenv("ACAUSAL_CACHE", str(tmp_path))
    monkeypatch.delenv("ACAUSAL_CACHE_DIR", raising=False)
    return tmp_path


def _oscillator(c=100.0):
    m = Model()
    m.ground = Fixed()
    m.mass = Mass(m=1.0, s=0.1, v=0.0)
    m.spring = Spring(c=c)
    m.connect(m.ground.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.mass.flange)
    return m


def test_every_namespace_lives_under_the_one_variable(root):
    assert store.cache_dir() == root
    for name in store.NAMESPACES:
        assert store.namespace(name) == root / name
    with pytest.raises(ValueError, match="no store namespace"):
        store.namespace("elsewhere")


def test_off_disables_all_but_what_must_be_a_file(monkeypatch):
    monkeypatch.setenv("ACAUSAL_CACHE", "off")
    monkeypatch.delenv("ACAUSAL_CACHE_DIR", raising=False)
    assert not store.enabled() and store.namespace("compile") is None
    assert store.read_bytes("compile", "k.pkl") is None
    assert store.write_bytes("sensitivity", "k.json", b"{}") is False
    assert store.namespace("c-build", required=True) == store.default_root() / "c-build"


def test_the_old_variable_is_read_with_a_deprecation_warning(root, tmp_path, monkeypatch):
    old = tmp_path / "libs"
    monkeypatch.setenv("ACAUSAL_CACHE_DIR", str(old))
    with pytest.warns(DeprecationWarning, match="ACAUSAL_CACHE_DIR is deprecated"):
        assert store.namespace("c-build", required=True) == old / "c-build"
    assert store.namespace("compile") == root / "compile"      # it only ever located C


def test_writes_are_atomic(root):
    assert store.write_bytes("sensitivity", "a.json", b"one")
    target = root / "sensitivity" / "a.json"
    with pytest.raises(RuntimeError):
        with store.atomic(target) as tmp:
            Path(tmp).write_bytes(b"half written")
            raise RuntimeError("writer died")
    assert store.read_bytes("sensitivity", "a.json") == b"one"
    assert sorted(p.name for p in target.parent.iterdir()) == ["a.json"]   # no temporary left
    made = []
    assert store.make_once(root / "c-build" / "x.o", lambda: made.append(1)) is True
    (root / "c-build" / "x.o").write_bytes(b"")
    assert store.make_once(root / "c-build" / "x.o", lambda: made.append(2)) is False
    assert made == [1]


def test_compiled_and_sensitivity_models_are_kept_in_their_namespaces(root):
    """x = x0 cos(w t), w = sqrt(c/m): dx/dc = -x0 t sin(w t) / (2 m w)."""
    cm = compile_model(_oscillator())
    res = cm.simulate(t_end=0.5, rtol=1e-10, atol=1e-12, output_step=0.01,
                      sensitivities=["spring.c"])
    assert len(list((root / "compile").glob("*.pkl"))) == 1
    assert len(list((root / "sensitivity").glob("sens_*.json"))) == 1
    w = np.sqrt(100.0)
    np.testing.assert_allclose(res.sensitivity("mass.s", "spring.c"),
                               -0.1 * res.t * np.sin(w * res.t) / (2 * w), rtol=0, atol=1e-9)
    again = compile_model(_oscillator())          # a new model object: both read back
    assert again.cache_hit
    res2 = again.simulate(t_end=0.5, rtol=1e-10, atol=1e-12, output_step=0.01,
                          sensitivities=["spring.c"])
    assert np.array_equal(res2.sensitivity("mass.s", "spring.c"),
                          res.sensitivity("mass.s", "spring.c"))
    assert len(list((root / "sensitivity").glob("sens_*.json"))) == 1
