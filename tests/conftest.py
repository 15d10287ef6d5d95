"""Suite-wide pytest hooks.

The versions this run used are printed at the end of every run (also under
``-q``), so that a red run on a fresh machine shows what moved since the
last green one: CI installs the newest versions pip resolves.

Tests may add lines to the same terminal summary through the
``terminal_report`` fixture (e.g. the fuzz tier's counts), printed with or
without ``-s``.
"""
import os
import platform
import shutil
import signal
import tempfile
from importlib import metadata

import pytest

# A test run started in the background (`nohup ... &`, `cmd &` in a script)
# inherits SIGINT and SIGHUP ignored, and so would every command the tests
# spawn: the tests that send them a terminal user's signals would measure
# that instead. Restore the defaults the spawned commands inherit.
for _name, _default in (("SIGINT", signal.default_int_handler), ("SIGHUP", signal.SIG_DFL)):
    _sig = getattr(signal, _name, None)
    if _sig is not None and signal.getsignal(_sig) is signal.SIG_IGN:
        signal.signal(_sig, _default)

VERSIONED = ("numpy", "scipy", "sympy", "scikit-sundae", "matplotlib", "pint", "click",
             "tqdm", "dask", "distributed", "hypothesis", "casadi", "pytest")
SUMMARY = pytest.StashKey[list]()


def pytest_configure(config):
    """The tests' compiled models and libraries go to a cache of this run
    (worker processes and CLI subprocesses inherit it), not the user's."""
    if "ACAUSAL_CACHE" not in os.environ:
        config._acausal_cache = tempfile.mkdtemp(prefix="acausal-test-cache-")
        os.environ["ACAUSAL_CACHE"] = config._acausal_cache


def pytest_unconfigure(config):
    path = getattr(config, "_acausal_cache", None)
    if path:
        shutil.rmtree(path, ignore_errors=True)


def _versions():
    out = [f"python {platform.python_version()}"]
    for name in VERSIONED:
        try:
            out.append(f"{name} {metadata.version(name)}")
        except metadata.PackageNotFoundError:
            continue
    return out


@pytest.fixture
def terminal_report(request):
    """A list; lines appended to it are printed in the terminal summary."""
    return request.config.stash.setdefault(SUMMARY, [])


def pytest_terminal_summary(terminalreporter, config):
    lines = config.stash.get(SUMMARY, [])
    if lines:
        terminalreporter.write_sep("-", "acausal summaries")
        for line in lines:
            terminalreporter.write_line(line)
    terminalreporter.write_sep("-", "versions")
    terminalreporter.write_line(", ".join(_versions()))


@pytest.fixture(autouse=True, scope="session")
def _commands_share_this_process():
    """Commands run in-process by CliRunner share the process with pytest:
    an interrupted one must not arm acausal.executor.exit_soon, which would
    end the whole test run (the tests that need it run the command in a
    subprocess)."""
    import acausal.infra.executor as ex
    ex.EXIT_SOON = False
    yield


@pytest.fixture(scope="session")
def c_library(tmp_path_factory):
    """``build(text, flags=())``: the C source ``text`` compiled as the
    compiled backend compiles a model (-O1, shared, with libm) into a
    ``ctypes.CDLL``; the test is skipped when there is no C compiler."""
    import ctypes
    import subprocess

    from acausal.runtime.backends.compiled import Unavailable, c_compiler
    try:
        cc = c_compiler()
    except Unavailable as exc:
        pytest.skip(str(exc))
    folder = tmp_path_factory.mktemp("c_library")
    made = []

    def build(text, flags=()):
        src, so = folder / f"lib{len(made)}.c", folder / f"lib{len(made)}.so"
        src.write_text(text)
        subprocess.run(cc.split() + ["-O1", "-shared", "-fPIC", *flags, "-o", str(so), str(src),
                                     "-lm"], check=True, capture_output=True)
        made.append(so)
        return ctypes.CDLL(os.fspath(so))
    return build
