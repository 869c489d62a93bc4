"""Plots of a forming run (host side): shear-angle map, out-of-plane deviation map, punch force curve."""
from __future__ import annotations

import numpy as np

from jaxform.plots.fields import curve, field_map


def _top_ply(result, k: int = -1):
    """Positions, faces and node selection of ply 1 at frame ``k``."""
    sel = result.ply_id == 1
    idx = np.nonzero(sel)[0]
    remap = -np.ones(len(sel), np.int64)
    remap[idx] = np.arange(len(idx))
    faces = result.faces[np.all(sel[result.faces], axis=1)]
    return result.x[k][idx], remap[faces], idx


def _title(result, what: str, k: int) -> str:
    """``"<case>: <what>, punch <d> mm"`` for frame ``k`` (the punch displacement at the frame's time),
    and below it what speaks against the result: an incomplete run, the warnings of its summary's
    ``findings`` (:func:`jaxform.forming.summary.findings`: not quasi-static, too deep a penetration,
    the case's symmetry lost)."""
    h = result.history
    t = result.t[k]
    d = float(np.interp(t, h["t_s"], h["punch_displacement_m"])) if len(h["t_s"]) else 0.0
    s = getattr(result, "summary", None) or {}
    doubts = [] if getattr(result, "complete", True) else ["INCOMPLETE run"]
    for f in s.get("findings") or []:
        if f["kind"] == "kinetic_energy":
            doubts.append(f"NOT quasi-static (KE/IE {s['max_ke_ie']:.2g})")
        elif f["kind"] == "asymmetric":
            doubts.append(f"NOT symmetric ({100 * s['half_turn_symmetry']['deviation']:.0f} % off its half-turn)")
        elif f["level"] == "warning":
            doubts.append(f["kind"])
    return f"{result.info.case.name}: {what}, punch {d * 1e3:.1f} mm" + ("\n" + "; ".join(doubts) if doubts else "")


def shear_map(result, k: int = -1):
    """Shear angle (degrees) of ply 1 at frame ``k``, top view of the deformed ply."""
    x, faces, idx = _top_ply(result, k)
    g = np.degrees(result.fields["shear_angle"][k][idx])
    lim = max(float(np.max(np.abs(g))), 1e-6)
    return field_map(x, faces, g, title=_title(result, "shear angle", k), label="shear angle (°)",
                     cmap="RdBu_r", vmin=-lim, vmax=lim)


def deviation_map(result, k: int = -1):
    """Out-of-plane deviation from the tool surface (mm) of ply 1 at frame ``k``."""
    x, faces, idx = _top_ply(result, k)
    d = np.maximum(result.fields["deviation"][k][idx], 0.0) * 1e3
    return field_map(x, faces, d, title=_title(result, "deviation from the tools", k),
                     label="deviation (mm)", cmap="magma")


def punch_force_curve(result):
    """Punch force (N) against punch displacement (mm)."""
    h = result.history
    return curve(np.asarray(h["punch_displacement_m"]) * 1e3, h["punch_force_N"], xlabel="punch displacement (mm)",
                 ylabel="punch force (N)", title=f"{result.info.case.name}: punch force")


__all__ = ["shear_map", "deviation_map", "punch_force_curve"]
