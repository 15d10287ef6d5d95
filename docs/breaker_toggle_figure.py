"""Table and figure of the toggle-latch section of docs/breaker_variants.md:
the base breaker (models/breaker_24kv.py) and the toggle variant
(models/breaker_24kv_toggle.py) at the six speeds of the doc's table, the
toggle's over-centre angle at 3.8 m/s, and one run of each drawn.

    python docs/breaker_toggle_figure.py      # prints the tables, writes docs/breaker_24kv_toggle.png
"""
import math
import sys
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "models"))

from acausal.modelfile import compile_file, evaluate_measures  # noqa: E402

SPEEDS = (3.3, 3.5, 3.8, 4.0, 4.2, 4.5)
OVER_CENTRE_DEG = (0.25, 0.5, 1.0, 2.0, 3.0)


def run(mf, cm, **params):
    res = cm.simulate(**mf.experiment.run_options(), params=params)
    return res, evaluate_measures(mf, res)


def main(out=ROOT / "docs" / "breaker_24kv_toggle.png"):
    base_f, base = compile_file(str(ROOT / "models" / "breaker_24kv.py"))
    tog_f, tog = compile_file(str(ROOT / "models" / "breaker_24kv_toggle.py"))
    rows = {"base": [], "toggle": []}
    for v in SPEEDS:
        rows["base"].append(run(base_f, base, v_impact=v)[1])
        rows["toggle"].append(run(tog_f, tog, v_impact=v)[1])
    print("| design | quantity | " + " | ".join(f"{v:.1f}" for v in SPEEDS) + " |")
    print("|---|---|" + "---|" * len(SPEEDS))
    for name, label in (("base", "base (cam and roller, e = 0.2 mm)"),
                        ("toggle", "toggle latch (l2 = 25 mm, 1 deg over centre)")):
        r = rows[name]
        print(f"| {label} | THRT [ms] | " + " | ".join(f"{m['thrt'] * 1e3:.3f}" for m in r) + " |")
        if name == "toggle":
            print("| | ΔTHRT vs base [ms] | " + " | ".join(
                f"{(m['thrt'] - b['thrt']) * 1e3:+.3f}" for m, b in zip(r, rows["base"])) + " |")
        print("| | contact period [ms] | "
              + " | ".join(f"{m['contact_period'] * 1e3:.3f}" for m in r) + " |")
        print("| | peak force [N] | " + " | ".join(f"{m['peak_force']:.0f}" for m in r) + " |")
    print()
    print("| over centre [deg] | " + " | ".join(f"{a:g}" for a in OVER_CENTRE_DEG) + " |")
    print("|---|" + "---|" * len(OVER_CENTRE_DEG))
    geo = __import__("breaker_24kv_toggle").toggle_geometry
    dead = geo(over_centre=0.0)["phia"]
    thrt, torque0 = [], []
    for a in OVER_CENTRE_DEG:
        res, m = run(tog_f, tog, **{"cam.phia": dead + math.radians(a)})
        thrt.append(m["thrt"] * 1e3)
        torque0.append(-res["cam.pin_a.axis.tau"][0])
    print("| THRT at 3.8 m/s [ms] | " + " | ".join(f"{t:.3f}" for t in thrt) + " |")
    print("| toggle torque on the hook when latched [N·m] | "
          + " | ".join(f"{t:.2f}" for t in torque0) + " |")
    draw(out, rows, base, tog, base_f, tog_f)


def draw(out, rows, base, tog, base_f, tog_f):
    fig = Figure(figsize=(10, 6.5))
    ax = fig.subplots(2, 2)
    for name, ls in (("base", "-"), ("toggle", "--")):
        ax[0, 0].plot(SPEEDS, [m["thrt"] * 1e3 for m in rows[name]], ls, marker="o", label=name)
        ax[0, 1].plot(SPEEDS, [m["contact_period"] * 1e3 for m in rows[name]], ls, marker="o",
                      label=name)
    ax[0, 0].set(xlabel="impact velocity [m/s]", ylabel="THRT [ms]")
    ax[0, 1].set(xlabel="impact velocity [m/s]", ylabel="contact period [ms]")
    for (mf, cm, label, ls) in ((base_f, base, "base: cam", "-"),
                                (tog_f, tog, "toggle latch", "--")):
        res, _ = run(mf, cm, v_impact=3.8)
        t = (res.t - res.t[0]) * 1e3
        ax[1, 0].plot(t, np.degrees(res["hook.phi"]), ls, label=label)
        ax[1, 1].plot(t, -res["cam.flange_a.tau"] if "cam.flange_a.tau" in res.names
                      else -res["cam.pin_a.axis.tau"], ls, label=label)
    ax[1, 0].set(xlabel="time [ms] (3.8 m/s)", ylabel="hook angle [deg]")
    ax[1, 1].set(xlabel="time [ms] (3.8 m/s)", ylabel="linkage torque on the hook [N·m]\n"
                 "(> 0 against the trip)")
    for a in ax.flat:
        a.grid(alpha=0.3)
        a.legend(fontsize=8)
    fig.suptitle("24 kV breaker: cam and roller (base) against a toggle latch")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
