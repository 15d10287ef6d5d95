"""Running the ``acausal`` command in a subprocess and killing it (faults tests)."""
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import psutil

from acausal.infra.checkpoint import Checkpoint

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent


# A mass on a spring to a wall (4 kg, 100 N/m, released at 0.2 m): the
# model of the model files these tests write, each with its own experiment,
# measures or misbehaviour around it
SPRING_IMPORTS = """\
from acausal import Experiment, Measure, Model
from acausal.mechanics.translational import Fixed, Mass, Spring
"""
SPRING_MODEL = """\
model = Model()
model.body = Mass(m=4.0, s=0.2, v=0.0)
model.k = Spring(c=100.0, s_rel0=0.0)
model.wall = Fixed()
model.connect(model.wall.flange, model.k.flange_a)
model.connect(model.k.flange_b, model.body.flange)
"""


# m s'' = 1e3 s^3 from s = 1, at rest: s blows up at a finite time (about
# 0.0586 s), where the solver fails: the model of the solver-failure tests
CUBIC_BLOWUP = """\
from acausal import Experiment, Model
from acausal.mechanics.translational import Force, Mass
model = Model()
model.mass = Mass(m=1.0, s=1.0, v=0.0)
model.push = Force(f=lambda s: 1e3 * s**3)
model.connect(model.push.flange, model.mass.flange)
experiment = Experiment(t_end=1.0, output_step=1e-3)
"""

# a mass on a spring driven by a force F (a condition of the data folders), k.c
# free: the model file of the batteries' data, calibrate and sweep cases
DRIVEN_SPRING = """\
from acausal import Experiment, Model
from acausal.mechanics.translational import Fixed, Force, Mass, Spring

model = Model()
F = model.parameter("F", 1.0, "N", "drive force", min=0.0, max=100.0)
model.wall = Fixed()
model.body = Mass(m=0.1, s=0.0, v=0.0)
model.k = Spring(c=40.0, s_rel0=0.0)
model.drive = Force(f=F)
model.connect(model.wall.flange, model.k.flange_a)
model.connect(model.k.flange_b, model.body.flange, model.drive.flange)
experiment = Experiment(t_end=0.1, rtol=1e-6, atol=1e-9, output_step=1e-3)
measures = {"s_end": lambda res: res.final()["body.s"]}
conditions = {"F": (0.1, 10.0, "N")}
free_parameters = {"k.c": (10.0, 160.0)}
"""


def spring_file(tail):
    """The text of a spring model file ending with ``tail`` (its
    experiment and measures)."""
    return SPRING_IMPORTS + "\n" + SPRING_MODEL + tail


def invoke(args):
    """The command run in this process (click's CliRunner)."""
    from click.testing import CliRunner

    from acausal.cli import main
    return CliRunner().invoke(main, [str(a) for a in args])


def one_error_line(r, code=2):
    """The command ended with ``code`` and exactly one 'error:' line, no traceback."""
    assert r.exception is None or isinstance(r.exception, SystemExit), repr(r.exception)
    assert "Traceback" not in r.output, r.output
    assert r.exit_code == code, (r.exit_code, r.output)
    errors = [ln for ln in r.stderr.splitlines() if "error:" in ln]
    assert len(errors) == 1, r.stderr
    return errors[0]


def copy_model(name, folder):
    """Copy a model file of this folder into ``folder`` (its own folder: the
    checkpoint hashes the model's neighbours)."""
    folder.mkdir(parents=True, exist_ok=True)
    return Path(shutil.copy(HERE / name, folder / name))


def env(log_dir, sleep=0.0):
    e = dict(os.environ, PYTHONPATH=str(ROOT), ACAUSAL_TEST_LOG=str(log_dir),
             ACAUSAL_TEST_SLEEP=str(sleep))
    log_dir.mkdir(parents=True, exist_ok=True)
    return e


def cli(args, environment, **kw):
    return subprocess.Popen([sys.executable, "-m", "acausal.cli", *map(str, args)],
                            env=environment, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True, **kw)


def wait_for(condition, proc, timeout=120.0, poll=0.02):
    """Poll ``condition()`` until true; fail if ``proc`` ends first or time runs out."""
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        if condition():
            return
        if proc.poll() is not None:
            out, err = proc.communicate()
            raise AssertionError(f"the command ended (exit {proc.returncode}) before the "
                                 f"kill:\n{out}\n{err}")
        time.sleep(poll)
    proc.kill()
    raise AssertionError("timed out waiting for the command")


def kill_tree_check(proc, sig, wait=10.0):
    """Send ``sig`` to ``proc`` (the main process only); return its
    descendants still alive ``wait`` seconds later (there should be none)
    and its stderr."""
    family = psutil.Process(proc.pid).children(recursive=True)
    assert [p for p in family if p.name() != "acausal-watch"], \
        "the command started no worker process"
    os.kill(proc.pid, sig)
    _, stderr = proc.communicate(timeout=60)
    _, alive = psutil.wait_procs(family, timeout=wait)
    for p in alive:  # do not leave them behind, even when the test fails
        p.kill()
    return alive, stderr


def valid_lines(path, types=()):
    """Records of a checkpoint file whose checksum is intact, and the count of the others."""
    store = Checkpoint(path.parent, path.stem, types)
    return store.load(), store.ignored


def logged(log_dir):
    """The values a test model's measure saw (one marker file per call)."""
    return sorted(float(p.read_text()) for p in Path(log_dir).iterdir())


def column_ulps(a, b):
    """(same, gap): where ``a`` and ``b`` agree to the bit, and their gap in
    ulps of each column's largest magnitude over the run. An absolute
    measure: numpy's array math (SIMD pow, tanh, exp) is one ulp off libm's
    on some values (numpy 2.4.6 on AVX-512: pow(x, 1.5) on 5 %, tanh on 27 %),
    and a force summed from terms the size of the column's peak carries that
    ulp into a small result (the breaker hook's acceleration: 71 of its own
    ulps, 2 of the column's). A printer that writes a function wrong is off
    by far more."""
    same = (a == b) | (np.isnan(a) & np.isnan(b))
    scale = np.max(np.abs(np.nan_to_num(np.where(same, a, np.fmax(np.abs(a), np.abs(b))))),
                   axis=0)
    gap = np.abs(a - b) / np.spacing(np.maximum(scale, np.finfo(float).tiny))
    return same, np.where(same, 0.0, gap)
