"""Claim 1 (woven Case A NLBM: one primary wrinkle per quadrant, along the diagonals) against the
assumed tool geometry and friction: ``jaxform study paper --element-size-mm 8 --only case-a-woven
--bending nlbm`` with one override set per variant (each into OUT/<variant>), then claim 1's verdict
and figures from each study's claims.json, one JSON line per variant on stdout.
Run: .venv/bin/python screen.py OUT [VARIANT ...] (default: all, in order)."""
import json
import subprocess
import sys
import time
from pathlib import Path

VARIANTS = {  # the paper's Table 2 (tool drawing) is missing: these are the assumptions of SPEC §4, varied
    "base": [],
    "blank-300": ["blank.size_mm=300"],
    "blank-200": ["blank.size_mm=200"],
    "die-opening-56": ["tools.die_opening_radius_mm=56"],
    "die-fillet-9.5": ["tools.die_fillet_mm=9.5"],
    "gap-4": ["holder.gap_mm=4"],
    "friction-0.1": ["fabric.friction_tool=0.1"],
    "friction-0.4": ["fabric.friction_tool=0.4"],
}

out = Path(sys.argv[1])
for name in sys.argv[2:] or list(VARIANTS):
    d = out / name
    cmd = [sys.executable, "-m", "jaxform", "study", "paper", "--out", str(d), "--element-size-mm", "8",
           "--only", "case-a-woven", "--bending", "nlbm", "--quiet"]
    for s in VARIANTS[name]:
        cmd += ["--set", s]
    t0 = time.perf_counter()
    rc = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    rec = {"variant": name, "overrides": VARIANTS[name], "rc": rc.returncode, "wall_s": round(wall, 1)}
    try:
        c1 = next(c for c in json.loads((d / "claims.json").read_text())["claims"] if c["id"] == 1)
        s = json.loads((d / "runs" / "case-a-woven-nlbm" / "summary.json").read_text())
        rec.update(verdict=c1["verdict"], why=c1["why"], measured=c1["measured"], complete=s["complete"],
                   max_ke_ie=s["max_ke_ie"], max_shear_deg=s["max_shear_angle_deg"], draw_in=s["draw_in"])
    except (OSError, StopIteration, KeyError, ValueError) as e:
        rec["error"] = f"{type(e).__name__}: {e}; stderr tail: {rc.stderr[-800:]}"
    print(json.dumps(rec), flush=True)
