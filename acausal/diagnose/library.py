"""Where the diagnosis finds its hypotheses: by default
:mod:`acausal.diagnose.hypotheses` (with :mod:`acausal.diagnose.graph`); any
module with the same interface (``HYPOTHESES``, ``build_extended``,
``write_extended_model`` and optionally ``ModelGraph``) can stand in, named
by its import path so that worker processes can import it too."""
from __future__ import annotations

import importlib
from types import SimpleNamespace

DEFAULT = "acausal.diagnose.hypotheses"


def load_library(name: str | None = None) -> SimpleNamespace:
    mod = importlib.import_module(name or DEFAULT)
    graph = getattr(mod, "ModelGraph", None)
    if graph is None:
        graph = importlib.import_module("acausal.diagnose.graph").ModelGraph
    return SimpleNamespace(name=name or DEFAULT, HYPOTHESES=mod.HYPOTHESES, ModelGraph=graph,
                           build_extended=mod.build_extended,
                           write_extended_model=mod.write_extended_model)
