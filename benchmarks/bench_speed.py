"""Punch-speed convergence study (issue 13): the data a quasi-static speed rule is read from.

For each (preset, element size) the same case runs at a ladder of punch speeds, each half the one
before, with the presets' numerics as shipped except the speed and the fibre mass (automatic). Consecutive rungs are compared by :func:`jaxform.forming.quasi_static_check`: the
final shear map's 95th percentile difference (limit 1 deg), the edge mid-side draw-in (2 %) and
the flange wrinkle count (no change). The first rung that passes against its half is the
converged speed of that case and size.

``run(quick)`` returns, per case and size, each rung's figures (wall time, steps, step, KE/IE,
max shear, draw-in, wrinkles) and each comparison; each rung is also printed as it ends (the driver
writes the file when the whole benchmark ends). Run one ladder at a time with ``JAXFORM_SPEED_CASES="case-a-woven-nlbm:8"`` (comma-separated
``name:size_mm``) and ``JAXFORM_SPEED_LADDER="500,250,125,62.5"`` (mm/s).
"""
from __future__ import annotations

import os

DEFAULT_CASES = "case-a-woven-nlbm:8,case-a-woven-nlbm:4"
DEFAULT_LADDER = "500,250,125,62.5"
AUTO = ('numerics.fibre_mass_scaling="auto"',)


def _rung(name, size_mm, speed):
    from jaxform import cases, forming

    case = cases.with_element_size(cases.load(name), size_mm * 1e-3)
    case = cases.apply_overrides(case, [*AUTO, f"process.speed_mm_per_s={speed}"])
    return forming.simulate(case, catch=True)


def _figures(r):
    s = r.summary
    return {"complete": r.complete, "reason": r.reason, "wall_time_s": r.wall_time_s, "n_steps": r.info.n_steps,
            "dt_s": r.info.dt, "max_ke_ie": s["max_ke_ie"], "max_shear_deg": s["max_shear_angle_deg"],
            "draw_in_edge_mid_mm": s["draw_in"]["edge_mid_m"] * 1e3,
            "draw_in_corner_mm": s["draw_in"]["corner_m"] * 1e3, "flange_wrinkles": s["flange_wrinkles"]}


def run(quick: bool = False) -> dict:
    from jaxform import forming

    specs = os.environ.get("JAXFORM_SPEED_CASES", "case-a-woven-nlbm:25" if quick else DEFAULT_CASES)
    ladder = [float(v) for v in os.environ.get("JAXFORM_SPEED_LADDER", "500,250" if quick else DEFAULT_LADDER)
              .split(",")]
    out = {"ladder_mm_per_s": ladder, "overrides": list(AUTO), "cases": {}}
    for spec in specs.split(","):
        name, size = spec.split(":")
        rungs, checks, prev = [], [], None
        for v in ladder:
            r = _rung(name, float(size), v)
            rungs.append({"speed_mm_per_s": v, **_figures(r)})
            print(f"[speed] {name} {size} mm {v} mm/s: {rungs[-1]}", flush=True)
            if prev is not None:
                checks.append(forming.quasi_static_check(prev, r))
                print(f"[speed]   check {checks[-1]}", flush=True)
            prev = r
        first = next((c["speed_mm_per_s"] for c in checks if c["quasi_static"]), None)
        out["cases"][f"{name}@{size}mm"] = {"rungs": rungs, "checks": checks, "converged_speed_mm_per_s": first}
    return out
