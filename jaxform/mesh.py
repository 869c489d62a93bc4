"""Ply meshes: node positions, triangles, neighbour tables for rotation-free bending, lumped areas.

A :class:`Mesh` is built on the host (numpy) from a reference configuration and then used, as a
pytree of arrays, inside jitted kernels. Everything the shell needs about the *reference*
geometry that does not depend on the material is precomputed here:

* ``tris`` (T, 3): triangles (a structured quad grid is split into two triangles per quad; a quad
  counts as two triangles in every figure). The membrane is integrated per triangle.
* ``node_area`` (N,): lumped reference area of each node (a third of each adjacent triangle), m².
  Lumped masses are ``areal_mass * node_area``; bending is integrated with these weights.
* ``nbr`` (N, K) and ``gfd`` (N, 5, K): for every node a padded neighbourhood (padding repeats the
  node itself with zero weight; the node itself, whose weight is always zero, is left out) and
  least-squares "generalised finite-difference" weights such
  that, for a field ``u`` on the nodes, ``sum_k gfd[i, m, k] * (u[nbr[i, k]] - u[i])`` estimates
  ``(du/dX, du/dY, d2u/dX2, d2u/dXdY, d2u/dY2)`` at node ``i`` in the node's local reference
  frame (``frame[i]``: rows ``t1, t2, n``). On a structured grid's interior the neighbourhood is
  the 3x3 patch and the weights are (row-averaged) central differences. Both are *stored*
  neighbour-major, ``nbr_k`` (K, N) and ``gfd_k`` (K, 5, N), the layout the kernels stream
  through (one contiguous row per neighbour slot); ``nbr``/``gfd`` are views in node-major order.
* ``frame`` (N, 3, 3) and ``tri_frame`` (T, 3, 3): local reference frames. ``t1`` is the global x
  axis projected on the tangent plane (the y axis where x is normal to the surface); ``n`` points
  to the ply's top face (``+z`` for a flat blank meshed counter-clockwise seen from above).
* ``corner_k`` (C, N): each node's triangle corners, so that per-corner values (the shell's
  triangle forces, the fibre mass's products) are assembled onto the nodes by gathers (:func:`assemble_corners`), not a scatter.

Several plies are stacked by concatenating their nodes and triangles; ``ply_nodes`` and
``ply_tris`` (static) give each ply's contiguous ranges, so kernels loop over plies (a handful)
with static slices and never over elements.
"""
from __future__ import annotations

import math
from typing import Any

import jax.numpy as jnp
import numpy as np

from jaxform._pytree import pytree_dataclass, static_field


@pytree_dataclass
class Mesh:
    """Reference mesh of one or more plies.

    Attributes:
        nodes: (N, 3) reference node positions, m.
        tris: (T, 3) int32 triangle corners (counter-clockwise about the ply normal).
        node_area: (N,) lumped reference area per node, m².
        nbr_k: (K, N) int32 padded neighbourhood of each node (itself as padding), neighbour-major.
        gfd_k: (K, 5, N) finite-difference weights for d/dX, d/dY, d2/dX2, d2/dXdY, d2/dY2 (1/m,
            1/m²), neighbour-major (see :attr:`nbr` and :attr:`gfd` for node-major views).
        frame: (N, 3, 3) local reference frame per node, rows (t1, t2, n).
        tri_frame: (T, 3, 3) local reference frame per triangle, rows (t1, t2, n).
        corner_k: (C, N) int32 the triangle corners of each node (:func:`corner_table`), for
            assembling per-corner values by gathers.
        ply_nodes: static tuple of (start, stop) node ranges, one per ply.
        ply_tris: static tuple of (start, stop) triangle ranges, one per ply.
        quads: static flag: True when ``tris`` come from a quad grid in pairs (2q, 2q+1).
        shape: static (nx, ny) node counts of a structured grid per ply, or None.
    """

    nodes: Any
    tris: Any
    node_area: Any
    nbr_k: Any
    gfd_k: Any
    frame: Any
    tri_frame: Any
    corner_k: Any
    ply_nodes: tuple = static_field(default=((0, 0),))
    ply_tris: tuple = static_field(default=((0, 0),))
    quads: bool = static_field(default=False)
    shape: tuple | None = static_field(default=None)

    @property
    def nbr(self):
        """(N, K) neighbourhood table, node-major view of ``nbr_k``."""
        return self.nbr_k.T

    @property
    def gfd(self):
        """(N, 5, K) finite-difference weights, node-major view of ``gfd_k``."""
        return self.gfd_k.transpose(2, 1, 0)

    @property
    def n_nodes(self) -> int:
        return int(np.shape(self.nodes)[0])

    @property
    def n_tris(self) -> int:
        return int(np.shape(self.tris)[0])

    @property
    def n_plies(self) -> int:
        return len(self.ply_nodes)

    @property
    def faces(self) -> np.ndarray:
        """(F, 4) quads when built from a quad grid, else the (T, 3) triangles (for output)."""
        tris = np.asarray(self.tris)
        if not self.quads:
            return tris
        a, b = tris[0::2], tris[1::2]
        # pair (p, q, s), (p, s, r) -> quad (p, q, s, r)
        return np.stack([a[:, 0], a[:, 1], a[:, 2], b[:, 2]], axis=1)

    @staticmethod
    def from_arrays(nodes, faces, *, min_size: float | None = None) -> "Mesh":
        """A one-ply mesh from node positions (N, 3) m (or (N, 2)) and faces (F, 3) or (F, 4).

        Quads are split along their (p, r) diagonal into two triangles. The reference surface may
        be curved; the bending uses each node's tangent plane.
        """
        nodes = np.asarray(nodes, dtype=np.float64)
        if nodes.ndim != 2 or nodes.shape[1] not in (2, 3):
            raise ValueError(f"Mesh.from_arrays: nodes have shape {nodes.shape}: need (N, 3) positions in m")
        if nodes.shape[1] == 2:
            nodes = np.concatenate([nodes, np.zeros((len(nodes), 1))], axis=1)
        if not np.all(np.isfinite(nodes)):
            raise ValueError("Mesh.from_arrays: node positions contain NaN or inf")
        faces = np.asarray(faces)
        if faces.ndim != 2 or faces.shape[1] not in (3, 4) or not np.issubdtype(faces.dtype, np.integer):
            raise ValueError(f"Mesh.from_arrays: faces have shape {faces.shape}, dtype {faces.dtype}: need (F, 3) or (F, 4) integers")
        if faces.size and (faces.min() < 0 or faces.max() >= len(nodes)):
            raise ValueError(f"Mesh.from_arrays: face indices must lie in [0, {len(nodes) - 1}]")
        quads = faces.shape[1] == 4
        if quads:
            tris = np.concatenate([faces[:, [0, 1, 2]], faces[:, [0, 2, 3]]], axis=0)
            # interleave so that triangles 2q, 2q+1 come from quad q
            tris = np.stack([faces[:, [0, 1, 2]], faces[:, [0, 2, 3]]], axis=1).reshape(-1, 3)
        else:
            tris = faces
        return _build([(nodes, tris.astype(np.int64))], quads=quads, shape=None)

    @staticmethod
    def rectangle(lx: float, ly: float, size: float, *, origin=(0.0, 0.0), plies: int = 1,
                  ply_spacing: float = 0.0, size_y: float | None = None) -> "Mesh":
        """A structured rectangular blank ``lx`` x ``ly`` (m) of quads of about ``size`` (m).

        ``plies`` copies are stacked ``ply_spacing`` (m) apart along +z (ply 0 at the bottom).
        ``size_y`` sets a different element size across (default ``size``).
        """
        for name, v in (("lx", lx), ("ly", ly), ("size", size)):
            if not (v > 0 and math.isfinite(v)):
                raise ValueError(f"Mesh.rectangle: {name} = {v!r}: must be a positive length in m")
        nx = max(1, int(round(lx / size))) + 1
        ny = max(1, int(round(ly / (size_y or size)))) + 1
        xs = origin[0] + np.linspace(0.0, lx, nx)
        ys = origin[1] + np.linspace(0.0, ly, ny)
        return Mesh.grid(xs, ys, plies=plies, ply_spacing=ply_spacing)

    @staticmethod
    def square(side: float, size: float, *, centred: bool = True, plies: int = 1, ply_spacing: float = 0.0) -> "Mesh":
        """A square blank of side ``side`` (m), centred on the origin by default."""
        o = -0.5 * side if centred else 0.0
        return Mesh.rectangle(side, side, size, origin=(o, o), plies=plies, ply_spacing=ply_spacing)

    @staticmethod
    def strip(length: float, width: float, n_length: int, n_width: int = 2, *, x0: float = 0.0) -> "Mesh":
        """A strip along x from ``x0`` to ``x0 + length`` with ``n_length`` x ``n_width`` quads, centred in y."""
        xs = x0 + np.linspace(0.0, length, n_length + 1)
        ys = np.linspace(-0.5 * width, 0.5 * width, n_width + 1)
        return Mesh.grid(xs, ys)

    @staticmethod
    def grid(xs, ys, *, plies: int = 1, ply_spacing: float = 0.0) -> "Mesh":
        """A structured grid with node coordinates ``xs`` (nx,) and ``ys`` (ny,) in the plane z = 0."""
        xs, ys = np.asarray(xs, float), np.asarray(ys, float)
        nx, ny = len(xs), len(ys)
        X, Y = np.meshgrid(xs, ys, indexing="xy")  # (ny, nx)
        nodes = np.stack([X.ravel(), Y.ravel(), np.zeros(X.size)], axis=1)
        idx = np.arange(nx * ny).reshape(ny, nx)
        p, q = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
        r, s = idx[1:, :-1].ravel(), idx[1:, 1:].ravel()
        tris = np.stack([np.stack([p, q, s], 1), np.stack([p, s, r], 1)], axis=1).reshape(-1, 3)
        if nx < 3 or ny < 3:
            raise ValueError(f"Mesh.grid: {nx} x {ny} nodes: need at least 3 nodes in each direction (curvature stencil)")
        # 3x3 patch per node, shifted inwards at the edges (one-sided at free boundaries)
        ci = np.clip(np.arange(nx) - 1, 0, nx - 3)
        cj = np.clip(np.arange(ny) - 1, 0, ny - 3)
        di, dj = np.meshgrid(np.arange(3), np.arange(3), indexing="xy")
        cols = ci[None, :, None] + di.ravel()[None, None, :]  # (1, nx, 9)
        rows = cj[:, None, None] + dj.ravel()[None, None, :]  # (ny, 1, 9)
        patch = (rows * nx + cols).reshape(nx * ny, 9)
        parts = []
        for k in range(plies):
            parts.append((nodes + np.array([0.0, 0.0, k * ply_spacing]), tris, patch))
        return _build(parts, quads=True, shape=(nx, ny))

    def replace(self, **changes) -> "Mesh":
        """The mesh with ``changes``; new triangles get their corner table (host side)."""
        import dataclasses

        if "tris" in changes and "corner_k" not in changes:
            nodes = changes.get("nodes", self.nodes)
            changes["corner_k"] = corner_table(np.asarray(changes["tris"]), int(np.shape(nodes)[0]))
        return dataclasses.replace(self, **changes)


# ------------------------------------------------------------------------------------------- host side


def corner_table(tris, n_nodes: int) -> np.ndarray:
    """(C, N) int32: for each node, where its triangle corners lie in the corner-major layout of
    per-corner values (``concatenate([v0, v1, v2], axis=-1)``, 3T long), ``C`` the most triangles
    on a node; padded with ``3 T`` (a zero appended to the values). Summing the gathered values
    over ``C`` assembles them onto the nodes, as a scatter-add by corner would, without one (a
    gather is the cheaper of the two on CPU)."""
    tris = np.asarray(tris)
    ids = np.concatenate([tris[:, 0], tris[:, 1], tris[:, 2]])
    order = np.argsort(ids, kind="stable")
    counts = np.bincount(ids, minlength=n_nodes)
    start = np.concatenate([[0], np.cumsum(counts)[:-1]])
    table = np.full((max(1, int(counts.max())), n_nodes), 3 * len(tris), np.int32)
    for j in range(table.shape[0]):
        has = counts > j
        table[j, has] = order[start[has] + j]
    return table


def assemble_corners(vals, mesh: Mesh):
    """(3, N): per-corner values ``vals`` (3, 3T), corner-major (:func:`corner_table`), summed onto
    their nodes by gathers; the same as ``zeros.at[:, corners].add(vals)``."""
    v = jnp.concatenate([vals, jnp.zeros((vals.shape[0], 1), vals.dtype)], axis=1)
    table = mesh.corner_k
    return sum(v[:, table[j]] for j in range(table.shape[0]))


def _unit(v):
    n = np.linalg.norm(v, axis=-1, keepdims=True)
    return v / np.where(n > 0, n, 1.0)


def _tangent_frames(normals):
    """Rows (t1, t2, n): t1 = global x projected on the plane (global y where x is ~normal)."""
    n = _unit(normals)
    ex = np.array([1.0, 0.0, 0.0])
    ey = np.array([0.0, 1.0, 0.0])
    base = np.where((np.abs(n @ ex) > 0.99)[:, None], ey, ex)
    t1 = _unit(base - (np.sum(base * n, -1, keepdims=True)) * n)
    t2 = np.cross(n, t1)
    return np.stack([t1, t2, n], axis=1)


def _neighbourhoods(nodes, tris, frames, *, min_points: int = 8):
    """Grow a distance-ranked neighbourhood over the mesh graph until the quadratic fit is well posed."""
    n = len(nodes)
    # adjacency
    edges = np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]], axis=0)
    adj = [set() for _ in range(n)]
    for a, b in edges:
        adj[a].add(b)
        adj[b].add(a)
    # characteristic spacing per node: mean adjacent edge length
    hloc = np.array([np.mean([np.linalg.norm(nodes[j] - nodes[i]) for j in adj[i]]) if adj[i] else 1.0 for i in range(n)])
    result = []
    for i in range(n):
        ring = {i}
        frontier = {i}
        chosen = None
        for depth in range(1, 6):
            nxt = set()
            for a in frontier:
                nxt |= adj[a]
            nxt -= ring
            ring |= nxt
            frontier = nxt
            cand = np.array(sorted(ring - {i}))
            if len(cand) < 5:
                continue
            d = nodes[cand] - nodes[i]
            loc = d @ frames[i][:2].T  # (m, 2)
            dist = np.linalg.norm(loc, axis=1)
            order = np.argsort(dist, kind="stable")
            for radius_factor in (1.5, 2.05, 2.3, 2.9, 3.2):
                sel = order[dist[order] <= radius_factor * hloc[i] * (1 + 1e-9)]
                if len(sel) < min_points - 0 and radius_factor < 3.2:
                    pass
                if len(sel) < 5:
                    continue
                A = _design(loc[sel], hloc[i])
                sv = np.linalg.svd(A, compute_uv=False)
                if sv[-1] > 1e-3 * sv[0] and len(sel) >= min(min_points, len(cand)):
                    chosen = cand[sel]
                    break
            if chosen is not None:
                break
        if chosen is None:
            raise ValueError(
                f"Mesh: node {i} has too few neighbours for a curvature estimate; the mesh needs at least "
                "3 nodes in each direction around every node (refine the mesh)"
            )
        result.append(chosen)
    return result, hloc


def _design(loc, h):
    X, Y = loc[:, 0] / h, loc[:, 1] / h
    return np.stack([X, Y, 0.5 * X * X, X * Y, 0.5 * Y * Y], axis=1)


def _gfd_weights_patch(nodes, frames, patch):
    """Vectorised weights for fixed-size 3x3 patches (N, 9) that include the node itself.

    The fit carries the cubic terms ``X² Y`` and ``X Y²`` besides the quadratic ones, so that the
    second derivatives are those *at the node*, also where the patch is shifted inwards (a free
    edge or corner): with the quadratic fit alone an edge node read the along-edge curvature
    averaged over its own row and the next two, and a curvature that grows towards the edge (a
    wave along it) was under-read, by half at 4 cells across (see ``tests/test_buckling.py``).
    On a centred patch the cubic columns are orthogonal to the quadratic ones, and the weights
    are the row-averaged central differences as before.
    """
    d = nodes[patch] - nodes[:, None, :]  # (N, K, 3)
    loc = np.einsum("nkc,nac->nka", d, frames[:, :2, :])  # (N, K, 2)
    h = np.sqrt(np.mean(np.sum(loc**2, -1), axis=1))  # patch scale
    X, Y = loc[..., 0] / h[:, None], loc[..., 1] / h[:, None]
    # (N, K, 7); the self row is zero
    A = np.stack([X, Y, 0.5 * X * X, X * Y, 0.5 * Y * Y, 0.5 * X * X * Y, 0.5 * X * Y * Y], axis=2)
    P = np.linalg.pinv(A)[:, :5]  # (N, 5, K): the derivatives up to second order
    pw = np.array([1, 1, 2, 2, 2])
    return patch.astype(np.int64), P / h[:, None, None] ** pw[None, :, None]


def _gfd_weights(nodes, frames, neigh, hloc):
    n = len(nodes)
    K = max(len(c) for c in neigh)
    nbr = np.tile(np.arange(n)[:, None], (1, K))
    w = np.zeros((n, 5, K))
    scale = np.array([1, 1, 2, 2, 2], float)  # (d/dX, d/dY) 1/h; second derivatives 1/h^2
    for i, c in enumerate(neigh):
        loc = (nodes[c] - nodes[i]) @ frames[i][:2].T
        A = _design(loc, hloc[i])
        P = np.linalg.pinv(A)  # (5, m): coefficients = P @ (u_c - u_i), in units of h
        pw = np.array([1, 1, 2, 2, 2])
        w[i, :, : len(c)] = P / hloc[i] ** pw[:, None]
        nbr[i, : len(c)] = c
    del scale
    return nbr, w


def _drop_self(nbr, w):
    """Remove the zero-weight entries that point at the node itself (they contribute nothing).

    Kept entries stay in order at the front of each row; rows are cut to the longest kept row,
    the rest padded with the node itself at zero weight.
    """
    n = len(nbr)
    own = (nbr == np.arange(n)[:, None]) & np.all(w == 0.0, axis=1)
    order = np.argsort(own, axis=1, kind="stable")
    nbr = np.take_along_axis(nbr, order, axis=1)
    w = np.take_along_axis(w, order[:, None, :], axis=2)
    K = int((~own).sum(axis=1).max())
    return nbr[:, :K], w[:, :, :K]


def _build(parts, *, quads: bool, shape) -> Mesh:
    all_nodes, all_tris, ply_nodes, ply_tris = [], [], [], []
    all_area, all_frames, all_tframes, all_nbr, all_w = [], [], [], [], []
    n_off, t_off = 0, 0
    K = 0
    per = []
    for part in parts:
        nodes, tris = part[0], part[1]
        e1 = nodes[tris[:, 1]] - nodes[tris[:, 0]]
        e2 = nodes[tris[:, 2]] - nodes[tris[:, 0]]
        cr = np.cross(e1, e2)
        area = 0.5 * np.linalg.norm(cr, axis=1)
        if np.any(area <= 1e-14 * max(1e-30, np.max(area))):
            raise ValueError("Mesh: degenerate (zero-area) triangles; clean the mesh")
        node_area = np.zeros(len(nodes))
        np.add.at(node_area, tris.ravel(), np.repeat(area / 3.0, 3))
        if np.any(node_area == 0):
            raise ValueError("Mesh: some nodes belong to no face; remove unused nodes")
        nsum = np.zeros_like(nodes)
        np.add.at(nsum, tris.ravel(), np.repeat(cr, 3, axis=0))
        frames = _tangent_frames(nsum)
        tframes = _tangent_frames(cr)
        if len(part) > 2:
            nbr, w = _gfd_weights_patch(nodes, frames, part[2])
        else:
            neigh, hloc = _neighbourhoods(nodes, tris, frames)
            nbr, w = _gfd_weights(nodes, frames, neigh, hloc)
        nbr, w = _drop_self(nbr, w)
        K = max(K, nbr.shape[1])
        per.append((nodes, tris, node_area, frames, tframes, nbr, w))
    for nodes, tris, node_area, frames, tframes, nbr, w in per:
        n, t = len(nodes), len(tris)
        pad = K - nbr.shape[1]
        if pad:
            nbr = np.concatenate([nbr, np.tile(np.arange(n)[:, None], (1, pad))], axis=1)
            w = np.concatenate([w, np.zeros((n, 5, pad))], axis=2)
        all_nodes.append(nodes)
        all_tris.append(tris + n_off)
        all_area.append(node_area)
        all_frames.append(frames)
        all_tframes.append(tframes)
        all_nbr.append(nbr + n_off)
        all_w.append(w)
        ply_nodes.append((n_off, n_off + n))
        ply_tris.append((t_off, t_off + t))
        n_off += n
        t_off += t
    return Mesh(
        nodes=np.concatenate(all_nodes),
        tris=np.concatenate(all_tris).astype(np.int32),
        node_area=np.concatenate(all_area),
        nbr_k=np.ascontiguousarray(np.concatenate(all_nbr).astype(np.int32).T),
        gfd_k=np.ascontiguousarray(np.concatenate(all_w).transpose(2, 1, 0)),
        frame=np.concatenate(all_frames),
        tri_frame=np.concatenate(all_tframes),
        corner_k=corner_table(np.concatenate(all_tris), n_off),
        ply_nodes=tuple(ply_nodes),
        ply_tris=tuple(ply_tris),
        quads=quads,
        shape=shape,
    )


__all__ = ["Mesh", "corner_table", "assemble_corners"]
