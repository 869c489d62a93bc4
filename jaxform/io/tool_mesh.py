"""Tools given as triangle mesh files (STL/OBJ/PLY via trimesh), turned into a :class:`GridSDF`.

Host side: reading, unit conversion and validation happen here, once; the sampled field is then a
pure-JAX, differentiable :class:`jaxform.tools.GridSDF`.

Accuracy. The field is sampled exactly (point–triangle distances, pseudo-normal sign)
at the grid nodes and interpolated trilinearly in between. Against the smooth surface the mesh
stands for, the error near the surface is the mesh's chordal error (``R (1 - cos(pi / n))`` for a
curve of radius ``R`` cut into ``n`` segments per half turn) plus the interpolation error,
about ``cell**2 / (8 R)`` for a surface of curvature radius ``R`` (0.04 mm for 4 mm cells on the
50 mm punch). ``tests/test_tools.py`` checks a capsule mesh against the analytic punch.

Cost. Sampling uses the certified cluster search of :mod:`jaxform.geometry` (a few hundred
point-triangle tests per grid point; more for points deep inside a solid, near its medial axis).
Keep the box tight around the part of the tool the fabric can touch and the cell about the element
size.

:func:`hemisphere_rig_mesh` meshes the wrinkle metric's analytic hemisphere rig (for plots and
files).
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from jaxform import units
from jaxform.geometry import build_triangle_index, closest_point_on_mesh
from jaxform.tools import STILL, GridSDF

_UNITS = {"m": 1.0, "mm": units.MM, "cm": 1.0e-2, "in": 0.0254}


def load_tool_mesh(path, *, units: str = "mm", require_watertight: bool = True):
    """Read a tool surface mesh and return ``(vertices (V, 3) m, faces (F, 3) int64)``.

    Args:
        path: an STL, OBJ or PLY file.
        units: length unit of the file's coordinates: ``"m"``, ``"mm"`` (default, CAD habit),
            ``"cm"`` or ``"in"``.
        require_watertight: refuse meshes that are not closed (the sign of the distance needs an
            inside); set False only for nearly closed meshes (the winding number tolerates holes).

    Raises:
        FileNotFoundError, ValueError: missing file, unknown unit, empty/non-triangle mesh, a mesh
            that is not watertight, or a size that suggests the wrong ``units``.
    """
    import trimesh

    path = Path(path)
    if not path.is_file():
        raise FileNotFoundError(f"tool mesh {str(path)!r}: no such file")
    if units not in _UNITS:
        raise ValueError(f"tool mesh units = {units!r}: must be one of {', '.join(_UNITS)}")
    if path.suffix.lower() not in (".stl", ".obj", ".ply"):
        raise ValueError(f"tool mesh {str(path)!r}: unsupported format {path.suffix!r} (use STL, OBJ or PLY)")
    mesh = trimesh.load(path, force="mesh", process=True)
    return _checked(mesh, str(path), _UNITS[units], require_watertight)


def mesh_arrays(mesh, *, units: str = "m", require_watertight: bool = True):
    """``(vertices m, faces)`` from an in-memory ``trimesh.Trimesh``, validated like a file."""
    if units not in _UNITS:
        raise ValueError(f"tool mesh units = {units!r}: must be one of {', '.join(_UNITS)}")
    return _checked(mesh, "trimesh", _UNITS[units], require_watertight)


def _checked(mesh, where, scale, require_watertight):
    faces = np.asarray(getattr(mesh, "faces", np.zeros((0, 3))), dtype=np.int64)
    vertices = np.asarray(getattr(mesh, "vertices", np.zeros((0, 3))), dtype=np.float64) * scale
    if faces.ndim != 2 or faces.shape[0] == 0 or faces.shape[1] != 3:
        raise ValueError(f"tool mesh {where}: no triangles found")
    if not np.all(np.isfinite(vertices)):
        raise ValueError(f"tool mesh {where}: non-finite vertex coordinates")
    if require_watertight and not mesh.is_watertight:
        raise ValueError(
            f"tool mesh {where}: not watertight (open edges); close the solid (e.g. trimesh "
            "fill_holes) or pass require_watertight=False"
        )
    size = float(np.max(np.ptp(vertices, axis=0)))
    if not 1.0e-3 <= size <= 10.0:
        raise ValueError(
            f"tool mesh {where}: largest extent {size:.3g} m after unit conversion; a forming tool "
            "is between 1 mm and 10 m (wrong units= option?)"
        )
    if require_watertight and mesh.volume < 0:  # inward-oriented: flip so normals point out
        faces = faces[:, ::-1].copy()
    return vertices, faces


def grid_sdf_from_mesh(vertices, faces, *, cell: float, lo=None, hi=None, padding: float | None = None,
                       motion=STILL) -> GridSDF:
    """Sample the signed distance of a closed triangle mesh on a regular grid.

    Method: for each grid point the closest point of the mesh is found by the certified search of
    :func:`jaxform.geometry.closest_point_on_mesh` (exact for every point). The sign is that of
    ``(p - q) . N`` with ``N`` the angle-weighted pseudo-normal of the closest feature (face, edge
    or vertex: Baerentzen & Aanaes), exact for a closed, consistently oriented mesh.

    Args:
        vertices: (V, 3) m; faces: (F, 3) int, closed and outward oriented (see
            :func:`load_tool_mesh`).
        cell: grid step, m (the user's resolution; about the fabric element size).
        lo, hi: (3,) corners of the sampled box, m; default: the mesh's bounding box grown by
            ``padding`` (default ``4 * cell``).
        motion: the tool's :class:`jaxform.tools.VerticalMotion`.

    Returns:
        :class:`jaxform.tools.GridSDF` with ``phi`` (nx, ny, nz) m and ``grad`` (nx, ny, nz, 3).
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    if not (isinstance(cell, (int, float)) and cell > 0 and math.isfinite(cell)):
        raise ValueError(f"grid_sdf_from_mesh: cell = {cell!r}: must be > 0 (m)")
    pad = 4.0 * cell if padding is None else float(padding)
    lo = vertices.min(axis=0) - pad if lo is None else np.asarray(lo, dtype=np.float64)
    hi = vertices.max(axis=0) + pad if hi is None else np.asarray(hi, dtype=np.float64)
    if lo.shape != (3,) or hi.shape != (3,) or np.any(hi <= lo):
        raise ValueError(f"grid_sdf_from_mesh: empty box lo = {lo}, hi = {hi} (m)")
    shape = tuple(int(math.ceil((h - l) / cell - 1e-9)) + 1 for l, h in zip(lo, hi))
    axes = [l + cell * np.arange(n) for l, n in zip(lo, shape)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    phi, grad = signed_distance(vertices, faces, grid)
    return GridSDF(
        phi=phi.reshape(shape),
        grad=grad.reshape(shape + (3,)),
        origin=lo,
        spacing=np.full(3, float(cell)),
        motion=motion,
    )


def signed_distance(vertices, faces, points, *, index=None):
    """Signed distance (N,) m and unit gradient (N, 3) of a closed mesh at ``points`` (N, 3), host side.

    See :func:`grid_sdf_from_mesh` for the method. ``index``: the mesh's
    :class:`jaxform.geometry.TriangleIndex` when the caller already has one (built here otherwise).
    """
    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    points = np.asarray(points, dtype=np.float64)
    if index is None:
        index = build_triangle_index(vertices, faces)
    q, w, ids = (np.asarray(a) for a in closest_point_on_mesh(points, index))
    qd = points - q
    dmin = np.sqrt(np.sum(qd * qd, axis=1))
    pseudo = _feature_pseudo_normals(vertices, faces)(ids, w)
    sign = np.where(np.sum(qd * pseudo, axis=1) < 0, -1.0, 1.0)
    scale = float(np.max(np.ptp(vertices, axis=0)))
    on_surface = dmin <= 1e-12 * max(scale, 1.0)
    pn = pseudo / np.maximum(np.linalg.norm(pseudo, axis=1, keepdims=True), 1e-300)
    grad = np.where(on_surface[:, None], pn, sign[:, None] * qd / np.maximum(dmin, 1e-300)[:, None])
    return sign * dmin, grad


def _feature_pseudo_normals(vertices, faces):
    """The angle-weighted pseudo-normal of the closest feature (Baerentzen & Aanaes).

    Returns a function of the closest triangle ids (N,) and barycentric weights (N, 3): the
    face normal inside a face, the sum of the two face normals on an edge, the angle-weighted sum
    of the face normals around a vertex (the weights are exactly one-hot / zero in the vertex and
    edge regions of :func:`jaxform.geometry.closest_point_triangle`)."""
    A, B, C = vertices[faces[:, 0]], vertices[faces[:, 1]], vertices[faces[:, 2]]
    nrm = np.cross(B - A, C - A)
    nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-300)
    ang = np.stack([_angle(B - A, C - A), _angle(C - B, A - B), _angle(A - C, B - C)], axis=1)
    vertex_n = np.zeros_like(vertices)
    for j in range(3):
        np.add.at(vertex_n, faces[:, j], ang[:, j, None] * nrm)
    # Edge j of a face is the one opposite corner j; both faces of an edge add their normal.
    opposite = np.stack([faces[:, [1, 2]], faces[:, [2, 0]], faces[:, [0, 1]]], axis=1)  # (F, 3, 2)
    keys = np.sort(opposite, axis=-1).reshape(-1, 2)
    _, edge_id = np.unique(keys, axis=0, return_inverse=True)
    edge_id = edge_id.reshape(-1)
    edge_n = np.zeros((edge_id.max() + 1, 3))
    np.add.at(edge_n, edge_id, np.repeat(nrm, 3, axis=0))
    edge_id = edge_id.reshape(-1, 3)

    def pseudo(ids, w):
        corner = np.argmax(w, axis=1)
        gone = np.argmin(w, axis=1)
        at_vertex = np.max(w, axis=1) == 1.0
        on_edge = ~at_vertex & (np.min(w, axis=1) == 0.0)
        out = nrm[ids]
        out = np.where(on_edge[:, None], edge_n[edge_id[ids, gone]], out)
        return np.where(at_vertex[:, None], vertex_n[faces[ids, corner]], out)

    return pseudo


def _angle(u, v):
    cos = np.sum(u * v, axis=1) / np.maximum(np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1), 1e-300)
    return np.arccos(np.clip(cos, -1.0, 1.0))


def load_tool_sdf(path, *, cell: float, units: str = "mm", padding: float | None = None, lo=None, hi=None,
                  motion=STILL, require_watertight: bool = True) -> GridSDF:
    """Read a tool mesh file and sample it into a :class:`GridSDF` (see :func:`grid_sdf_from_mesh`)."""
    vertices, faces = load_tool_mesh(path, units=units, require_watertight=require_watertight)
    return grid_sdf_from_mesh(vertices, faces, cell=cell, lo=lo, hi=hi, padding=padding, motion=motion)


def hemisphere_rig_mesh(radius: float = 0.05, center=(0.0, 0.0, 0.0), size: float = 0.002,
                        extent: float | None = None, base_plane: bool = True):
    """A triangle mesh of :func:`jaxform.tools.hemisphere_rig` for plots and files (numpy).

    Args:
        radius: hemisphere radius, m; center: (3,) sphere centre on the base plane, m.
        size: target edge length, m.
        extent: outer radius of the base-plane annulus, m (default 2.5 ``radius``).
        base_plane: mesh the base plane too.

    Returns:
        ``(vertices (V, 3) m, faces (F, 3) int64)``.
    """
    radius = float(radius)
    center = np.asarray(center, dtype=np.float64)
    extent = 2.5 * radius if extent is None else float(extent)
    # Cap: rings of latitude from the pole to the equator.
    n_lat = max(2, int(np.ceil(0.5 * np.pi * radius / size)))
    verts = [center + [0, 0, radius]]
    faces = []
    prev = [0]
    for i in range(1, n_lat + 1):
        th = 0.5 * np.pi * i / n_lat
        n_ring = max(6, int(np.ceil(2 * np.pi * radius * np.sin(th) / size)))
        phi = 2 * np.pi * np.arange(n_ring) / n_ring
        start = len(verts)
        verts.extend(center + np.stack([radius * np.sin(th) * np.cos(phi),
                                        radius * np.sin(th) * np.sin(phi),
                                        np.full(n_ring, radius * np.cos(th))], 1))
        cur = list(range(start, start + n_ring))
        faces.extend(_stitch(prev, cur))
        prev = cur
    verts = np.asarray(verts)
    faces = np.asarray(faces, np.int64)
    if not base_plane:
        return verts, faces
    # Base plane: an annulus from the equator out to radius ``extent``, ring by ring.
    rim = prev
    n_ring = len(rim)
    phi = 2 * np.pi * np.arange(n_ring) / n_ring
    all_v = [verts]
    n0 = len(verts)
    for r in np.linspace(radius, extent, max(2, int(np.ceil((extent - radius) / size)) + 1))[1:]:
        all_v.append(center + np.stack([r * np.cos(phi), r * np.sin(phi), np.zeros(n_ring)], 1))
        idx = list(range(n0, n0 + n_ring))
        n0 += n_ring
        faces = np.concatenate([faces, np.asarray(_stitch(rim, idx), np.int64)])
        rim = idx
    return np.concatenate(all_v), faces


def _stitch(inner, outer):
    """Triangles between two closed rings (counter-clockwise seen from +z on the cap)."""
    tris = []
    ni, no = len(inner), len(outer)
    i = j = 0
    while i < ni or j < no:
        a_i, a_o = inner[i % ni], outer[j % no]
        if ni == 1:
            tris.append([a_i, a_o, outer[(j + 1) % no]])
            j += 1
            if j >= no:
                break
            continue
        # advance along whichever ring is behind in angle
        if j >= no or (i < ni and (i + 1) / ni < (j + 1) / no):
            tris.append([a_i, a_o, inner[(i + 1) % ni]])
            i += 1
        else:
            tris.append([a_i, a_o, outer[(j + 1) % no]])
            j += 1
    return tris


__all__ = ["load_tool_mesh", "mesh_arrays", "grid_sdf_from_mesh", "signed_distance", "load_tool_sdf",
           "hemisphere_rig_mesh"]
