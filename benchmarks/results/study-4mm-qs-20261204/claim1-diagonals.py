"""Claim 1 looked into (2026-12-05): curvature, moment and deviation in the flange sectors within 15 deg of the diagonals and of the mid-sides, on the last frames of the woven Case A runs in .git/study/qs4 (the folder run.sh writes). Run from the repository root: python benchmarks/results/study-4mm-qs-20261204/claim1-diagonals.py > claim1-diagonals.log"""
import sys, json, numpy as np, meshio
import jax; jax.config.update("jax_platforms", "cpu")
from jaxform import metrics
root = ".git/study/qs4/runs/"
for run in ["case-a-woven-nlbm", "case-a-woven-lbm-init", "case-a-woven-lbm-41", "case-a-woven-lbm-inf"]:
    import glob
    f = sorted(glob.glob(root + run + "/frames_*.vtu"))[-1]
    m = meshio.read(f)
    x0 = meshio.read(root + run + "/frames_00000.vtu").points
    x = m.points
    faces = [c.data for c in m.cells][0]
    dev = m.point_data["deviation_m"]
    M = m.point_data["bending_moment_N"]
    k1, k2 = metrics.principal_curvatures(x, faces)
    kmax = np.maximum(np.abs(np.asarray(k1)), np.abs(np.asarray(k2)))
    r = np.hypot(x[:, 0], x[:, 1]); th = np.degrees(np.arctan2(x[:, 1], x[:, 0])) % 360
    fl = (r > 0.06) & (x[:, 2] > -0.01)  # flange: outside the die opening, not drawn into the die
    # sectors: mid-side (within 15 deg of 0/90/180/270) vs diagonal (within 15 deg of 45/135/...)
    d_mid = np.minimum.reduce([np.abs(((th - a + 180) % 360) - 180) for a in (0, 90, 180, 270)])
    d_diag = np.minimum.reduce([np.abs(((th - a + 180) % 360) - 180) for a in (45, 135, 225, 315)])
    out = {}
    for name, sel in (("mid", fl & (d_mid < 15)), ("diag", fl & (d_diag < 15))):
        Mm = np.abs(M[sel]) if M.ndim == 1 else np.max(np.abs(M[sel]), axis=1)
        out[name] = {"dev_max_mm": 1e3 * float(dev[sel].max()), "kmax_p95": float(np.percentile(kmax[sel], 95)),
                     "kmax_max": float(kmax[sel].max()), "M_p95_mN": 1e3 * float(np.percentile(Mm, 95)), "n": int(sel.sum())}
    print(run, f.split("/")[-1], M.shape, json.dumps(out))
