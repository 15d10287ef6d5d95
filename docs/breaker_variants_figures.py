"""Tables and figures of docs/breaker_variants.md from the sweep CSVs that
``acausal sweep`` wrote to docs/variants/ (see the doc for the commands).

    python docs/breaker_variants_figures.py [docs/variants]

Prints the markdown tables and writes docs/breaker_variants_sweep.png.
"""
import math
import sys
from pathlib import Path

import numpy as np

from acausal.studies.sweep import read_rows

DESIGNS = [  # (csv stem, label)
    ("breaker_24kv", "base (plunger armature, one hook)"),
    ("breaker_24kv_light_hook", "light hook (Jh -32 %, kh x2)"),
    ("breaker_24kv_rotary_armature", "rotary armature (clapper, 0.16 kg at the pin)"),
    ("breaker_24kv_two_stage", "two-stage latch (trip lever, ratio 1.2)"),
]
MA, MEFF_ROT = 0.22, 1.0e-4 / 0.025**2   # [kg] plunger mass, clapper Ja/la^2


def load(folder, stem):
    """Rows of one sweep sorted by v_impact, as dicts of floats (ok rows only)."""
    rows = read_rows(Path(folder, f"{stem}.csv"))
    bad = [r for r in rows if r["status"] != "ok"]
    if bad:
        print(f"warning: {stem}: {len(bad)} failed point(s)", file=sys.stderr)
    out = [{k: float(v) for k, v in r.items() if k not in ("status", "error") and v != ""}
           for r in rows if r["status"] == "ok"]
    return sorted(out, key=lambda r: r["v_impact"])


def table(data, speeds=(3.3, 3.5, 3.8, 4.0, 4.2, 4.5)):
    base = {round(r["v_impact"], 6): r for r in data["breaker_24kv"]}
    lines = ["| design | quantity | " + " | ".join(f"{v:.1f}" for v in speeds) + " |",
             "|---|---|" + "---|" * len(speeds)]
    for stem, label in DESIGNS:
        rows = {round(r["v_impact"], 6): r for r in data[stem]}
        get = (lambda key, v, rows=rows: rows[round(v, 6)][key])
        lines.append(f"| {label} | THRT [ms] | "
                     + " | ".join(f"{get('thrt', v) * 1e3:.3f}" for v in speeds) + " |")
        if stem != "breaker_24kv":
            lines.append("| | ΔTHRT vs base [ms] | " + " | ".join(
                f"{(get('thrt', v) - base[round(v, 6)]['thrt']) * 1e3:+.3f}" for v in speeds)
                + " |")
        lines.append("| | peak force [N] | "
                     + " | ".join(f"{get('peak_force', v):.0f}" for v in speeds) + " |")
        lines.append("| | contact period [ms] | "
                     + " | ".join(f"{get('contact_period', v) * 1e3:.3f}" for v in speeds) + " |")
        if "n_impacts" in next(iter(rows.values())):
            n = " | ".join(f"{get('n_impacts', v):.0f}"
                           + (f" + {get('n_latch_impacts', v):.0f}" if "n_latch_impacts"
                              in rows[round(v, 6)] else "") for v in speeds)
            lines.append(f"| | impacts | {n} |")
    return "\n".join(lines)


def equal_energy(data):
    """THRT of the clapper at the pin speed giving the plunger's kinetic energy."""
    base, rot = data["breaker_24kv"], data["breaker_24kv_rotary_armature"]
    vr = np.array([r["v_impact"] for r in rot])
    tr = np.array([r["thrt"] for r in rot])
    lines = ["| plunger v [m/s] | kinetic energy [J] | clapper pin v [m/s] | THRT plunger [ms] "
             "| THRT clapper [ms] |", "|---|---|---|---|---|"]
    for r in base:
        v2 = r["v_impact"] * math.sqrt(MA / MEFF_ROT)
        if v2 <= vr[-1]:
            lines.append(f"| {r['v_impact']:.1f} | {0.5 * MA * r['v_impact'] ** 2:.2f} | "
                         f"{v2:.3f} | {r['thrt'] * 1e3:.3f} | "
                         f"{np.interp(v2, vr, tr) * 1e3:.3f} |")
    return "\n".join(lines)


def figure(data, path):
    import matplotlib
    matplotlib.use("Agg")
    from matplotlib.figure import Figure
    fig = Figure(figsize=(7, 6.4))
    ax1, ax2 = fig.subplots(2, 1, sharex=True)
    for (stem, label), mk in zip(DESIGNS, "osD^"):
        rows = data[stem]
        v = [r["v_impact"] for r in rows]
        ax1.plot(v, [r["thrt"] * 1e3 for r in rows], mk + "-", ms=3.5, label=label)
        ax2.plot(v, [r["peak_force"] for r in rows], mk + "-", ms=3.5, label=label)
    ax1.set_ylabel("THRT [ms]")
    ax2.set_ylabel("peak impact force\narmature contact [N]")
    ax2.set_xlabel("impact velocity v_impact [m/s]")
    for ax in (ax1, ax2):
        ax.grid(alpha=0.3)
    ax1.legend(fontsize=8)
    fig.suptitle("24 kV breaker variants: acausal sweep, v_impact = 3.3 .. 4.5 m/s",
                 fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(folder="docs/variants"):
    data = {stem: load(folder, stem) for stem, _ in DESIGNS}
    print(table(data))
    print()
    print(equal_energy(data))
    out = Path(folder).parent / "breaker_variants_sweep.png"
    figure(data, out)
    print(f"\nwrote {out}")


if __name__ == "__main__":
    main(*sys.argv[1:])
