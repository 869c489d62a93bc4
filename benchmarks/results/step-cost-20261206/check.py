"""Compare two pickled runs of run.py (OUT/A.pkl against OUT/B.pkl): the quasi-static check's three
figures (forming.quasi_static_check: shear map p95, edge mid-side draw-in, flange wrinkles), each run's
energy balance, KE/IE and wall time, written to OUT/check.json. Exit 1 if a run is incomplete.
Run: .venv/bin/python check.py OUT_DIR A B"""
import json
import pickle
import sys
from pathlib import Path

from jaxform import forming

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from energy_balance import balance  # noqa: E402  (benchmarks/)

out, a, b = Path(sys.argv[1]), sys.argv[2], sys.argv[3]
runs = {k: pickle.load(open(out / f"{k}.pkl", "rb")) for k in (a, b)}
rec = {}
for k, v in runs.items():
    r, s = v["result"], v["result"].summary
    rec[k] = {"wall_s": v["wall_s"], "complete": r.complete, "reason": r.reason, "n_steps": s["numerics"]["n_steps"],
              "dt_s": s["numerics"]["dt_s"], "max_ke_ie": s["max_ke_ie"], "max_shear_deg": s["max_shear_angle_deg"],
              "draw_in": s["draw_in"], "flange_wrinkles": s["flange_wrinkles"], "energy_balance": balance(r)}
rec["check"] = forming.quasi_static_check(runs[b]["result"], runs[a]["result"])
(out / "check.json").write_text(json.dumps(rec, indent=1))
print(json.dumps({k: (v if k != "check" else {q: w for q, w in v.items() if "per_frame" not in q}) for k, v in rec.items()}, indent=1))
sys.exit(0 if all(v["result"].complete for v in runs.values()) else "check.py: a run is incomplete")
