"""The nominal run of a model file (its experiment, default parameters),
once per process and file version: the graph and the hypotheses take their
typical magnitudes (parameter scales, bounds) from it."""
from __future__ import annotations

import os

_NOMINAL = {}


def nominal_result(path):
    """The nominal simulation result of the model file at ``path``; None if
    it fails."""
    from ...errors import AcausalError
    from ...modelfile import compile_file
    apath = os.path.abspath(path)
    key = (apath, os.path.getmtime(apath))
    if key not in _NOMINAL:
        try:
            mf, cm = compile_file(apath)
            _NOMINAL[key] = cm.simulate(**mf.experiment.run_options(dense=True))
        except AcausalError:
            _NOMINAL[key] = None
    return _NOMINAL[key]
