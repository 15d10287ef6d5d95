"""The ``acausal`` command: simulate, variables, calibrate, sweep, diagnose.

Exit codes: 0 success, 2 a model or input error (one readable message on
stderr), 3 a solver failure (time and component named).
"""
import json
import sys

import click

from .errors import AcausalError, SolverError


def _fail(exc):
    code = 3 if isinstance(exc, SolverError) else 2
    click.echo(f"acausal: error: {exc}", err=True)
    sys.exit(code)


def _parse_sets(sets):
    out = {}
    for item in sets:
        if "=" not in item:
            raise click.BadParameter(f"--set {item!r}: expected PATH=VALUE")
        k, v = item.split("=", 1)
        try:
            out[k.strip()] = float(v)
        except ValueError:
            raise click.BadParameter(f"--set {item!r}: {v!r} is not a number") from None
    return out


@click.group()
@click.version_option(package_name="acausal")
def main():
    """Equation-based simulation of mechanisms."""


@main.command()
@click.argument("file", type=click.Path(dir_okay=False))
@click.option("--t-end", type=float, help="stop time [s] (default: the model file's)")
@click.option("--set", "sets", multiple=True, metavar="PATH=VALUE",
              help="override a parameter, e.g. --set contact.K=6.25e8")
@click.option("--out", type=click.Path(dir_okay=False), help="write all variables to CSV")
@click.option("--plot", type=click.Path(dir_okay=False), help="write a figure (PNG, PDF...)")
@click.option("--json", "as_json", is_flag=True, help="print one JSON object")
@click.option("--rtol", type=float)
@click.option("--atol", type=float)
def simulate(file, t_end, sets, out, plot, as_json, rtol, atol):
    """Simulate a model file."""
    from .modelfile import compile_file, evaluate_measures
    try:
        params = _parse_sets(sets)
        mf, cm = compile_file(file)
        opts = mf.experiment.run_options()
        for k, v in dict(t_end=t_end, rtol=rtol, atol=atol).items():
            if v is not None:
                opts[k] = v
        try:
            res = cm.simulate(params=params, **opts)
        except SolverError as exc:
            if exc.result is not None and out:
                exc.result.to_csv(out)
                click.echo(f"acausal: partial results up to t = {exc.t:.6g} s written to {out}",
                           err=True)
            raise
        measures = evaluate_measures(mf, res)
        if out:
            res.to_csv(out)
        if plot:
            _plot(mf, res, plot)
    except (AcausalError, click.BadParameter) as exc:
        _fail(exc)
    if as_json:
        click.echo(json.dumps({
            "final": res.final(),
            "events": [{"t": t, "name": n} for t, n in res.events],
            "measures": measures,
            "stats": {k: res.stats.get(k) for k in ("nfev", "steps", "wall_s", "compile_s",
                                                    "njev", "events")},
        }, indent=1))
    else:
        click.echo(f"simulated {mf.path}: t = {res.t[0]:g} .. {res.t[-1]:g} s, "
                   f"{len(res.events)} events, {res.stats['steps']} steps, "
                   f"{res.stats['wall_s'] * 1e3:.1f} ms (compile {cm.compile_s:.2f} s)")
        for k, v in measures.items():
            click.echo(f"  {k} = {v:.6g}")


def _plot(mf, res, path):
    custom = mf.namespace.get("plot")
    if callable(custom):
        custom(res, path)
        return
    names = custom or [s.name for s in res.model.dae.y[:res.model.dae.n_states]
                       if "." in s.name and not s.name.startswith("der(")][:6]
    res.plot(names, path, title=mf.path.rsplit("/", 1)[-1])


@main.command()
@click.argument("file", type=click.Path(dir_okay=False))
def variables(file):
    """List parameters and variables with units and defaults."""
    from .modelfile import compile_file
    try:
        mf, cm = compile_file(file)
    except AcausalError as exc:
        _fail(exc)
    click.echo("PARAMETERS (settable with --set)")
    for p in cm.params:
        click.echo(f"  {p.name:32s} = {p.default:<12.6g} [{p.unit}]  {p.decl.desc}")
    for name, val in cm.structural.items():
        click.echo(f"  {name:32s} = {val!r:<12} (structural)")
    for name, val in cm.bound.items():
        click.echo(f"  {name:32s} = {val} (bound)")
    click.echo("VARIABLES")
    states = {s.name for s in cm.dae.y[:cm.dae.n_states]}
    for name in cm.var_names:
        info = cm.flat.variables[name]
        st = info.start
        kind = "state" if name in states else ""
        start = f"start {st.value}{' (fixed)' if st.fixed else ''}"
        click.echo(f"  {name:32s} [{info.unit}] {info.desc}; {start} {kind}")
    for d in cm.discretes:
        click.echo(f"  {d.symbol.name:32s} [{d.unit}] {d.desc}; discrete, start {d.start.value}")


@main.command()
@click.argument("file", type=click.Path(dir_okay=False))
@click.argument("data", type=click.Path(file_okay=False))
@click.option("--fit", required=True, metavar="P1,P2,...",
              help="parameters to fit; with --method report give PARAM:MEASURE pairs "
                   "in the order the report calibrates them (contact.K:contact_period,hook.bh:thrt)")
@click.option("--method", type=click.Choice(["lsq", "report"]), default="lsq", show_default=True)
@click.option("--experiments", metavar="E1,E2,...|all",
              help="fit these experiments, or 'all' (default: the rows the data marks "
                   "use=calibrate, every row without a use column); the others are "
                   "predicted and compared")
@click.option("--json", "as_json", is_flag=True, help="print one JSON object")
def calibrate(file, data, fit, method, experiments, as_json):
    """Fit parameters of a model file to a measured dataset."""
    from . import calibrate as cal
    from .modelfile import compile_file
    try:
        mf, cm = compile_file(file)
        ds = cal.model_dataset(file, data)
        chosen = None
        if experiments:
            chosen = "all" if experiments.strip() == "all" else [
                x.strip() for x in experiments.split(",") if x.strip()]
        ds, held = cal.split(ds, chosen)
        items = [x.strip() for x in fit.split(",") if x.strip()]
        if method == "report":
            pairs = []
            for it in items:
                if ":" not in it:
                    raise click.BadParameter(f"--fit {it!r}: the report method needs PARAM:MEASURE")
                p, m = it.split(":", 1)
                pairs.append((p, m))
            cal.check_names(cm, [p for p, _ in pairs])
            out = cal.report_method(file, ds, pairs)
        else:
            names = [it.split(":", 1)[0] for it in items]
            cal.check_names(cm, names)
            out = cal.least_squares(file, ds, names)
        out.validation = cal.validate(file, held, out.values)
    except (AcausalError, click.BadParameter) as exc:
        _fail(exc)
    if as_json:
        click.echo(json.dumps(out.to_dict(), indent=1, default=float))
        return
    click.echo(f"calibration ({out.method}) of {file} against {data} "
               f"({', '.join(e.name for e in ds.experiments)}): {out.n_sim} simulations")
    for name, v in out.values.items():
        ci = out.ci95.get(name)
        ci_s = f"  95% CI [{ci[0]:.6g}, {ci[1]:.6g}]" if ci else ""
        click.echo(f"  {name} = {v:.6g}{ci_s}")
    if out.correlation is not None and len(out.values) > 1:
        click.echo("  correlation:")
        for name, row in zip(out.values, out.correlation):
            click.echo(f"    {name:20s} " + " ".join(f"{x:+.3f}" for x in row))
    click.echo("  residuals (simulated - measured):")
    for exp, sig in out.residuals.items():
        click.echo(f"    {exp}: " + ", ".join(f"{k} {v:+.4g}" for k, v in sig.items()))
    if out.validation:
        click.echo("  held back, predicted with these values (simulated - measured):")
        for exp, sig in out.validation.items():
            click.echo(f"    {exp}: " + ", ".join(
                f"{k} {v}" if k == "error" else f"{k} {v:+.4g}" for k, v in sig.items()))


@main.command()
@click.argument("file", type=click.Path(dir_okay=False))
@click.option("--param", "params", multiple=True, required=True, metavar="NAME=A:B:N",
              help="a swept parameter: start:stop:count, a list a,b,c, or one value")
@click.option("--measure", "measures", multiple=True, required=True, help="measure(s) to record")
@click.option("--out", type=click.Path(dir_okay=False), default="sweep.csv", show_default=True,
              help="results CSV; running again with the same file resumes")
@click.option("--plot", type=click.Path(dir_okay=False), help="plot the first measure")
@click.option("--scheduler", help="Dask scheduler address (default: local processes)")
@click.option("--workers", type=int, help="local worker processes (default: all cores)")
@click.option("--no-progress", is_flag=True)
def sweep(file, params, measures, out, plot, scheduler, workers, no_progress):
    """Run a grid of simulations in parallel."""
    import functools
    import os

    from .executor import open_executor
    from .modelfile import compile_file, sweep_task
    from .sweep import grid, parse_param, plot_sweep, run_sweep
    try:
        mf, cm = compile_file(file)
        specs = [parse_param(p) for p in params]
        for name, _ in specs:
            cm.param_index(name)
        for m in measures:
            if m not in mf.measures:
                raise click.BadParameter(f"--measure {m!r}: the model file defines "
                                         f"{sorted(mf.measures) or 'no measures'}")
        task = functools.partial(sweep_task, os.path.abspath(file))
        with open_executor(scheduler, workers) as ex:
            rows = run_sweep(task, grid(specs), out, executor=ex, measures=list(measures),
                             progress=not no_progress)
        if plot:
            plot_sweep(rows, specs[0][0], measures[0], plot)
    except (AcausalError, click.BadParameter, ValueError) as exc:
        _fail(exc)
    failed = sum(1 for r in rows if r.get("status") != "ok")
    click.echo(f"{len(rows)} points, {failed} failed; results in {out}")


def _csv_list(text):
    return None if text is None else [x.strip() for x in text.split(",") if x.strip()]


@main.command()
@click.argument("file", type=click.Path(dir_okay=False))
@click.argument("data", type=click.Path(file_okay=False))
@click.option("--json", "json_path", type=click.Path(dir_okay=False),
              help="write the summary as one JSON object to this file")
@click.option("--report", "report_dir", type=click.Path(file_okay=False), default="diagnosis",
              show_default=True, help="folder for report.md, plots and the extended model")
@click.option("--scheduler", help="Dask scheduler address (default: local processes)")
@click.option("--workers", type=int, help="local worker processes (default: all cores)")
@click.option("--hypotheses", metavar="ID,ID,...", help="only these hypotheses")
@click.option("--locations", metavar="PATH,PATH,...",
              help="only these locations (a path or a prefix of paths)")
@click.option("--alpha", type=float, default=0.01, show_default=True,
              help="family significance level of the discrepancy decision")
@click.option("--starts", type=click.IntRange(0, 64), default=4, show_default=True,
              help="Latin-hypercube starts per fit (besides the neutral and calibrated ones)")
@click.option("--refine", type=click.IntRange(1, 8), default=2, show_default=True,
              help="best starts refined per fit (their agreement is reported)")
@click.option("--no-progress", is_flag=True)
@click.option("--library", hidden=True, help="module standing in for the hypothesis library")
def diagnose(file, data, json_path, report_dir, scheduler, workers, hypotheses, locations,
             alpha, starts, refine, no_progress, library):
    """Show what a model gets wrong against measured data, name the cause,
    extend the model and measure the gain."""
    from .data import DataError
    from .diagnose.problem import FitSettings
    from .diagnose.run import diagnose as run_diagnosis
    try:
        if not 0 < alpha < 1:
            raise click.BadParameter(f"--alpha {alpha}: must be between 0 and 1")
        out = run_diagnosis(file, data, out_dir=report_dir, scheduler=scheduler,
                            workers=workers, progress=not no_progress,
                            hypotheses=_csv_list(hypotheses), locations=_csv_list(locations),
                            alpha=alpha, library=library,
                            settings=FitSettings(lhs=starts, refine=refine))
    except (AcausalError, DataError, click.BadParameter, ValueError, ImportError) as exc:
        _fail(exc)
    if json_path:
        with open(json_path, "w") as f:
            json.dump(out, f, indent=1)
    g = out["gain"]
    if not out["discrepancy"]:
        click.echo("no significant discrepancy between the calibrated model and the data")
    elif out["unexplained"]["value"]:
        click.echo(f"discrepancy not explained by the library; located at the node of "
                   f"{out['unexplained']['node']}")
    elif out["cause"] is None:
        click.echo("discrepancy, but the evidence is weak: no cause named"
                   + (f" (best candidate: {out['ranking'][0]['cause']} at "
                      f"{out['ranking'][0]['location']})" if out["ranking"] else ""))
    else:
        click.echo(f"discrepancy; cause: {out['cause']} at {out['location']}")
        for e in out["equivalent_causes"]:
            click.echo(f"  equivalent: {e['cause']} at {e['location']}")
    click.echo(f"error [instrument floor units]: train {g['before']['train']:.3g} -> "
               f"{g['after']['train']:.3g}, held-out {g['before']['heldout']:.3g} -> "
               f"{g['after']['heldout']:.3g}")
    if out["extended_model"]:
        click.echo(f"extended model: {out['extended_model']}")
    click.echo(f"report: {report_dir}/report.md" + (f"; JSON: {json_path}" if json_path else ""))


if __name__ == "__main__":  # pragma: no cover
    main()
