"""The quasi-static measures between two finished run folders of one case at the same speed that differ
in their numerics (issue 13, done-when 5: against a run without the new device): python compare.py A B.
Each frame's shear map (p95 of the node differences), the edge mid-side draw-in, the flange wrinkles,
through forming.quasi_static_check itself (the 'half' slot holds B, at A's speed), and the numerics."""
import json, sys
from jaxform.forming import quasi_static_check
from jaxform.study.measures import _as_result, load_run

a, b = load_run(sys.argv[1]), load_run(sys.argv[2])
v = float(a.summary["numerics"]["punch_speed_m_per_s"])
assert abs(float(b.summary["numerics"]["punch_speed_m_per_s"]) - v) < 1e-9 * v, "same speed expected"
c = quasi_static_check(_as_result(a, v), _as_result(b, v))
keys = ("dt_s", "n_steps", "contact_implicit_normal", "contact_safety", "max_penetration_ply", "step_cuts")
out = {"a": sys.argv[1], "b": sys.argv[2], "check": c,
       "numerics": {k: [r.summary["numerics"].get(k) for r in (a, b)] for k in keys},
       "wall_time_s": [r.summary.get("wall_time_s") for r in (a, b)],
       "max_ke_ie": [r.summary.get("max_ke_ie") for r in (a, b)],
       "draw_in_mm": [r.summary.get("draw_in_edge_mid_mm") for r in (a, b)]}
print(json.dumps(out, indent=1, default=str))
