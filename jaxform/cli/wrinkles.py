"""``jaxform wrinkles``: the paper's wrinkle metric on any surface mesh (host side).

The tool knows where it is. On a frame of a ``jaxform run`` folder (``frames_#####.vtu`` beside
``frames.pvd`` and ``summary.json``), or with ``--tool run`` / ``--tool RUN_DIR``, the tool is the
run's own rig (:func:`jaxform.forming.rig.build_tools` of the case in ``summary.json``): the punch
moved down by its displacement at that frame's time, and the die. The blank holder is left out,
like the run's ``deviation_m``: in the flange a wrinkle lifting towards it would look smaller.
The ply thickness and index default to the run's.

No plausible wrong answer with exit 0: every argument (sections included) is parsed and checked
before any work; a mesh whose size contradicts ``--units``, nodes inside a tool, a tool far from
the part, a ``--tool`` or ``--ply-thickness-mm`` that disagrees with the run the frame comes from
are errors that say what to do. ``--force`` measures anyway (each overridden check is printed and
recorded under ``forced`` in ``summary.json``) and also writes into a non-empty folder that is not
a ``jaxform wrinkles`` output; a rerun into its own output folder replaces it without ``--force``.
"""
from __future__ import annotations

import dataclasses
import json
import math
import pathlib
import re
import sys
import time

import numpy as np

from jaxform.io.frames import read_frame_index

PRESETS = {
    "hemisphere": "the paper's hemisphere as a male mould: punch apex up on a flat base plane "
    "(hemisphere:radius_mm=50,x_mm=0,y_mm=0,z_mm=0,base=1); not the pose of a 'jaxform run' rig",
    "plane": "a flat tool z = const (plane:z_mm=0)",
    "run": "the rig of the 'jaxform run' folder MESH is a frame of (the default for such a frame); "
    "or give the run folder itself: --tool runs/a",
}

OUTPUTS = ("wrinkles.vtu", "summary.json", "distance.png", "kappa_max.png", "zones.png", "section_*.csv",
           "cloud_distance.vtu", "cloud_distance.png")
"""What the command writes into its folder (a rerun replaces all of it)."""

DEFECT_TOLERANCE = 0.02
"""A node is a defect where ``d > d_crit + 0.02 h``: a ply lying on the tool is not one for the
rounding of its coordinates (float32 frames put a flat ply ~1e-8 m above h/2); no wrinkle is 6 um."""

_FRAME = re.compile(r"frames_(\d+)\.vtu$")


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "wrinkles",
        help="find and measure wrinkles on a surface mesh (distance to the tool, curvature, zones)",
        description="Evaluate the wrinkle metric of the source paper (SPEC section 5) on any "
        "meshio-readable surface (VTU, Abaqus .inp, OBJ, PLY, STL...): distance of every node to "
        "the tool, principal curvatures by iterative quadric fitting, wrinkle/bridging/conforming "
        "zones. Writes DIR/wrinkles.vtu, DIR/summary.json and PNG maps. With --cloud, also the "
        "distance of every measured point to the surface (as CloudCompare does for scans). "
        "On a frame of a 'jaxform run' folder the tool is the run's own rig at that frame "
        "(punch moved down by the stroke so far, and the die) and the ply thickness is the run's: "
        "'jaxform wrinkles runs/a/frames_00010.vtu --out W' is enough.",
    )
    p.add_argument("mesh", help="surface mesh file (the formed ply), e.g. a frame of a 'jaxform run' folder")
    p.add_argument("--tool", default=None,
                   help="tool mesh file, a run folder, or a preset: "
                   + "; ".join(f"{k}: {v}" for k, v in PRESETS.items())
                   + ". Required unless MESH is a frame of a 'jaxform run' folder; given with such a "
                   "frame it must agree with the run's rig (else --force)")
    p.add_argument("--ply-thickness-mm", type=float, default=None,
                   help="ply thickness h, mm (default: the run's, for a frame of a run; otherwise required)")
    p.add_argument("--ply-index", type=int, default=None,
                   help="position of the ply in the stack from the tool (d_crit = (i - 1/2) h; default 1); "
                   "on a frame of a multi-ply run, the ply measured")
    p.add_argument("--kappa-threshold-per-m", type=float, default=100.0,
                   help="curvature separating wrinkles from bridging, 1/m, > 0 (default 100: radius 10 mm)")
    p.add_argument("--units", choices=("auto", "m", "mm"), default="auto",
                   help="units of the mesh file (auto: mm when it is more than 5 units across)")
    p.add_argument("--tool-units", choices=("auto", "m", "mm"), default="auto",
                   help="units of the tool file")
    p.add_argument("--section", action="append", default=[], metavar="X1,Y1,X2,Y2",
                   help="a straight section in the base plane, mm; its amplitude profile goes to "
                   "DIR/section_<k>.csv (repeatable; write --section=-34,0,34,0 when it starts with -)")
    p.add_argument("--cloud", help="measured point cloud (PLY/XYZ/CSV) to compare with the mesh")
    p.add_argument("--cloud-units", choices=("auto", "m", "mm"), default="auto")
    p.add_argument("--out", required=True,
                   help="output directory (a rerun into an earlier 'jaxform wrinkles' output replaces it)")
    p.add_argument("--force", action="store_true",
                   help="go on where the command would stop: write into a non-empty directory that is "
                   "not a 'jaxform wrinkles' output, and measure although a check failed (mesh size vs "
                   "--units, nodes inside the tool, tool far from the part, --tool or "
                   "--ply-thickness-mm disagreeing with the run); each overridden check is printed and "
                   "listed under 'forced' in summary.json")
    p.set_defaults(handler=run)


# ---------------------------------------------------------------------------------------------
# Tools: where they are
# ---------------------------------------------------------------------------------------------


@dataclasses.dataclass
class _Tool:
    """A tool to measure against: analytic :mod:`jaxform.tools` each with its vertical
    displacement ``dz`` (m), or a triangle mesh ``(vertices, faces)``."""

    text: str
    analytic: tuple = ()
    dz: tuple = ()
    mesh: tuple | None = None

    offsets: tuple | None = None  # the nominal distance of the ply's mid-surface to each tool, m

    def measure(self, nodes, dcrit: float):
        """``(distance, d_crit, phi)``: (N,) distance to the tool the node conforms to, m; (N,)
        its d_crit there (``dcrit``, or that tool's offset); (N,) signed distance to the nearest
        tool (negative inside), or None for a mesh tool. The tool a node conforms to is the one it
        exceeds its offset least (a stack's ply i: punch at (i - 1/2) h, die at (n - i + 1/2) h)."""
        if self.mesh is not None:
            from jaxform import metrics as M

            d = np.asarray(M.tool_distance(nodes, *self.mesh, check=False), dtype=np.float64)
            return d, np.full(len(d), dcrit), None
        from jaxform import tools

        phi = np.stack([np.asarray(tools.sdf(t, nodes, dz)[0], np.float64) for t, dz in zip(self.analytic, self.dz)])
        off = np.asarray(self.offsets if self.offsets is not None else (dcrit,) * len(phi))[:, None]
        j = np.argmin(phi - off, axis=0)[None]
        return (np.abs(np.take_along_axis(phi, j, 0)[0]), np.take_along_axis(np.broadcast_to(off, phi.shape), j, 0)[0],
                phi.min(axis=0))


def _parse_preset(spec: str):
    """A preset tool spec as a :class:`_Tool`, or None when ``spec`` names no preset."""
    from jaxform import tools

    name, _, rest = spec.partition(":")
    if name not in ("hemisphere", "plane"):
        return None
    params = {}
    for item in filter(None, rest.split(",")):
        key, sep, val = item.partition("=")
        if not sep:
            raise ValueError(f"tool parameter {item!r} must be key=value")
        try:
            params[key.strip()] = float(val)
        except ValueError:
            raise ValueError(f"tool parameter {key!r} must be a number, got {val!r}") from None
        if not math.isfinite(params[key.strip()]):
            raise ValueError(f"tool parameter {key!r} must be finite, got {val!r}")
    if name == "hemisphere":
        allowed = {"radius_mm", "x_mm", "y_mm", "z_mm", "base"}
        bad = set(params) - allowed
        if bad:
            raise ValueError(f"unknown hemisphere parameters {sorted(bad)}; allowed: {sorted(allowed)}")
        radius_mm = params.get("radius_mm", 50.0)
        if not radius_mm > 0:
            raise ValueError(f"hemisphere radius_mm must be > 0, got {radius_mm:g}")
        rig = tools.hemisphere_rig(radius_mm * 1e-3,
                                   tuple(params.get(k, 0.0) * 1e-3 for k in ("x_mm", "y_mm", "z_mm")),
                                   base_plane=bool(params.get("base", 1.0)))
        return _Tool(f"hemisphere rig (apex up), punch radius {radius_mm:g} mm", rig, (0.0,) * len(rig))
    bad = set(params) - {"z_mm"}
    if bad:
        raise ValueError(f"unknown plane parameters {sorted(bad)}; allowed: ['z_mm']")
    return _Tool("plane", (tools.Plane(point=(0.0, 0.0, params.get("z_mm", 0.0) * 1e-3)),), (0.0,))


@dataclasses.dataclass
class _Run:
    """A ``jaxform run`` folder: its case, summary and frame times."""

    folder: pathlib.Path
    case: object
    summary: dict
    frames: dict  # file name -> time, s


def _is_run_folder(folder: pathlib.Path) -> bool:
    return folder.is_dir() and (folder / "summary.json").is_file() and (folder / "frames.pvd").is_file()


def _run_of_frame(mesh: pathlib.Path) -> pathlib.Path | None:
    """The run folder ``mesh`` is a frame of, or None."""
    if _FRAME.search(mesh.name) and _is_run_folder(mesh.parent):
        return mesh.parent
    return None


def _load_run(folder: pathlib.Path) -> _Run:
    from jaxform.forming.case import from_dict

    try:
        summary = json.loads((folder / "summary.json").read_text())
    except (OSError, ValueError) as err:
        raise ValueError(f"{folder / 'summary.json'} is not readable JSON ({err}); is {folder} a 'jaxform run' "
                         "folder? Give --tool and --ply-thickness-mm explicitly") from None
    if not isinstance(summary, dict) or not isinstance(summary.get("inputs"), dict):
        raise ValueError(f"{folder / 'summary.json'} has no 'inputs' (the case the run used): the rig cannot be "
                         "rebuilt; give --tool and --ply-thickness-mm explicitly")
    try:
        case = from_dict(summary["inputs"])
    except ValueError as err:
        raise ValueError(f"{folder / 'summary.json'}: its 'inputs' are not a valid case ({err})") from None
    return _Run(folder, case, summary, read_frame_index(folder / "frames.pvd"))


def _run_tool(run: _Run, mesh: pathlib.Path, h: float, ply: int):
    """The rig of ``run`` posed at the time of frame ``mesh`` (the run's last frame when ``mesh`` is
    not one of its frames), ply ``ply`` of thickness ``h``: ``(tool, rig_facts)``."""
    from jaxform import tools
    from jaxform.forming.rig import build_tools

    same = mesh.parent.resolve() == run.folder.resolve() and mesh.name in run.frames
    if same:
        t, when = run.frames[mesh.name], f"frame {mesh.name}"
    elif run.frames:
        name = max(run.frames, key=run.frames.get)
        t, when = run.frames[name], f"the run's last frame {name} ({mesh} is not a frame of it)"
    else:
        raise ValueError(f"{run.folder / 'frames.pvd'} lists no frame: the run wrote nothing to measure against")
    rig = build_tools(run.case)
    hist = run.summary.get("history") or {}
    ts, us = hist.get("t_s"), hist.get("punch_displacement_m")
    if ts and us and len(ts) == len(us):
        down = float(np.interp(t, np.asarray(ts, float), np.asarray(us, float)))  # what the run did
        source = "history.punch_displacement_m"
    else:
        down = -float(tools.displacement(rig.punch, t))
        source = "the case's punch motion"
    facts = {"run": str(run.folder), "case": getattr(run.case, "name", None), "frame": when, "time_s": t,
             "punch_displacement_m": down, "punch_displacement_from": source,
             "tools": ["punch", "die"], "holder": "left out (as the run's deviation_m)"}
    text = (f"the rig of run {run.folder} at {when}, t = {t:.6g} s: punch moved down {down * 1e3:.4g} mm, die "
            "(holder left out)")
    n = run.case.n_plies
    return _Tool(text, (rig.punch, rig.die), (-down, 0.0), offsets=((ply - 0.5) * h, (n - ply + 0.5) * h)), facts


def _read_checked(reader, path, units, problems, **kw):
    """``reader(path, units=...)``; a size at odds with ``units`` goes to ``problems``."""
    try:
        return reader(path, units=units, on_units_mismatch="raise", **kw)
    except ValueError as err:
        if "units=" not in str(err):
            raise
        problems.append(f"{err} (use --units/--tool-units/--cloud-units m or mm, or auto)")
        return reader(path, units=units, on_units_mismatch="ignore", **kw)


def _where_the_tool_is(spec, mesh_path: pathlib.Path):
    """``(run, run_dir, preset)``: the run whose rig is the tool (``run_dir``), or the run ``mesh_path``
    is a frame of (then ``--tool`` is checked against its rig), and the preset tool, if any."""
    frame_of = _run_of_frame(mesh_path)
    run_dir = frame_of if spec in (None, "run") else None
    if spec == "run" and frame_of is None:
        raise ValueError(f"--tool run: {mesh_path} is not a frame of a 'jaxform run' folder (frames_#####.vtu "
                         "beside frames.pvd and summary.json); give the run folder: --tool RUN_DIR")
    if spec is None and frame_of is None:
        raise ValueError(f"--tool is required: {mesh_path} is not a frame of a 'jaxform run' folder, so the "
                         "tool is unknown (a mesh file, a run folder, or a preset: " + ", ".join(PRESETS) + ")")
    if spec not in (None, "run") and pathlib.Path(spec).is_dir():
        if not _is_run_folder(pathlib.Path(spec)):
            raise ValueError(f"--tool {spec}: a directory but not a 'jaxform run' folder (no summary.json and "
                             "frames.pvd)")
        run_dir = pathlib.Path(spec)
    if run_dir is not None:
        return _load_run(run_dir), run_dir, None
    preset = _parse_preset(spec)
    if preset is None and not pathlib.Path(spec).is_file():
        raise ValueError(f"--tool {spec!r} is neither an existing file nor a preset ({', '.join(PRESETS)}) "
                         "nor a 'jaxform run' folder")
    try:  # a frame of a run measured against another tool: the run's rig is the reference
        return (_load_run(frame_of) if frame_of is not None else None), None, preset
    except ValueError:
        return None, None, preset


# ---------------------------------------------------------------------------------------------
# Arguments, checked before any work
# ---------------------------------------------------------------------------------------------


def _parse_sections(texts) -> list:
    """``[(text, (x1, y1), (x2, y2))]`` in m; ValueError for anything but four finite numbers of a
    section of non-zero length."""
    out = []
    for text in texts:
        try:
            vals = [float(t) for t in text.split(",")]
        except ValueError:
            vals = []
        if len(vals) != 4 or not all(math.isfinite(v) for v in vals):
            raise ValueError(f"--section {text!r}: expected four numbers X1,Y1,X2,Y2 in mm "
                             "(write --section=-34,0,34,0 when it starts with -)")
        x1, y1, x2, y2 = (v * 1e-3 for v in vals)
        if x1 == x2 and y1 == y2:
            raise ValueError(f"--section {text!r}: its two ends are the same point")
        out.append((text, (x1, y1), (x2, y2)))
    return out


def _check_args(args) -> None:
    for name, val in (("--ply-thickness-mm", args.ply_thickness_mm), ("--kappa-threshold-per-m", args.kappa_threshold_per_m)):
        if val is not None and not (math.isfinite(val) and val > 0):
            raise ValueError(f"{name} must be a positive number, got {val:g}")
    if args.ply_index is not None and args.ply_index < 1:
        raise ValueError(f"--ply-index counts from 1 (the ply on the tool), got {args.ply_index}")
    if args.cloud and not pathlib.Path(args.cloud).exists():
        raise FileNotFoundError(f"no such point-cloud file: {args.cloud}")


def _check_out(out: pathlib.Path, force: bool) -> None:
    """Refuse now (before any work) what :func:`jaxform.io.output.prepare_output_dir` would refuse."""
    from jaxform.io.output import MARKER

    if out.exists() and not out.is_dir():
        raise FileExistsError(f"output path {out} exists and is a file; choose a directory")
    if out.is_dir() and any(out.iterdir()) and not force:
        marker = out / MARKER
        if not (marker.exists() and marker.read_text().strip() == "wrinkles"):
            raise FileExistsError(f"output directory {out} is not empty and was not written by 'jaxform wrinkles'; "
                                  "choose another directory or pass --force to write into it")


def _stats(values: np.ndarray) -> dict:
    v = np.asarray(values, dtype=float)
    return {"min": float(v.min()), "mean": float(v.mean()), "median": float(np.median(v)),
            "p95": float(np.percentile(v, 95)), "p99": float(np.percentile(v, 99)),
            "max": float(v.max()), "rms": float(np.sqrt(np.mean(v * v)))}


def _select_ply(nodes, faces, data, ply: int, n_plies: int, path):
    """The nodes and faces of ply ``ply`` of a multi-ply frame (by its ``ply_id`` point data)."""
    pid = data.get("ply_id")
    if pid is None:
        raise ValueError(f"{path} has no 'ply_id' point data to pick ply {ply} of the {n_plies}-ply run from")
    pid = np.asarray(pid).reshape(-1)
    keep = pid[faces].min(axis=1) == ply
    keep &= pid[faces].max(axis=1) == ply
    if not keep.any():
        raise ValueError(f"{path}: no face of ply {ply} (ply_id)")
    f = faces[keep]
    used = np.unique(f)
    remap = -np.ones(len(nodes), np.int64)
    remap[used] = np.arange(len(used))
    return nodes[used], remap[f]


# ---------------------------------------------------------------------------------------------
# The command
# ---------------------------------------------------------------------------------------------


def run(args) -> int:
    from jaxform import metrics as M
    from jaxform.geometry import quads_to_triangles
    from jaxform.io.output import prepare_output_dir
    from jaxform.io.surface import read_point_cloud, read_surface, write_vtu
    from jaxform.plots import wrinkles as P

    t0 = time.perf_counter()
    # 1. every argument, before any work or any file written
    _check_args(args)
    sections = _parse_sections(args.section)
    out = pathlib.Path(args.out)
    _check_out(out, args.force)
    mesh_path = pathlib.Path(args.mesh)
    if not mesh_path.exists():
        raise FileNotFoundError(f"no such mesh file: {mesh_path}")
    run, run_dir, preset = _where_the_tool_is(args.tool, mesh_path)
    case = run.case if run is not None else None
    if args.ply_thickness_mm is None and case is None:
        raise ValueError("--ply-thickness-mm is required (the ply thickness h, mm) when MESH is not a frame of a "
                         "'jaxform run' folder")
    n_plies, ply = (case.n_plies if case is not None else 1), args.ply_index or 1
    if ply > n_plies and case is not None:
        raise ValueError(f"--ply-index {ply}: the run {run.folder} has {n_plies} ply(ies)")

    # 2. read everything and measure the distance; what cannot be right is a problem (--force: a warning)
    problems: list[str] = []
    h_run = float(case.ply_thickness) if case is not None else None
    h = args.ply_thickness_mm * 1e-3 if args.ply_thickness_mm is not None else h_run
    if h_run is not None and not math.isclose(h, h_run, rel_tol=1e-6):
        problems.append(f"--ply-thickness-mm {args.ply_thickness_mm:g} but the run {run.folder} formed plies "
                        f"{h_run * 1e3:g} mm thick; leave it out to use the run's")
    units = "m" if run is not None and args.units == "auto" else args.units  # jaxform writes metres
    nodes, faces, data = _read_checked(read_surface, mesh_path, units, problems, point_data=True)
    if n_plies > 1 and "ply_id" in data:  # a frame of a stack: the ply measured
        nodes, faces = _select_ply(nodes, faces, data, ply, n_plies, mesh_path)
    rig_facts = None
    if run_dir is not None:
        tool, rig_facts = _run_tool(run, mesh_path, h, ply)
    elif preset is not None:
        tool = preset
    else:
        tv, tf = _read_checked(read_surface, args.tool, args.tool_units, problems, triangulate=True)
        tool = _Tool(f"mesh {args.tool} ({len(tf)} triangles)", mesh=(tv, tf))
        span_m, span_t = (np.linalg.norm(np.ptp(a, axis=0)) for a in (nodes, tv))
        if span_m > 0 and span_t > 0 and not (1e-2 < span_t / span_m < 1e2):
            problems.append(f"the mesh is {span_m:.4g} m across and the tool {span_t:.4g} m: mixed units? "
                            "set --units and --tool-units (m or mm) explicitly")
    cloud = _read_checked(read_point_cloud, args.cloud, args.cloud_units, problems) if args.cloud else None
    dcrit = float(M.d_crit(h, ply))
    dist, dcrit_node, phi = tool.measure(nodes, dcrit)
    excess = dist - dcrit_node  # a run's rig: its deviation_m
    if run is not None and run_dir is None:  # --tool given for a frame of a run: must agree with its rig
        rig_tool, _ = _run_tool(run, mesh_path, h, ply)
        gap = np.abs(dist - rig_tool.measure(nodes, dcrit)[0])
        if gap.max() > max(1e-3, h):
            problems.append(f"--tool {args.tool} disagrees with the rig {run.folder} was formed on by up to "
                            f"{gap.max() * 1e3:.3g} mm; leave --tool out (or --tool run) to measure against the "
                            f"run's own rig ({rig_tool.text})")
    inside = phi < -max(0.5 * h, 1e-4) if phi is not None else np.zeros(len(nodes), bool)
    if inside.any():
        problems.append(f"{int(inside.sum())} of {len(nodes)} nodes are inside the tool ({tool.text}), up to "
                        f"{-phi.min() * 1e3:.3g} mm deep: the mesh is not where the tool is (wrong tool, pose, "
                        "offset or --units?)")
    far = max(10.0 * dcrit, 0.05 * float(np.linalg.norm(np.ptp(nodes, axis=0))))
    if dist.min() > far:
        problems.append(f"the closest node is {dist.min() * 1e3:.4g} mm from the tool ({tool.text}), more than "
                        f"{far * 1e3:.3g} mm: the part was not formed on this tool here (wrong tool, pose, offset "
                        "or --units?)")
    if problems and not args.force:
        raise ValueError("; ".join(problems) + ". Pass --force to measure anyway")

    # 3. the metric (nothing written yet)
    k1, k2 = (np.asarray(k) for k in M.principal_curvatures(nodes, faces))
    km = np.maximum(np.abs(k1), np.abs(k2))
    labels = np.asarray(M.classify_zones(excess, km, DEFECT_TOLERANCE * h, kappa_threshold=args.kappa_threshold_per_m,
                                         faces=faces))
    areas = np.asarray(M.node_areas(nodes, faces))
    zarea = np.asarray(M.zone_areas(labels, areas))
    count, region = M.count_wrinkle_regions(labels, faces, areas, min_area=4.0 * np.median(areas))
    radius = np.asarray(M.wrinkle_radius(km))
    amp = np.where(labels == M.WRINKLE, dist, 0.0)
    profiles = []
    for text, a, b in sections:
        s, val, valid, height = (np.asarray(x) for x in M.section_profile(nodes, faces, dist, a, b, 400))
        ex = np.asarray(M.section_profile(nodes, faces, excess, a, b, 400)[1])
        profiles.append((text, s, val, valid, height, ex))
    cd = None
    if cloud is not None:
        cd = np.asarray(M.tool_distance(cloud, nodes, np.asarray(quads_to_triangles(faces)), check=False))

    defect = labels != M.CONFORMING
    summary = {
        "mesh": str(args.mesh), "tool": tool.text, "n_nodes": int(len(nodes)),
        "n_faces": int(len(faces)), "ply_thickness_m": h, "ply_index": ply,
        "d_crit_m": dcrit, "defect_tolerance_m": DEFECT_TOLERANCE * h, "kappa_threshold_per_m": args.kappa_threshold_per_m,
        "zone_area_m2": {"conforming": float(zarea[0]), "bridging": float(zarea[1]),
                         "wrinkle": float(zarea[2])},
        "wrinkle_count": int(count),
        "max_wrinkle_amplitude_m": float(amp.max()),
        "max_distance_m": float(dist.max()),
        "distance_m": _stats(dist),
        "kappa_max_per_m": _stats(km),
        "kappa_max_defect_per_m": _stats(km[defect]) if defect.any() else None,
        "forced": problems,
    }
    if rig_facts is not None:
        summary["rig"] = rig_facts

    # 4. write (only now)
    out = prepare_output_dir(out, force=args.force, owner="wrinkles", replaces=OUTPUTS)
    written = [write_vtu(out / "wrinkles.vtu", nodes, faces, point_data={
        "distance_m": dist, "k1_per_m": k1, "k2_per_m": k2, "kappa_max_per_m": km,
        "excess_over_d_crit_m": excess, "wrinkle_radius_m": radius, "zone": labels.astype(np.int32),
        "wrinkle_region": np.asarray(region), "node_area_m2": areas})]
    written.append(P.plot_node_field(out / "distance.png", nodes, faces, dist, scale=1e3,
                                     title="Distance to the tool", label="d (mm)"))
    written.append(P.plot_node_field(out / "kappa_max.png", nodes, faces, km, cmap="magma",
                                     title="kappa_max", label="kappa_max (1/m)",
                                     vmax=float(np.percentile(km, 99.5))))
    written.append(P.plot_zones(out / "zones.png", nodes, faces, labels,
                                title=f"Zones (d_crit {dcrit * 1e3:g} mm, "
                                f"kappa >= {args.kappa_threshold_per_m:g} 1/m)"))
    rows = []
    for k, (text, s, val, valid, height, ex) in enumerate(profiles):
        path = out / f"section_{k}.csv"
        with open(path, "w") as fh:
            fh.write("s_mm,amplitude_mm,height_mm,valid\n")
            for row in zip(s * 1e3, val * 1e3, height * 1e3, valid.astype(int)):
                fh.write("{:.6f},{:.6f},{:.6f},{:d}\n".format(*row))
        written.append(path)
        rows.append({"points_mm": text, "file": path.name,
                     "wrinkle_count": int(M.count_section_wrinkles(ex, valid, min_amplitude=DEFECT_TOLERANCE * h)),
                     "max_amplitude_m": float(val[valid].max()) if valid.any() else None})
    if rows:
        summary["sections"] = rows
    if cloud is not None:
        written.append(write_vtu(out / "cloud_distance.vtu", cloud, None,
                                 point_data={"distance_to_surface_m": cd}))
        written.append(P.plot_node_field(out / "cloud_distance.png", cloud, None, cd, scale=1e3,
                                         title="Cloud to surface distance", label="distance (mm)"))
        summary["cloud"] = {"file": str(args.cloud), "n_points": int(len(cloud)),
                            "distance_m": _stats(cd)}
    summary["wall_time_s"] = time.perf_counter() - t0
    (out / "summary.json").write_text(json.dumps(summary, indent=2))
    written.append(out / "summary.json")
    for msg in problems:
        print(f"jaxform wrinkles: warning (--force): {msg}", file=sys.stderr)
    print(f"jaxform wrinkles: tool: {tool.text}")
    print(f"jaxform wrinkles: {summary['wrinkle_count']} wrinkle region(s), wrinkle area "
          f"{zarea[2] * 1e6:.1f} mm^2, bridging {zarea[1] * 1e6:.1f} mm^2, max amplitude "
          f"{summary['max_wrinkle_amplitude_m'] * 1e3:.3f} mm")
    for p in written:
        print(f"  wrote {p}")
    return 0
