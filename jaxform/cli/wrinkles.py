"""``jaxform wrinkles``: the paper's wrinkle metric on any surface mesh (host side)."""
from __future__ import annotations

import json
import pathlib
import time

import numpy as np

PRESETS = {
    "hemisphere": "the paper's rig: hemispherical punch on a flat base plane "
    "(hemisphere:radius_mm=50,x_mm=0,y_mm=0,z_mm=0,base=1)",
    "plane": "a flat tool z = const (plane:z_mm=0)",
}


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "wrinkles",
        help="find and measure wrinkles on a surface mesh (distance to the tool, curvature, zones)",
        description="Evaluate the wrinkle metric of the source paper (SPEC section 5) on any "
        "meshio-readable surface (VTU, Abaqus .inp, OBJ, PLY, STL...): distance of every node to "
        "the tool, principal curvatures by iterative quadric fitting, wrinkle/bridging/conforming "
        "zones. Writes DIR/wrinkles.vtu, DIR/summary.json and PNG maps. With --cloud, also the "
        "distance of every measured point to the surface (as CloudCompare does for scans).",
    )
    p.add_argument("mesh", help="surface mesh file (the formed ply)")
    p.add_argument("--tool", required=True,
                   help="tool mesh file, or a preset: " + "; ".join(f"{k}: {v}" for k, v in PRESETS.items()))
    p.add_argument("--ply-thickness-mm", type=float, required=True, help="ply thickness h, mm")
    p.add_argument("--ply-index", type=int, default=1,
                   help="position of the ply in the stack from the tool (d_crit = (i - 1/2) h)")
    p.add_argument("--kappa-threshold-per-m", type=float, default=100.0,
                   help="curvature separating wrinkles from bridging, 1/m (default 100: radius 10 mm)")
    p.add_argument("--units", choices=("auto", "m", "mm"), default="auto",
                   help="units of the mesh file (auto: mm when it is more than 5 units across)")
    p.add_argument("--tool-units", choices=("auto", "m", "mm"), default="auto",
                   help="units of the tool file")
    p.add_argument("--section", action="append", default=[], metavar="X1,Y1,X2,Y2",
                   help="a straight section in the base plane, mm; its amplitude profile goes to "
                   "DIR/section_<k>.csv (repeatable; write --section=-34,0,34,0 when it starts with -)")
    p.add_argument("--cloud", help="measured point cloud (PLY/XYZ/CSV) to compare with the mesh")
    p.add_argument("--cloud-units", choices=("auto", "m", "mm"), default="auto")
    p.add_argument("--out", required=True, help="output directory")
    p.add_argument("--force", action="store_true", help="write into a non-empty output directory")
    p.set_defaults(handler=run)


def _parse_tool(spec: str, units: str):
    """The tool as ``(vertices, faces)`` of a mesh file, or a tuple of :mod:`jaxform.tools` tools."""
    from jaxform import tools
    from jaxform.io.surface import read_surface

    path = pathlib.Path(spec)
    if path.exists():
        v, f = read_surface(path, units=units, triangulate=True)
        return (v, f), f"mesh {path} ({len(f)} triangles)"
    name, _, rest = spec.partition(":")
    params = {}
    for item in filter(None, rest.split(",")):
        key, sep, val = item.partition("=")
        if not sep:
            raise ValueError(f"tool parameter {item!r} must be key=value")
        try:
            params[key.strip()] = float(val)
        except ValueError:
            raise ValueError(f"tool parameter {key!r} must be a number, got {val!r}") from None
    if name == "hemisphere":
        allowed = {"radius_mm", "x_mm", "y_mm", "z_mm", "base"}
        bad = set(params) - allowed
        if bad:
            raise ValueError(f"unknown hemisphere parameters {sorted(bad)}; allowed: {sorted(allowed)}")
        radius_mm = params.get("radius_mm", 50.0)
        rig = tools.hemisphere_rig(radius_mm * 1e-3,
                                   tuple(params.get(k, 0.0) * 1e-3 for k in ("x_mm", "y_mm", "z_mm")),
                                   base_plane=bool(params.get("base", 1.0)))
        return rig, f"hemisphere rig, punch radius {radius_mm:g} mm"
    if name == "plane":
        bad = set(params) - {"z_mm"}
        if bad:
            raise ValueError(f"unknown plane parameters {sorted(bad)}; allowed: ['z_mm']")
        return (tools.Plane(point=(0.0, 0.0, params.get("z_mm", 0.0) * 1e-3)),), "plane"
    raise ValueError(f"--tool {spec!r} is neither an existing file nor a preset "
                     f"({', '.join(PRESETS)})")


def _check_out(out: pathlib.Path, force: bool) -> None:
    if out.exists() and not out.is_dir():
        raise FileExistsError(f"--out {out} exists and is not a directory")
    if out.exists() and any(out.iterdir()) and not force:
        raise FileExistsError(f"--out {out} is not empty; pass --force to write into it")
    out.mkdir(parents=True, exist_ok=True)


def _stats(values: np.ndarray) -> dict:
    v = np.asarray(values, dtype=float)
    return {"min": float(v.min()), "mean": float(v.mean()), "median": float(np.median(v)),
            "p95": float(np.percentile(v, 95)), "p99": float(np.percentile(v, 99)),
            "max": float(v.max()), "rms": float(np.sqrt(np.mean(v * v)))}


def run(args) -> int:
    import jax.numpy as jnp

    from jaxform import metrics as M
    from jaxform.geometry import quads_to_triangles
    from jaxform.io.surface import read_point_cloud, read_surface, write_vtu
    from jaxform.plots import wrinkles as P

    t0 = time.perf_counter()
    if not args.ply_thickness_mm > 0:
        raise ValueError(f"--ply-thickness-mm must be positive, got {args.ply_thickness_mm}")
    if args.ply_index < 1:
        raise ValueError(f"--ply-index counts from 1 (the ply on the tool), got {args.ply_index}")
    out = pathlib.Path(args.out)
    nodes, faces = read_surface(args.mesh, units=args.units)
    tool, tool_text = _parse_tool(args.tool, args.tool_units)
    _check_out(out, args.force)

    if isinstance(tool[0], np.ndarray):  # a mesh file: (vertices, faces)
        tv, tf = tool
        span_m = np.linalg.norm(np.ptp(nodes, axis=0))
        span_t = np.linalg.norm(np.ptp(tv, axis=0))
        if span_m > 0 and span_t > 0 and not (1e-2 < span_t / span_m < 1e2):
            raise ValueError(
                f"the mesh is {span_m:.4g} m across and the tool {span_t:.4g} m: mixed units? "
                "set --units and --tool-units (m or mm) explicitly")
        dist = np.asarray(M.tool_distance(nodes, tv, tf))
    else:
        dist = np.asarray(M.tool_distance(nodes, tool))
    k1, k2 = (np.asarray(k) for k in M.principal_curvatures(nodes, faces))
    km = np.maximum(np.abs(k1), np.abs(k2))
    h = args.ply_thickness_mm * 1e-3
    dcrit = float(M.d_crit(h, args.ply_index))
    labels = np.asarray(M.classify_zones(dist, km, dcrit, kappa_threshold=args.kappa_threshold_per_m,
                                         faces=faces))
    areas = np.asarray(M.node_areas(nodes, faces))
    zarea = np.asarray(M.zone_areas(labels, areas))
    count, region = M.count_wrinkle_regions(labels, faces, areas, min_area=4.0 * np.median(areas))
    radius = np.asarray(M.wrinkle_radius(km))
    amp = np.where(labels == M.WRINKLE, dist, 0.0)

    written = []
    written.append(write_vtu(out / "wrinkles.vtu", nodes, faces, point_data={
        "distance_m": dist, "k1_per_m": k1, "k2_per_m": k2, "kappa_max_per_m": km,
        "wrinkle_radius_m": radius, "zone": labels.astype(np.int32),
        "wrinkle_region": np.asarray(region), "node_area_m2": areas}))
    written.append(P.plot_node_field(out / "distance.png", nodes, faces, dist, scale=1e3,
                                     title="Distance to the tool", label="d (mm)"))
    written.append(P.plot_node_field(out / "kappa_max.png", nodes, faces, km, cmap="magma",
                                     title="kappa_max", label="kappa_max (1/m)",
                                     vmax=float(np.percentile(km, 99.5))))
    written.append(P.plot_zones(out / "zones.png", nodes, faces, labels,
                                title=f"Zones (d_crit {dcrit * 1e3:g} mm, "
                                f"kappa >= {args.kappa_threshold_per_m:g} 1/m)"))
    defect = labels != M.CONFORMING
    summary = {
        "mesh": str(args.mesh), "tool": tool_text, "n_nodes": int(len(nodes)),
        "n_faces": int(len(faces)), "ply_thickness_m": h, "ply_index": args.ply_index,
        "d_crit_m": dcrit, "kappa_threshold_per_m": args.kappa_threshold_per_m,
        "zone_area_m2": {"conforming": float(zarea[0]), "bridging": float(zarea[1]),
                         "wrinkle": float(zarea[2])},
        "wrinkle_count": int(count),
        "max_wrinkle_amplitude_m": float(amp.max()),
        "max_distance_m": float(dist.max()),
        "distance_m": _stats(dist),
        "kappa_max_per_m": _stats(km),
        "kappa_max_defect_per_m": _stats(km[defect]) if defect.any() else None,
    }
    sections = []
    for k, text in enumerate(args.section):
        try:
            x1, y1, x2, y2 = (float(t) * 1e-3 for t in text.split(","))
        except ValueError:
            raise ValueError(f"--section {text!r}: expected X1,Y1,X2,Y2 in mm") from None
        s, val, valid, height = (np.asarray(a) for a in M.section_profile(
            nodes, faces, dist, (x1, y1), (x2, y2), 400))
        path = out / f"section_{k}.csv"
        with open(path, "w") as fh:
            fh.write("s_mm,amplitude_mm,height_mm,valid\n")
            for row in zip(s * 1e3, val * 1e3, height * 1e3, valid.astype(int)):
                fh.write("{:.6f},{:.6f},{:.6f},{:d}\n".format(*row))
        written.append(path)
        sections.append({"points_mm": text, "file": path.name,
                         "wrinkle_count": int(M.count_section_wrinkles(val, valid, min_amplitude=dcrit)),
                         "max_amplitude_m": float(val[valid].max()) if valid.any() else None})
    if sections:
        summary["sections"] = sections
    if args.cloud:
        cloud = read_point_cloud(args.cloud, units=args.cloud_units)
        cd = np.asarray(M.tool_distance(cloud, nodes, np.asarray(quads_to_triangles(faces))))
        written.append(write_vtu(out / "cloud_distance.vtu", cloud, None,
                                 point_data={"distance_to_surface_m": cd}))
        written.append(P.plot_node_field(out / "cloud_distance.png", cloud, None, cd, scale=1e3,
                                         title="Cloud to surface distance", label="distance (mm)"))
        summary["cloud"] = {"file": str(args.cloud), "n_points": int(len(cloud)),
                            "distance_m": _stats(cd)}
    summary["wall_time_s"] = time.perf_counter() - t0
    (out / "summary.json").write_text(json.dumps(summary, indent=2))
    written.append(out / "summary.json")
    print(f"jaxform wrinkles: {summary['wrinkle_count']} wrinkle region(s), wrinkle area "
          f"{zarea[2] * 1e6:.1f} mm^2, bridging {zarea[1] * 1e6:.1f} mm^2, max amplitude "
          f"{summary['max_wrinkle_amplitude_m'] * 1e3:.3f} mm")
    for p in written:
        print(f"  wrote {p}")
    del jnp
    return 0
