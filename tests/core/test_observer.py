"""The hybrid loop's observer hooks (acausal/runtime/observer.py): an
observer that only records sees them in the documented order on a run with
events and mode changes (a Hertz impact), and leaves the solution
bit-identical; the event-time sensitivities the sensitivity observer
carries match the impact's closed form."""
import os

import numpy as np
import pytest

from acausal.modelfile import compile_file
from acausal.runtime import hybrid
from acausal.runtime.observer import RunObserver

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
HERTZ = os.path.join(ROOT, "models", "examples", "hertz_impact.py")


class Recorder(RunObserver):
    """The plain run, recording each hook it is called with."""

    def __init__(self):
        self.calls = []

    def system(self, cm, atol, p):
        self.calls.append(("system",))
        return super().system(cm, atol, p)

    def on_start(self, run, point, d, cb, starts):
        self.calls.append(("on_start", point.t))
        return super().on_start(run, point, d, cb, starts)

    def on_rows(self, run, count):
        self.calls.append(("on_rows", count))

    def on_event(self, run, point, d, fired, kind):
        self.calls.append(("on_event", kind, tuple(fired)))

    def on_log(self, run, k, i):
        self.calls.append(("on_log", k, i))

    def on_mode_change(self, run, events, point, d_before, d, observed):
        self.calls.append(("on_mode_change", tuple(d_before), tuple(d)))
        return super().on_mode_change(run, events, point, d_before, d, observed)

    def on_instant_end(self, run):
        self.calls.append(("on_instant_end",))

    def finish(self, run, rows, stats, status, message):
        self.calls.append(("finish", status))
        return super().finish(run, rows, stats, status, message)


@pytest.fixture(scope="module")
def hertz():
    mf, cm = compile_file(HERTZ)
    return cm, mf.experiment.run_options()


def test_hooks_in_order_and_the_solution_untouched(hertz, monkeypatch):
    cm, opts = hertz
    plain = cm.simulate(**opts)
    rec = Recorder()
    monkeypatch.setattr(hybrid, "_observer", lambda cm, names: rec)
    res = cm.simulate(**opts)
    for a in ("t", "y", "yp", "d"):
        assert np.array_equal(getattr(res, a), getattr(plain, a))
    assert res.events == plain.events and len(res.events) >= 2   # contact closes, opens
    names = [c[0] for c in rec.calls]
    assert names[:2] == ["system", "on_start"] and names[-1] == "finish"
    assert names.count("finish") == 1 and rec.calls[-1] == ("finish", "ok")
    assert sum(c[1] for c in rec.calls if c[0] == "on_rows") == len(res.t)
    assert [c[1] for c in rec.calls if c[0] == "on_log"] == list(range(len(res.events)))
    # every mode change comes after the events that caused it, inside one instant
    for k, c in enumerate(rec.calls):
        if c[0] == "on_mode_change":
            before = names[:k]
            assert "on_event" in before and before.index("on_event") < k
            assert "on_instant_end" in names[k:]
    assert names.count("on_instant_end") >= 1
    assert {c[1] for c in rec.calls if c[0] == "on_event"} <= {"observer", "instant", "recheck"}


def test_the_sensitivity_observer_gives_the_event_times(hertz):
    """First contact at t1 = gap0 / v0, whatever the stiffness; the contact
    lasts t_c = 2.94328 delta_max / v0 with delta_max = (5 m v0^2 /
    (4 K))^(2/5), so the separation's d t2 / dK = -(2/5) t_c / K."""
    cm, opts = hertz
    res = cm.simulate(sensitivities=["contact.K"], **opts)
    (t1,), (t2,) = res.event_times("contact.onset"), res.event_times("contact.release")
    tc = 2.94328 * (5 * 0.1 * 1.0 / (4 * 1e9)) ** 0.4 / 1.0
    assert t1 == pytest.approx(1e-4, rel=1e-6) and t2 - t1 == pytest.approx(tc, rel=1e-5)
    (d1,) = res.event_sensitivity("contact.K", "contact.onset")
    (d2,) = res.event_sensitivity("contact.K", "contact.release")
    assert abs(d1) < 1e-9 * tc / 1e9
    assert d2 == pytest.approx(-0.4 * tc / 1e9, rel=1e-4)
