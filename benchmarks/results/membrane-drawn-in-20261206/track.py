"""Where a Case A run's blank goes, frame by frame, from a ``jaxform run`` folder: the punch travel,
the blank edge's closest approach to the punch axis (the die opening is 53 mm), the lowest node
below the punch's pole (a ply hanging ahead of the punch), the share of the initial flange now
inside the die opening, and the work gravity has done against the internal energy.
Run: .venv/bin/python track.py RUN_DIR [RUN_DIR ...]"""
import json
import sys
from pathlib import Path

import meshio
import numpy as np

from jaxform.io.frames import read_frame_index

for folder in map(Path, sys.argv[1:]):
    s = json.loads((folder / "summary.json").read_text())
    h, t_ = s["history"], s["inputs"]["tools"]
    r_open = 1e-3 * t_["die_opening_radius_mm"]
    r_flange = r_open + 1e-3 * t_["die_fillet_mm"]
    index = read_frame_index(folder / "frames.pvd")
    print(f"{folder}: {s['case']}, complete {s['complete']}, max KE/IE {s['max_ke_ie']:.3g}, "
          f"draw-in {1e3 * s['draw_in']['edge_mid_m']:.1f} / {1e3 * s['draw_in']['corner_m']:.1f} mm")
    print("  t s    punch mm  edge r min mm  below pole mm  flange inside %  gravity work / IE")
    for name, t in index.items():
        f = meshio.read(folder / name)
        x, x0 = f.points, f.points - f.point_data["displacement_m"]
        half = np.max(np.abs(x0[:, :2]))
        edge = np.max(np.abs(x0[:, :2]), axis=1) > half - 1e-6
        flange = np.hypot(x0[:, 0], x0[:, 1]) > r_flange
        punch = float(np.interp(t, h["t_s"], h["punch_displacement_m"]))
        pole = x0[:, 2].max() - abs(punch)  # the punch apex starts on the stack
        k = int(np.searchsorted(h["t_s"], t))
        k = min(k, len(h["t_s"]) - 1)
        ie = h["internal_energy_J"][k]
        g = h["energies_J"]["gravity_work"][k]
        print(f"  {t:5.3f}  {1e3 * abs(punch):7.1f}  {1e3 * np.min(np.hypot(x[edge, 0], x[edge, 1])):12.1f}  "
              f"{1e3 * max(0.0, pole - x[:, 2].min()):12.1f}  {100 * np.mean(np.hypot(x[flange, 0], x[flange, 1]) < r_open):14.1f}  "
              f"{g / ie if ie > 0 else float('nan'):10.2f}")
