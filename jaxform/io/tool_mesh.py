"""Tools given as triangle mesh files (STL/OBJ/PLY via trimesh), turned into a :class:`GridSDF`.

Host side: reading, unit conversion and validation happen here, once; the sampled field is then a
pure-JAX, differentiable :class:`jaxform.tools.GridSDF`.

Accuracy. The field is sampled exactly (point–triangle distances, pseudo-normal sign)
at the grid nodes and interpolated trilinearly in between. Against the smooth surface the mesh
stands for, the error near the surface is the mesh's chordal error (``R (1 - cos(pi / n))`` for a
curve of radius ``R`` cut into ``n`` segments per half turn) plus the interpolation error,
about ``cell**2 / (8 R)`` for a surface of curvature radius ``R`` (0.04 mm for 4 mm cells on the
50 mm punch). ``tests/test_tools.py`` checks a capsule mesh against the analytic punch.

Cost. Sampling uses a k-d tree over the (subdivided) triangles, ``O(grid points x k)``: about a
second per 1e5 grid points on a CPU. Keep the box tight around the part of the tool the fabric
can touch and the cell about the element size.
"""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from jaxform import units
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
                       motion=STILL, k: int = 24) -> GridSDF:
    """Sample the signed distance of a closed triangle mesh on a regular grid.

    Method: the mesh is first subdivided (watertight, no T-junctions) until every edge is shorter
    than ``cell``; for each grid point the ``k`` triangles with the nearest centroids (k-d tree) are
    searched exactly (:func:`jaxform.tools.closest_point_triangle`). The result is *certified exact*
    where the k-th centroid is farther than the distance found plus the largest triangle radius;
    uncertified points within ``3 * cell`` of the surface are searched again with ``8 k``
    candidates; elsewhere the error is at most the largest triangle radius (< ``cell``). The sign is
    that of ``(p - q) . N`` with ``N`` the angle-weighted pseudo-normal of the closest feature
    (face, edge or vertex: Baerentzen & Aanaes), exact for a closed, consistently oriented mesh.

    Args:
        vertices: (V, 3) m; faces: (F, 3) int, closed and outward oriented (see
            :func:`load_tool_mesh`).
        cell: grid step, m (the user's resolution; about the fabric element size).
        lo, hi: (3,) corners of the sampled box, m; default: the mesh's bounding box grown by
            ``padding`` (default ``4 * cell``).
        motion: the tool's :class:`jaxform.tools.VerticalMotion`.
        k: candidate triangles per point.

    Returns:
        :class:`jaxform.tools.GridSDF` with ``phi`` (nx, ny, nz) m and ``grad`` (nx, ny, nz, 3).
    """
    import trimesh

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
    v, f = trimesh.remesh.subdivide_to_size(vertices, faces, max_edge=cell, max_iter=30)
    phi, grad = signed_distance(np.asarray(v), np.asarray(f), grid, k=k, band=3.0 * cell)
    return GridSDF(
        phi=phi.reshape(shape),
        grad=grad.reshape(shape + (3,)),
        origin=lo,
        spacing=np.full(3, float(cell)),
        motion=motion,
    )


_CLOSEST = None


def _closest_candidates(points, A, B, C, idx, step: int = 8192):
    """Closest points ``q`` (N, k, 3) and barycentric weights (N, k, 3) on candidate triangles."""
    global _CLOSEST
    import jax
    import jax.numpy as jnp

    from jaxform.tools import closest_point_triangle

    if _CLOSEST is None:
        _CLOSEST = jax.jit(jax.vmap(jax.vmap(closest_point_triangle, in_axes=(None, 0, 0, 0))))
    n = points.shape[0]
    step = min(step, n)
    out_q, out_w = [], []
    for s in range(0, n, step):
        i = idx[s:s + step]
        p = points[s:s + step]
        m = len(p)
        if m < step:  # pad to a fixed chunk shape: one compilation
            p = np.concatenate([p, np.repeat(p[-1:], step - m, 0)])
            i = np.concatenate([i, np.repeat(i[-1:], step - m, 0)])
        q, w = _CLOSEST(jnp.asarray(p), jnp.asarray(A[i]), jnp.asarray(B[i]), jnp.asarray(C[i]))
        out_q.append(np.asarray(q)[:m])
        out_w.append(np.asarray(w)[:m])
    return np.concatenate(out_q), np.concatenate(out_w)


def signed_distance(vertices, faces, points, *, k: int = 24, band: float = 0.0):
    """Signed distance (N,) m and unit gradient (N, 3) of a closed mesh at ``points`` (N, 3), host side.

    See :func:`grid_sdf_from_mesh` for the method and its guarantees (``band``: distance within
    which uncertified points get a wider search).
    """
    from scipy.spatial import cKDTree

    vertices = np.asarray(vertices, dtype=np.float64)
    faces = np.asarray(faces, dtype=np.int64)
    points = np.asarray(points, dtype=np.float64)
    A, B, C = vertices[faces[:, 0]], vertices[faces[:, 1]], vertices[faces[:, 2]]
    nrm = np.cross(B - A, C - A)
    nrm /= np.maximum(np.linalg.norm(nrm, axis=1, keepdims=True), 1e-300)
    ang = np.stack([_angle(B - A, C - A), _angle(C - B, A - B), _angle(A - C, B - C)], axis=1)
    cen = (A + B + C) / 3.0
    rad = np.max(np.linalg.norm(np.stack([A, B, C]) - cen, axis=-1), axis=0)
    tree = cKDTree(cen)
    nf = faces.shape[0]

    def search(pts, kk):
        kk = int(min(kk, nf))
        dc, idx = tree.query(pts, k=kk)
        dc, idx = dc.reshape(len(pts), kk), idx.reshape(len(pts), kk)
        q, w = _closest_candidates(pts, A, B, C, idx)
        d = np.linalg.norm(q - pts[:, None, :], axis=-1)
        best = np.argmin(d, axis=1)
        dmin = d[np.arange(len(pts)), best]
        certified = (kk == nf) | (dc[:, -1] >= dmin + rad.max())
        return idx, q, w, d, best, dmin, certified

    idx, q, w, d, best, dmin, ok = search(points, k)
    redo = np.flatnonzero(~ok & (dmin < band))
    if redo.size:
        r = search(points[redo], 8 * k)
        kk = r[0].shape[1]
        pad = lambda a, fill: np.concatenate([a, np.full(a.shape[:1] + (kk - a.shape[1],) + a.shape[2:], fill, a.dtype)], 1)
        idx, d = pad(idx, 0), pad(d, np.inf)
        q, w = pad(q, 0.0), pad(w, 0.0)
        idx[redo], q[redo], w[redo], d[redo], best[redo], dmin[redo] = r[:6]
    n = len(points)
    scale = float(np.max(np.ptp(vertices, axis=0)))
    qb = q[np.arange(n), best]
    # The closest *feature* may be shared by several triangles (an edge, a vertex): those whose
    # closest point is the same point. (Equal distances to different points, on the medial axis,
    # are not ties.)
    tie = np.linalg.norm(q - qb[:, None, :], axis=-1) <= 1e-9 * scale
    corner = np.argmax(w, axis=-1)
    at_vertex = np.max(w, axis=-1) > 1.0 - 1e-9
    weight = np.where(at_vertex, ang[idx, corner], 1.0) * tie
    pseudo = np.sum(weight[..., None] * nrm[idx], axis=1)
    diff = points - qb
    sign = np.where(np.sum(diff * pseudo, axis=1) < 0, -1.0, 1.0)
    on_surface = dmin <= 1e-12 * max(scale, 1.0)
    pn = pseudo / np.maximum(np.linalg.norm(pseudo, axis=1, keepdims=True), 1e-300)
    grad = np.where(on_surface[:, None], pn, sign[:, None] * diff / np.maximum(dmin, 1e-300)[:, None])
    return sign * dmin, grad


def _angle(u, v):
    cos = np.sum(u * v, axis=1) / np.maximum(np.linalg.norm(u, axis=1) * np.linalg.norm(v, axis=1), 1e-300)
    return np.arccos(np.clip(cos, -1.0, 1.0))


def load_tool_sdf(path, *, cell: float, units: str = "mm", padding: float | None = None, lo=None, hi=None,
                  motion=STILL, require_watertight: bool = True) -> GridSDF:
    """Read a tool mesh file and sample it into a :class:`GridSDF` (see :func:`grid_sdf_from_mesh`)."""
    vertices, faces = load_tool_mesh(path, units=units, require_watertight=require_watertight)
    return grid_sdf_from_mesh(vertices, faces, cell=cell, lo=lo, hi=hi, padding=padding, motion=motion)


__all__ = ["load_tool_mesh", "mesh_arrays", "grid_sdf_from_mesh", "signed_distance", "load_tool_sdf"]
