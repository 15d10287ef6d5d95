"""Where the diagnosis finds its hypotheses: by default
:mod:`acausal.diagnose.library.hypotheses` (with :mod:`acausal.diagnose.library.graph`); any
module with the same interface (``HYPOTHESES``, ``build_extended``,
``write_extended_model`` and optionally ``ModelGraph``, ``build_pair`` and
``FAMILIES``) can stand in, named
by its import path so that worker processes can import it too."""
from __future__ import annotations

import importlib
from dataclasses import dataclass
from types import SimpleNamespace

from ...errors import DiagnosisError

DEFAULT = "acausal.diagnose.library.hypotheses"


def load_library(name: str | None = None) -> SimpleNamespace:
    try:
        mod = importlib.import_module(name or DEFAULT)
    except ImportError as exc:
        if name is None:
            raise  # the package's own library: a broken install, not a user error
        raise DiagnosisError(f"hypothesis library {name!r} cannot be imported: {exc}") from None
    graph = getattr(mod, "ModelGraph", None)
    if graph is None:
        graph = importlib.import_module("acausal.diagnose.library.graph").ModelGraph
    return SimpleNamespace(name=name or DEFAULT, HYPOTHESES=mod.HYPOTHESES, ModelGraph=graph,
                           build_extended=mod.build_extended,
                           write_extended_model=mod.write_extended_model,
                           build_pair=getattr(mod, "build_pair", None),
                           FAMILIES=getattr(mod, "FAMILIES", {}),
                           graph_of=lambda path: _graph_of(graph, path))


def _graph_of(graph_cls, path):
    """The graph of a model file with its nominal run attached when the
    library can (``ModelGraph.from_file``): the hypotheses take their typical
    magnitudes (parameter scales and bounds) from that run."""
    from_file = getattr(graph_cls, "from_file", None)
    if from_file is not None:
        return from_file(path)
    from ...modelfile import compile_file
    return graph_cls(compile_file(path)[0].model)


@dataclass(frozen=True)
class FamilyIndex:
    """hypothesis id -> (family, member position); ``members``: family ->
    member ids (the head first). Families: :mod:`.families`."""

    of: dict
    members: dict
    refines: frozenset = frozenset()   # members that only refine their head in a regime
    #                                    the data must show (Hypothesis.refines): named
    #                                    over the head only beyond the parsimony margin

    def family(self, hid):
        """The cause class of a hypothesis (its own id when it has no family)."""
        return self.of.get(hid, (hid, 0))[0]

    def is_head(self, hid):
        return self.of.get(hid, (hid, 0))[1] == 0

    def mates(self, hid):
        """The other members of ``hid``'s family (none without a family)."""
        return tuple(m for m in self.members.get(self.family(hid), ()) if m != hid)


def family_index(library) -> FamilyIndex:
    lib = load_library(library)
    fams = getattr(lib, "FAMILIES", None) or {}
    refines = frozenset(hid for hid, h in lib.HYPOTHESES.items()
                        if getattr(h, "refines", None))
    return FamilyIndex({m: (f, i) for f, ms in fams.items() for i, m in enumerate(ms)},
                       {f: tuple(ms) for f, ms in fams.items()}, refines)
