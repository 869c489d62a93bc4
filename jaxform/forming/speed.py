"""The automatic punch speed (``process.speed_mm_per_s = "auto"``, the presets' default): the
speed found quasi-static by the convergence study, by the plies' fibre layout. Host-side, read by
:func:`jaxform.forming.case.from_dict` when it builds a case (no physics of its own)."""
from __future__ import annotations

import math

from jaxform.materials import preset as fabric_preset


def along_edges(angles, tol_deg: float = 10.0) -> bool:
    """Every fibre angle (rad) within ``tol_deg`` of the blank's x or y axis."""
    return all(min(a % (0.5 * math.pi), 0.5 * math.pi - a % (0.5 * math.pi)) <= math.radians(tol_deg)
               for a in (float(t) for t in angles))


QUASI_STATIC_SPEED = {"along": 0.0625, "off_axis": 0.03125}
"""``process.speed_mm_per_s = "auto"`` (the presets' default), m/s: the punch speed found
quasi-static by the convergence study (``benchmarks/bench_speed.py``, README "Punch speed"), for
plies whose fibres run along the blank's edges (woven 0/90) and off them (the +-45 deg NCF). A
rung passes when halving its speed moves the final shear map by < 1 deg at the 95th percentile,
the edge draw-in by < 2 % and the flange wrinkle count not at all (:func:`jaxform.forming.quasi_static_check`)."""


def quasi_static_speed(preset: str, orientations) -> tuple[float, str]:
    """The automatic punch speed (m/s) of a case of fabric ``preset`` with plies at
    ``orientations`` (rad), and why: :data:`QUASI_STATIC_SPEED` for the fibre layout (the slower
    where a stack mixes layouts). Measured on Case A (see :data:`QUASI_STATIC_SPEED`); for other
    geometries and fabrics it is a starting point: ``jaxform run ... --verify-quasi-static``
    checks a run against half its speed."""
    base = fabric_preset(preset).fibre_angles
    along = all(along_edges([a + o for a in base]) for o in orientations)
    key = "along" if along else "off_axis"
    layout = ("fibres along the blank's edges" if along else "fibres off the blank's edges")
    return QUASI_STATIC_SPEED[key], (f"auto: {1e3 * QUASI_STATIC_SPEED[key]:g} mm/s, quasi-static on Case A "
                                     f"for {layout} (benchmarks/bench_speed.py)")
