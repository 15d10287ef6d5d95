"""Records of a dataset: experiments, traces, instrument, and the error type."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

import numpy as np

from ..errors import DataError, UnknownNameError

__all__ = ["DataError", "Instrument", "Trace", "MeasuredExperiment", "Dataset"]


@dataclass
class Instrument:
    """How one signal was measured; ``resolution`` and ``noise_std`` in SI."""

    signal: str
    resolution: float = 0.0
    noise_std: float = 0.0

    def floor(self) -> float:
        """Per-sample standard deviation (SI) residuals should stay within.

        Rounding to a step ``resolution`` adds an error uniform on
        ``±resolution/2``, of standard deviation ``resolution/sqrt(12)``; it is
        independent of the noise, so the variances add:
        ``sqrt(noise_std**2 + resolution**2 / 12)``.
        """
        return math.hypot(self.noise_std, self.resolution / math.sqrt(12.0))


@dataclass
class Trace:
    """Sampled signals: ``time`` in s, ``signals`` name -> array in SI."""

    time: np.ndarray
    signals: dict[str, np.ndarray]
    file: Optional[Path] = None


@dataclass
class MeasuredExperiment:
    """One measured experiment: SI ``conditions`` and measured-only SI
    ``measures`` (and a measured ``trace``). Not the simulation settings of a
    model file, which are :class:`acausal.lang.Experiment`.

    ``use`` is 'calibrate' (fitted by ``acausal calibrate``) or 'validate'
    (held back: predicted with the calibrated values and compared)."""

    name: str
    conditions: dict[str, float]
    measures: dict[str, float] = field(default_factory=dict)
    trace: Optional[Trace] = None
    line: Optional[int] = None
    use: str = "calibrate"


@dataclass
class Dataset:
    """Experiments and instrument description read from (or for) ``folder``;
    ``notes``: one line for each change made to the data after reading (a
    trace thinned by the diagnosis)."""

    folder: Optional[Path]
    experiments: list[MeasuredExperiment]
    instrument: dict[str, Instrument] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)   # what was done to the data (thinned)

    @property
    def condition_names(self) -> list[str]:
        """Condition names, in column order."""
        return list(dict.fromkeys(n for e in self.experiments for n in e.conditions))

    @property
    def measure_names(self) -> list[str]:
        """Names of the measures taken in at least one experiment."""
        return list(dict.fromkeys(n for e in self.experiments for n in e.measures))

    def experiment(self, name: str) -> MeasuredExperiment:
        """The experiment called ``name`` (UnknownNameError, also a KeyError,
        if there is none)."""
        for e in self.experiments:
            if e.name == name:
                return e
        raise UnknownNameError(f"no experiment {name!r}", file=self.folder)


def __getattr__(name):
    """``Experiment``: the old name of :class:`MeasuredExperiment` (deprecated)."""
    if name == "Experiment":
        import warnings
        warnings.warn("acausal.data.Experiment is now acausal.data.MeasuredExperiment (a "
                      "measured experiment; acausal.Experiment is a model file's simulation "
                      "settings)", DeprecationWarning, stacklevel=2)
        return MeasuredExperiment
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
