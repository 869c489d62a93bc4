"""What the paper study measures on one finished ``jaxform run`` folder (host side, numpy), and the
quasi-static check of two such folders (:func:`quasi_static_check_dirs`).

A run folder (``frames.pvd``, ``frames_#####.vtu``, ``summary.json``) is read back as a
:class:`RunData`; :func:`measure_run` turns it into the figures the claims compare (JSON-ready
numbers) and the arrays the figures draw (sections, densities). Everything is read from the
files, so a study can be analysed again without running anything.

Definitions (top view of the formed part, punch axis at the origin, SI units):

* the dome: nodes within ``DOME_FRACTION`` of the punch radius of the axis;
* the flange: nodes initially outside the die opening and its fillet
  (:func:`jaxform.forming.summary.flange_mask`);
* the holder-edge band: radii from the holder opening minus ``EDGE_BAND`` to the die opening plus
  its fillet plus ``EDGE_BAND``, where the ply bends over the die fillet and the holder's edge;
* sections (:func:`sections`): the paper's A-A' and B-B' paths are not in our copy of it, so we
  define them in quadrant 1: A-A' along the 45 deg diagonal from the punch's edge to the blank's
  corner, B-B' across the flange, perpendicular to A-A' at its mid-flange radius, spanning the
  quadrant from the x axis to the y axis (the two shear regions of a 0/90 fabric and, for the
  +-45 NCF, the boundary between its positive- (x) and negative-shear (y) regions).
"""
from __future__ import annotations

import dataclasses
import json
import pathlib

import numpy as np

DOME_FRACTION = 0.9
"""Nodes within this fraction of the punch radius (top view) are on the dome."""
EDGE_BAND = 3e-3
"""Half-width added on both sides of the holder edge/die fillet radii, m."""
SECTION_SAMPLES = 400
"""Samples along a section."""
KAPPA_WRINKLE = 100.0
"""Curvature above which a defect is a wrinkle, 1/m (:func:`jaxform.metrics.classify_zones`'s default)."""


@dataclasses.dataclass
class RunData:
    """One run folder read back.

    Attributes:
        name: folder name; folder: its path; summary: ``summary.json``; case: the
        :class:`~jaxform.forming.case.Case` it ran; faces: (F, 4) connectivity; ply_id: (N,) 1-based;
        x_ref: (N, 3) blank positions, m; frames: list of ``(t_s, punch_m, path)`` in time order.
    """

    name: str
    folder: pathlib.Path
    summary: dict
    case: object
    faces: np.ndarray
    ply_id: np.ndarray
    x_ref: np.ndarray
    frames: list

    def frame(self, k: int = -1) -> tuple[np.ndarray, dict]:
        """``(x (N, 3) m, point data)`` of frame ``k`` (default the last)."""
        import meshio

        m = meshio.read(self.frames[k][2])
        return np.asarray(m.points, float), {key: np.asarray(v, float) for key, v in m.point_data.items()}

    def frame_at_stroke(self, stroke: float) -> int:
        """Index of the frame whose punch displacement is closest to ``stroke`` (m)."""
        return int(np.argmin([abs(p - stroke) for _, p, _ in self.frames]))


def load_run(folder) -> RunData:
    """Read a ``jaxform run`` folder (raises ``ValueError`` saying what is missing)."""
    import meshio

    from jaxform.forming.case import from_dict
    from jaxform.io.frames import read_frame_index

    folder = pathlib.Path(folder)
    try:
        summary = json.loads((folder / "summary.json").read_text())
        index = read_frame_index(folder / "frames.pvd")
    except (OSError, ValueError) as err:
        raise ValueError(f"{folder} is not a readable run folder ({err})") from None
    if not index:
        raise ValueError(f"{folder} has no frames: {summary.get('reason')}")
    case = from_dict(summary["inputs"])
    h = summary.get("history") or {}
    t_hist, p_hist = np.asarray(h.get("t_s", []), float), np.asarray(h.get("punch_displacement_m", []), float)
    frames = []
    for fname, t in sorted(index.items(), key=lambda kv: kv[1]):
        punch = float(np.interp(t, t_hist, p_hist)) if len(t_hist) else float("nan")
        frames.append((float(t), punch, folder / fname))
    m0 = meshio.read(frames[0][2])
    x0 = np.asarray(m0.points, float)
    faces = np.concatenate([c.data for c in m0.cells])
    ply = np.asarray(m0.point_data["ply_id"]).astype(int).ravel()
    x_ref = x0 - np.asarray(m0.point_data["displacement_m"], float)
    return RunData(folder.name, folder, summary, case, faces, ply, x_ref, frames)


def _as_result(run: RunData, speed: float):
    """The part of a :class:`~jaxform.forming.driver.FormingResult` that
    :func:`~jaxform.forming.quasi_static_check` reads, from the run's files (punch speed m/s)."""
    from types import SimpleNamespace

    shear = np.stack([np.radians(run.frame(k)[1]["shear_angle_deg"]) for k in range(len(run.frames))])
    s = run.summary
    return SimpleNamespace(info=SimpleNamespace(case=SimpleNamespace(process=SimpleNamespace(speed=speed)), x0=run.x_ref),
                           complete=bool(s.get("complete")), reason=s.get("reason"), summary=s,
                           t=np.array([f[0] for f in run.frames]), fields={"shear_angle": shear},
                           history={k: np.asarray(v, float) for k, v in (s.get("history") or {}).items()
                                    if k in ("t_s", "punch_displacement_m")})


def quasi_static_check_dirs(run_dir, half_dir) -> dict:
    """:func:`~jaxform.forming.quasi_static_check` of two finished ``jaxform run`` folders of one
    case, the second run at half the first's punch speed: each frame's shear-angle map, and the
    draw-in, flange wrinkles and half-turn symmetry of ``summary.json``. So a pair run apart (on
    another day or machine) is certified as ``jaxform run --verify-quasi-static`` certifies the pair
    it runs, without running either again. Raises ``ValueError`` where the two are not such a pair:
    the same folder, inputs that differ beyond the speed, another speed ratio, other frames."""
    from jaxform.forming import quasi_static_check
    from jaxform.study.plan import comparable, differences

    a, b = load_run(run_dir), load_run(half_dir)
    if a.folder.resolve() == b.folder.resolve():
        raise ValueError(f"{a.folder} given twice: give a run and the same case run at half its speed")
    speeds, inputs = [], []
    for r in (a, b):
        v = (r.summary.get("numerics") or {}).get("punch_speed_m_per_s")
        if not v:
            raise ValueError(f"{r.folder}/summary.json records no punch speed (numerics.punch_speed_m_per_s)")
        d = comparable(r.summary.get("inputs") or {})
        d.get("process", {}).pop("speed_mm_per_s", None)  # the one input the pair differs in
        speeds.append(float(v))
        inputs.append(d)
    diff = differences(inputs[1], inputs[0], label=f"in {a.folder.name}")
    if diff:
        raise ValueError(f"{b.folder} ran other inputs than {a.folder} besides the speed: {'; '.join(diff[:3])}")
    if abs(speeds[1] - 0.5 * speeds[0]) > 1e-6 * speeds[0]:
        raise ValueError(f"{b.folder} ran at {1e3 * speeds[1]:g} mm/s and {a.folder} at {1e3 * speeds[0]:g} mm/s: the "
                         f"check compares a run with one at half its speed ({0.5e3 * speeds[0]:g} mm/s)")
    if len(a.frames) != len(b.frames):
        raise ValueError(f"{a.folder} has {len(a.frames)} frames and {b.folder} {len(b.frames)}: the check compares "
                         "them frame by frame")
    check = quasi_static_check(_as_result(a, speeds[0]), _as_result(b, speeds[1]))
    check.update(run_dir=str(a.folder), half_speed_dir=str(b.folder))
    return check


def sections(case) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """The study's sections ``{name: (start (2,), end (2,))}`` in m (module docstring)."""
    t = case.tools
    half = 0.5 * float(case.blank_size)
    d = np.array([1.0, 1.0]) / np.sqrt(2.0)
    r0, r1 = float(t.punch_radius), float(np.sqrt(2.0) * half)
    flange_in = float(t.die_opening_radius + t.die_fillet)
    r_mid = 0.5 * (flange_in + half)  # mid-flange along the diagonal (the flange reaches ~ half at the mid-sides)
    c = r_mid * d
    w = np.array([1.0, -1.0]) / np.sqrt(2.0)
    # from the x axis to the y axis through c, perpendicular to the diagonal
    return {"A-A'": (r0 * d, r1 * d), "B-B'": (c + r_mid * w, c - r_mid * w)}


def _ply(run: RunData, x: np.ndarray, data: dict, ply: int):
    sel = run.ply_id == ply
    local = np.cumsum(sel) - 1
    faces = local[run.faces[np.all(sel[run.faces], axis=1)]]
    return sel, x[sel], faces, {k: v[sel] for k, v in data.items()}


def _stats(v) -> dict:
    v = np.asarray(v, float)
    if not v.size:
        return {"mean": None, "p95": None, "max": None}
    return {"mean": float(v.mean()), "p95": float(np.percentile(v, 95)), "max": float(v.max())}


def about_x_axis(angle_deg) -> np.ndarray:
    """Whether each angle (deg, top view) is within 45 deg of the +-x axes (else it is about the +-y axes)."""
    return np.abs(((np.asarray(angle_deg, float) + 45.0) % 180.0) - 45.0) < 45.0


def _sector_counts(wrinkles) -> dict:
    """Wrinkles about the +-x axes (within 45 deg of 0 or 180 deg) and about the +-y axes."""
    about_x = about_x_axis([w["angle_deg"] for w in wrinkles])
    return {"x": int(np.sum(about_x)), "y": int(np.sum(~about_x))}


def _under(w: dict, r, ang) -> np.ndarray:
    """(N,) nodes under a census wrinkle: within its radial extent and half its width of its angle."""
    dth = np.radians((ang - w["angle_deg"] + 180.0) % 360.0 - 180.0)
    return (r >= w["r_inner_m"]) & (r <= w["r_outer_m"]) & (np.abs(dth) * r <= 0.5 * max(w["width_m"], 1e-3))


def _census(case, x, dev, faces):
    from jaxform.forming.summary import flange_census

    return [w.to_dict() for w in flange_census(x, dev, faces, case)]


def measure_frame(run: RunData, k: int = -1, *, ply: int = 1, curvature: bool = True, frame=None) -> tuple[dict, dict]:
    """Figures and arrays of frame ``k``, ply ``ply``: ``(figures, arrays)``.

    ``figures`` (JSON-ready): stroke, deviation on the dome and the flange, mirror symmetry,
    M_f^RMS and where its largest values lie, shear, fibre strain (most compressive value and its
    angle), kappa_max in wrinkle zones, the census of the flange and its counts about the x and y
    axes, the sections' RMS, largest amplitude and peak counts, and the correlation of the flange's
    deviation with its shear. ``arrays``: ``x``, ``faces``, the ply's point data, ``kappa_max``,
    ``zones`` and the sampled sections ``{name: (s, amplitude, valid)}``. ``frame``: frame ``k``
    as :meth:`RunData.frame` gives it, when already read.
    """
    from jaxform import metrics
    from jaxform.forming.summary import flange_mask, shear_mirror_odd, symmetry_error

    x_all, data_all = run.frame(k) if frame is None else frame
    sel, x, faces, data = _ply(run, x_all, data_all, ply)
    case = run.case
    t = case.tools
    x_ref = run.x_ref[sel]
    r = np.hypot(x[:, 0], x[:, 1])
    ang = np.degrees(np.arctan2(x[:, 1], x[:, 0])) % 360.0
    dev = data["deviation_m"]
    h = float(case.ply_thickness)
    dcrit = (ply - 0.5) * h if ply == 1 else 0.5 * h
    dome = r < DOME_FRACTION * float(t.punch_radius)
    flange = flange_mask(x_ref, case)
    gamma = data["shear_angle_deg"]
    mf = data["M_f_rms_N"]
    strain = data["fibre_strain"].min(axis=1) if data["fibre_strain"].ndim == 2 else data["fibre_strain"]
    lo, hi = float(t.holder_opening_radius) - EDGE_BAND, float(t.die_opening_radius + t.die_fillet) + EDGE_BAND
    top = mf >= np.percentile(mf, 98) if mf.size else np.zeros(0, bool)
    fig = {
        "frame": int(k % len(run.frames)), "t_s": run.frames[k][0], "stroke_m": run.frames[k][1], "ply": ply,
        "d_crit_m": dcrit,
        "dome_max_deviation_m": float(dev[dome].max()) if dome.any() else None,
        "flange_deviation_m": _stats(dev[flange]),
        "symmetry_deviation": symmetry_error(x_ref, dev),
        "symmetry_shear": symmetry_error(x_ref, gamma, odd=shear_mirror_odd(case, ply)),
        "shear_abs_deg": _stats(np.abs(gamma)),
        "M_f_rms_N": _stats(mf),
        "M_f_rms_top2pc_median_radius_m": float(np.median(r[top])) if top.any() else None,
        "M_f_rms_top2pc_in_edge_band": float(np.mean((r[top] >= lo) & (r[top] <= hi))) if top.any() else None,
        "edge_band_m": [lo, hi],
        "fibre_strain_min": float(strain.min()),
        "fibre_strain_min_angle_deg": float(ang[np.argmin(strain)]),
        "fibre_strain_min_radius_m": float(r[np.argmin(strain)]),
    }
    if flange.any():
        g, d = np.abs(gamma[flange]), dev[flange]
        fig["flange_deviation_shear_correlation"] = (float(np.corrcoef(g, d)[0, 1])
                                                     if np.std(g) > 0 and np.std(d) > 0 else None)
        high = g >= np.percentile(g, 90)
        fig["flange_deviation_high_shear_m"] = float(np.mean(d[high]))
        fig["flange_deviation_other_m"] = float(np.mean(d[~high])) if (~high).any() else None
    about_x = about_x_axis(ang)
    fl = flange if flange.any() else np.ones_like(flange)
    fig["shear_mean_about_deg"] = {"x": float(np.mean(gamma[fl & about_x])) if (fl & about_x).any() else None,
                                   "y": float(np.mean(gamma[fl & ~about_x])) if (fl & ~about_x).any() else None}
    census = _census(case, x, dev, faces)
    for w in census:  # the shear under each wrinkle: which shear region it lies in
        under = _under(w, r, ang)
        w["shear_mean_deg"] = float(np.mean(gamma[under])) if under.any() else None
        w["shear_abs_mean_deg"] = float(np.mean(np.abs(gamma[under]))) if under.any() else None
    fig["wrinkles"] = census
    fig["flange_shear_abs_mean_deg"] = float(np.mean(np.abs(gamma[flange]))) if flange.any() else None
    fig["flange_wrinkles"] = len(census)
    fig["wrinkles_about"] = _sector_counts(census)
    arrays = {"x": x, "faces": faces, "data": data, "r": r, "angle_deg": ang, "sections": {}}
    kmax = None
    if curvature:
        k1, k2 = metrics.principal_curvatures(x, faces, check=False)
        kmax = np.asarray(metrics.kappa_max(k1, k2), float)
        zones = np.asarray(metrics.classify_zones(dev, kmax, dcrit, kappa_threshold=KAPPA_WRINKLE, faces=faces))
        arrays.update(kappa_max=kmax, zones=zones)
        wz = zones == metrics.WRINKLE
        bz = zones == metrics.BRIDGING
        fig["kappa_max_wrinkle_zone_per_m"] = _stats(kmax[wz])
        fig["kappa_max_dome_per_m"] = _stats(kmax[dome])
        fig["wrinkle_zone_nodes"] = int(wz.sum())
        fig["wrinkle_zone_nodes_500_1500"] = int(np.sum(wz & (kmax >= 500.0) & (kmax <= 1500.0)))
        fig["bridging_m"] = _stats(dev[bz])
        base = bz & (r > 0.8 * float(t.punch_radius)) & (r < hi)
        fig["bridging_at_base_m"] = _stats(dev[base])
    for name, (a, b) in sections(case).items():
        s, v, valid, _ = (np.asarray(z) for z in metrics.section_profile(x, faces, dev, a, b, SECTION_SAMPLES))
        arrays["sections"][name] = (s, v, valid)
        vv = v[valid]
        fig[f"section {name}"] = {
            "rms_m": float(np.sqrt(np.mean(vv ** 2))) if vv.size else None,
            "max_m": float(vv.max()) if vv.size else None,
            "peaks": int(metrics.count_section_wrinkles(v, valid, min_amplitude=dcrit)),
            "start_m": list(map(float, a)), "end_m": list(map(float, b))}
    return fig, arrays


def measure_run(run: RunData, *, strokes=()) -> tuple[dict, dict]:
    """The study's figures for one run: ``(figures, arrays)``.

    ``figures``: its summary's headline numbers, the last frame of every ply
    (:func:`measure_frame`, key ``"ply <i>"``) and, for each stroke in ``strokes`` (m), the
    punch-side ply at the frame nearest that stroke (key ``"stroke <mm> mm"``, no curvature).
    ``arrays``: the arrays of each of those, under the same keys.
    """
    s = run.summary
    out = {"folder": str(run.folder), "complete": bool(s.get("complete")), "reason": s.get("reason"),
           "wall_time_s": s.get("wall_time_s"), "max_ke_ie": s.get("max_ke_ie"), "findings": s.get("findings") or [],
           "max_shear_angle_deg": s.get("max_shear_angle_deg"), "draw_in": s.get("draw_in"),
           "numerics": s.get("numerics"), "element_size_m": float(run.case.element_size),
           "shear_reading": run.case.fabric.shear_reading,
           "frames": len(run.frames)}
    arrays = {}
    last = run.frame(-1)
    for ply in range(1, int(run.ply_id.max()) + 1):
        out[f"ply {ply}"], arrays[f"ply {ply}"] = measure_frame(run, -1, ply=ply, frame=last)
    for stroke in strokes:
        key = f"stroke {1e3 * stroke:g} mm"
        out[key], arrays[key] = measure_frame(run, run.frame_at_stroke(stroke), curvature=False)
    return out, arrays


__all__ = ["DOME_FRACTION", "EDGE_BAND", "SECTION_SAMPLES", "KAPPA_WRINKLE", "RunData", "about_x_axis", "load_run", "sections",
           "measure_frame", "measure_run", "quasi_static_check_dirs"]
