"""The diagnosis driver: from a model file and measured data to a named
cause, an extended model and the measured gain.

:func:`diagnose` chains the stages (calibrate -> fit -> decide -> family
members -> pairs -> tied sites fitted -> cross-validate -> rank -> shown row ->
locate -> intervals -> extend -> next experiment -> views), each a function
``stage(ctx, state) -> state`` of this module: ``ctx`` (a
:class:`~.stages.context.Context`) holds the executor, the progress
setting, the collector of finished fits and the clock; ``state`` (a
:class:`~.stages.state.State`) what the stages computed so far, each
stage returning a new one. The final state becomes a
:class:`~.report.result.Diagnosis`, from which the report is rendered
(:mod:`.report`, a pure view) and the JSON summary taken
(:func:`.report.result.summary`). The options are one
:class:`~.options.DiagnosisOptions`.

Errors are in units of the instrument floor throughout (RMS of
(simulated - measured)/floor): 1.0 is what the instrument's noise and
resolution alone explain.
"""
from __future__ import annotations

import dataclasses
import json
from pathlib import Path

from ..infra.executor import open_executor
from .options import DiagnosisOptions
from .report.result import Diagnosis, details, summary
from .stages import chain as stages
from .stages.chain import DiagnosisError
from .stages.context import Clock, Context
from .stages.families import family_index, fit_members, prefer_simplest
from .stages.intervals import intervals
from .stages.kinematics import Kinematics, equivalents, kinematics, placements, \
    prefer_site, tied_candidates
from .stages.locate import Location, locate
from .stages.nextexp import next_experiment
from .stages.resume import FitStore
from .stages.state import State
from .stages.tasks import fit_candidate
from .stages.verdict import SameCause, same_laws

__all__ = ["diagnose", "run_stages", "DiagnosisError", "DiagnosisOptions"]


# -- the stages, each stage(ctx, state) -> state ------------------------------------------
def calibrated(ctx: Context, s: State) -> State:
    """The nominal model's free parameters fitted (:func:`.stages.chain.calibrate`)."""
    return dataclasses.replace(s, calibration=stages.calibrate(ctx, s.problem))


def fitted(ctx: Context, s: State) -> State:
    """Every candidate fitted (:func:`.stages.chain.fit`)."""
    return dataclasses.replace(s, fits=stages.fit(ctx, s.problem, s.calibration, s.candidates))


def decided(ctx: Context, s: State) -> State:
    """The fits so far scored and the discrepancy decided (:func:`.stages.chain.decide`)."""
    return dataclasses.replace(s, decision=stages.decide(s.dataset, s.calibration, s.fits,
                                                         s.options.alpha))


def members_fitted(ctx: Context, s: State) -> State:
    """The other members of each competitive family fitted and the decision
    taken again with them (:func:`.stages.families.fit_members`; option
    ``families``): at rigidly tied sites (:meth:`.stages.kinematics.Kinematics.places`)
    at one of them, then each fitted member at the others from its converted
    fit (:func:`.stages.kinematics.placements`)."""
    if not s.options.families:
        return s
    if s.decision is not None and s.decision.discrepancy:
        s = with_kinematics(ctx, s)
    places = s.kinematics.places() if s.kinematics is not None else None
    with ctx.clock.timing("families_s"):
        members = fit_members(ctx, s.problem, s.calibration, s.decision, places)
        more = _other_placements(ctx, s, members.fits, "family members", singles=True)
        members = dataclasses.replace(members, fits=members.fits + more)
    s = dataclasses.replace(s, members=members)
    if not members.fits:
        return s
    return decided(ctx, dataclasses.replace(s, fits=s.fits + members.fits))


def _allowed(options):
    """Whether a site is among the user's ``locations`` (exact, or a prefix
    followed by '.'), as a function of the site; None: every site is."""
    locs = options.locations
    if locs is None:
        return None
    return lambda loc: any(loc == w or loc.startswith(w + ".") for w in locs)


def _other_placements(ctx: Context, s: State, fits, what, singles=False) -> tuple:
    """The fits of ``fits``' other placements at rigidly tied sites
    (:func:`.stages.kinematics.placements`: pairs, and single causes too
    with ``singles``; none already among ``fits`` or the decision's rows),
    each refined from its converted fit (:func:`.stages.chain.placement_tasks`;
    a pair with a floor at each member's own fit, :func:`.stages.chain.with_floors`)."""
    if s.kinematics is None:
        return ()
    moves = placements(s.problem, s.kinematics, fits, _allowed(s.options), singles=singles,
                       fitted=s.decision.rows)
    if not moves:
        return ()
    rows = {r.candidate.key: r for r in s.decision.rows}
    tasks = [stages.with_floors(t, rows) for t in stages.placement_tasks(s.problem,
                                                                         s.calibration, moves)]
    return tuple(ctx.run(fit_candidate, tasks, f"fitting {what} at rigidly tied sites"))


def with_kinematics(ctx: Context, s: State) -> State:
    """``s`` with its tied sites (:func:`.stages.kinematics.kinematics`, read
    from the calibrated nominal runs) when not yet read."""
    if s.kinematics is not None:
        return s
    with ctx.clock.timing("kinematics_s"):
        return dataclasses.replace(s, kinematics=kinematics(s.problem, s.calibration))


def pairs_searched(ctx: Context, s: State) -> State:
    """When the best single cause leaves misfit (option ``pairs``): the pair
    search (:func:`.stages.chain.search_pairs`, rigidly tied sites one place:
    :meth:`.stages.kinematics.Kinematics.places`) and, when a pair comes out
    best, its members refitted alone from the pair's point
    (:func:`.stages.chain.member_refit_tasks`), each followed by the decision."""
    if not (s.options.pairs and stages.pairs_needed(s.decision)):
        return s
    s = with_kinematics(ctx, s)
    with ctx.clock.timing("pairs_s"):
        got = stages.search_pairs(ctx, s.problem, s.calibration, s.decision,
                                  s.kinematics.places())
        got = dataclasses.replace(got, fits=got.fits + _other_placements(ctx, s, got.fits,
                                                                         "pairs"))
        s = decided(ctx, dataclasses.replace(s, fits=s.fits + got.fits, pair_search=got,
                                             pair_screen_n_sim=got.screen_n_sim))
        again = stages.member_refit_tasks(s.problem, s.calibration, s.decision)
        if again:
            refits = ctx.run(fit_candidate, again, "refitting the pair's members")
            s = decided(ctx, dataclasses.replace(s, fits=s.fits + tuple(refits)))
    return s


def tied_fitted(ctx: Context, s: State) -> State:
    """The tied sites read from the calibrated nominal runs
    (:func:`.stages.kinematics.kinematics`) and, when a discrepancy is found,
    each of the best rows fitted with a member moved to a site tied to its
    own, where it was not (:func:`.stages.kinematics.tied_candidates`), then
    the decision again: a cause is compared at both tied sites before either
    is shown."""
    d = s.decision
    if d is None or not d.discrepancy or not d.rows:
        return s
    s = with_kinematics(ctx, s)
    cands = tied_candidates(s.problem, s.kinematics, d.rows, _allowed(s.options))
    if not cands:
        return s
    with ctx.clock.timing("tied_s"):
        rows = {r.candidate.key: r for r in d.rows}
        got = ctx.run(fit_candidate, [stages.with_floors(t, rows) for t in stages.fit_tasks(
            s.problem, s.calibration, cands)], "fitting at tied sites")
    return decided(ctx, dataclasses.replace(s, fits=s.fits + tuple(got)))


def cross_validated(ctx: Context, s: State) -> State:
    """Exact leave-one-experiment-out refits (:func:`.stages.chain.cross_validate`)."""
    return dataclasses.replace(s, cv=stages.cross_validate(
        ctx, s.problem, s.dataset, s.calibration, s.decision, s.options.exact_cv))


def ranked(ctx: Context, s: State) -> State:
    """The ranking and the verdict (:func:`.stages.chain.rank`)."""
    same = SameCause(family_index(s.problem.library), s.kinematics,
                     same_laws(s.problem.library))
    return dataclasses.replace(s, ranking=stages.rank(s.dataset, s.calibration, s.decision,
                                                      s.cv, s.members.unfitted
                                                      + s.pair_search.unfitted, same))


def shown(ctx: Context, s: State) -> State:
    """The row shown moved to the simplest member of its family the data
    support (:func:`.stages.families.prefer_simplest`, with ``families``),
    then to a kinematically tied site whose coordinate is measured when the
    data cannot tell the two apart (:func:`.stages.kinematics.prefer_site`)."""
    rk = s.ranking
    if s.options.families:
        rk = prefer_simplest(rk, family_index(s.problem.library))
    if rk.after is None:
        return dataclasses.replace(s, ranking=rk,
                                   kinematics=Kinematics(message="no cause to place"))
    kin = s.kinematics
    if kin is None:
        with ctx.clock.timing("kinematics_s"):
            kin = kinematics(s.problem, s.calibration)
    return dataclasses.replace(s, ranking=prefer_site(rk, kin), kinematics=kin)


def located(ctx: Context, s: State) -> State:
    """A discrepancy the library does not explain located (:mod:`.stages.locate`;
    option ``generic``)."""
    if not s.options.generic:
        return dataclasses.replace(s, location=Location(skipped="not run (generic=False)"))
    return dataclasses.replace(s, location=locate(ctx, s.problem, s.calibration, s.decision,
                                                  s.ranking))


def profiled(ctx: Context, s: State) -> State:
    """Checked or profiled 95 % intervals (:mod:`.stages.intervals`; option ``profile``)."""
    if not s.options.profile:
        return s
    with ctx.clock.timing("profile_s"):
        ivs = intervals(ctx, s.problem, s.calibration, s.ranking)
    return dataclasses.replace(s, intervals=ivs)


def extended(ctx: Context, s: State) -> State:
    """The named cause's extended model file written into ``out_dir``
    (:func:`.stages.chain.extend`) and its kinematically tied sites
    (:func:`.stages.kinematics.equivalents`)."""
    Path(s.out_dir).mkdir(parents=True, exist_ok=True)
    path = stages.extend(s.problem, s.ranking, s.out_dir)
    return dataclasses.replace(s, extended_model=path,
                               tied=equivalents(s.problem, s.kinematics, s.ranking))


def designed(ctx: Context, s: State) -> State:
    """The library's families and the next experiment that splits the best
    candidate's class (:mod:`.stages.nextexp`; option ``design``)."""
    index = family_index(s.problem.library)
    if not s.options.design:
        return dataclasses.replace(s, families=index)
    def side_by_side(fn, jobs):       # the rivals' simulations on the executor
        return ctx.run(fn, jobs, "designing the next experiment", checkpoint=False,
                       progress=False)
    with ctx.clock.timing("design_s"):
        nxt = next_experiment(s.problem, s.dataset, s.decision, s.ranking, index,
                              map_jobs=side_by_side)
    return dataclasses.replace(s, families=index, next_experiment=nxt)


def viewed(ctx: Context, s: State) -> State:
    """What the report shows that needs simulations (:mod:`.stages.views`; option ``views``)."""
    if not s.options.views:
        return s
    from .stages.views import views as make_views
    return dataclasses.replace(s, views=make_views(s.problem, s.calibration, s.ranking))


# -- the chain ------------------------------------------------------------------------------
def run_stages(model_path, data_folder, options: DiagnosisOptions | None = None, *, out_dir,
               collect=None, **keywords) -> Diagnosis:
    """The stages in order; returns the :class:`Diagnosis` (writes only the
    extended model file into ``out_dir``). ``options``: a
    :class:`DiagnosisOptions` (None: the defaults); ``keywords``: its fields,
    replacing those of ``options`` (``run_stages(model, data, out_dir=...,
    workers=2, pairs=False)``). ``collect(task, result)`` is called as each
    fit result arrives (a checkpoint store plugs in there)."""
    opts = DiagnosisOptions.of(options, "run_stages", **keywords)
    clock = Clock()
    problem, ds = stages.load_problem(model_path, data_folder, opts.library, opts.settings)
    s = State(problem, ds, opts, str(out_dir),
              stages.candidates(problem, opts.hypotheses, opts.locations))
    with open_executor(opts.scheduler, opts.workers) as ex:
        ctx = Context(ex, opts.progress, collect, clock)
        s = _timed(fitted, ctx, _timed(calibrated, ctx, s))
        t_fit = clock.elapsed()
        for stage in (decided, members_fitted, pairs_searched, tied_fitted, cross_validated,
                      ranked, shown,
                      located, profiled, extended, designed):
            s = _timed(stage, ctx, s)
    t_cv = clock.elapsed() - t_fit
    ctx = Context(None, opts.progress, collect, clock)   # the stage below submits no task
    s = _timed(viewed, ctx, s)
    return diagnosis_of(s, _timing(s, clock, t_fit, t_cv))


def _timed(stage, ctx: Context, s: State) -> State:
    """``stage(ctx, s)``, its wall time recorded as ``stage_<name>_s`` (every
    stage's share of a slow case, in ``candidates.json``'s timing)."""
    with ctx.clock.timing(f"stage_{stage.__name__}_s"):
        return stage(ctx, s)


def _timing(s: State, clock: Clock, t_fit: float, t_cv: float) -> dict:
    """``candidates.json``'s timing: the fit stage's and the later stages'
    wall times, candidates, simulations, the total and each timed stage's."""
    extra = dict(clock.times)
    if s.location is not None and s.location.n_sim:
        extra["located_n_sim"] = s.location.n_sim    # the located term's (not in n_sim)
    if s.pair_screen_n_sim is not None:
        extra["pair_screen_n_sim"] = s.pair_screen_n_sim
        ps = s.pair_search
        extra["pair_screen"] = dict(pairs=ps.screened, within_reach=ps.within_reach,
                                    fitted=ps.fitted, share=ps.share,
                                    unfitted=[u.label for u in ps.unfitted])
    return dict(fit_s=t_fit, cv_s=t_cv, n_candidates=len(s.candidates), n_sim=s.n_sim,
                total_s=clock.elapsed(), **extra)


def diagnosis_of(s: State, timing: dict) -> Diagnosis:
    """The :class:`Diagnosis` of the final state."""
    return Diagnosis(problem=s.problem, dataset=s.dataset, calibration=s.calibration,
                     n_candidates=len(s.candidates), decision=s.decision, cv=s.cv,
                     ranking=s.ranking, extended_model=s.extended_model, views=s.views,
                     next_experiment=s.next_experiment, timing=timing, location=s.location,
                     intervals=s.intervals, families=s.families, kinematics=s.kinematics,
                     tied=s.tied)


def diagnose(model_path, data_folder, options: DiagnosisOptions | None = None, *, out_dir,
             collect=None, on_resume=None, **keywords) -> dict:
    """Diagnose ``model_path`` against the dataset folder ``data_folder``.

    Writes ``report.md``, ``diagnosis.json``, ``candidates.json``, plots and
    (when a cause is named) the extended model file into ``out_dir``;
    returns the summary dict (docs/diagnosis.md). ``options``: a
    :class:`DiagnosisOptions` (None: the command line's defaults);
    ``keywords``: its fields, replacing those of ``options``
    (``diagnose(model, data, out_dir=..., workers=2, hypotheses=[...])``;
    ``max_nfev`` kept for compatibility). Finished fits are kept in
    ``<out_dir>/checkpoint/`` (a run after an interruption resumes) unless
    ``collect`` takes them instead; ``on_resume(n, path)`` is called when
    ``n`` fits of an interrupted run of the same command are found in its
    checkpoint ``path``.
    """
    opts = DiagnosisOptions.of(options, "diagnose", **keywords)
    store = None
    if collect is None:   # keep finished fits in <out_dir>/checkpoint/ (resume after a kill)
        store = collect = FitStore(out_dir, model_path, data_folder, opts.checkpoint_key())
        if store.saved and on_resume is not None:
            on_resume(len(store.saved), store.checkpoint.path)
    d = run_stages(model_path, data_folder, opts, out_dir=out_dir, collect=collect)
    out_dir = Path(out_dir)
    from .report.markdown import write_report
    write_report(out_dir, d, plots=opts.plots)
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
