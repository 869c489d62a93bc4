"""Exact test of a surface mesh for triangles that pass through each other (issue 19).

A fold must lie on itself, not through itself: :func:`intersecting_pairs` lists every pair of
faces of a mesh (triangles, or quads split along their 0-2 diagonal) that cross each other.

Method (host side, vectorised numpy; not differentiated):

* broad phase: a k-d tree of the face centroids (``scipy.spatial.cKDTree.query_pairs``) with the
  radius ``2 R``, ``R`` the largest centroid-to-corner distance, gives every pair of faces whose
  bounding spheres meet; their bounding boxes then filter the pairs;
* narrow phase: two non-coplanar triangles intersect if and only if an edge of one crosses the
  other (the end points of the intersection segment lie on edges). An edge crosses a triangle
  when its two ends lie strictly on opposite sides of the triangle's plane and the line passes
  strictly inside the three edges (signed volumes, Moller & Trumbore / Shewchuk's orientation
  predicates, with a relative tolerance). Touching (a layer lying *on* another at any distance,
  down to zero) is not an intersection;
* neighbours: faces sharing an edge are never counted (they meet along it by construction);
  faces sharing one corner ``v`` are counted only when the edge opposite ``v`` of one crosses the
  other (the only way two such triangles can cross beyond ``v``); the two halves of a quad are
  one face.

Coplanar overlaps (two layers exactly in one plane) are not detected: they have measure zero in
a simulation and no side to be on.
"""
from __future__ import annotations

import numpy as np

__all__ = ["triangulate", "candidate_pairs", "segments_cross_triangles", "intersecting_pairs"]

_REL_TOL = 1e-12  # signed volumes below this times the edge length cubed count as zero


def triangulate(faces) -> tuple[np.ndarray, np.ndarray]:
    """``(tris (T, 3) int64, owner (T,) int64)``: triangles of (F, 3) or (F, 4) faces (quads split
    along 0-2) and the face each came from."""
    faces = np.asarray(faces, np.int64)
    if faces.ndim != 2 or faces.shape[1] not in (3, 4):
        raise ValueError(f"faces of shape {faces.shape}: need (F, 3) triangles or (F, 4) quads")
    ids = np.arange(len(faces))
    if faces.shape[1] == 3:
        return faces, ids
    return np.concatenate([faces[:, [0, 1, 2]], faces[:, [0, 2, 3]]]), np.concatenate([ids, ids])


def candidate_pairs(p: np.ndarray) -> np.ndarray:
    """(P, 2) int64 pairs ``i < j`` of triangles ``p`` (T, 3, 3) whose bounding boxes overlap."""
    from scipy.spatial import cKDTree

    if len(p) < 2:
        return np.zeros((0, 2), np.int64)
    cen = p.mean(axis=1)
    rad = float(np.sqrt(np.max(np.sum((p - cen[:, None]) ** 2, axis=-1))))
    pairs = cKDTree(cen).query_pairs(2.0 * rad * (1.0 + 1e-9), output_type="ndarray").astype(np.int64)
    lo, hi = p.min(axis=1), p.max(axis=1)
    i, j = pairs[:, 0], pairs[:, 1]
    keep = np.all((lo[i] <= hi[j]) & (lo[j] <= hi[i]), axis=1)
    return pairs[keep]


def _orient(a, b, c, d):
    """Signed volume ``det[b - a, c - a, d - a]`` (...) of (..., 3) points."""
    return np.einsum("...i,...i->...", np.cross(b - a, c - a), d - a)


def segments_cross_triangles(s0, s1, a, b, c) -> np.ndarray:
    """(...) bool: the segment ``s0 s1`` passes strictly through the triangle ``abc`` ((..., 3) each).

    Both ends strictly on opposite sides of the plane, and the line strictly inside the three
    edges (same sign of the three signed volumes ``(s0, s1, edge)``). Zero (within a tolerance
    relative to the size) counts as touching, not crossing.
    """
    scale = np.maximum.reduce([np.abs(x).max(axis=-1) for x in (s1 - s0, b - a, c - a)]) + 1e-300
    tol = _REL_TOL * scale**3
    d0, d1 = _orient(a, b, c, s0), _orient(a, b, c, s1)
    opposite = ((d0 > tol) & (d1 < -tol)) | ((d0 < -tol) & (d1 > tol))
    e0, e1, e2 = _orient(s0, s1, a, b), _orient(s0, s1, b, c), _orient(s0, s1, c, a)
    inside = ((e0 > tol) & (e1 > tol) & (e2 > tol)) | ((e0 < -tol) & (e1 < -tol) & (e2 < -tol))
    return opposite & inside


def _cross_pairs(p, q, ea, eb):
    """Any edge of triangles ``p`` (edges selected by ``ea`` (P, 3) bool) through ``q``, or the
    other way round (``eb``)."""
    hit = np.zeros(len(p), bool)
    for k in range(3):
        u, w = p[:, k], p[:, (k + 1) % 3]
        hit |= ea[:, k] & segments_cross_triangles(u, w, q[:, 0], q[:, 1], q[:, 2])
        u, w = q[:, k], q[:, (k + 1) % 3]
        hit |= eb[:, k] & segments_cross_triangles(u, w, p[:, 0], p[:, 1], p[:, 2])
    return hit


def intersecting_pairs(nodes, faces, *, triangles=None, chunk: int = 200_000) -> np.ndarray:
    """Pairs of faces of a mesh that pass through each other.

    Args:
        nodes: (N, 3) node positions (any length unit: the test is scale-free).
        faces: (F, 3) triangles or (F, 4) quads (split along their 0-2 diagonal), int.
        triangles: optional (2F, 3) int the quads' own split, quad ``q`` into triangles ``2q`` and
            ``2q + 1`` (a warped quad is two different surfaces split one way or the other: give
            the split the solver used, e.g. :func:`jaxform.forming.rig.grid_triangles`).
        chunk: candidate pairs tested at a time (memory).

    Returns:
        (P, 2) int64 face indices ``i < j``, sorted, each pair once.
    """
    x = np.asarray(nodes, np.float64)
    if x.ndim != 2 or x.shape[1] != 3:
        raise ValueError(f"nodes of shape {x.shape}: need (N, 3)")
    if triangles is None:
        tris, owner = triangulate(faces)
    else:
        tris = np.asarray(triangles, np.int64)
        if np.shape(faces)[1] != 4 or tris.shape != (2 * len(faces), 3):
            raise ValueError(f"triangles of shape {tris.shape} for faces of shape {np.shape(faces)}: need (2F, 3) for quads")
        owner = np.arange(len(tris)) // 2
    if len(tris) and (tris.min() < 0 or tris.max() >= len(x)):
        raise ValueError(f"faces refer to nodes {tris.min()}..{tris.max()} but there are {len(x)} nodes")
    p = x[tris]
    pairs = candidate_pairs(p)
    pairs = pairs[owner[pairs[:, 0]] != owner[pairs[:, 1]]]
    found = []
    for s in range(0, len(pairs), chunk):
        i, j = pairs[s:s + chunk, 0], pairs[s:s + chunk, 1]
        ti, tj = tris[i], tris[j]
        same = ti[:, :, None] == tj[:, None, :]  # (P, 3, 3) corner k of i is corner l of j
        shared = same.sum(axis=(1, 2))
        in_i, in_j = same.any(axis=2), same.any(axis=1)  # (P, 3) corner shared
        # edge k (corner k -> k+1) is tested unless it touches a shared corner
        ea = ~(in_i | np.roll(in_i, -1, axis=1))
        eb = ~(in_j | np.roll(in_j, -1, axis=1))
        test = shared <= 1
        hit = np.zeros(len(i), bool)
        hit[test] = _cross_pairs(p[i[test]], p[j[test]], ea[test], eb[test])
        found.append(np.stack([owner[i[hit]], owner[j[hit]]], axis=1))
    if not found:
        return np.zeros((0, 2), np.int64)
    out = np.sort(np.concatenate(found), axis=1)
    return np.unique(out, axis=0) if len(out) else out.reshape(0, 2)
