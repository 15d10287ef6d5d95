"""Calling the library from Python (not the command line, which keeps every
library warning from the terminal) prints no numerical library's warning
for what the library itself handles: scipy's LinAlgWarning from the
re-initialisation's solves (an ill-conditioned matrix: the iterations judge
their own convergence), numpy's "loadtxt: input contained no data" from a
chunk of a trace that held only comments."""
import os
import subprocess
import sys
import warnings

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

# a user's script: the breaker with a near-massless hook (the massless-hook
# limit: ill-conditioned re-initialisations), on both backends
SCRIPT = """
import sys
from acausal.modelfile import compile_file
mf, cm = compile_file(sys.argv[1])
opts = mf.experiment.run_options()
for backend in ("compiled", "sundae"):
    r = cm.simulate(params={"hook.Jh": 1e-30}, backend=backend, **opts)
    print(backend, r.status, r.t[-1])
"""


def test_simulating_an_ill_conditioned_model_prints_no_linalg_warning(tmp_path):
    """Both runs end normally; stderr is empty (it held 8 LinAlgWarnings,
    two lines each, before the re-initialisation's module ignored them)."""
    env = dict(os.environ, PYTHONPATH=ROOT + os.pathsep + os.environ.get("PYTHONPATH", ""),
               PYTHONWARNINGS="")
    proc = subprocess.run([sys.executable, "-c", SCRIPT,
                           os.path.join(ROOT, "models", "breaker_24kv.py")],
                          capture_output=True, text=True, env=env, timeout=300)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.split("\n")
    assert [ln.split()[0] for ln in lines if ln] == ["compiled", "sundae"], proc.stdout
    assert "Warning" not in proc.stderr, proc.stderr
    assert proc.stderr.strip() == "", proc.stderr


def test_a_chunk_of_only_comments_reads_without_a_warning(tmp_path, monkeypatch):
    """The numeric reader without pandas parses a large trace in chunks; a
    chunk that held only comment lines made numpy warn (and gave no rows,
    rightly). Now the chunk is skipped before numpy sees it: the same
    values, no warning."""
    from acausal.data import table
    monkeypatch.setitem(sys.modules, "pandas", None)        # pandas not installed
    monkeypatch.setattr(table, "FAST_MIN_BYTES", 0)         # the chunked reader
    monkeypatch.setattr(table, "CHUNK_LINES", 1)            # chunks of about 24 bytes
    path = tmp_path / "trace.csv"
    path.write_text("time [s],x [m]\n0,1.5\n"
                    + "# a comment line that fills a chunk by itself\n" * 6
                    + "0.5,2.5\n  \n# the end\n1,3.5\n")
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        tab, values = table.read_numeric_table(path, progress=False)
    assert tab.names == ["time", "x"]
    np.testing.assert_array_equal(values, [[0.0, 1.5], [0.5, 2.5], [1.0, 3.5]])
    assert [str(w.message) for w in caught] == []
