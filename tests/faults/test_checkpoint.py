"""acausal.infra.checkpoint: damaged lines are ignored, later appends stay intact,
values round-trip, and the inputs' hash changes with any input."""
import math
from pathlib import Path

import numpy as np
import pytest

from acausal.infra.checkpoint import Checkpoint, input_key


def test_truncated_and_damaged_lines_are_ignored_and_appends_stay_whole(tmp_path):
    store = Checkpoint(tmp_path / "ck", "abc")
    for i in range(3):
        store.append(f"p{i}", {"x": float(i), "tag": f"t{i}"})
    raw = store.path.read_bytes()
    lines = raw.split(b"\n")
    flipped = lines[1].replace(b'"x":1.0', b'"x":7.0')       # a damaged record
    store.path.write_bytes(b"\n".join([lines[0], flipped, lines[2]]) + b"\n" + lines[2][:25])
    assert store.load() == {"p0": {"x": 0.0, "tag": "t0"}, "p2": {"x": 2.0, "tag": "t2"}}
    assert store.ignored == 2                                 # the damaged and the cut line
    store.append("p1", {"x": 1.0, "tag": "t1"})               # after the cut line
    assert store.load()["p1"] == {"x": 1.0, "tag": "t1"} and store.ignored == 1


def test_values_round_trip(tmp_path):
    store = Checkpoint(tmp_path, "k")
    value = {"a": np.arange(6.0).reshape(2, 3), "t": (1, "x", None), "nan": math.nan,
             "inf": -math.inf, "ints": {1: np.int64(3)}, "ok": np.bool_(True)}
    store.append("v", value)
    got = store.load()["v"]
    np.testing.assert_array_equal(got["a"], value["a"])
    assert got["a"].dtype == np.float64 and got["t"] == (1, "x", None)
    assert math.isnan(got["nan"]) and got["inf"] == -math.inf
    assert got["ints"] == {1: 3} and got["ok"] is True


def test_unknown_dataclass_is_refused(tmp_path):
    from dataclasses import dataclass

    @dataclass
    class Thing:
        x: float

    with pytest.raises(TypeError, match="Thing"):
        Checkpoint(tmp_path, "k").append("t", Thing(1.0))
    store = Checkpoint(tmp_path, "k", types=(Thing,))
    store.append("t", Thing(2.0))
    assert store.load() == {"t": Thing(2.0)}
    assert Checkpoint(tmp_path, "k").load() == {}  # a store without the type skips it


def test_input_key_follows_file_contents_and_options(tmp_path):
    model = tmp_path / "m.py"
    model.write_text("a = 1\n")
    data = tmp_path / "data"
    data.mkdir()
    (data / "e.csv").write_text("t,x\n0,1\n")
    base = input_key(model, data, {"t_end": 1.0})
    assert input_key(model, data, {"t_end": 1.0}) == base
    assert input_key(model, data, {"t_end": 2.0}) != base
    model.write_text("a = 2\n")
    assert input_key(model, data, {"t_end": 1.0}) != base
    model.write_text("a = 1\n")
    (data / "e.csv").write_text("t,x\n0,2\n")
    assert input_key(model, data, {"t_end": 1.0}) != base


def test_discard_removes_the_store_and_an_empty_folder(tmp_path):
    a, b = Checkpoint(tmp_path / "ck", "a"), Checkpoint(tmp_path / "ck", "b")
    a.append("x", 1.0)
    b.append("x", 2.0)
    a.discard()
    assert not a.path.exists() and b.load() == {"x": 2.0}
    b.discard()
    assert not Path(tmp_path / "ck").exists()
