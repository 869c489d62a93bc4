"""Per frame of a run folder: punch travel, the ply's mean in-plane displacement, each edge
mid-side node's draw-in (+x, +y, -x, -y), max node speed. python drift.py RUN_DIR"""
import sys, json, glob
import numpy as np, meshio
d = sys.argv[1]
files = sorted(glob.glob(f"{d}/frames_*.vtu"))
m0 = meshio.read(files[0]); x0 = m0.points
half = x0[:, 0].max()
ids = {k: int(np.argmin(np.hypot(x0[:, 0] - px, x0[:, 1] - py) + 1e3 * (np.abs(x0[:, 2] - x0[:, 2].max())))) for k, (px, py) in
       {"+x": (half, 0), "+y": (0, half), "-x": (-half, 0), "-y": (0, -half)}.items()}
s = json.load(open(f"{d}/summary.json"))
for f, t in zip(files, s["frame_times_s"]):
    m = meshio.read(f); x = m.points
    u = x - x0
    di = {k: 1e3 * (np.hypot(*x0[i, :2]) - np.hypot(*x[i, :2])) for k, i in ids.items()}
    print(f"t {t:.3f} s  mean u_xy {1e3*u[:,0].mean():6.2f} {1e3*u[:,1].mean():6.2f} mm  draw-in " +
          " ".join(f"{k} {v:5.1f}" for k, v in di.items()))
