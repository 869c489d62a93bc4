"""``jaxform check-intersections RUN_DIR|MESH``: does a formed part pass through itself?

Reads the last frame of a ``jaxform run`` folder (the ``frames.pvd`` entry with the largest time)
or any surface mesh meshio reads (VTU, OBJ, PLY, STL, Abaqus .inp, ...), and lists the pairs of
faces that cross each other (:func:`jaxform.metrics.intersections.intersecting_pairs`: faces
sharing an edge, and touching layers, are not intersections). A run's quads are split into the
triangles it was simulated with; other quad meshes along their 0-2 diagonal. Exit status 0: none; 1: some
found; 2: bad input. ``--json FILE`` writes the pairs and counts.
"""
from __future__ import annotations

import pathlib
import sys


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "check-intersections",
        help="report faces of a run's last frame (or any mesh) that pass through each other",
        description=__doc__,
    )
    p.add_argument("path", type=pathlib.Path, help="a 'jaxform run' folder or a surface mesh file")
    p.add_argument("--show", type=int, default=10, help="pairs to print (default 10)")
    p.add_argument("--json", type=pathlib.Path, default=None, help="write pairs and counts to this JSON file")
    p.set_defaults(handler=run)


def last_frame(folder: pathlib.Path) -> pathlib.Path:
    """The frame file of the largest time listed in ``folder/frames.pvd``."""
    index = folder / "frames.pvd"
    if not index.is_file():
        raise ValueError(f"{folder} is a folder without frames.pvd: give a 'jaxform run' folder or a mesh file")
    from jaxform.io.frames import read_frame_index

    frames = read_frame_index(index)
    if not frames:
        raise ValueError(f"{index} lists no frame: the run wrote nothing to check")
    return folder / max(frames, key=frames.get)


def _run_triangles(path, nodes, faces, ply):
    """The triangles a ``jaxform run`` folder's blank was simulated with (its quads are split along
    alternating diagonals, :func:`jaxform.forming.rig.grid_triangles`), or None for other meshes."""
    if not path.is_dir() or faces.shape[1] != 4 or ply is None:
        return None
    import numpy as np

    from jaxform.forming.rig import grid_quads, grid_triangles

    plies = len(np.unique(ply))
    n = int(round(np.sqrt(len(nodes) / plies)))
    if n * n * plies != len(nodes) or not np.array_equal(grid_quads(n, n, plies), faces):
        return None
    return grid_triangles(n, plies)


def run(args) -> int:
    import numpy as np

    from jaxform.io.frames import write_json
    from jaxform.io.surface import read_surface
    from jaxform.metrics.intersections import intersecting_pairs

    path = args.path
    if not path.exists():
        raise FileNotFoundError(f"no such run folder or mesh file: {path}")
    mesh = last_frame(path) if path.is_dir() else path
    nodes, faces, data = read_surface(mesh, units="m", on_units_mismatch="ignore", point_data=True)
    ply = np.asarray(data["ply_id"]).reshape(len(nodes), -1)[:, 0].astype(int) if "ply_id" in data else None
    pairs = intersecting_pairs(nodes, faces, triangles=_run_triangles(path, nodes, faces, ply))
    counts = {}
    if ply is not None and len(pairs):
        fp = ply[faces[:, 0]]
        for a, b in zip(fp[pairs[:, 0]], fp[pairs[:, 1]]):
            key = f"ply {a}" if a == b else f"plies {min(a, b)}-{max(a, b)}"
            counts[key] = counts.get(key, 0) + 1
    print(f"{mesh}: {len(faces)} faces, {len(pairs)} intersecting pairs"
          + (" (" + ", ".join(f"{k}: {v}" for k, v in sorted(counts.items())) + ")" if counts else ""))
    cen = nodes[faces].mean(axis=1)
    for i, j in pairs[: max(args.show, 0)]:
        c = 0.5 * (cen[i] + cen[j])
        print(f"  faces {i} and {j} near ({c[0]:.6g}, {c[1]:.6g}, {c[2]:.6g})")
    if len(pairs) > args.show > 0:
        print(f"  ... and {len(pairs) - args.show} more")
    if args.json is not None:
        write_json(args.json, {"mesh": str(mesh), "faces": int(len(faces)), "intersecting_pairs": int(len(pairs)),
                               "by_ply": counts, "pairs": pairs})
    sys.stdout.flush()
    return 1 if len(pairs) else 0
