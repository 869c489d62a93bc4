"""Nodal principal curvatures by iterative quadric fitting (source paper, appendix B).

At every node P:

1. the faces around P are split into triangles (a quad ``P, A, B, C`` gives ``PAB`` and ``PBC``)
   and the nodal normal is Max's weighted sum of eq. B.2,
   ``n_P = sum_i (PP_i x PP_{i+1}) / (|PP_i|^2 |PP_{i+1}|^2)``;
2. a local frame ``{e1, e2, e3 = n_P}`` (B.3-B.6; ``e1`` from the global x axis, or y when the
   normal is close to x);
3. the least-squares fit of ``z = a x^2 + b xy + c y^2 + d x + e y`` (B.7) through the neighbour
   nodes, in the local frame. The neighbours are every node of the faces around P (eight on a
   regular quad grid, six on a regular triangle grid); where that gives fewer than five (corners,
   some boundary nodes) the two-ring is used;
4. the corrected normal ``(-d, -e, 1) / sqrt(1 + d^2 + e^2)`` (B.8) replaces ``n_P`` and steps 2-3
   are repeated until the normal moves less than ``tol`` (at most ``max_iter`` times: the loop has a
   fixed length so that it compiles, and nodes that have converged stop changing);
5. Gauss and mean curvature and the principal curvatures from the fit (B.9).

Sign convention (SPEC section 2): a curvature is positive when the surface bends *away* from the
node normal, whose orientation follows the face winding (counter-clockwise faces seen from the
normal side). A sphere with outward-pointing normals has ``k1 = k2 = +1/R``. ``k1 >= k2``.
``kappa_max = max(|k1|, |k2|)`` does not depend on the orientation.

Design: the neighbour tables depend on the connectivity only, so they are built once on the host
(numpy) as padded fixed-width tables with masks (:func:`curvature_stencil`): build the stencil at
the edge and pass it (a pytree) to :func:`curvatures_from_stencil` for many frames;
:func:`principal_curvatures` is the convenience that builds it on every call. The fit (:func:`curvatures_from_stencil`) is pure JAX with fixed shapes: jit-able,
vmap-able over frames of node positions, differentiable with respect to the node positions (safe
norms and divisions; the tiny ridge term keeps the 5x5 normal equations solvable for degenerate
neighbourhoods, so every node, boundary nodes included, gets a finite value).

Under ``jit``/``vmap``, ``faces`` must be concrete (a numpy array, or a JAX array closed over):
``jax.vmap(lambda x: principal_curvatures(x, faces))(frames)`` works.
"""
from __future__ import annotations

import warnings
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from jaxform._pytree import pytree_dataclass, static_field
from jaxform.geometry import safe_norm, safe_normalize, safe_sqrt

__all__ = [
    "CurvatureStencil",
    "MeshWarning",
    "curvature_stencil",
    "curvatures_from_stencil",
    "principal_curvatures",
    "kappa_max",
]


class MeshWarning(UserWarning):
    """A surface mesh that can be measured but may give misleading values (non-manifold edges,
    inconsistent orientation, degenerate faces, unused nodes)."""


@pytree_dataclass
class CurvatureStencil:
    """Neighbour tables of a surface mesh for :func:`curvatures_from_stencil` (host-built).

    Attributes:
      fan: (N, T, 2) int32, the two other corners ``(P_i, P_{i+1})`` of each triangle around each
        node, counter-clockwise as the faces are wound (quads split through the node).
      fan_mask: (N, T) bool, which fan rows are real.
      ring: (N, W) int32, neighbour nodes used for the quadric fit (padded with the node itself).
      ring_mask: (N, W) bool, which ring entries are real.
      n_nodes: number of nodes (static).
    """

    fan: Any
    fan_mask: Any
    ring: Any
    ring_mask: Any
    n_nodes: int = static_field(default=0)


def _pad_table(owner: np.ndarray, values: np.ndarray, n: int, fill_self: bool):
    """Group ``values`` rows by ``owner`` into an (n, width, ...) table with a mask."""
    order = np.argsort(owner, kind="stable")
    owner = owner[order]
    values = values[order]
    counts = np.bincount(owner, minlength=n)
    width = max(1, int(counts.max()) if len(counts) else 1)
    starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
    slot = np.arange(len(owner)) - starts[owner]
    shape = (n, width) + values.shape[1:]
    table = np.empty(shape, dtype=np.int32)
    if fill_self:
        table[...] = np.arange(n, dtype=np.int32).reshape((n, 1) + (1,) * (values.ndim - 1))
    else:
        table[...] = 0
    mask = np.zeros((n, width), bool)
    table[owner, slot] = values
    mask[owner, slot] = True
    return table, mask, counts


def validate_faces(faces, n_nodes: int) -> np.ndarray:
    """Check faces given by the user; return them as an int64 numpy array.

    Raises ValueError for a wrong shape, non-integers or indices out of range; warns
    (:class:`MeshWarning`) about faces with repeated corners and non-manifold edges."""
    if isinstance(faces, jax.core.Tracer):
        raise TypeError(
            "faces must be concrete (numpy, or a JAX array closed over), not traced: the neighbour "
            "tables are built on the host. Under jit/vmap, close over faces instead of passing them "
            "as an argument, e.g. jax.vmap(lambda x: principal_curvatures(x, faces))(frames)."
        )
    f = np.asarray(faces)
    if f.ndim != 2 or f.shape[1] not in (3, 4):
        raise ValueError(f"faces must have shape (F, 3) triangles or (F, 4) quads, got {f.shape}")
    if not np.issubdtype(f.dtype, np.integer):
        raise ValueError(f"faces must be integers, got dtype {f.dtype}")
    if f.shape[0] == 0:
        raise ValueError("the mesh has no faces")
    if f.min() < 0 or f.max() >= n_nodes:
        raise ValueError(f"faces refer to nodes {f.min()}..{f.max()} but there are {n_nodes} nodes")
    f = f.astype(np.int64)
    k = f.shape[1]
    srt = np.sort(f, axis=1)
    repeated = (srt[:, 1:] == srt[:, :-1]).any(axis=1)
    if repeated.any():
        warnings.warn(
            f"{int(repeated.sum())} faces have repeated corners (degenerate, first: face "
            f"{int(np.argmax(repeated))}); they add nothing to the normals",
            MeshWarning,
            stacklevel=3,
        )
    edges = np.stack([f, np.roll(f, -1, axis=1)], axis=-1).reshape(-1, 2)
    edges = edges[edges[:, 0] != edges[:, 1]]
    und = np.sort(edges, axis=1)
    _, inv, cnt = np.unique(und, axis=0, return_inverse=True, return_counts=True)
    if (cnt > 2).any():
        warnings.warn(
            f"{int((cnt > 2).sum())} edges are shared by more than two faces (non-manifold); "
            "curvatures there mix separate sheets",
            MeshWarning,
            stacklevel=3,
        )
    # Orientation: an interior edge is traversed once in each direction by consistently wound faces.
    directed, dcnt = np.unique(edges, axis=0, return_counts=True)
    if (dcnt > 1).any() and not (cnt > 2).any():
        warnings.warn(
            f"{int((dcnt > 1).sum())} edges are traversed in the same direction by two faces: the "
            "faces are not consistently oriented, so normals (and curvature signs) flip; "
            "kappa_max is unaffected only away from those edges",
            MeshWarning,
            stacklevel=3,
        )
    del k, inv, directed
    return f


def _build_stencil(f: np.ndarray, n: int, rings: int = 1) -> CurvatureStencil:
    k = f.shape[1]
    # Fan triangles: for every corner j of every face, the triangles of the split through it.
    owners, pairs = [], []
    for j in range(k):
        for t in range(k - 2):
            owners.append(f[:, j])
            pairs.append(np.stack([f[:, (j + 1 + t) % k], f[:, (j + 2 + t) % k]], axis=1))
    owner = np.concatenate(owners)
    pair = np.concatenate(pairs)
    fan, fan_mask, _ = _pad_table(owner, pair, n, fill_self=True)
    # One-ring: every other node of the faces around the node.
    a = np.repeat(f, k, axis=1).reshape(-1)
    b = np.tile(f, (1, k)).reshape(-1)
    keep = a != b
    pairs_ab = np.unique(np.stack([a[keep], b[keep]], axis=1), axis=0)
    counts = np.bincount(pairs_ab[:, 0], minlength=n)
    # Two-ring where the one-ring has fewer than five nodes.
    few = np.nonzero(counts < 5)[0] if rings == 1 else np.arange(n)
    if len(few):
        starts = np.concatenate([[0], np.cumsum(counts)])
        nbrs = [pairs_ab[starts[i]:starts[i + 1], 1] for i in range(n)]
        extra = []
        for i in few:
            second = set(nbrs[i].tolist())
            for j in nbrs[i]:
                second.update(nbrs[j].tolist())
            second.discard(i)
            extra.append(np.array(sorted(second), dtype=np.int64))
        is_few = np.zeros(n, bool)
        is_few[few] = True
        base = pairs_ab[~is_few[pairs_ab[:, 0]]]
        add = np.concatenate([np.stack([np.full(len(e), i), e], 1) for i, e in zip(few, extra)]
                             + [np.zeros((0, 2), np.int64)])
        pairs_ab = np.concatenate([base, add])
    ring, ring_mask, _ = _pad_table(pairs_ab[:, 0], pairs_ab[:, 1], n, fill_self=True)
    return CurvatureStencil(fan=fan, fan_mask=fan_mask, ring=ring, ring_mask=ring_mask, n_nodes=n)


def curvature_stencil(faces, n_nodes: int, *, rings: int = 1, check: bool = True) -> CurvatureStencil:
    """Neighbour tables for :func:`curvatures_from_stencil` (host side; build once per mesh).

    Args:
      faces: (F, 3) triangles or (F, 4) quads, node indices (int32/int64, numpy or concrete JAX).
      n_nodes: number of nodes N.
      rings: 1 (the paper: the one-ring, two-ring only where the one-ring has fewer than five
        nodes) or 2 (the two-ring everywhere: less sensitive to noise, e.g. on scanned or
        triangulated noisy surfaces, at the price of resolution).
      check: validate the faces (errors for bad indices; :class:`MeshWarning` for degenerate,
        non-manifold or inconsistently oriented faces).
    """
    f = np.ascontiguousarray(np.asarray(faces)) if not isinstance(faces, jax.core.Tracer) else faces
    if check or isinstance(f, jax.core.Tracer):
        f = validate_faces(f, n_nodes)
    if rings not in (1, 2):
        raise ValueError(f"rings must be 1 or 2, got {rings!r}")
    return _build_stencil(f.astype(np.int64), int(n_nodes), int(rings))


# ----------------------------------------------------------------------------------------------
# Kernel
# ----------------------------------------------------------------------------------------------
def _dot(a, b):
    return jnp.sum(a * b, axis=-1)


def _frame(n):
    """Orthonormal tangent vectors (e1, e2) for unit normals n (N,3): B.3-B.4."""
    dtype = n.dtype
    ex = jnp.array([1.0, 0.0, 0.0], dtype)
    ey = jnp.array([0.0, 1.0, 0.0], dtype)
    use_y = jnp.abs(n[:, 0:1]) > 0.9  # normal (nearly) parallel to E1: project E2 instead
    base = jnp.where(use_y, ey, ex)
    e1 = safe_normalize(base - _dot(base, n)[:, None] * n, jnp.broadcast_to(ey, n.shape))
    e2 = safe_normalize(jnp.cross(n, e1), jnp.broadcast_to(ey, n.shape))
    return e1, e2


def _solve_spd5(m, r):
    """Solve m x = r for symmetric positive definite m (..., 5, 5), by an unrolled Cholesky."""
    n = 5
    L = [[None] * n for _ in range(n)]
    for i in range(n):
        for j in range(i + 1):
            s = m[..., i, j]
            for q in range(j):
                s = s - L[i][q] * L[j][q]
            if i == j:
                L[i][i] = jnp.sqrt(jnp.maximum(s, jnp.finfo(s.dtype).tiny))
            else:
                L[i][j] = s / L[j][j]
    y = [None] * n
    for i in range(n):
        s = r[..., i]
        for q in range(i):
            s = s - L[i][q] * y[q]
        y[i] = s / L[i][i]
    x = [None] * n
    for i in reversed(range(n)):
        s = y[i]
        for q in range(i + 1, n):
            s = s - L[q][i] * x[q]
        x[i] = s / L[i][i]
    return jnp.stack(x, axis=-1)


def _fit(d, w, n, h):
    """Least-squares quadric B.7 in the frame of normal n.

    d: (N, W, 3) neighbour offsets, m; w: (N, W) 0/1 weights; n: (N, 3) unit normals;
    h: (N,) length scale, m. Returns coefficients (N, 5) = a, b, c (1/m), d, e (-), frame."""
    e1, e2 = _frame(n)
    inv_h = 1.0 / h
    x = _dot(d, e1[:, None, :]) * inv_h[:, None]
    y = _dot(d, e2[:, None, :]) * inv_h[:, None]
    z = _dot(d, n[:, None, :]) * inv_h[:, None]
    A = jnp.stack([x * x, x * y, y * y, x, y], axis=-1) * w[..., None]  # (N, W, 5)
    M = jnp.einsum("nwi,nwj->nij", A, A)
    rhs = jnp.einsum("nwi,nw->ni", A, z * w)
    # A small ridge keeps the normal equations solvable where the neighbourhood cannot separate all
    # five terms (e.g. a boundary node whose neighbours lie on two lines): minimum-norm-like fit.
    rel = 1e-10 if M.dtype == jnp.float64 else 1e-5
    ridge = rel * jnp.trace(M, axis1=-2, axis2=-1) / 5.0 + jnp.finfo(M.dtype).tiny * 1e6
    M = M + ridge[:, None, None] * jnp.eye(5, dtype=M.dtype)
    coef = _solve_spd5(M, rhs)
    scale = jnp.stack([inv_h, inv_h, inv_h, jnp.ones_like(h), jnp.ones_like(h)], axis=-1)
    return coef * scale, e1, e2


def _curvatures_from_stencil(nodes, stencil: CurvatureStencil, *, max_iter: int = 10,
                            tol: float | None = None):
    """Principal curvatures from a precomputed stencil (pure JAX; see the module docstring).

    Args:
      nodes: (N, 3) node positions, m.
      stencil: from :func:`curvature_stencil`.
      max_iter: maximum number of normal corrections (B.8), a fixed loop length.
      tol: stop correcting a node's normal once it moves less than this (rad); default 1e-10 in
        float64, 1e-6 in float32.

    Returns:
      (k1, k2): (N,) principal curvatures, 1/m, ``k1 >= k2``, positive when the surface bends
      away from the node normal.
    """
    x = jnp.asarray(nodes)
    if not jnp.issubdtype(x.dtype, jnp.floating):
        x = x.astype(jnp.result_type(float))
    dtype = x.dtype
    if tol is None:
        tol = 1e-10 if dtype == jnp.float64 else 1e-6
    fan = jnp.asarray(stencil.fan)
    fmask = jnp.asarray(stencil.fan_mask)
    ring = jnp.asarray(stencil.ring)
    w = jnp.asarray(stencil.ring_mask).astype(dtype)

    # B.2: weighted normal from the triangle fan.
    u = x[fan[..., 0]] - x[:, None, :]
    v = x[fan[..., 1]] - x[:, None, :]
    uu = _dot(u, u)
    vv = _dot(v, v)
    den = uu * vv
    ok = fmask & (den > 0.0)
    c = jnp.cross(u, v) / jnp.where(ok, den, 1.0)[..., None]
    n0 = jnp.sum(jnp.where(ok[..., None], c, 0.0), axis=1)

    d = x[ring] - x[:, None, :]  # (N, W, 3)
    dist = safe_norm(d)
    cnt = jnp.maximum(jnp.sum(w, axis=1), 1.0)
    h = jnp.sum(dist * w, axis=1) / cnt
    h = jnp.where(h > 0.0, h, 1.0)
    # Fallback normal for a node whose fan cancels (should not happen on a valid mesh): +z.
    ez = jnp.broadcast_to(jnp.array([0.0, 0.0, 1.0], dtype), x.shape)
    n = safe_normalize(n0, ez)

    def body(_, state):
        n, coef, done = state
        cf, e1, e2 = _fit(d, w, n, h)
        dd, ee = cf[:, 3], cf[:, 4]
        n_new = safe_normalize(-dd[:, None] * e1 - ee[:, None] * e2 + n, n)  # B.8, R^T n_new
        change = safe_norm(n_new - n)
        coef = jnp.where(done[:, None], coef, cf)
        n = jnp.where(done[:, None], n, n_new)
        done = done | (change < tol)
        return n, coef, done

    coef0 = jnp.zeros((x.shape[0], 5), dtype)
    _, coef, _ = jax.lax.fori_loop(0, max_iter, body, (n, coef0, jnp.zeros(x.shape[0], bool)))
    a, b, cc, dd, ee = (coef[:, i] for i in range(5))
    g = 1.0 + dd * dd + ee * ee
    K = (4.0 * a * cc - b * b) / (g * g)  # B.9
    H = (a + cc + a * ee * ee + cc * dd * dd - b * dd * ee) / (g * jnp.sqrt(g))
    # B.9 gives curvature positive towards the normal; SPEC: positive away from it.
    H = -H
    disc = H * H - K
    root = safe_sqrt(disc)
    return H + root, H - root


curvatures_from_stencil = jax.jit(_curvatures_from_stencil, static_argnames=("max_iter", "tol"))
curvatures_from_stencil.__doc__ = _curvatures_from_stencil.__doc__  # compiled once per mesh shape: call it per frame


def principal_curvatures(nodes, faces, *, max_iter: int = 10, tol: float | None = None,
                         rings: int = 1, check: bool = True):
    """Principal curvatures at every node by iterative quadric fitting (appendix B).

    Args:
      nodes: (N, 3) node positions, m; numpy or JAX, float32 or float64.
      faces: (F, 3) triangles or (F, 4) quads, int32/int64; must be concrete (see module doc).
      max_iter, tol: normal-correction loop, see :func:`curvatures_from_stencil`.
      rings: fitting neighbourhood, see :func:`curvature_stencil` (1, the paper's, by default).
      check: validate input: raise on non-finite concrete nodes or bad faces, warn
        (:class:`MeshWarning`) about degenerate, non-manifold or inconsistently wound faces.

    Returns:
      (k1, k2): (N,) principal curvatures, 1/m, ``k1 >= k2``, finite at every node (boundary
      nodes included), in the dtype of ``nodes``.
    """
    if not isinstance(nodes, jax.core.Tracer):
        arr = np.asarray(nodes)
        if arr.ndim != 2 or arr.shape[1] != 3:
            raise ValueError(f"nodes must have shape (N, 3), got {arr.shape}")
        if check:
            bad = ~np.isfinite(arr).all(axis=1)
            if bad.any():
                raise ValueError(
                    f"nodes has {int(bad.sum())} non-finite (NaN/inf) rows, first at index "
                    f"{int(np.argmax(bad))}; fix or remove them before measuring curvature"
                )
    n_nodes = nodes.shape[0]
    st = curvature_stencil(faces, n_nodes, rings=rings, check=check)
    return curvatures_from_stencil(nodes, st, max_iter=max_iter, tol=tol)


def kappa_max(k1, k2):
    """Largest absolute principal curvature (paper eq. 2): (N,) 1/m -> (N,) 1/m."""
    return jnp.maximum(jnp.abs(k1), jnp.abs(k2))
