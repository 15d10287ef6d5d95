"""The compiled backend builds its driver's C sources once per cache: each
model's library compiles only its own generated code and links the cached
driver objects."""
import glob
import os

import pytest

from acausal import compile_model
from acausal.mechanics.translational import Fixed, Mass, Spring
from acausal.lang.component import Model


def _oscillator(c):
    m = Model()
    m.mass = Mass(m=1.0, s=0.1, v=0.0)
    m.spring = Spring(c=c)
    m.ground = Fixed()
    m.connect(m.ground.flange, m.spring.flange_a)
    m.connect(m.spring.flange_b, m.mass.flange)
    return m


def test_driver_objects_built_once_and_shared(tmp_path, monkeypatch):
    pytest.importorskip("acausal.runtime.backends.compiled")
    from acausal.runtime.backends import compiled
    try:
        compiled._compiler()
    except compiled.Unavailable:
        pytest.skip("no C compiler")
    monkeypatch.setenv("ACAUSAL_CACHE_DIR", str(tmp_path))
    a = compile_model(_oscillator(100.0), cache=False)
    m2 = _oscillator(100.0)
    m2.mass2 = Mass(m=2.0)            # another structure (rigidly joined): another library
    m2.connect(m2.mass.flange, m2.mass2.flange)
    b = compile_model(m2, cache=False)
    ra = a.simulate(t_end=0.5, backend="compiled")
    rb = b.simulate(t_end=0.5, backend="compiled")
    d = os.path.join(str(tmp_path), "compiled")
    assert len(glob.glob(os.path.join(d, "acs_*.so"))) == 2
    assert len(glob.glob(os.path.join(d, "ida_driver_*.o"))) == 1
    assert len(glob.glob(os.path.join(d, "reinit_*.o"))) == 1
    # closed forms: x = 0.1 cos(w t), w^2 = c/m
    import numpy as np
    for r, m in ((ra, 1.0), (rb, 3.0)):
        w = np.sqrt(100.0 / m)
        assert np.allclose(r["mass.s"], 0.1 * np.cos(w * r.t), atol=1e-5)
