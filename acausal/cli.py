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


if __name__ == "__main__":  # pragma: no cover
    main()
