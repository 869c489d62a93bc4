"""The quasi-static check's three measures (`forming.quasi_static_check`) from two finished
`jaxform run` folders of the same case and mesh, the second at half the first's speed: the last
frame's shear-angle map difference at the 95th percentile of the nodes (VTU `shear_angle_deg`), the
edge mid-side draw-in's relative difference and the two flange wrinkle counts (`summary.json`), with
the limits of `forming.QUASI_STATIC_LIMITS`, and each run's half-turn asymmetry.

    python compare.py RUN HALF_SPEED_RUN
"""
import json
import pathlib
import sys

import meshio
import numpy as np

from jaxform.forming.summary import QUASI_STATIC_LIMITS as LIM

runs = [pathlib.Path(a) for a in sys.argv[1:3]]
s = [json.loads((r / "summary.json").read_text()) for r in runs]
g = [meshio.read(sorted(r.glob("frames_*.vtu"))[-1]).point_data["shear_angle_deg"] for r in runs]
p95 = float(np.percentile(np.abs(np.asarray(g[0], float) - np.asarray(g[1], float)), 95))
d = [x["draw_in"]["edge_mid_m"] for x in s]
rel = abs(d[0] - d[1]) / abs(d[1])
w = [x["flange_wrinkles"] for x in s]
out = {"speeds_mm_per_s": [1e3 * x["numerics"]["punch_speed_m_per_s"] for x in s], "complete": [x["complete"] for x in s],
       "shear_p95_deg": p95, "draw_in_edge_mid_mm": [1e3 * v for v in d], "draw_in_edge_mid_rel": rel,
       "flange_wrinkles": w, "half_turn_deviation": [(x.get("half_turn_symmetry") or {}).get("deviation") for x in s],
       "quasi_static": bool(p95 < LIM["shear_p95_deg"] and rel < LIM["draw_in_edge_mid_rel"] and w[0] == w[1])}
print(json.dumps(out, indent=1))
