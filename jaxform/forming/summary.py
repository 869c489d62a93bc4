"""What a forming run says, on the host (numpy): draw-in, the flange's wrinkle census,
mirror symmetry, the JSON-ready summary (SPEC section 6 keys), and the half-speed check."""
from __future__ import annotations

import math

import jax
import numpy as np

from jaxform.metrics.wrinkles import ring_max
from jaxform.penalty import MAX_PENETRATION
from jaxform.forming.case import to_dict
from jaxform.forming.fields import ENERGY_KEYS, HISTORY_KEYS
from jaxform.forming.numerics import expected_pressure
from jaxform.forming.rig import RunInfo


def draw_in(x, info: RunInfo) -> dict:
    """Blank-edge draw-in of ply 1, m: mean over the four edge mid-sides and the four corners.

    Mid-side: the reduction of the distance to the punch axis along the edge normal; corner: the
    reduction of the radial distance.
    """
    x = np.asarray(x)
    x0 = info.x0
    mid, cor = info.edge_mid, info.corners
    axis = np.array([0, 0, 1, 1])
    d_mid = np.abs(x0[mid, axis]) - np.abs(x[mid, axis])
    d_cor = np.hypot(x0[cor, 0], x0[cor, 1]) - np.hypot(x[cor, 0], x[cor, 1])
    return {"edge_mid_m": float(np.mean(d_mid)), "corner_m": float(np.mean(d_cor)),
            "edge_mid_each_m": d_mid.tolist(), "corner_each_m": d_cor.tolist()}


def flange_mask(x_ref, case) -> np.ndarray:
    """(N,) nodes initially on the flange (outside the die opening and its fillet)."""
    r = np.hypot(x_ref[:, 0], x_ref[:, 1])
    return r > float(case.tools.die_opening_radius + case.tools.die_fillet)


def flange_census(x, deviation, faces, case) -> list:
    """The wrinkles of one ply's flange (:func:`jaxform.metrics.census.wrinkle_census` from the
    die opening's fillet outwards): ``x`` (N, 3) its nodes, ``deviation`` (N,) m, ``faces``
    (F, 3|4) its faces (indices into ``x``)."""
    from jaxform.metrics.census import wrinkle_census

    return wrinkle_census(x, deviation, faces=faces,
                          r_inner=float(case.tools.die_opening_radius + case.tools.die_fillet))


def symmetry_error(x_ref, values, *, odd: bool = False) -> dict:
    """Mirror symmetry of a nodal field about the x and y axes of the blank.

    Returns ``{"x": e_x, "y": e_y}``: ``max |v - s v_mirror| / max |v|`` with the mirror node found
    by reference position and ``s = -1`` for fields that change sign under a mirror (``odd``: the
    shear angle of a 0/90° fabric), else 1.
    """
    v = np.asarray(values)
    sign = -1.0 if odd else 1.0
    out = {}
    for name, sx, sy in (("x", 1, -1), ("y", -1, 1)):
        idx = mirror_index(x_ref, sx, sy)
        out[name] = float(np.max(np.abs(v - sign * v[idx])) / max(np.max(np.abs(v)), 1e-30))
    return out


def mirror_index(x_ref, sx: int, sy: int) -> np.ndarray:
    """(N,) the node at each node's image under ``(x, y) -> (sx x, sy y)`` (``sx, sy`` = ±1: the
    mirrors about the blank's axes and the 180° rotation), matched by reference position to 1 µm;
    a node without an image maps to itself."""
    key = np.round(np.asarray(x_ref)[:, :2] * 1e6).astype(np.int64)
    lut = {(a, b): i for i, (a, b) in enumerate(map(tuple, key))}
    return np.array([lut.get((sx * a, sy * b), i) for i, (a, b) in enumerate(map(tuple, key))])


def shear_mirror_odd(case, ply: int = 1) -> bool:
    """Whether ply ``ply``'s shear angle changes sign under the blank's mirrors (the ``odd`` of
    :func:`symmetry_error`): where its fibres run along the blank's edges (0/90°) a mirror maps each
    family onto itself and reverses the angle between them; where they run off them (±45°) a mirror
    swaps the two families, and the angle keeps its sign."""
    from jaxform.forming.speed import along_edges
    from jaxform.materials import preset as fabric_preset

    o = case.orientations[ply - 1]
    return along_edges([a + o for a in fabric_preset(case.fabric.preset).fibre_angles])


HALF_TURN_TOL = 0.2
"""The largest half-turn asymmetry of ply 1's deviation from the tools (a fraction of its largest
value, :func:`half_turn_symmetry`) a run may end with before :func:`findings` warns. At the last
frame of runs as shipped: woven Case A NLBM at 2 mm 2.9 % (2.5 % at half speed); NCF Case A at
4 mm, LBM B_init 0.1 %, LBM B_41.5 4.8 % (21 % node by node: a wrinkle one element off its image),
NLBM 99.5 % (its flange folded on one side only, from 40-45 mm), LBM B_inf 100 % (wrinkles without
images, from 34-40 mm), membrane-only 94 % (from 13-19 mm)."""


def _ply_1(result):
    """``(top, faces)``: the (N,) mask of ply 1's nodes and its faces with node indices within it."""
    top = np.asarray(result.ply_id) == 1
    faces = np.asarray(result.faces)
    return top, (np.cumsum(top) - 1)[faces[np.all(top[faces], axis=1)]]


def _off_image(v, image, faces):
    """(F,) for nodal values ``v`` (F, N): the largest distance of a node's value from the range its
    image node's one ring (the faces around it, ``faces`` (M, k)) spans, so that a feature one
    element off its image counts as matched (the mesh resolves no finer)."""
    vt = np.asarray(v, dtype=float).T  # (N, F)
    hi, lo = np.asarray(ring_max(vt, faces)), -np.asarray(ring_max(-vt, faces))
    return np.max(np.maximum(np.maximum(vt - hi[image], lo[image] - vt), 0.0), axis=0)


def half_turn_symmetry(result) -> dict | None:
    """How far ply 1's result is from the half-turn symmetry of the case, or None where the case
    has none to keep (a punch from a mesh file) or the run wrote no frame.

    The hemisphere rig's tools are axisymmetric and the blank is a square centred on the punch
    axis, meshed symmetrically, so a rotation by 180 deg about the axis maps the case onto itself
    whatever the fibre layout (each fibre onto a fibre, the shear angle and the deviation onto
    themselves); a deterministic answer keeps that symmetry. Returns ``deviation`` and
    ``shear_angle``: how far a node's value lies outside the range of its image's one ring (a
    feature one element off its image matches it), at most, over ``max(max |v|, floor)``, at the
    last frame (floor: the ply thickness, resp. one degree); ``deviation_per_frame``;
    ``broken_between_punch_m``: the punch travel of the last frame within :data:`HALF_TURN_TOL`
    before the frames that all exceed it and of the first of them (None while the last frame is
    within it); ``edge_mid_pairs_m``: the edge mid-side draw-in ``[[+x, -x], [+y, -y]]``;
    ``tolerance``.
    """
    case, info = result.info.case, result.info
    dev = result.fields.get("deviation")
    if case.tools.punch_mesh is not None or dev is None or not len(dev):
        return None
    top, faces = _ply_1(result)
    idx = mirror_index(info.x0[top], -1, -1)
    d = np.asarray(dev)[:, top]
    per = _off_image(d, idx, faces) / np.maximum(np.max(np.abs(d), axis=1), float(case.ply_thickness))
    g = np.asarray(result.fields["shear_angle"][-1:])[:, top]
    shear = float(_off_image(g, idx, faces)[0] / max(float(np.max(np.abs(g))), math.radians(1.0)))
    h = result.history
    depth = np.abs(np.interp(np.asarray(result.t)[:len(per)], h["t_s"], h["punch_displacement_m"]))
    within = np.flatnonzero(per <= HALF_TURN_TOL)
    broken = None
    if per[-1] > HALF_TURN_TOL:
        k = int(within[-1]) + 1 if within.size else 0
        broken = [float(depth[k - 1]) if k else 0.0, float(depth[k])]
    mid = draw_in(result.x[-1], info)["edge_mid_each_m"]
    return {"deviation": float(per[-1]), "shear_angle": shear, "deviation_per_frame": per.tolist(),
            "broken_between_punch_m": broken, "edge_mid_pairs_m": [mid[:2], mid[2:]], "tolerance": HALF_TURN_TOL}


def _step_choice(info, history) -> dict:
    """How the step and the contact stiffness were chosen (:func:`jaxform.forming.numerics.contact_numerics`),
    and the deepest penetration the run's samples saw, as a fraction of the ply thickness (the
    automatic contact keeps it below :data:`jaxform.penalty.MAX_PENETRATION` at the expected pressure)."""
    n = getattr(info, "numerics", None)
    if n is None:
        return {}
    p, why = expected_pressure(info.case)
    pen = history.get("max_penetration_m")
    return {"dt_governed_by": n.governed_by, "contact_safety": n.safety, "step_budget": n.budget,
            "step_choice": n.why, "contact_implicit_normal": bool(n.implicit_normal),
            "expected_pressure_Pa": p, "expected_pressure_choice": why,
            "max_penetration_ply": float(np.max(pen)) / float(info.case.ply_thickness) if pen is not None and len(pen)
            else None, "penetration_limit_ply": MAX_PENETRATION}


def _momentum_term(result) -> dict:
    """The summary's ``fibre_mass_momentum_term`` (whether the run ended with it) and why."""
    given = bool(getattr(result.info.case, "fibre_mass_momentum_term", False))
    sw = getattr(result, "momentum_term_from", None)
    if sw is not None:
        why = (f"switched on by the driver at step {sw['step']} (t = {sw['t_s']:.4g} s, punch "
               f"{1e3 * sw['punch_displacement_m']:.3g} mm): the next chunk failed without it ({sw['cause']})")
    elif getattr(result.model, "fibre_mass", None) is None:
        why = "no fibre mass"
    else:
        why = "given" if given else "off"
    return {"fibre_mass_momentum_term": bool(given or sw is not None), "fibre_mass_momentum_term_choice": why,
            "fibre_mass_momentum_term_from_step": None if sw is None else int(sw["step"])}


def _step_cuts(result) -> dict:
    """Where the driver cut the step (:data:`jaxform.forming.driver.MAX_STEP_CUT`; a cut stays, so
    at most three): ``step_cuts`` (step, time, punch, cut, contact_stiffness, cause each), the
    step the run ended with, and the factor its contacts' penalty ended with (the driver stiffens
    an automatic contact, with a cut, where a node penetrated too deep)."""
    cuts = [dict(c) for c in getattr(result, "step_cuts", None) or []]
    return {"step_cuts": cuts, "smallest_dt_s": result.info.dt / (cuts[-1]["cut"] if cuts else 1),
            "contact_stiffness_factor": cuts[-1]["contact_stiffness"] if cuts else 1.0}


QUASI_STATIC_KE_IE = 0.1
"""A run whose kinetic energy exceeds this fraction of the internal energy over the last 80 % of the
stroke is not quasi-static by its own numbers (:func:`findings`)."""


def findings(s: dict) -> list[dict]:
    """What a run's own numbers say against reading it as the quasi-static answer, from its summary
    ``s``: each ``{"kind", "level", "text"}``, ``level`` "warning" (the result itself is in doubt:
    ``kinetic_energy`` above :data:`QUASI_STATIC_KE_IE`, a ``penetration`` deeper than the contact
    was set for, an ``asymmetric`` result beyond :data:`HALF_TURN_TOL`) or "note" (a ``step_cut``
    or ``contact_stiffened`` by the driver: a fast event, not quasi-static there). ``jaxform run``
    prints them; the maps' titles name the warnings."""
    out = []
    k = s.get("max_ke_ie")
    if k is not None and k > QUASI_STATIC_KE_IE:
        out.append({"kind": "kinetic_energy", "level": "warning", "text": (
            f"not quasi-static by its own numbers: the kinetic energy reached {k:.3g} x the internal energy over "
            f"the last 80% of the stroke (quasi-static: below {QUASI_STATIC_KE_IE:g}); inertia shapes this result. "
            "Lower process.speed_mm_per_s.")})
    n = s.get("numerics") or {}
    pen = n.get("max_penetration_ply")
    if pen is not None and pen > n["penetration_limit_ply"]:
        out.append({"kind": "penetration", "level": "warning", "text": (
            f"a node penetrated a tool or ply by {pen:.3g} x the ply thickness (the contact is set for "
            f"{n['penetration_limit_ply']:g} at {n['expected_pressure_Pa']:.3g} Pa): the pressures exceed the expected "
            "one; raise contact.expected_pressure_Pa for a stiffer contact")})
    sym = s.get("half_turn_symmetry")
    if sym and sym["deviation"] > sym["tolerance"]:
        (px, mx), (py, my) = (1e3 * np.asarray(p) for p in sym["edge_mid_pairs_m"])
        lo, hi = (1e3 * v for v in sym["broken_between_punch_m"])
        out.append({"kind": "asymmetric", "level": "warning", "text": (
            f"the result has lost the case's symmetry: turned half a turn about the punch axis the case is the same "
            f"(axisymmetric tools, a centred blank), but ply 1's deviation from the tools differs from its image by up "
            f"to {100 * sym['deviation']:.0f} % of its largest value (rounding alone: a few %), and the edge mid-sides "
            f"drew in {px:.1f} / {mx:.1f} mm (+x / -x) and {py:.1f} / {my:.1f} mm (+y / -y). It set in between "
            f"{lo:.1f} and {hi:.1f} mm of punch travel: from there the buckling chose among patterns the case does not "
            "tell apart (where the wrinkles lie, or a snap on one side), so this is one of the results the run could "
            "have given, not the converged answer (--verify-quasi-static compares another).")})
    k_before, cut_before = 1.0, 1
    for c in n.get("step_cuts") or []:  # a few: each cut and each stiffening stays
        where = f"from step {c['step']} (t = {c['t_s']:.4g} s, punch {1e3 * c['punch_displacement_m']:.3g} mm: {c['cause']})"
        if c["contact_stiffness"] > k_before:
            out.append({"kind": "contact_stiffened", "level": "note", "text": (
                f"the contact was stiffened to x{c['contact_stiffness']:g} "
                + (f"with the step cut to 1/{c['cut']} " if c["cut"] > cut_before else
                   "(the step kept: the normal forces are integrated backward) ")
                + f"{where}: "
                f"the pressures exceed the expected {n['expected_pressure_Pa']:.3g} Pa")})
        else:
            out.append({"kind": "step_cut", "level": "note", "text": (
                f"a chunk failed at the run's step {where}; the run went on with the step cut to 1/{c['cut']}: a fast "
                "event, not quasi-static there")})
        k_before, cut_before = c["contact_stiffness"], c["cut"]
    return out


def summarize(result) -> dict:
    """The summary of a :class:`~jaxform.forming.driver.FormingResult` (SPEC section 6 keys and more; JSON-ready)."""
    import jaxform

    info = result.info
    case = info.case
    h = result.history
    n = len(h["t_s"])
    ie = h["tension_J"] + h["shear_J"] + h["bending_J"] if n else np.zeros(0)
    ke = h["kinetic_J"] if n else np.zeros(0)
    T = info.stroke_time
    late = h["t_s"] >= 0.2 * T if n else np.zeros(0, bool)
    ratio = np.where(ie > 0, ke / np.maximum(ie, 1e-300), np.inf) if len(ie) else ie
    max_ke_ie = float(np.max(ratio[late])) if np.any(late) else None
    if max_ke_ie is not None and not math.isfinite(max_ke_ie):
        max_ke_ie = None  # no internal energy yet (JSON has no inf)
    gam = result.fields.get("shear_angle")
    max_shear = float(np.degrees(np.max(np.abs(gam)))) if gam is not None and gam.size else None
    di = draw_in(result.x[-1], info) if len(result.x) else None
    dev = result.fields.get("deviation")
    flange = flange_mask(info.x0, case)
    max_dev = float(np.max(dev[-1][flange])) if dev is not None and len(dev) else None
    census = None
    if dev is not None and len(dev):
        top, faces = _ply_1(result)
        census = flange_census(result.x[-1][top], dev[-1][top], faces, case)
    s = {
        "complete": bool(result.complete),
        "reason": result.reason,
        "case": case.name,
        "inputs": to_dict(case),
        "numerics": {"dt_s": info.dt, "stable_dt_s": info.stable_dt, "n_steps": info.n_steps,
                     "steps_done": int(h["step"][-1]) if len(h["step"]) else 0, "stroke_time_s": T,
                     "nodes": int(len(info.x0)), "mass_scaling": float(case.mass_scaling),
                     "fibre_mass_scaling": float(getattr(info, "fibre_mass_factor", case.fibre_mass_scaling or 1.0)),
                     "fibre_mass_choice": "auto" if case.fibre_mass_scaling is None else "given",
                     **_momentum_term(result),
                     # products with the fibre-tension stiffness per step: degree - 1
                     "fibre_mass_degree": getattr(getattr(result.model, "fibre_mass", None), "degree", None),
                     "dtype": case.dtype,
                     "punch_speed_m_per_s": float(case.process.speed),
                     "speed_choice": case.process.speed_choice or "given", **_step_choice(info, h),
                     **_step_cuts(result)},
        "max_ke_ie": max_ke_ie,
        "max_shear_angle_deg": max_shear,
        "max_flange_deviation_m": max_dev,
        "flange_wrinkles": None if census is None else len(census),
        "wrinkles": None if census is None else [w.to_dict() for w in census],
        "draw_in": di,
        "wall_time_s": result.wall_time_s,
        "frames_written": int(len(result.t)),
        "frame_times_s": result.t.tolist(),
        "history": {
            **{k: v.tolist() for k, v in h.items() if k not in {HISTORY_KEYS[e] for e in ENERGY_KEYS}},
            "energies_J": {k: h[HISTORY_KEYS[k]].tolist() for k in ENERGY_KEYS},
            "internal_energy_J": ie.tolist(),
            "ke_ie": [None if not np.isfinite(r) else float(r) for r in ratio],
        },
        "versions": {"jaxform": jaxform.__version__, "jax": jax.__version__, "numpy": np.__version__},
    }
    s["half_turn_symmetry"] = half_turn_symmetry(result)
    s["findings"] = findings(s)
    s["warnings"] = warning_kinds(s["findings"])  # beside "complete": a result in doubt does not read as success
    return s


def warning_kinds(found) -> list[str]:
    """The kinds of the findings ``found`` (:func:`findings`) that put the result in doubt (level "warning")."""
    return [f["kind"] for f in found or [] if f["level"] == "warning"]


QUASI_STATIC_LIMITS = {"shear_p95_deg": 1.0, "draw_in_edge_mid_rel": 0.02, "flange_wrinkles_diff": 0}
"""Halving the punch speed may change the final shear-angle map by less than 1° at the 95th
percentile of the nodes, the edge mid-side draw-in by less than 2 %, and the number of flange
wrinkles not at all (the quasi-static criterion of issue 13)."""


def quasi_static_check(result, half) -> dict:
    """How far a run is from quasi-static: its differences from ``half``, the same case (same
    mesh) run at half the punch speed, both :class:`~jaxform.forming.driver.FormingResult` s.

    Returns a JSON-ready dict: the two speeds (mm/s), ``shear_p95_deg`` (95th percentile over the
    nodes of the final shear-angle difference), ``draw_in_edge_mid_rel`` (relative difference of
    the edge mid-side draw-in), ``flange_wrinkles`` (the two counts) and ``flange_wrinkles_diff``,
    the ``limits`` (:data:`QUASI_STATIC_LIMITS`) and ``quasi_static`` (all within them); and
    along the stroke, ``shear_p95_deg_per_frame`` at ``punch_mm_per_frame`` and
    ``shear_agrees_to_punch_mm``, the punch travel after which the maps differ beyond the limit at
    every frame to the end (the full stroke where the last frame agrees; ``None`` where none does):
    where a run leaves quasi-static for good (NCF Case A at 4 mm: 35 mm of its 50, then the
    shear law's tangent drops 5.4x and the flange snaps; woven LBM B_inf: 35 mm too, after a
    start-up transient at 5 mm that the later frames forget). A check that cannot be made (a run
    incomplete, or no frame) says why in ``reason`` and is not passed.
    """
    out = {"speed_mm_per_s": 1e3 * float(result.info.case.process.speed),
           "half_speed_mm_per_s": 1e3 * float(half.info.case.process.speed),
           "limits": dict(QUASI_STATIC_LIMITS), "quasi_static": False, "reason": None}
    for name, r in (("run", result), ("half-speed run", half)):
        if not r.complete or not len(r.t):
            out["reason"] = f"the {name} is incomplete ({r.reason}): no comparison"
            return out
    if len(result.info.x0) != len(half.info.x0):
        raise ValueError(f"quasi_static_check: the runs have {len(result.info.x0)} and {len(half.info.x0)} nodes: "
                         "they must share a mesh")
    sa, sb = (np.asarray(r.fields["shear_angle"]) for r in (result, half))
    per = [float(np.percentile(np.degrees(np.abs(a - b)), 95)) for a, b in zip(sa, sb)]
    depth = 1e3 * np.abs(np.interp(result.t[:len(per)], result.history["t_s"], result.history["punch_displacement_m"]))
    agree = np.flatnonzero(np.asarray(per) < QUASI_STATIC_LIMITS["shear_p95_deg"])  # the last one precedes the trailing failures
    out.update(shear_p95_deg_per_frame=per, punch_mm_per_frame=depth.tolist(),
               shear_agrees_to_punch_mm=float(depth[agree[-1]]) if agree.size else None)
    d0, d1 = (float(r.summary["draw_in"]["edge_mid_m"]) for r in (result, half))
    w0, w1 = (r.summary["flange_wrinkles"] for r in (result, half))
    out.update(shear_p95_deg=per[-1], draw_in_edge_mid_rel=abs(d0 - d1) / max(abs(d1), 1e-30),
               draw_in_edge_mid_m=[d0, d1], flange_wrinkles=[w0, w1],
               flange_wrinkles_diff=None if w0 is None or w1 is None else abs(int(w0) - int(w1)))
    lim = QUASI_STATIC_LIMITS
    out["quasi_static"] = bool(out["shear_p95_deg"] < lim["shear_p95_deg"]
                               and out["draw_in_edge_mid_rel"] < lim["draw_in_edge_mid_rel"]
                               and out["flange_wrinkles_diff"] is not None
                               and out["flange_wrinkles_diff"] <= lim["flange_wrinkles_diff"])
    if not out["quasi_static"]:
        out["cause"] = quasi_static_cause(*(r.summary.get("half_turn_symmetry") for r in (result, half)))
    return out


def quasi_static_cause(sym, sym_half) -> dict:
    """Why two runs at a speed and its half differ, from their :func:`half_turn_symmetry` s
    (``None`` where a case has none): ``kind`` and ``text`` (what it means and what to do).

    ``"path_dependent"`` where either run lost the case's half-turn symmetry: its flange buckled
    into one of several patterns the case does not tell apart, and a slower run is not known to
    converge there (woven LBM B_inf at 8 mm, 62.5 to 7.8 mm/s at 698f81f: draw-in 28.6, 27.3,
    27.5, 29.5 mm, each shear map 4.2-5.3 deg from the next slower one, symmetry lost in all four:
    ``benchmarks/results/strain-fix-reruns-20261207/``); otherwise ``"inertia"``: the run is too fast."""
    lost = [bool(s and s["deviation"] > s["tolerance"]) for s in (sym, sym_half)]
    if any(lost):
        at = min(1e3 * s["broken_between_punch_m"][1] for s, b in zip((sym, sym_half), lost) if b)
        who = "runs" if all(lost) else "run" if lost[0] else "half-speed run"
        return {"kind": "path_dependent", "text": (
            f"the {who} lost the case's half-turn symmetry (by {at:.1f} mm of punch travel): the flange buckled into "
            "one of several patterns the case does not tell apart, which a slower run is not known to settle (woven "
            "LBM B_inf down to 1/8 of its automatic speed). Take the result as one of those patterns, not a converged "
            "answer.")}
    kept = "keep the case's symmetry and still differ" if sym and sym_half else "differ (the case has no symmetry to test)"
    return {"kind": "inertia", "text": (
        f"the two runs {kept}: most likely inertia shapes the result; run at process.speed_mm_per_s halved and "
        "check again.")}

__all__ = ["warning_kinds", "draw_in", "flange_mask", "flange_census", "symmetry_error", "mirror_index", "shear_mirror_odd", "summarize",
           "QUASI_STATIC_KE_IE", "findings", "HALF_TURN_TOL", "half_turn_symmetry",
           "QUASI_STATIC_LIMITS", "quasi_static_check", "quasi_static_cause"]
