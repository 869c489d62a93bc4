"""Surface meshes and point clouds in and out (host side: files, meshio).

``read_surface`` turns any meshio-readable surface (VTU, Abaqus .inp, OBJ, PLY, STL, ...) into
``nodes`` (N, 3) float64 in m and ``faces`` (F, 3) or (F, 4) int64; ``read_point_cloud`` reads PLY,
XYZ or CSV points; ``write_vtu`` writes a mesh with point and cell data.
"""
from __future__ import annotations

import pathlib
import warnings

import numpy as np

__all__ = ["UnitsWarning", "read_surface", "read_point_cloud", "write_vtu", "guess_units"]

_TRI = {"triangle", "triangle6", "triangle7"}
_QUAD = {"quad", "quad8", "quad9"}
_VOLUME = {"tetra", "tetra10", "hexahedron", "hexahedron20", "hexahedron27", "wedge", "pyramid"}
# Extent (bounding-box diagonal) above which coordinates are taken for millimetres.
_MM_IF_LARGER_THAN = 5.0


class UnitsWarning(UserWarning):
    """Coordinates whose size suggests other units than the ones given (mm read as m...)."""


def guess_units(points: np.ndarray) -> str:
    """'mm' when the bounding-box diagonal exceeds 5 (no fabric part is 5 m across), else 'm'."""
    span = float(np.linalg.norm(np.ptp(points, axis=0))) if len(points) else 0.0
    return "mm" if span > _MM_IF_LARGER_THAN else "m"


def _scale(points: np.ndarray, units: str, path, on_mismatch: str = "warn") -> np.ndarray:
    if units not in ("m", "mm", "auto"):
        raise ValueError(f"units must be 'm', 'mm' or 'auto', got {units!r}")
    if on_mismatch not in ("warn", "raise", "ignore"):
        raise ValueError(f"on_units_mismatch must be 'warn', 'raise' or 'ignore', got {on_mismatch!r}")
    guessed = guess_units(points)
    span = float(np.linalg.norm(np.ptp(points, axis=0))) if len(points) else 0.0
    message = None
    if units == "auto":
        units = guessed
    elif units == "m" and guessed == "mm":
        message = (f"{path}: the coordinates span {span:.4g} units, which as metres is larger than any "
                   "fabric part; the file is probably in mm (pass units='mm' or 'auto')")
    elif units == "mm" and span < 0.5:
        message = (f"{path}: the coordinates span only {span:.4g} units, which as millimetres is tiny; "
                   "the file is probably in m (pass units='m' or 'auto')")
    if message and on_mismatch == "raise":
        raise ValueError(message)
    if message and on_mismatch == "warn":
        warnings.warn(message, UnitsWarning, stacklevel=3)
    return points * (1e-3 if units == "mm" else 1.0)


def _meshio_read(path: pathlib.Path):
    """``meshio.read`` with every failure (meshio even calls ``sys.exit`` on a corrupt VTU) turned
    into a ValueError naming the file."""
    import contextlib
    import io

    import meshio

    if path.is_dir():
        raise ValueError(f"{path} is a directory, not a mesh file")
    if path.stat().st_size == 0:
        raise ValueError(f"{path} is empty (0 bytes): not a mesh; export the surface again")
    chatter = io.StringIO()
    try:
        with contextlib.redirect_stdout(chatter), contextlib.redirect_stderr(chatter):
            return meshio.read(path)
    except (Exception, SystemExit) as err:  # meshio raises many kinds; say which file and why
        said = " ".join(chatter.getvalue().split())
        why = str(err) if not isinstance(err, SystemExit) else ""
        why = "; ".join(filter(None, [said, why])) or type(err).__name__
        raise ValueError(f"could not read {path} as a surface mesh: {why} (a corrupt, truncated or "
                         "empty file, or not a format meshio reads: VTU/VTK, Abaqus .inp, OBJ, PLY, STL...)") from None


def read_surface(path, *, units: str = "m", triangulate: bool = False, on_units_mismatch: str = "warn",
                 point_data: bool = False):
    """Read a surface mesh.

    Args:
      path: any file meshio reads (VTU/VTK, Abaqus .inp, OBJ, PLY, STL, ...).
      units: units of the file's coordinates: 'm', 'mm', or 'auto' (mm when the mesh is more
        than 5 units across).
      triangulate: return triangles only (quads split along their 0-2 diagonal).
      on_units_mismatch: what a size at odds with the given units does: 'warn'
        (:class:`UnitsWarning`, the default), 'raise' (ValueError) or 'ignore'.
      point_data: also return the file's point data (name -> (N, ...) array, renumbered like the nodes).

    Returns:
      nodes: (N, 3) float64, m (only nodes used by a face, renumbered);
      faces: (F, 4) int64 if every face is a quad, else (F, 3) int64 (quads split);
      with ``point_data=True`` a third item, the dict of point data.

    Raises:
      FileNotFoundError; ValueError, naming the file, for an empty or unreadable file, a file with
      no points, no cells or no surface cells (e.g. only volume cells), or non-finite coordinates.
    """
    path = pathlib.Path(path)
    if not path.exists():
        raise FileNotFoundError(f"no such mesh file: {path}")
    mesh = _meshio_read(path)
    pts = np.asarray(mesh.points, dtype=np.float64)
    if pts.size == 0:
        raise ValueError(f"{path} has no points: an empty mesh (export the surface again)")
    if pts.ndim != 2 or pts.shape[1] not in (2, 3):
        raise ValueError(f"{path}: points have shape {pts.shape}, expected (N, 3)")
    if pts.shape[1] == 2:
        pts = np.column_stack([pts, np.zeros(len(pts))])
    if not any(len(block.data) for block in mesh.cells):
        raise ValueError(f"{path} has {len(pts)} points but no cells: a point cloud, not a surface mesh "
                         "(export the faces too; measured points go to --cloud)")
    tris, quads, skipped = [], [], set()
    for block in mesh.cells:
        if block.type in _TRI:
            tris.append(np.asarray(block.data)[:, :3])
        elif block.type in _QUAD:
            quads.append(np.asarray(block.data)[:, :4])
        elif block.type == "polygon" or block.type.startswith("polygon"):
            data = np.asarray(block.data)
            for k in range(1, data.shape[1] - 1):  # fan triangulation
                tris.append(data[:, [0, k, k + 1]])
        else:
            skipped.add(block.type)
    tris = [t for t in tris if len(t)]
    quads = [q for q in quads if len(q)]
    if not tris and not quads:
        kinds = ", ".join(sorted(skipped)) or "none"
        hint = " (a volume mesh: extract its surface first)" if skipped & _VOLUME else ""
        raise ValueError(f"{path} has no surface cells: no triangle or quad faces (cell types: {kinds}){hint}")
    if quads and not tris and not triangulate:
        faces = np.concatenate(quads)
    else:
        q = np.concatenate(quads) if quads else np.zeros((0, 4), np.int64)
        faces = np.concatenate(tris + [q[:, [0, 1, 2]], q[:, [0, 2, 3]]])
    faces = faces.astype(np.int64)
    if faces.min() < 0 or faces.max() >= len(pts):
        raise ValueError(f"{path}: faces refer to nodes {faces.min()}..{faces.max()} but there are {len(pts)} points")
    used = np.unique(faces)
    data = {k: np.asarray(v) for k, v in mesh.point_data.items()} if point_data else {}
    if len(used) < len(pts):
        remap = -np.ones(len(pts), np.int64)
        remap[used] = np.arange(len(used))
        faces = remap[faces]
        pts = pts[used]
        data = {k: v[used] for k, v in data.items()}
    bad = ~np.isfinite(pts).all(axis=1)
    if bad.any():
        raise ValueError(f"{path}: {int(bad.sum())} nodes have non-finite (NaN/inf) coordinates")
    nodes = _scale(pts, units, path, on_units_mismatch)
    return (nodes, faces, data) if point_data else (nodes, faces)


def read_point_cloud(path, *, units: str = "m", on_units_mismatch: str = "warn"):
    """Read measured points: PLY (vertices), XYZ (whitespace columns x y z ...) or CSV (columns
    x, y, z by header name, else the first three). Returns (P, 3) float64 in m (see
    :func:`read_surface` for ``units`` and ``on_units_mismatch``). Rows with non-finite values are
    dropped with a warning."""
    path = pathlib.Path(path)
    if not path.exists():
        raise FileNotFoundError(f"no such point-cloud file: {path}")
    suffix = path.suffix.lower()
    if suffix == ".ply" or suffix in (".vtu", ".vtk", ".obj", ".stl"):
        pts = np.asarray(_meshio_read(path).points, dtype=np.float64)
    elif suffix in (".xyz", ".txt", ".pts", ".asc"):
        pts = np.loadtxt(path, comments=("#", "//"), ndmin=2)[:, :3]
    elif suffix == ".csv":
        with open(path) as fh:
            first = fh.readline()
        has_header = any(c.isalpha() for c in first.replace("e-", "").replace("e+", "").replace("E", ""))
        if has_header:
            names = [c.strip().lower() for c in first.split(",")]
            data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
            cols = []
            for key in ("x", "y", "z"):
                match = [i for i, nme in enumerate(names) if nme == key or nme.startswith(key + "_")
                         or nme.startswith(key + " ")]
                cols.append(match[0] if match else None)
            pts = data[:, cols] if None not in cols else data[:, :3]
        else:
            pts = np.loadtxt(path, delimiter=",", ndmin=2)[:, :3]
    else:
        raise ValueError(f"unknown point-cloud format {suffix!r}: use .ply, .xyz or .csv")
    if pts.ndim != 2 or pts.shape[1] < 3 or len(pts) == 0:
        raise ValueError(f"{path}: no 3D points found")
    bad = ~np.isfinite(pts).all(axis=1)
    if bad.any():
        warnings.warn(f"{path}: dropped {int(bad.sum())} points with non-finite coordinates",
                      UserWarning, stacklevel=2)
        pts = pts[~bad]
    return _scale(pts[:, :3].astype(np.float64), units, path, on_units_mismatch)


def write_vtu(path, nodes, faces=None, *, point_data=None, cell_data=None) -> pathlib.Path:
    """Write a surface (or, with ``faces=None``, a point cloud) to VTU for ParaView.

    Args:
      nodes: (N, 3) m. faces: (F, 3) or (F, 4) int, or None for vertex cells.
      point_data: name -> (N,) or (N, k) arrays. cell_data: name -> (F,) arrays.
    """
    import meshio

    nodes = np.asarray(nodes, dtype=np.float64)
    if faces is None:
        cells = [("vertex", np.arange(len(nodes)).reshape(-1, 1))]
    else:
        f = np.asarray(faces)
        cells = [("quad" if f.shape[1] == 4 else "triangle", f.astype(np.int64))]
    pd = {k: np.asarray(v) for k, v in (point_data or {}).items()}
    cd = {k: [np.asarray(v)] for k, v in (cell_data or {}).items()}
    path = pathlib.Path(path)
    meshio.write(path, meshio.Mesh(nodes, cells, point_data=pd, cell_data=cd))
    return path
