"""The diagnosis driver: from a model file and measured data to a named
cause, an extended model and the measured gain.

:func:`diagnose` chains the stages of :mod:`.stages` (calibrate ->
candidates -> fit -> family members -> decide -> pairs -> cross-validate ->
rank -> tied sites -> locate -> intervals -> extend -> next experiment -> views),
keeps what they return in a :class:`~.result.Diagnosis`, renders the
report from it (:mod:`.report`, a pure view) and returns the JSON summary
(:func:`.result.summary`).

Errors are in units of the instrument floor throughout (RMS of
(simulated - measured)/floor): 1.0 is what the instrument's noise and
resolution alone explain.
"""
from __future__ import annotations

import json
import time
from pathlib import Path

from ..infra.executor import open_executor
from .stages import chain as stages
from .stages import stats as st
from .stages.families import Members, family_index, fit_members, prefer_simplest
from .stages.intervals import intervals
from .stages.kinematics import Kinematics, equivalents, kinematics, prefer_site
from .stages.locate import Location, locate
from .stages.nextexp import next_experiment
from .problem import FitSettings
from .report.result import Diagnosis, details, summary
from .stages.resume import FitStore
from .stages.chain import DiagnosisError
from .stages.tasks import fit_candidate

__all__ = ["diagnose", "run_stages", "DiagnosisError"]


def run_stages(model_path, data_folder, *, out_dir, scheduler=None, workers=None,
               progress=True, hypotheses=None, locations=None, alpha=st.ALPHA,
               exact_cv=True, library=None, views=True, settings=None,
               collect=None, generic=True, pairs=True, families=True, profile=True,
               design=True) -> Diagnosis:
    """The stages in order; returns the :class:`Diagnosis` (writes only the
    extended model file into ``out_dir``). ``collect(task, result)`` is
    called as each fit result arrives (a checkpoint store plugs in there).
    ``generic``: locate a discrepancy the library does not explain
    (:mod:`.locate`); ``pairs``: search pairs of causes when the best single
    one leaves misfit (:func:`.stages.search_pairs`); ``families``: fit
    the other members of a competitive family (:mod:`.families`);
    ``profile``: profile-likelihood intervals where the linearised ones fail
    the check (:mod:`.intervals`); ``design``: the next experiment that
    splits the best candidate's class (:mod:`.nextexp`)."""
    t0, clock = time.perf_counter(), {}
    problem, ds = stages.load_problem(model_path, data_folder, library, settings)
    cands = stages.candidates(problem, hypotheses, locations)
    with open_executor(scheduler, workers) as ex:
        cal = stages.calibrate(problem, ex, progress, collect)
        fits = stages.fit(problem, cal, cands, ex, progress, collect)
        t_fit = time.perf_counter() - t0
        dec = stages.decide(ds, cal, fits, alpha)
        members = _timed(clock, "families_s", fit_members, problem, cal, dec, ex, progress,
                         collect) if families else Members()
        if members.fits:
            fits += members.fits
            dec = stages.decide(ds, cal, fits, alpha)
        if pairs and stages.pairs_needed(dec):
            fits, dec = _timed(clock, "pairs_s", _pairs, problem, ds, cal, dec, fits, ex,
                               (progress, collect, alpha), clock)
        cv = stages.cross_validate(problem, ds, cal, dec, ex, exact_cv, progress)
        rk = stages.rank(ds, cal, dec, cv, members.unfitted)
        rk, kin = _shown(problem, cal, rk, families, clock)
        where = locate(problem, cal, dec, rk, ex, progress, collect) if generic else Location(
            skipped="not run (generic=False)")
        ivs = _timed(clock, "profile_s", intervals, problem, cal, rk, ex,
                     progress) if profile else None
    Path(out_dir).mkdir(parents=True, exist_ok=True)
    extended = stages.extend(problem, rk, out_dir)
    tied = equivalents(problem, kin, rk)
    index = family_index(problem.library)
    nxt = _timed(clock, "design_s", next_experiment, problem, ds, dec, rk,
                 index) if design else None
    t_cv = time.perf_counter() - t0 - t_fit
    shown = None
    if views:
        from .stages.views import views as make_views
        shown = make_views(problem, cal, rk)
    n_sim = cal.fit.n_sim + sum(r.fit.n_sim for r in fits if r.fit is not None) + clock.get(
        "pair_screen_n_sim", 0)
    timing = dict(fit_s=t_fit, cv_s=t_cv, n_candidates=len(cands), n_sim=n_sim,
                  total_s=time.perf_counter() - t0, **clock)
    return Diagnosis(problem, ds, cal, len(cands), dec, cv, rk, extended, shown,
                     nxt, timing, where, ivs, index, kin, tied)


def _shown(problem, cal, rk, families, clock):
    """(ranking, Kinematics): the row shown moved to the simplest member of
    its family the data support (:func:`.families.prefer_simplest`), then to
    a kinematically tied site whose coordinate is measured when the data
    cannot tell the two apart (:func:`.kinematics.prefer_site`)."""
    if families:
        rk = prefer_simplest(rk, family_index(problem.library))
    if rk.after is None:
        return rk, Kinematics(message="no cause to place")
    kin = _timed(clock, "kinematics_s", kinematics, problem, cal)
    return prefer_site(rk, kin), kin


def _pairs(problem, ds, cal, dec, fits, ex, opts, clock):
    """(fits, decision) after the pair search (:func:`.stages.search_pairs`)
    and, when a pair comes out best, its members refitted alone from the
    pair's point (:func:`.stages.member_refit_tasks`)."""
    progress, collect, alpha = opts
    got, clock["pair_screen_n_sim"] = stages.search_pairs(problem, cal, dec, ex, progress,
                                                          collect)
    fits += got
    dec = stages.decide(ds, cal, fits, alpha)
    again = stages.member_refit_tasks(problem, cal, dec)
    if not again:
        return fits, dec
    fits += tuple(stages.run_tasks(ex, fit_candidate, again, "refitting the pair's members",
                                   progress, collect))
    return fits, stages.decide(ds, cal, fits, alpha)


def _timed(clock, key, fn, *args):
    """``fn(*args)``, its wall time [s] kept in ``clock[key]``."""
    t = time.perf_counter()
    out = fn(*args)
    clock[key] = time.perf_counter() - t
    return out


def diagnose(model_path, data_folder, *, out_dir, scheduler=None, workers=None,
             progress=True, hypotheses=None, locations=None, alpha=st.ALPHA,
             exact_cv=True, library=None, plots=True, max_nfev=60, settings=None,
             collect=None, generic=True, pairs=True, families=True, profile=True,
             design=True, on_resume=None) -> dict:
    """Diagnose ``model_path`` against the dataset folder ``data_folder``.

    Writes ``report.md``, ``diagnosis.json``, ``candidates.json``, plots and
    (when a cause is named) the extended model file into ``out_dir``;
    returns the summary dict (docs/diagnosis.md). ``hypotheses`` /
    ``locations`` restrict the candidates; ``alpha`` is the family
    significance level of the discrepancy decision; ``exact_cv`` refits the
    nominal and best models without each experiment (else the linearised
    leave-one-out); ``library`` names a module standing in for
    :mod:`acausal.diagnose.hypotheses`; ``settings`` a
    :class:`~.problem.FitSettings` (``max_nfev`` kept for compatibility);
    ``on_resume(n, path)`` is called when ``n`` fits of an interrupted run
    of the same command are found in its checkpoint ``path``.
    """
    settings = settings or FitSettings(max_nfev=max_nfev)
    store = None
    if collect is None:   # keep finished fits in <out_dir>/checkpoint/ (resume after a kill)
        store = collect = FitStore(out_dir, model_path, data_folder, dict(
            hypotheses=hypotheses, locations=locations, alpha=alpha, exact_cv=exact_cv,
            library=library, settings=repr(settings), generic=generic, pairs=pairs,
            families=families))
        if store.saved and on_resume is not None:
            on_resume(len(store.saved), store.checkpoint.path)
    d = run_stages(model_path, data_folder, out_dir=out_dir, scheduler=scheduler,
                   workers=workers, progress=progress, hypotheses=hypotheses,
                   locations=locations, alpha=alpha, exact_cv=exact_cv, library=library,
                   settings=settings, collect=collect, generic=generic, pairs=pairs,
                   families=families, profile=profile, design=design)
    out_dir = Path(out_dir)
    from .report.markdown import write_report
    write_report(out_dir, d, plots=plots)
    out = summary(d)
    (out_dir / "diagnosis.json").write_text(json.dumps(out, indent=1))
    (out_dir / "candidates.json").write_text(json.dumps(details(d), indent=1))
    if store is not None:
        store.discard()
    return out


def candidates(model_path, library=None, hypotheses=None, locations=None):
    """(library, graph, [(hyp_id, location, [Param...])]) the model graph
    offers (for scripts such as benchmarks/detection_power.py)."""
    from .library.loader import load_library
    from .problem import Problem
    lib = load_library(library)
    problem = Problem(str(model_path), "", lib.name, ())
    cands = stages.candidates(problem, hypotheses, locations)
    return lib, lib.graph_of(model_path), [(c.hypothesis, c.location, list(c.params))
                                           for c in cands]
