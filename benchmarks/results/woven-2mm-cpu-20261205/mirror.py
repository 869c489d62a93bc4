"""Mirror symmetry of a run's last frame (issue 13 done-when 6): shear and deviation about x and y."""
import glob, json, sys
import numpy as np, meshio
from jaxform.forming.summary import symmetry_error

d = sys.argv[1]
files = sorted(glob.glob(f"{d}/frames_*.vtu"))
x_ref = meshio.read(files[0]).points
m = meshio.read(files[-1])
dev, gam = np.asarray(m.point_data["deviation_m"]), np.asarray(m.point_data["shear_angle_deg"])
s = json.load(open(f"{d}/summary.json"))
out = {"frame": files[-1].split("/")[-1], "complete": s["complete"], "wall_time_s": s["wall_time_s"],
       "steps": s["numerics"]["steps_done"], "dt_s": s["numerics"]["dt_s"],
       "max_ke_ie": s["max_ke_ie"], "max_shear_deg": s["max_shear_angle_deg"], "flange_wrinkles": s["flange_wrinkles"],
       "draw_in_each_m": s["draw_in"].get("edge_mid_each_m"),
       "symmetry_deviation": symmetry_error(x_ref, dev), "symmetry_shear": symmetry_error(x_ref, gam, odd=True),
       "deviation_max_m": float(np.abs(dev).max()), "shear_max_abs_deg": float(np.abs(gam).max())}
# the same in an RMS norm (the max-norm above is set by the worst node)
for name, v, odd in (("deviation", dev, False), ("shear", gam, True)):
    key = np.round(x_ref[:, :2] * 1e6).astype(np.int64)
    lut = {(a, b): i for i, (a, b) in enumerate(map(tuple, key))}
    for ax, sx, sy in (("x", 1, -1), ("y", -1, 1)):
        idx = np.array([lut.get((sx * a, sy * b), i) for i, (a, b) in enumerate(map(tuple, key))])
        r = v - (-1.0 if odd else 1.0) * v[idx]
        out[f"rms_{name}_{ax}"] = float(np.sqrt(np.mean(r**2)) / np.sqrt(np.mean(v**2)))
print(json.dumps(out, indent=1))
