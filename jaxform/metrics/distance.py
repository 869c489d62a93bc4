"""Unsigned distance from fabric nodes to a tool surface (paper eq. 1, SPEC section 5).

``d_P = |P - P'|`` with ``P'`` the closest point of the tool surface, which need not be a tool node.

Triangle-mesh tools
    The exact distance is a minimum over all tool triangles of the point-triangle distance. Doing
    that for every node against every triangle is ``O(N F)``; the paper restricted the search to a
    local bounding sphere. jaxform does the same with fixed shapes: the tool triangles are grouped
    host side into spatially compact clusters (Morton order of the centroids, ``G`` triangles each)
    with a bounding sphere per cluster (:func:`build_tool_index`). For each node the ``K`` clusters
    whose spheres come closest are searched exhaustively; the answer is *certified* exact when the
    next cluster's sphere is no closer than the distance found. Nodes that are not certified (rare:
    nodes equidistant from large parts of the tool, such as the centre of a sphere) are searched
    against every triangle, a fixed-size batch at a time, inside a ``lax.while_loop``. The result is
    therefore exact for every node, not only for the typical one.

    The search only picks *which* triangle is closest (integers); the distance itself is recomputed
    from that triangle with differentiable, safe operations, so ``jax.grad`` with respect to the node
    positions is finite everywhere (zero where a node lies exactly on the tool).

Analytic tools
    :class:`HemisphereRig` (the paper's hemispherical punch of radius 50 mm on a flat base plane) and
    :class:`PlaneTool` evaluate the distance in closed form; pass one as ``tool_vertices`` (with
    ``tool_faces=None``) to :func:`tool_distance` or call its ``distance`` method.

Everything is pure JAX. The tool index is built on the host from *concrete* tool arrays and cached
(keyed by the bytes of the arrays); under ``jit``/``vmap`` close over the tool arrays (or pass numpy
arrays) rather than passing them as traced arguments. With traced tool arrays :func:`tool_distance`
still works, by an exhaustive (slow, exact) search.
"""
from __future__ import annotations

import hashlib
import warnings
from dataclasses import dataclass
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from jaxform._pytree import pytree_dataclass, static_field

__all__ = [
    "ToolIndex",
    "ToolWarning",
    "HemisphereRig",
    "PlaneTool",
    "build_tool_index",
    "tool_distance",
    "distance_to_index",
    "point_triangle_sqdist",
    "closest_triangle_brute",
]


class ToolWarning(UserWarning):
    """A tool that is probably not the one intended (far from the fabric, wrong units...)."""


# ----------------------------------------------------------------------------------------------
# Point-triangle distance (one point, one triangle; vmapped by broadcasting)
# ----------------------------------------------------------------------------------------------
def _dot(a, b):
    return jnp.sum(a * b, axis=-1)


def _safe_sqrt(x):
    """sqrt with a zero (not NaN/inf) gradient at and below 0."""
    ok = x > 0.0
    return jnp.where(ok, jnp.sqrt(jnp.where(ok, x, 1.0)), 0.0)


def point_triangle_sqdist(p, a, b, c):
    """Squared distance from points to triangles (broadcasting over leading axes).

    Args:
      p: (..., 3) points, m.
      a, b, c: (..., 3) triangle corners, m. Degenerate triangles (zero area) are handled as the
        union of their edges.

    Returns:
      (...,) squared distance, m^2. Differentiable; no NaN for degenerate input.
    """
    ab = b - a
    ac = c - a
    ap = p - a
    n = jnp.cross(ab, ac)
    nn = _dot(n, n)
    scale = jnp.maximum(_dot(ab, ab), _dot(ac, ac))
    nondegenerate = nn > 1e-24 * scale * scale
    nn_safe = jnp.where(nondegenerate, nn, 1.0)
    # Barycentric coordinates (v along ab, w along ac) of the projection of p on the plane.
    w = _dot(jnp.cross(ab, ap), n) / nn_safe
    v = _dot(jnp.cross(ap, ac), n) / nn_safe
    inside = nondegenerate & (v >= 0.0) & (w >= 0.0) & (v + w <= 1.0)
    d_plane = _dot(ap, n) ** 2 / nn_safe

    def seg(q, e):  # squared distance from q (relative to the segment start) to the segment e
        ee = _dot(e, e)
        t = jnp.clip(_dot(q, e) / jnp.where(ee > 0.0, ee, 1.0), 0.0, 1.0)
        r = q - t[..., None] * e
        return _dot(r, r)

    d_edges = jnp.minimum(jnp.minimum(seg(ap, ab), seg(ap, ac)), seg(p - b, c - b))
    return jnp.where(inside, d_plane, d_edges)


# ----------------------------------------------------------------------------------------------
# Host-side index
# ----------------------------------------------------------------------------------------------
@pytree_dataclass
class ToolIndex:
    """Triangle tool prepared for the nearest-triangle search (build with :func:`build_tool_index`).

    Triangles are sorted along a Morton curve and grouped into clusters of ``G`` consecutive
    triangles, clusters into super-clusters of ``S`` consecutive clusters; each group carries a
    bounding sphere and an axis-aligned box (both used as lower bounds of the distance).

    Attributes:
      tri: (F, 3, 3) triangle corners, m.
      cluster_tri: (C, G) triangle ids of each cluster (padded by repeating a member), int32.
      cluster_center, cluster_lo, cluster_hi: (C, 3) sphere centres and box corners, m.
      cluster_radius: (C,) sphere radii, m.
      super_cluster: (NS, S) cluster ids of each super-cluster (padded by repetition), int32.
      super_center, super_lo, super_hi: (NS, 3) sphere centres and box corners, m.
      super_radius: (NS,) sphere radii, m.
      ks, k: super-clusters, then clusters searched per node in the first pass (static).
      ks2, k2: the same for the second pass, for nodes the first could not certify (static).
      batch: nodes per second-pass / exhaustive batch (static).
    """

    tri: Any
    cluster_tri: Any
    cluster_center: Any
    cluster_radius: Any
    cluster_lo: Any
    cluster_hi: Any
    super_cluster: Any
    super_center: Any
    super_radius: Any
    super_lo: Any
    super_hi: Any
    ks: int = static_field(default=6)
    k: int = static_field(default=16)
    ks2: int = static_field(default=16)
    k2: int = static_field(default=64)
    batch: int = static_field(default=512)


def _morton_keys(points: np.ndarray) -> np.ndarray:
    lo = points.min(axis=0)
    span = np.maximum(points.max(axis=0) - lo, 1e-300)
    q = np.clip(((points - lo) / span * 1023.0).astype(np.int64), 0, 1023)

    def spread(x):
        x = x & 0x3FF
        x = (x | (x << 16)) & 0x030000FF
        x = (x | (x << 8)) & 0x0300F00F
        x = (x | (x << 4)) & 0x030C30C3
        x = (x | (x << 2)) & 0x09249249
        return x

    return spread(q[:, 0]) | (spread(q[:, 1]) << 1) | (spread(q[:, 2]) << 2)


def validate_tool(tool_vertices, tool_faces) -> tuple[np.ndarray, np.ndarray]:
    """Check a triangle tool given by the user; return float64 vertices and int64 faces.

    Raises ValueError for an empty tool, faces that are not triangles, indices out of range, or
    non-finite coordinates. Degenerate (zero-area) triangles are allowed (they act as segments)."""
    v = np.asarray(tool_vertices, dtype=np.float64)
    f = np.asarray(tool_faces)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"tool_vertices must have shape (V, 3), got {v.shape}")
    if f.ndim != 2 or f.shape[1] != 3:
        raise ValueError(
            f"tool_faces must be triangles with shape (F, 3), got {f.shape}; split quads first "
            "(jaxform.io.read_surface(..., triangulate=True) does)"
        )
    if f.shape[0] == 0 or v.shape[0] == 0:
        raise ValueError("the tool is empty (no triangles): nothing to measure the distance to")
    if not np.issubdtype(f.dtype, np.integer):
        raise ValueError(f"tool_faces must be integers, got dtype {f.dtype}")
    if f.min() < 0 or f.max() >= v.shape[0]:
        raise ValueError(
            f"tool_faces refer to vertices {f.min()}..{f.max()} but there are {v.shape[0]} vertices"
        )
    bad = ~np.isfinite(v).all(axis=1)
    if bad.any():
        raise ValueError(
            f"tool_vertices has {int(bad.sum())} non-finite (NaN/inf) rows, first at {int(np.argmax(bad))}"
        )
    return v, f.astype(np.int64)


def _bounds(pts: np.ndarray):
    """(C, P, 3) points of each group -> sphere centre, radius, box lo, box hi (never too small)."""
    lo = pts.min(axis=1)
    hi = pts.max(axis=1)
    center = 0.5 * (lo + hi)
    radius = np.sqrt(((pts - center[:, None, :]) ** 2).sum(-1)).max(axis=1)
    pad = 1e-12 * (np.abs(pts).max() + 1e-300)
    return center, radius * (1.0 + 1e-12) + pad, lo - pad, hi + pad


def _group(ids: np.ndarray, size: int) -> np.ndarray:
    n_groups = -(-len(ids) // size)
    out = np.empty(n_groups * size, dtype=np.int64)
    out[: len(ids)] = ids
    out[len(ids):] = ids[-1]  # pad with a real member: harmless for a minimum
    return out.reshape(n_groups, size)


def build_tool_index(tool_vertices, tool_faces, *, cluster_size: int = 8, super_size: int = 16,
                     ks: int = 6, k: int = 16, ks2: int = 16, k2: int = 64,
                     batch: int = 512) -> ToolIndex:
    """Prepare a triangle tool for :func:`distance_to_index` (host side, numpy).

    Args:
      tool_vertices: (V, 3) tool vertex positions, m (numpy or concrete JAX array).
      tool_faces: (F, 3) triangle vertex indices, integer.
      cluster_size: triangles per cluster ``G``.
      super_size: clusters per super-cluster ``S``.
      ks, k: super-clusters and clusters searched per node in the first pass.
      ks2, k2: the same in the second pass (nodes the first pass could not certify).
      batch: nodes per second-pass and exhaustive-search batch.

    Returns:
      A :class:`ToolIndex` (float64 arrays; cast to the nodes' dtype at query time).
    """
    v, f = validate_tool(tool_vertices, tool_faces)
    tri = v[f]  # (F, 3, 3)
    order = np.argsort(_morton_keys(tri.mean(axis=1)), kind="stable")
    cluster_tri = _group(order, max(1, min(int(cluster_size), len(order))))
    n_cl, g = cluster_tri.shape
    c_center, c_radius, c_lo, c_hi = _bounds(tri[cluster_tri].reshape(n_cl, g * 3, 3))
    super_cluster = _group(np.arange(n_cl), max(1, min(int(super_size), n_cl)))
    n_s, s = super_cluster.shape
    s_center, s_radius, s_lo, s_hi = _bounds(tri[cluster_tri[super_cluster]].reshape(n_s, s * g * 3, 3))
    ks = int(min(ks, n_s))
    ks2 = int(min(max(ks2, ks), n_s))
    return ToolIndex(
        tri=tri, cluster_tri=cluster_tri.astype(np.int32), cluster_center=c_center,
        cluster_radius=c_radius, cluster_lo=c_lo, cluster_hi=c_hi,
        super_cluster=super_cluster.astype(np.int32), super_center=s_center,
        super_radius=s_radius, super_lo=s_lo, super_hi=s_hi,
        ks=ks, k=int(min(k, ks * s)), ks2=ks2, k2=int(min(max(k2, k), ks2 * s)), batch=int(batch),
    )


_INDEX_CACHE: dict = {}


def _cached_index(tool_vertices, tool_faces) -> ToolIndex:
    v = np.ascontiguousarray(np.asarray(tool_vertices))
    f = np.ascontiguousarray(np.asarray(tool_faces))
    h = hashlib.blake2b(digest_size=16)
    for arr in (v, f):
        h.update(str((arr.shape, arr.dtype.str)).encode())
        h.update(arr.tobytes())
    key = h.hexdigest()
    idx = _INDEX_CACHE.get(key)
    if idx is None:
        idx = build_tool_index(v, f)
        if len(_INDEX_CACHE) > 16:
            _INDEX_CACHE.pop(next(iter(_INDEX_CACHE)))
        _INDEX_CACHE[key] = idx
    return idx


# ----------------------------------------------------------------------------------------------
# Kernels
# ----------------------------------------------------------------------------------------------
def _tri_sqdist_rows(p, tri):
    """p (M,3), tri (M,T,3,3) -> (M,T) squared distances."""
    return point_triangle_sqdist(p[:, None, :], tri[..., 0, :], tri[..., 1, :], tri[..., 2, :])


def _sqdist_soa(px, py, pz, t):
    """Point-triangle squared distance in components-first layout (fast on CPU).

    px, py, pz: (B, 1) point coordinates; t: 9 arrays (B, T): ax, ay, az, bx, by, bz, cx, cy, cz.
    Same algorithm as :func:`point_triangle_sqdist`; used only to *select* the closest triangle.
    """
    ax, ay, az, bx, by, bz, cx, cy, cz = t
    abx, aby, abz = bx - ax, by - ay, bz - az
    acx, acy, acz = cx - ax, cy - ay, cz - az
    apx, apy, apz = px - ax, py - ay, pz - az
    nx = aby * acz - abz * acy
    ny = abz * acx - abx * acz
    nz = abx * acy - aby * acx
    nn = nx * nx + ny * ny + nz * nz
    ab2 = abx * abx + aby * aby + abz * abz
    ac2 = acx * acx + acy * acy + acz * acz
    scale = jnp.maximum(ab2, ac2)
    ok = nn > 1e-24 * scale * scale
    inv = 1.0 / jnp.where(ok, nn, 1.0)
    # w = (ab x ap).n / nn, v = (ap x ac).n / nn
    w = ((aby * apz - abz * apy) * nx + (abz * apx - abx * apz) * ny + (abx * apy - aby * apx) * nz) * inv
    v = ((apy * acz - apz * acy) * nx + (apz * acx - apx * acz) * ny + (apx * acy - apy * acx) * nz) * inv
    inside = ok & (v >= 0.0) & (w >= 0.0) & (v + w <= 1.0)
    dn = apx * nx + apy * ny + apz * nz
    d_plane = dn * dn * inv

    def seg(qx, qy, qz, ex, ey, ez, ee):
        t_ = jnp.clip((qx * ex + qy * ey + qz * ez) / jnp.where(ee > 0.0, ee, 1.0), 0.0, 1.0)
        rx, ry, rz = qx - t_ * ex, qy - t_ * ey, qz - t_ * ez
        return rx * rx + ry * ry + rz * rz

    bcx, bcy, bcz = cx - bx, cy - by, cz - bz
    d_e = jnp.minimum(seg(apx, apy, apz, abx, aby, abz, ab2), seg(apx, apy, apz, acx, acy, acz, ac2))
    d_e = jnp.minimum(d_e, seg(px - bx, py - by, pz - bz, bcx, bcy, bcz,
                               bcx * bcx + bcy * bcy + bcz * bcz))
    return jnp.where(inside, d_plane, d_e)


def _soa_rows(p, tri9, tids):
    """p (B,3), tri9 (9,F), tids (B,T) -> (B,T) squared distances."""
    t = tuple(tri9[i][tids] for i in range(9))
    return _sqdist_soa(p[:, 0:1], p[:, 1:2], p[:, 2:3], t)


def closest_triangle_brute(nodes, tri, *, node_batch: int = 64, tri_batch: int = 4096):
    """Index of the closest triangle for each node, by exhaustive search (exact, O(N F)).

    Args:
      nodes: (N, 3) points, m.
      tri: (F, 3, 3) triangle corners, m.

    Returns:
      (N,) int32 triangle ids.
    """
    n_tri = tri.shape[0]
    tb = min(tri_batch, n_tri)
    n_tb = -(-n_tri // tb)
    pad = n_tb * tb - n_tri
    tri_p = jnp.concatenate([tri, jnp.repeat(tri[-1:], pad, axis=0)], axis=0)
    tri_p = tri_p.reshape(n_tb, tb, 9).transpose(0, 2, 1)  # (n_tb, 9, tb) components first

    def one_chunk(p):  # p (B, 3)
        def body(carry, chunk):
            best_d, best_i = carry
            t, base = chunk  # t (9, tb)
            d = _sqdist_soa(p[:, 0:1], p[:, 1:2], p[:, 2:3], tuple(t[i][None, :] for i in range(9)))
            j = jnp.argmin(d, axis=1)
            dj = jnp.take_along_axis(d, j[:, None], axis=1)[:, 0]
            better = dj < best_d
            return (jnp.where(better, dj, best_d), jnp.where(better, base + j.astype(jnp.int32), best_i)), None

        init = (jnp.full(p.shape[0], jnp.inf, p.dtype), jnp.zeros(p.shape[0], jnp.int32))
        bases = jnp.arange(n_tb, dtype=jnp.int32) * tb
        (_, best_i), _ = jax.lax.scan(body, init, (tri_p, bases))
        return jnp.minimum(best_i, n_tri - 1)

    n = nodes.shape[0]
    nb = max(1, min(node_batch, n))
    n_nb = -(-n // nb)
    padded = jnp.concatenate([nodes, jnp.repeat(nodes[-1:], n_nb * nb - n, axis=0)], axis=0)
    out = jax.lax.map(one_chunk, padded.reshape(n_nb, nb, 3))
    return out.reshape(-1)[:n]


def _lower_bound(p, bounds):
    """p (B,3); bounds: 10 arrays (B,M) or (M,) (centre xyz, radius, lo xyz, hi xyz) -> (B,M), m.

    The larger of the bounding-sphere and bounding-box distances: a lower bound of the distance
    from the point to anything inside the group."""
    cx, cy, cz, r, lx, ly, lz, hx, hy, hz = bounds
    px, py, pz = p[:, 0:1], p[:, 1:2], p[:, 2:3]
    lb_sphere = _safe_sqrt((px - cx) ** 2 + (py - cy) ** 2 + (pz - cz) ** 2) - r
    ox = jnp.maximum(jnp.maximum(lx - px, px - hx), 0.0)
    oy = jnp.maximum(jnp.maximum(ly - py, py - hy), 0.0)
    oz = jnp.maximum(jnp.maximum(lz - pz, pz - hz), 0.0)
    return jnp.maximum(lb_sphere, _safe_sqrt(ox * ox + oy * oy + oz * oz))


def _smallest(vals, k: int):
    """The k smallest entries of each row (B, M): indices (B, k) and the next value (B,) (inf if none).

    k + 1 passes of argmin: much faster on CPU than a sort-based top_k for small k."""
    ids = []
    col = jnp.arange(vals.shape[1])
    for _ in range(k):
        i = jnp.argmin(vals, axis=1)
        ids.append(i)
        vals = jnp.where(col[None, :] == i[:, None], jnp.inf, vals)
    nxt = jnp.min(vals, axis=1) if k < vals.shape[1] else jnp.full(vals.shape[0], jnp.inf, vals.dtype)
    return jnp.stack(ids, axis=1), nxt


def _soa_bounds(center, radius, lo, hi, dtype):
    arr = jnp.concatenate([jnp.asarray(center, dtype).T, jnp.asarray(radius, dtype)[None],
                           jnp.asarray(lo, dtype).T, jnp.asarray(hi, dtype).T], axis=0)
    return arr  # (10, M)


def _cluster_search(p, index: ToolIndex, ks: int, k: int, dtype):
    """Two-level search; p (B,3) -> closest triangle id (B,), certified exact (B,)."""
    sb = _soa_bounds(index.super_center, index.super_radius, index.super_lo, index.super_hi, dtype)
    cb = _soa_bounds(index.cluster_center, index.cluster_radius, index.cluster_lo,
                     index.cluster_hi, dtype)
    tri9 = jnp.asarray(index.tri, dtype).reshape(-1, 9).T
    lb_s = _lower_bound(p, tuple(sb[i][None, :] for i in range(10)))
    sel_s, next_s = _smallest(lb_s, ks)
    cl = jnp.asarray(index.super_cluster)[sel_s].reshape(p.shape[0], -1)  # (B, ks*S)
    lb_c = _lower_bound(p, tuple(cb[i][cl] for i in range(10)))
    sel_c, next_c = _smallest(lb_c, k)
    cl_sel = jnp.take_along_axis(cl, sel_c, axis=1)  # (B, k)
    tids = jnp.asarray(index.cluster_tri)[cl_sel].reshape(p.shape[0], -1)
    d = _soa_rows(p, tri9, tids)
    j = jnp.argmin(d, axis=1)
    best = jnp.take_along_axis(tids, j[:, None], axis=1)[:, 0]
    dmin = _safe_sqrt(jnp.take_along_axis(d, j[:, None], axis=1)[:, 0])
    # Exact when no unsearched super-cluster and no unsearched cluster can come closer. The small
    # relative margin absorbs rounding in the bounds (a tie is not a miss: equal distance).
    margin = 1e-12 * (1.0 + dmin)
    certified = (next_s + margin >= dmin) & (next_c + margin >= dmin)
    return best, certified


def _closest_triangle_indexed(nodes, index: ToolIndex, node_chunk: int = 1024):
    """Closest triangle id per node, exact: first pass, second pass, exhaustive search."""
    dtype = nodes.dtype
    n = nodes.shape[0]
    b = max(1, min(node_chunk, n))
    n_b = -(-n // b)
    padded = jnp.concatenate([nodes, jnp.repeat(nodes[-1:], n_b * b - n, axis=0)], axis=0)
    best, cert = jax.lax.map(lambda q: _cluster_search(q, index, index.ks, index.k, dtype),
                             padded.reshape(n_b, b, 3))
    best = best.reshape(-1)[:n]
    cert = cert.reshape(-1)[:n]
    m = min(index.batch, n)
    tri = jnp.asarray(index.tri, dtype)

    def pass_loop(best, cert, finder):
        tried = cert

        def cond(state):
            return ~jnp.all(state[2])

        def body(state):
            best, cert, tried = state
            ids = jnp.nonzero(~tried, size=m, fill_value=n)[0]
            valid = ids < n
            found, ok = finder(nodes[jnp.minimum(ids, n - 1)])
            tgt = jnp.where(valid, ids, n)
            best = best.at[tgt].set(found, mode="drop")
            cert = cert.at[tgt].set(ok, mode="drop")
            tried = tried.at[tgt].set(True, mode="drop")
            return best, cert, tried

        best, cert, _ = jax.lax.while_loop(cond, body, (best, cert, tried))
        return best, cert

    if index.k2 > index.k or index.ks2 > index.ks:
        best, cert = pass_loop(best, cert,
                               lambda q: _cluster_search(q, index, index.ks2, index.k2, dtype))
    best, _ = pass_loop(best, cert,
                        lambda q: (closest_triangle_brute(q, tri), jnp.ones(q.shape[0], bool)))
    return best


@jax.jit
def _distance_to_index_jit(nodes, index):
    best = jax.lax.stop_gradient(_closest_triangle_indexed(jax.lax.stop_gradient(nodes), index))
    t = jnp.asarray(index.tri, nodes.dtype)[best]
    return _safe_sqrt(point_triangle_sqdist(nodes, t[:, 0], t[:, 1], t[:, 2]))


def distance_to_index(nodes, index: ToolIndex):
    """Unsigned distance from nodes to an indexed triangle tool (pure JAX, exact).

    Args:
      nodes: (N, 3) node positions, m.
      index: :class:`ToolIndex` from :func:`build_tool_index`.

    Returns:
      (N,) distance to the closest point of the tool surface, m. Differentiable w.r.t. ``nodes``.
    """
    nodes = jnp.asarray(nodes)
    if not jnp.issubdtype(nodes.dtype, jnp.floating):
        nodes = nodes.astype(jnp.result_type(float))
    # Pad the node count to a few bucket sizes, so that calls with different numbers of nodes
    # share compiled programs (padding rows repeat the last node and are dropped).
    n = nodes.shape[0]
    if n == 0:
        return jnp.zeros((0,), nodes.dtype)
    n_pad = max(64, 1 << (n - 1).bit_length()) if n <= 1024 else -(-n // 1024) * 1024
    padded = jnp.concatenate([nodes, jnp.broadcast_to(nodes[-1:], (n_pad - n, 3))], axis=0)
    return _distance_to_index_jit(padded, index)[:n]


# ----------------------------------------------------------------------------------------------
# Analytic tools
# ----------------------------------------------------------------------------------------------
@pytree_dataclass
class HemisphereRig:
    """The paper's hemisphere forming rig as seen by the metric: a hemispherical punch of radius
    ``radius`` standing on an infinite flat base plane (the die/blank-holder plane).

    The surface is the upper half-sphere ``|x - c| = R, z >= c_z`` together with the plane
    ``z = c_z`` outside the circle of radius ``R`` (when ``base_plane``).

    Attributes:
      radius: punch radius, m (default 0.05).
      center: (3,) centre of the sphere, on the base plane, m.
      base_plane: include the flat base plane (static).
    """

    radius: Any = 0.05
    center: Any = (0.0, 0.0, 0.0)
    base_plane: bool = static_field(default=True)

    def distance(self, nodes):
        """(N, 3) node positions, m -> (N,) unsigned distance to the rig surface, m."""
        x = jnp.asarray(nodes)
        dtype = x.dtype if jnp.issubdtype(x.dtype, jnp.floating) else jnp.result_type(float)
        x = x.astype(dtype)
        c = jnp.asarray(self.center, dtype)
        r_s = jnp.asarray(self.radius, dtype)
        q = x - c
        rho = _safe_sqrt(q[:, 0] ** 2 + q[:, 1] ** 2)
        z = q[:, 2]
        # Distance to the rim circle (rho = R, z = 0): closest point of both parts when not above.
        d_rim = _safe_sqrt((rho - r_s) ** 2 + z**2)
        d_cap = jnp.where(z >= 0.0, jnp.abs(_safe_sqrt(_dot(q, q)) - r_s), d_rim)
        if not self.base_plane:
            return d_cap
        d_plane = jnp.where(rho >= r_s, jnp.abs(z), d_rim)
        return jnp.minimum(d_cap, d_plane)

    def mesh(self, size: float = 0.002, extent: float | None = None):
        """A triangle mesh of the rig for plots and files (host side, numpy): (V,3) m, (F,3).

        ``extent``: outer radius of the base-plane annulus, m (default 2.5 R)."""
        return _hemisphere_mesh(float(self.radius), np.asarray(self.center, float), size,
                                extent if extent is not None else 2.5 * float(self.radius),
                                self.base_plane)


@pytree_dataclass
class PlaneTool:
    """An infinite flat tool: the plane through ``point`` with normal ``normal``.

    Attributes:
      point: (3,) a point of the plane, m.
      normal: (3,) plane normal (any length).
    """

    point: Any = (0.0, 0.0, 0.0)
    normal: Any = (0.0, 0.0, 1.0)

    def distance(self, nodes):
        """(N, 3) node positions, m -> (N,) unsigned distance to the plane, m."""
        x = jnp.asarray(nodes)
        dtype = x.dtype if jnp.issubdtype(x.dtype, jnp.floating) else jnp.result_type(float)
        x = x.astype(dtype)
        n = jnp.asarray(self.normal, dtype)
        n = n / _safe_sqrt(_dot(n, n))
        return jnp.abs(_dot(x - jnp.asarray(self.point, dtype), n))

    def mesh(self, size: float = 0.01, extent: float = 0.15):
        """A square triangle mesh of the plane (host side): (V,3) m, (F,3)."""
        n = np.asarray(self.normal, float)
        n = n / np.linalg.norm(n)
        u = np.cross(n, [1.0, 0, 0] if abs(n[0]) < 0.9 else [0, 1.0, 0])
        u /= np.linalg.norm(u)
        w = np.cross(n, u)
        m = max(2, int(round(2 * extent / size)) + 1)
        s = np.linspace(-extent, extent, m)
        a, b = np.meshgrid(s, s, indexing="ij")
        v = np.asarray(self.point, float) + a.reshape(-1, 1) * u + b.reshape(-1, 1) * w
        return v, _grid_triangles(m, m)


def _grid_triangles(nx: int, ny: int) -> np.ndarray:
    i, j = np.meshgrid(np.arange(nx - 1), np.arange(ny - 1), indexing="ij")
    a = (i * ny + j).ravel()
    b, c, d = a + ny, a + ny + 1, a + 1
    return np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)]).astype(np.int64)


def _hemisphere_mesh(radius, center, size, extent, base_plane):
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


# ----------------------------------------------------------------------------------------------
# Public entry point
# ----------------------------------------------------------------------------------------------
def _is_concrete(x) -> bool:
    return not isinstance(x, jax.core.Tracer)


def tool_distance(nodes, tool_vertices, tool_faces=None, *, check: bool = True):
    """Exact unsigned distance from each node to the closest point of a tool surface.

    Args:
      nodes: (N, 3) fabric node positions, m; numpy or JAX, float32 or float64.
      tool_vertices: (V, 3) tool triangle-mesh vertices, m; or an analytic tool
        (:class:`HemisphereRig`, :class:`PlaneTool`, a :class:`ToolIndex`) with ``tool_faces=None``.
      tool_faces: (F, 3) tool triangles, int32 or int64.
      check: when ``nodes`` are concrete, raise on non-finite nodes and warn (:class:`ToolWarning`)
        when the tool is far from every node.

    Returns:
      (N,) distance, m, in the dtype of ``nodes``. Pure JAX: jit-able and vmap-able over ``nodes``
      (close over the tool arrays, which then must be concrete), differentiable w.r.t. ``nodes``.
    """
    if check and _is_concrete(nodes):
        arr = np.asarray(nodes)
        if arr.ndim != 2 or arr.shape[-1] != 3:
            raise ValueError(f"nodes must have shape (N, 3), got {arr.shape}")
        bad = ~np.isfinite(arr).all(axis=1)
        if bad.any():
            raise ValueError(
                f"nodes has {int(bad.sum())} non-finite (NaN/inf) rows, first at index "
                f"{int(np.argmax(bad))}; fix or remove them before measuring distances"
            )
    if tool_faces is None:
        if isinstance(tool_vertices, ToolIndex):
            d = distance_to_index(nodes, tool_vertices)
        elif hasattr(tool_vertices, "distance"):
            d = tool_vertices.distance(nodes)
        else:
            raise ValueError("tool_faces is required when tool_vertices is an array of vertices")
    elif _is_concrete(tool_vertices) and _is_concrete(tool_faces):
        d = distance_to_index(nodes, _cached_index(tool_vertices, tool_faces))
    else:
        # Traced tool: no host-side index possible; exhaustive exact search.
        x = jnp.asarray(nodes)
        tri = jnp.asarray(tool_vertices, x.dtype)[jnp.asarray(tool_faces)]
        best = jax.lax.stop_gradient(closest_triangle_brute(jax.lax.stop_gradient(x), tri))
        t = tri[best]
        d = _safe_sqrt(point_triangle_sqdist(x, t[:, 0], t[:, 1], t[:, 2]))
    if check and _is_concrete(nodes) and np.asarray(nodes).shape[0] > 0:
        _warn_if_far(np.asarray(nodes), np.asarray(d))
    return d


def _warn_if_far(nodes: np.ndarray, d: np.ndarray) -> None:
    span = float(np.linalg.norm(nodes.max(axis=0) - nodes.min(axis=0)))
    dmin = float(d.min())
    if span > 0 and dmin > 0.25 * span:
        warnings.warn(
            f"the closest fabric node is {dmin:.4g} m from the tool, more than a quarter of the "
            f"fabric's size ({span:.4g} m): wrong tool, tool offset or units (mm vs m)?",
            ToolWarning,
            stacklevel=3,
        )
