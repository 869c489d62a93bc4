"""The woven Case A presets at 4 mm as shipped (issue 13, done-when 3), each run by
``jaxform run PRESET --element-size-mm 4 --out RUNS/PRESET --quiet`` one after the other on both
cores; this collects each run's summary.json into presets.json (wall time, completion, KE/IE, shear,
draw-in, wrinkles, numerics; next to this script, or into OUT.json with ``--out``). Exit 1 if a
run is missing or incomplete (its row is still written).
Run: .venv/bin/python collect.py RUNS_DIR PRESET [PRESET ...] [--out OUT.json]"""
import json
import sys
from pathlib import Path

args = sys.argv[1:]
out = Path(__file__).resolve().parent / "presets.json"
if "--out" in args:
    i = args.index("--out")
    out, args = Path(args[i + 1]), args[:i] + args[i + 2:]
runs, names = Path(args[0]), args[1:]
rows, bad = {}, []
for name in names:
    path = runs / name / "summary.json"
    if not path.exists():
        rows[name], bad = None, bad + [name]
        continue
    s = json.loads(path.read_text())
    if "numerics" not in s:  # the summary a run writes at its start: running, or killed before its end
        rows[name], bad = {"complete": False, "reason": s.get("reason")}, bad + [name]
        continue
    n = s["numerics"]
    rows[name] = {"complete": s["complete"], "reason": s["reason"], "wall_time_s": s.get("wall_time_s"),
                  "max_ke_ie": s["max_ke_ie"], "max_shear_deg": s["max_shear_angle_deg"],
                  "draw_in_edge_mid_mm": 1e3 * s["draw_in"]["edge_mid_m"], "draw_in_corner_mm": 1e3 * s["draw_in"]["corner_m"],
                  "flange_wrinkles": s["flange_wrinkles"], "n_steps": n["n_steps"], "dt_s": n["dt_s"],
                  "dt_governed_by": n["dt_governed_by"], "fibre_mass_scaling": n["fibre_mass_scaling"],
                  "fibre_mass_momentum_term_from_step": n["fibre_mass_momentum_term_from_step"],
                  "punch_speed_mm_per_s": 1e3 * n["punch_speed_m_per_s"], "step_cuts": n["step_cuts"],
                  "findings": [f["text"] for f in s.get("findings", [])]}
    if not s["complete"]:
        bad.append(name)
out.write_text(json.dumps(rows, indent=1))
for k, v in rows.items():
    print(k, v if v is None else {q: v.get(q) for q in ("complete", "wall_time_s", "max_ke_ie", "max_shear_deg", "draw_in_edge_mid_mm",
                                                    "draw_in_corner_mm", "flange_wrinkles", "n_steps")})
sys.exit(f"collect.py: missing or incomplete: {', '.join(bad)}" if bad else 0)
