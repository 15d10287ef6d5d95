"""CombiTimeTable: interpolation, an event at every breakpoint,
extrapolation rules, CSV files and one clear line for a bad table."""
import numpy as np
import pytest

from acausal import Model, compile_model
from acausal.blocks import CombiTimeTable
from acausal.errors import AcausalError, DataError, ModelError, ParameterError
from acausal.mechanics.translational import Force, Mass

TABLE = [[0.0, 0.0, 10.0], [0.3, 1.0, 10.0], [0.3, 2.0, 5.0], [0.6, 0.0, 5.0], [1.0, 4.0, 0.0]]


def run(t_end=1.5, backend="sundae", **kw):
    m = Model()
    m.tab = CombiTimeTable(**kw)
    return compile_model(m, cache=False).simulate(t_end=t_end, backend=backend,
                                                  output_step=1e-3)


def away(res, instants):
    keep = np.ones(res.t.size, bool)
    for te in instants:
        keep &= np.abs(res.t - te) > 1e-9
    return keep


@pytest.mark.parametrize("backend", ["sundae", "compiled"])
def test_linear_interpolation_events_and_a_jump(backend):
    res = run(table=TABLE, backend=backend, t_end=1.0)
    assert [t for t, _ in res.events] == [0.3, 0.6]          # t = 0 is the start
    assert all(n == "tab.breakpoint" for _, n in res.events)
    T = np.array(TABLE)
    k = away(res, [0.3])
    ref1 = np.where(res.t < 0.3, np.interp(res.t, T[:2, 0], T[:2, 1]),
                    np.interp(res.t, T[2:, 0], T[2:, 1]))
    assert np.max(np.abs(res["tab.y1"][k] - ref1[k])) < 1e-12
    j = np.flatnonzero(res.t == 0.3)
    assert list(res["tab.y1"][j]) == [1.0, 2.0]              # the jump at the repeated time
    assert list(res["tab.y2"][j]) == [10.0, 5.0]


def test_extrapolation_rules():
    t = None
    for rule, after in (("LastTwoPoints", lambda t: 4.0 + 10 * (t - 1.0)),
                        ("HoldLastPoint", lambda t: 4.0 + 0 * t)):
        res = run(table=TABLE, columns=2, extrapolation=rule, t_end=1.5)
        t = res.t
        late = t > 1.0 + 1e-9
        assert np.max(np.abs(res["tab.y1"][late] - after(t[late]))) < 1e-12, rule
    res = run(table=[[0, 0], [1, 2], [2, 0]], extrapolation="Periodic", t_end=5.0)
    k = away(res, [1, 2, 3, 4])
    tri = lambda t: 2 - np.abs(2 * np.mod(t, 2) - 2)  # noqa: E731
    assert np.max(np.abs(res["tab.y1"][k] - tri(res.t[k]))) < 1e-12
    assert [t for t, _ in res.events] == pytest.approx([1, 2, 3, 4], abs=1e-15)
    with pytest.raises(ModelError, match=r"tab: at time 1 s the run leaves the table's range "
                                         r"\[0, 1\] s \(extrapolation='NoExtrapolation'\)"):
        run(table=TABLE, extrapolation="NoExtrapolation", t_end=1.5)
    res = run(table=TABLE, extrapolation="NoExtrapolation", t_end=1.0)   # up to its end
    assert res.status == "ok" and res["tab.y1"][-1] == 4.0


def test_constant_segments_time_scale_shift_start_and_offset():
    res = run(table=[[0, 1], [1, 3], [2, 2]], smoothness="ConstantSegments", t_end=2.5)
    k = away(res, [1, 2])
    ref = np.where(res.t < 1, 1.0, np.where(res.t < 2, 3.0, 2.0 + (res.t - 2) * -1))
    assert np.max(np.abs(res["tab.y1"][k] - ref[k])) < 1e-12
    # model time = shiftTime + timeScale*T; offset added; offset alone before startTime
    res = run(table=[[0, 0], [1, 1]], timeScale=0.5, shiftTime=0.2, startTime=0.3,
              offset=10.0, extrapolation="HoldLastPoint", t_end=1.0)
    k = away(res, [0.3, 0.7])
    ref = 10.0 + np.where(res.t < 0.3, 0.0, np.clip((res.t - 0.2) / 0.5, 0, 1))
    assert np.max(np.abs(res["tab.y1"][k] - ref[k])) < 1e-12
    # (0.2: the table's first row, where it starts to interpolate)
    assert [t for t, _ in res.events] == pytest.approx([0.2, 0.3, 0.7], abs=1e-15)


def test_a_table_force_drives_a_mass():
    """A force ramp 0 -> 2 N over 0.5 s, then held: v(1) = 0.5 + 1 m/s."""
    m = Model()
    m.tab = CombiTimeTable(table=[[0, 0], [0.5, 2.0]], extrapolation="HoldLastPoint")
    m.force = Force()
    m.mass = Mass(m=1.0, s=0.0, v=0.0)
    m.connect(m.tab.y1, m.force.f)
    m.connect(m.force.flange, m.mass.flange)
    cm = compile_model(m, cache=False)
    for backend in ("sundae", "compiled"):
        res = cm.simulate(t_end=1.0, rtol=1e-10, atol=1e-12, backend=backend)
        assert abs(res["mass.v"][-1] - 1.5) < 1e-9
        # s(0.5) = 4 t^3/6, then v(0.5) = 0.5 and a = 2
        assert abs(res["mass.s"][-1] - (4 * 0.5 ** 3 / 6 + 0.5 * 0.5 + 2 * 0.5 ** 2 / 2)) < 1e-9


def test_csv_file_with_a_header_and_columns_by_name(tmp_path):
    f = tmp_path / "force.csv"
    f.write_text("# measured force\ntime,left,right\n0,0,1\n1,2,3\n")
    res = run(fileName=str(f), columns=("right", "left"), t_end=1.0)
    assert res.at("tab.y1", 0.5) == pytest.approx(2.0) and res.at("tab.y2", 0.5) == 1.0
    m = Model()
    m.tab = CombiTimeTable(fileName=str(f))
    assert len(m.tab.y) == 2 and m.tab.y[1].path == "tab.y2"


@pytest.mark.parametrize("text, line, reason", [
    ("0,0\n1,1\n0.5,2\n", 3, "time 0.5 is less than the time 1 of the row before"),
    ("0,0\n1,1\n1,2\n1,3\n", 4, "appears three times"),
    ("0,0\n1,1,3\n", 2, "row has 3 values, expected 2"),
    ("t,y\n0,0\n1,abc\n", 3, "y: 'abc' is not a finite number"),
])
def test_bad_table_files_name_file_and_line(tmp_path, text, line, reason):
    f = tmp_path / "bad.csv"
    f.write_text(text)
    with pytest.raises(DataError) as err:
        CombiTimeTable(fileName=str(f))
    msg = str(err.value)
    assert msg.startswith(f"{f}:{line}: ") and reason in msg and "\n" not in msg


def test_bad_tables_in_one_line(tmp_path):
    with pytest.raises(DataError, match="table file not found"):
        CombiTimeTable(fileName=str(tmp_path / "missing.csv"))
    with pytest.raises(ModelError, match=r"CombiTimeTable table row 3: time 0.5 is less"):
        CombiTimeTable(table=[[0, 0], [1, 1], [0.5, 2]])
    with pytest.raises(ParameterError, match=r"shape \(3,\)"):
        CombiTimeTable(table=[0, 1, 2])
    with pytest.raises(ParameterError, match=r"columns: 4 is not a data column"):
        CombiTimeTable(table=TABLE, columns=(4,))
    with pytest.raises(ParameterError, match="either table="):
        CombiTimeTable()
    with pytest.raises(ParameterError, match="not one of"):
        CombiTimeTable(table=TABLE, extrapolation="Linear")
    for exc in (DataError, ModelError, ParameterError):
        assert issubclass(exc, AcausalError)
