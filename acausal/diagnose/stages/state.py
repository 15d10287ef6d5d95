"""The diagnosis's state between its stages (:class:`State`): every stage is
``stage(ctx, state) -> state`` (:mod:`acausal.diagnose.run`) and returns a
new state with its own fields set (``dataclasses.replace``); none changes
the state it is given."""
from __future__ import annotations

from dataclasses import dataclass, field

from ...data import Dataset
from ..library.loader import FamilyIndex
from ..options import DiagnosisOptions
from ..problem import Problem
from .chain import CrossValidation, Decision, NominalFit, PairSearch, Ranking
from .families import Members
from .intervals import Intervals
from .kinematics import Kinematics
from .locate import Location
from .nextexp import NextStep
from .views import Views


@dataclass(frozen=True)
class State:
    """What the stages computed so far. Inputs: ``problem``, ``dataset``,
    ``options``, ``out_dir`` (where the extended model file is written) and
    ``candidates`` (every (hypothesis, location) to fit). Then, in the order
    the stages set them: the nominal fit (``calibration``), every candidate
    fit so far (``fits``), the ``decision``, the family ``members``, the
    simulations the pair screen spent (``pair_screen_n_sim``; None: the pair
    search did not run) and the pair search's outcome (``pair_search``),
    the tied sites (``kinematics``, before the fits at tied sites), the
    exact leave-one-out refits (``cv``), the ``ranking``, the located
    discrepancy (``location``), the profile ``intervals``, the
    ``extended_model`` file, the named cause's kinematically ``tied``
    sites, the library's ``families``, the ``next_experiment`` and the
    report's ``views``. A stage that did not run leaves its field at its
    default."""

    problem: Problem
    dataset: Dataset
    options: DiagnosisOptions
    out_dir: str
    candidates: tuple = ()
    calibration: NominalFit | None = None
    fits: tuple = ()
    decision: Decision | None = None
    members: Members = field(default_factory=Members)
    pair_screen_n_sim: int | None = None
    pair_search: PairSearch = field(default_factory=PairSearch)
    cv: CrossValidation | None = None
    ranking: Ranking | None = None
    kinematics: Kinematics | None = None
    location: Location | None = None
    intervals: Intervals | None = None
    extended_model: str | None = None
    tied: tuple = ()
    families: FamilyIndex | None = None
    next_experiment: NextStep | None = None
    views: Views | None = None

    @property
    def n_sim(self) -> int:
        """Simulations of the fits so far (the nominal fit, every candidate
        fit, the pair screen)."""
        return (self.calibration.fit.n_sim
                + sum(r.fit.n_sim for r in self.fits if r.fit is not None)
                + (self.pair_screen_n_sim or 0))
