"""Issue 13, done-when 6: is the formed flange's loss of mirror symmetry float32 rounding grown by
the buckling, or the model? Woven Case A NLBM at 4 mm, the preset's automatic numerics, run in
float32 (as shipped) and in float64 (each in its own process), and the last frame's deviation and
shear maps compared with their mirror images about x and y and with their 180° rotation (which the
union-jack mesh, the fabric and the rig all keep exactly): max |v - v'| / max |v| and the same in
RMS. Run: .venv/bin/python run.py float32|float64 OUT_DIR (both cores)."""
import json
import sys
import time
from pathlib import Path

import jax
import numpy as np

dtype, out = sys.argv[1], Path(sys.argv[2])
if dtype == "float64":
    jax.config.update("jax_enable_x64", True)
from jaxform import cases, forming  # noqa: E402
from jaxform.forming.summary import shear_mirror_odd  # noqa: E402

case = cases.apply_overrides(cases.with_element_size(cases.load("case-a-woven-nlbm"), 4e-3), [f"numerics.dtype={dtype!r}"])
t0 = time.time()
r = forming.simulate(case, catch=True)
wall = time.time() - t0
x0 = r.info.x0
key = np.round(x0[:, :2] * 1e6).astype(np.int64)
lut = {(a, b): i for i, (a, b) in enumerate(map(tuple, key))}


def errors(v, odd):
    res = {}
    for name, sx, sy, sign in (("mirror_x", 1, -1, -1.0 if odd else 1.0), ("mirror_y", -1, 1, -1.0 if odd else 1.0),
                               ("rot180", -1, -1, 1.0)):
        idx = np.array([lut[(sx * a, sy * b)] for a, b in map(tuple, key)])
        d = v - sign * v[idx]
        res[name] = {"max": float(np.max(np.abs(d)) / np.max(np.abs(v))), "rms": float(np.sqrt(np.mean(d**2) / np.mean(v**2)))}
    return res


s = r.summary
rec = {"dtype": dtype, "wall_s": wall, "complete": r.complete, "reason": r.reason, "n_steps": s["numerics"]["n_steps"],
       "dt_s": s["numerics"]["dt_s"], "max_ke_ie": s["max_ke_ie"], "max_shear_deg": s["max_shear_angle_deg"],
       "draw_in": s["draw_in"], "flange_wrinkles": s["flange_wrinkles"],
       "deviation_max_m": float(np.max(np.abs(r.fields["deviation"][-1]))),
       "deviation": errors(np.asarray(r.fields["deviation"][-1], np.float64), False),
       "shear": errors(np.asarray(r.fields["shear_angle"][-1], np.float64), shear_mirror_odd(case))}
(out / f"{dtype}.json").write_text(json.dumps(rec, indent=1))
print(json.dumps(rec), flush=True)
