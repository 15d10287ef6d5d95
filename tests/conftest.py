"""Suite-wide pytest hooks.

The versions this run used are printed at the end of every run (also under
``-q``), so that a red run on a fresh machine shows what moved since the
last green one: CI installs the newest versions pip resolves.
"""
import platform
from importlib import metadata

VERSIONED = ("numpy", "scipy", "sympy", "scikit-sundae", "matplotlib", "pint", "click",
             "tqdm", "dask", "distributed", "hypothesis", "casadi", "pytest")


def _versions():
    out = [f"python {platform.python_version()}"]
    for name in VERSIONED:
        try:
            out.append(f"{name} {metadata.version(name)}")
        except metadata.PackageNotFoundError:
            continue
    return out


def pytest_terminal_summary(terminalreporter):
    terminalreporter.write_sep("-", "versions")
    terminalreporter.write_line(", ".join(_versions()))
