"""The options of a diagnosis (:class:`DiagnosisOptions`): what it searches,
how it decides, which stages run, how hard each fit tries, where it runs and
what it writes. Every default is the command line's (``acausal diagnose``).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

from .problem import ALPHA, FitSettings


@dataclass(frozen=True)
class DiagnosisOptions:
    """Options of :func:`acausal.diagnose.run.diagnose` (and of
    :func:`~acausal.diagnose.run.run_stages`).

    What is searched:

    * ``hypotheses``: hypothesis ids to try (a name or a list; None: every
      hypothesis of the library, a family's members other than its head
      fitted only where the head is competitive);
    * ``locations``: component paths to keep (exact, or a prefix followed
      by '.'; None: every site);
    * ``library``: the module standing in for
      :mod:`acausal.diagnose.library.hypotheses` (None: that one).

    How it decides:

    * ``alpha``: the family significance level of the discrepancy decision;
    * ``exact_cv``: refit the nominal and the best models without each
      experiment (False: the linearised leave-one-out only).

    Which stages run (each True by default):

    * ``families``: fit the other members of a competitive family;
    * ``pairs``: search pairs of causes when the best single one leaves misfit;
    * ``generic``: locate a discrepancy the library does not explain;
    * ``profile``: profile-likelihood intervals where the linearised ones
      fail the check;
    * ``design``: the next experiment that splits the best candidate's class;
    * ``views``: the report's simulated traces, residuals and fingerprints.

    How hard each fit tries: ``settings`` (:class:`~.problem.FitSettings`).

    Where it runs: ``scheduler`` (a Dask scheduler address; None: local
    processes), ``workers`` (local worker processes; None: all cores; with a
    ``"serial"`` scheduler every task runs in this process), ``progress``
    (progress bars).

    What it writes: ``plots`` (the report's figures).
    """

    hypotheses: object = None
    locations: object = None
    library: str | None = None
    alpha: float = ALPHA
    exact_cv: bool = True
    families: bool = True
    pairs: bool = True
    generic: bool = True
    profile: bool = True
    design: bool = True
    views: bool = True
    settings: FitSettings = field(default_factory=FitSettings)
    scheduler: str | None = None
    workers: int | None = None
    progress: bool = True
    plots: bool = True

    @classmethod
    def of(cls, options=None, what="diagnose", **keywords) -> "DiagnosisOptions":
        """``options`` (None: the defaults) with ``keywords`` (field names)
        replaced; ``max_nfev`` (kept for compatibility) sets the fits'
        iterations (``settings.max_nfev``) when no ``settings`` keyword is
        given; ``settings=None`` means the default settings. An unknown keyword is a
        TypeError naming it, as for any function (``what``: the caller's name)."""
        base = options if options is not None else cls()
        if "max_nfev" in keywords:
            max_nfev = keywords.pop("max_nfev")
            if keywords.get("settings") is None:
                keywords["settings"] = dataclasses.replace(base.settings or FitSettings(),
                                                           max_nfev=max_nfev)
        if keywords.get("settings", base.settings) is None:
            keywords["settings"] = FitSettings()
        return replaced(base, what, **keywords)

    def checkpoint_key(self) -> dict:
        """The options a finished fit depends on: the checkpoint store's key
        (:class:`.stages.resume.FitStore`; where and how it runs are left out,
        so a resumed run may use other workers)."""
        return dict(hypotheses=self.hypotheses, locations=self.locations, alpha=self.alpha,
                    exact_cv=self.exact_cv, library=self.library, settings=repr(self.settings),
                    generic=self.generic, pairs=self.pairs, families=self.families)


def replaced(record, what, **keywords):
    """The dataclass ``record`` with the fields ``keywords`` replaced; a
    keyword that names no field is a TypeError naming it, as for any
    function (``what``: the function taking the keywords)."""
    names = {f.name for f in dataclasses.fields(record)}
    unknown = [k for k in keywords if k not in names]
    if unknown:
        raise TypeError(f"{what}() got an unexpected keyword argument {unknown[0]!r}")
    return dataclasses.replace(record, **keywords)
