"""Run one independent case (seed 0, 30 floors) and keep its folder:
python one_case.py gear_cogging KEEP_DIR [workers]."""
import sys, json, time, os
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))
import independent_cases as IC
name, keep = sys.argv[1], sys.argv[2]
workers = int(sys.argv[3]) if len(sys.argv) > 3 else 2
case = IC.C.CASES[name]
t0 = time.time()
r = IC.run_one(case, 30.0 if case.scale and case.laws else None, 0, workers, keep=keep)
print(json.dumps({k: r[k] for k in ('verdict','wall_s','n_sim','located_n_sim','cpu_s_children','heldout_after','ok')}))
det = json.load(open(os.path.join(keep, "out", "candidates.json")))
print(json.dumps(det.get("timing"), indent=0, default=str)[:3000])
