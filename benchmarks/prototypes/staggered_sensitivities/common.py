"""The located case the prototype works on: a gear_cogging diagnosis kept by
``one_case.py`` (its folder in ACAUSAL_PROTO_CASE: data/ and out/candidates.json)."""
import json, os, sys, time, numpy as np
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
sys.path.insert(0, os.path.join(ROOT, "tests", "diagnose", "independent"))
from acausal.diagnose.stages.chain import load_problem
from acausal.diagnose.stages.fitting import FitRuns, residuals_of, run_options
from acausal.diagnose.library import generic as gen
import cases as C
case = C.CASES["gear_cogging"]; keep = os.environ.get("ACAUSAL_PROTO_CASE") or sys.exit(
    "set ACAUSAL_PROTO_CASE to a kept gear_cogging case (see README.md)")
problem, ds = load_problem(case.model, keep + "/data")
d = json.load(open(keep + "/out/candidates.json"))
T = d["located"][0]
vals = T["values"]; nx, nv = T["resolution"]; node = T["node"]
mf, cm = gen.build_at(case.model, node, nx, nv)
cm = cm.with_defaults(dict(gen.range_values(T["ranges"])))
pair = (mf, cm)
