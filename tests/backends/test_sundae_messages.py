"""SUNDIALS' own error line (scikit-sundae ``print``s it to stdout) is
carried in the failed run's message and printed by nobody: a diagnosis
whose trial points fail, or a sweep, shows no wall of solver lines.

The model: m s'' = 1e3 s^3 from s = 1 blows up at a finite time (about
0.0586 s); with 200 steps allowed per output interval, IDA gives up there
with its "mxstep" error (-22) after a fraction of a second."""
import threading

import numpy as np
import pytest

from acausal import SolverError, compile_model
from acausal.runtime.backends import sundae
from tests.faults import helpers as h

MODEL = h.CUBIC_BLOWUP


def _fail(tmp_path):
    from acausal.modelfile import load_model_file
    p = tmp_path / "blowup.py"
    p.write_text(MODEL)
    mf = load_model_file(str(p))
    with pytest.raises(SolverError) as err:
        compile_model(mf.model).simulate(t_end=1.0, output_step=1e-3, max_steps=200,
                                         backend="sundae")
    return err.value


def test_the_sundials_line_is_in_the_error_not_on_stdout(tmp_path, capfd):
    err = _fail(tmp_path)
    out, errout = capfd.readouterr()
    assert "[IDA" not in out and "[IDA" not in errout
    msg = str(err)
    assert "SUNDIALS: [IDASolve, Error: -22]" in msg and "mxstep" in msg
    assert err.t == pytest.approx(0.0586, abs=2e-3)
    assert "\n" not in msg


def test_threads_catch_their_own_lines_and_stdout_is_restored(capsys):
    """Two threads inside the catch, a third printing outside it: each
    buffer holds only its own thread's line, the third's reaches stdout,
    and stdout is the original stream once all are out."""
    import sys
    before = sys.stdout
    go = threading.Barrier(3, timeout=30)
    got = {}

    def inside(k):
        with sundae._caught_prints() as buf:
            go.wait()
            print(f"line {k}")
            go.wait()
        got[k] = buf.getvalue()

    def outside():
        go.wait()
        print("plain")
        go.wait()

    ts = [threading.Thread(target=inside, args=(k,)) for k in (1, 2)] + \
        [threading.Thread(target=outside)]
    for t in ts:
        t.start()
    for t in ts:
        t.join()
    assert got == {1: "line 1\n", 2: "line 2\n"}
    assert capsys.readouterr().out == "plain\n"
    assert sys.stdout is before


def test_a_run_that_succeeds_says_nothing_and_keeps_its_result(tmp_path, capfd):
    from acausal.modelfile import load_model_file
    p = tmp_path / "free.py"
    p.write_text(MODEL.replace("1e3 * s**3", "-4.0 * s"))
    res = compile_model(load_model_file(str(p)).model).simulate(t_end=1.0, output_step=1e-2,
                                                 backend="sundae")
    np.testing.assert_allclose(res["mass.s"][-1], np.cos(2.0), atol=1e-4)
    assert capfd.readouterr().out == ""


def test_only_sundials_lines_are_kept_anything_else_is_passed_on(capsys):
    """The residuals are generated code and print nothing, but a callback
    that did would not be silenced: only SUNDIALS' lines are taken."""
    text = ("\n[IDASolve, Error: -22] At t = 0.05, mxstep steps taken before reaching tout.\n\n"
            "checking the law at 0.3\n[IDAHandleFailure, Error: -4] At t = 0.05 and h = 1e-15, "
            "the corrector convergence failed repeatedly or with |h| = hmin.\n")
    got = sundae._sundials_lines(text)
    assert [g[:22] for g in got] == ["[IDASolve, Error: -22]", "[IDAHandleFailure, Err"]
    assert capsys.readouterr().out.strip() == "checking the law at 0.3"
