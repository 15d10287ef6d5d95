"""Finished fits of a diagnosis survive an interruption (even a kill).

A :class:`FitStore` is the collector of the stages' :class:`.context.Context`:
each fit result is appended to ``<report>/checkpoint/<hash>.jsonl``
(:class:`acausal.checkpoint.Checkpoint`: one checksummed line per record)
as soon as it arrives, and a task whose result is already there is not
submitted again. A task is a picklable dataclass and its result depends
only on it, so a record is keyed by a hash of the pickled task; the store
itself is named by a hash of the model file (and its neighbours), the data
folder and the diagnosis options
(:meth:`acausal.diagnose.options.DiagnosisOptions.checkpoint_key`), so
changed inputs start afresh. The stored value is the pickled result (base64
text): the store is written and read only by this package, in the user's
own report folder.
"""
from __future__ import annotations

import base64
import hashlib
import pickle
from pathlib import Path

from ...infra.checkpoint import Checkpoint, input_key, source_files


def task_key(task) -> str:
    """A stable key of one task (its type and pickled fields)."""
    return f"{type(task).__name__} {hashlib.sha256(pickle.dumps(task)).hexdigest()[:24]}"


class FitStore:
    """``store(task, result)`` keeps a result; ``store.get(task)`` finds it."""

    def __init__(self, out_dir, model_path, data_folder, options: dict):
        key = input_key(source_files(model_path), Path(data_folder), options)
        self.checkpoint = Checkpoint(Path(out_dir) / "checkpoint", key)
        self.saved = self.checkpoint.load()

    def get(self, task):
        text = self.saved.get(task_key(task))
        return None if text is None else pickle.loads(base64.b64decode(text))

    def __call__(self, task, result) -> None:
        text = base64.b64encode(pickle.dumps(result)).decode("ascii")
        self.checkpoint.append(task_key(task), text)
        self.saved[task_key(task)] = text

    def discard(self) -> None:
        """The diagnosis finished: its fits are in the report."""
        self.checkpoint.discard()
