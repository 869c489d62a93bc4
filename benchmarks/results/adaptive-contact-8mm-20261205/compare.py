"""The 8 mm NCF LBM B_init run with the study's numerics (stiffened once) against the preset's own
numerics (no stiffening): shear map at the last frame, node by node (same mesh), and draw-in."""
import json
import pathlib
import sys

import meshio
import numpy as np

root = pathlib.Path(sys.argv[1])
a, b = (meshio.read(root / r / "frames_00010.vtu") for r in ("case-a-ncf-lbm-init-study", "case-a-ncf-lbm-init"))
sa, sb = a.point_data["shear_angle_deg"], b.point_data["shear_angle_deg"]
d = np.abs(sa - sb)
print(f"shear |angle| p95: study numerics {np.percentile(np.abs(sa), 95):.2f} deg, preset numerics "
      f"{np.percentile(np.abs(sb), 95):.2f} deg; difference p95 {np.percentile(d, 95):.2f} deg, max {d.max():.2f} deg")
for r in ("case-a-ncf-lbm-init-study", "case-a-ncf-lbm-init", "case-a-ncf-membrane-study"):
    s = json.loads((root / r / "summary.json").read_text())
    n = s["numerics"]
    print(f"{r}: complete {s['complete']}, wall {s['wall_time_s']:.0f} s, dt {n['dt_s']:.3g} s x {n['n_steps']}, "
          f"edge draw-in {[round(x * 1e3, 2) for x in s['draw_in']['edge_mid_each_m']]} mm, max KE/IE {s['max_ke_ie']:.3g}, "
          f"deepest {n['max_penetration_ply']:.3f} h, stiffened {[(c['step'], round(c['punch_displacement_m'] * 1e3, 1), c['contact_stiffness']) for c in n['step_cuts']]}")
