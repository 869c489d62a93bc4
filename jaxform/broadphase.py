"""Contact candidates of a moving surface by a cell grid of fixed capacity (issue 19).

The narrow phase (:func:`jaxform.contact.ply_contact`) tests each node against ``K`` candidate
triangles; this module finds them without looking at every triangle, with fixed shapes inside
``jit`` (JAX MD's cell list, ``jax_md/partition.py``, with sorted keys instead of a dense grid so
that a thin sheet in a large box costs nothing for its empty cells):

1. bin the triangle centroids into cubic cells of side ``cell = reach + R`` (``R`` the largest
   centroid-to-corner distance, ``reach`` the search distance): a triangle within ``reach`` of a
   point has its centroid in the point's cell or one of the 26 around it;
2. sort the cell keys (``(i << 20) | (j << 10) | k``, 1024 cells a side, indices clipped);
3. per point, look up the 27 cells by binary search and read them in pages of ``cap`` triangles
   per cell (fixed shape ``(27 cap,)``), as many pages as the fullest of them needs (per block
   of points): every triangle of the 27 cells is looked at, however crowded a fold makes a
   cell, while a small ``cap`` keeps the usual sparse cell cheap;
4. drop the pairs ``mask(point, triangle)`` refuses (a node's own neighbourhood in self-contact),
   keep the ``K`` nearest centroids; a slot left empty gets the point's ``fallback`` triangle.

Cost per refresh: a sort of the F keys and ``27 * cap * pages`` distance tests per point, i.e.
``O(N + F log F)`` against ``O(N F)`` for :func:`nearest_centroids` (the brute-force reference). The
candidates stay valid while no point has moved by more than half the skin (``reach`` minus the
contact distance) since the refresh, measured from the displacement all points share
(:func:`moved_beyond`, the Verlet-list criterion: it ties the refresh to the largest relative
node speed). The search is integer bookkeeping: no gradient flows through
it (its inputs are ``stop_gradient``-ed, so the page loop may have a traced trip count).
"""
from __future__ import annotations

from typing import Any, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from jaxform.batching import any_member

__all__ = ["nearest_centroids", "cell_size", "grid_keys", "cell_ranges", "candidates", "moved_beyond", "SearchState", "initial_search_state",
           "initial_state_of", "refreshed"]

_BITS = 10
_SIDE = 1 << _BITS  # cells per axis
_OFFSETS = np.array([(i, j, k) for i in (-1, 0, 1) for j in (-1, 0, 1) for k in (-1, 0, 1)], np.int32)


def cell_size(tri_x, reach):
    """``reach + R`` (m): the cell side for triangles ``tri_x`` (F, 3, 3) m and search distance ``reach`` (m)."""
    cen = jnp.mean(tri_x, axis=1)
    r2 = jnp.max(jnp.sum((tri_x - cen[:, None, :]) ** 2, axis=-1))
    return reach + jnp.sqrt(r2) * 1.0001 + 1e-12


def _ijk(p, lo, cell):
    return jnp.clip(jnp.floor((p - lo) / cell).astype(jnp.int32), 0, _SIDE - 1)


def _key(ijk):
    return (ijk[..., 0] << (2 * _BITS)) | (ijk[..., 1] << _BITS) | ijk[..., 2]


def grid_keys(centroids, lo, cell):
    """``(sorted_keys (F,), order (F,))``: cell keys of the centroids (F, 3) sorted, and the
    triangle ids in that order."""
    keys = _key(_ijk(centroids, lo, cell))
    order = jnp.argsort(keys).astype(jnp.int32)
    return keys[order], order


def cell_ranges(points, sorted_keys, lo, cell):
    """``(start (B, 27), end (B, 27))``: the slices of the sorted triangle list binned in the 27
    cells around each point (B, 3) (empty where a cell lies outside the grid)."""
    ijk = _ijk(points, lo, cell)[:, None, :] + _OFFSETS[None]  # (B, 27, 3)
    inside = jnp.all((ijk >= 0) & (ijk < _SIDE), axis=-1)
    keys = jnp.where(inside, _key(ijk), -1)
    start = jnp.searchsorted(sorted_keys, keys, side="left").astype(jnp.int32)
    end = jnp.where(inside, jnp.searchsorted(sorted_keys, keys, side="right").astype(jnp.int32), start)
    return start, end


def candidates(points, tri_x, k: int, reach, *, mask=None, refine=None, fallback=None, cap: int = 8,
               chunk: int = 512):
    """The ``k`` triangles with the nearest centroids within reach of each point.

    Args:
        points: (N, 3) query points, m.
        tri_x: (F, 3, 3) triangle corners, m.
        k: candidates per point (static).
        reach: () search distance, m (contact distance plus skin): every triangle with a point
            closer than ``reach`` is among those looked at.
        mask: optional ``mask(point_ids (B,), tri_ids (B, M)) -> (B, M) bool``, the pairs allowed.
        refine: optional costlier test of the same form, applied only to the ``2 k`` nearest pairs
            ``mask`` allows (a short list), before the ``k`` nearest are kept.
        fallback: optional (N,) int triangle of each point for the empty slots (default 0); it
            must be a pair ``mask`` allows, and is then beyond ``reach`` whenever a slot is empty.
        cap: triangles read per cell and page (static; the fullest cell a block of points looks
            at sets that block's number of pages); chunk: points per block (static).

    Returns:
        ``(ids (N, k) int32, found (N, k) bool)``: nearest first; empty slots hold the point's
        best candidate, or its ``fallback`` when it has none.
    """
    points = jax.lax.stop_gradient(jnp.asarray(points))
    tri_x = jax.lax.stop_gradient(jnp.asarray(tri_x))
    n = points.shape[0]
    cen = jnp.mean(tri_x, axis=1)
    cell = cell_size(tri_x, reach)
    lo = jnp.minimum(jnp.min(cen, axis=0), jnp.min(points, axis=0)) - cell
    sorted_keys, order = grid_keys(cen, lo, cell)
    fb = jnp.zeros((n,), jnp.int32) if fallback is None else jnp.asarray(fallback, jnp.int32)
    chunk = int(max(1, min(chunk, n)))
    pad = (-n) % chunk
    pid = jnp.concatenate([jnp.arange(n, dtype=jnp.int32), jnp.zeros((pad,), jnp.int32)]).reshape(-1, chunk)
    keep = 2 * k if refine is not None else k
    lane = jnp.arange(cap, dtype=jnp.int32)

    def block(ids_p):
        p = points[ids_p]
        start, end = cell_ranges(p, sorted_keys, lo, cell)
        pages = (jnp.max(end - start) + cap - 1) // cap  # the fullest cell this block looks at

        def page(q, best):  # merge the page-q triangles of the 27 cells into the ``keep`` nearest
            slot = start[..., None] + q * cap + lane  # (B, 27, cap)
            ids = order[jnp.clip(slot, 0, order.shape[0] - 1)].reshape(chunk, -1)
            valid = (slot < end[..., None]).reshape(chunk, -1)
            if mask is not None:
                valid = valid & mask(ids_p, ids)
            d2 = jnp.where(valid, jnp.sum((p[:, None, :] - cen[ids]) ** 2, axis=-1), jnp.inf)
            neg, j = jax.lax.top_k(-jnp.concatenate([best[0], d2], axis=1), keep)
            return -neg, jnp.take_along_axis(jnp.concatenate([best[1], ids], axis=1), j, axis=1)

        d2, ids = jax.lax.fori_loop(0, pages, page, (jnp.full((chunk, keep), jnp.inf, points.dtype),
                                                     jnp.zeros((chunk, keep), jnp.int32)))
        if refine is not None:
            d2 = jnp.where(refine(ids_p, ids), d2, jnp.inf)
        neg, j = jax.lax.top_k(-d2, k)
        best = jnp.take_along_axis(ids, j, axis=1)
        found = jnp.isfinite(neg)
        first = jnp.where(found[:, :1], best[:, :1], fb[ids_p][:, None])
        return jnp.where(found, best, first), found

    ids, found = jax.lax.map(block, pid)
    return ids.reshape(-1, k)[:n].astype(jnp.int32), found.reshape(-1, k)[:n]


def nearest_centroids(points, centroids, k: int, chunk: int = 1024):
    """The ``k`` nearest centroids of each point: a candidate table for a *moving* mesh.

    Unlike :func:`jaxform.geometry.closest_triangle` nothing is certified (the closest triangle is among the
    candidates when the mesh is fine against the query distance); it needs no host-built index,
    so it can be refreshed inside ``jit`` (the reference the cell grid replaces). Cost ``O(N F)``, ``chunk`` points at
    a time.

    Args:
        points: (N, 3) positions, m.
        centroids: (F, 3) triangle centroids, m.
        k: candidates per point (static; capped at F).

    Returns:
        (N, k) int32 triangle ids, nearest first.
    """
    ps = jnp.asarray(points)
    cen = jnp.asarray(centroids)
    n = ps.shape[0]
    chunk = int(max(1, min(chunk, n)))
    pad = (-n) % chunk
    ps = jnp.concatenate([ps, jnp.zeros((pad, 3), ps.dtype)]).reshape(-1, chunk, 3)
    k = int(min(k, cen.shape[0]))

    def block(p):
        d2 = jnp.sum((p[:, None, :] - cen[None, :, :]) ** 2, axis=-1)
        return jax.lax.top_k(-d2, k)[1].astype(jnp.int32)

    return jax.lax.map(block, ps).reshape(-1, k)[:n]


def moved_beyond(x, x_ref, distance):
    """() bool: the points ``x`` (N, 3) may have moved against each other by more than twice
    ``distance`` (m) since ``x_ref`` (N, 3).

    The displacements ``d = x - x_ref`` are measured from ``c``, the centre of their bounding box:
    a node and a point of a triangle (or of an edge) close or part by at most ``|d_i - d_v| <=
    |d_i - c| + |d_v - c|``, so while no ``|d_j - c|`` exceeds ``distance`` no pair has closed by
    more than ``2 distance``: the Verlet-list guarantee of ``|d_j| <= distance``, with the motion
    every node shares left out (a blank sagging into the die,
    the punch carrying its middle down: its bounding box's centre).
    """
    d = x - x_ref
    c = 0.5 * (jnp.max(d, axis=0) + jnp.min(d, axis=0))
    return jnp.max(jnp.sum((d - c) ** 2, axis=-1)) > distance * distance


class SearchState(NamedTuple):
    """State of a contact load's candidate table (a load state: fixed shapes).

    Attributes:
        candidates: (N_s, K) int32 triangle ids (``~id`` where the node was on the back side).
        step: () int32 calls so far; x_ref: (N, 3) positions at the last refresh, m;
        last: () int32 call of the last refresh; refreshes: () int32 refreshes so far.
    """

    candidates: Any
    step: Any
    x_ref: Any
    last: Any
    refreshes: Any


def initial_search_state(x, search) -> SearchState:
    """The :class:`SearchState` for positions ``x`` (N, 3); ``search(x) -> candidates``."""
    z = jnp.asarray(0, jnp.int32)
    return SearchState(search(x), z, x, z, z + 1)


@jax.jit
def initial_state_of(load, x) -> SearchState:
    """:func:`initial_search_state` of a contact load (a pytree with a ``search(x)`` method),
    compiled: op by op, a grid search compiles each of its hundreds of operations on its own."""
    return initial_search_state(x, load.search)


def refreshed(state: SearchState, x, search, half_skin, every: int = 0) -> SearchState:
    """``state`` advanced by one call: the table rebuilt (``lax.cond``) when the points may have
    moved against each other by more than the skin (:func:`moved_beyond` with ``half_skin``, m)
    since the last refresh, or, with ``every`` > 0 (static), ``every`` calls have passed. The
    criterion alone keeps every pair that can touch among those looked at; ``every`` only bounds
    how stale the choice of the nearest ``k`` may grow (the default 0: never by count)."""
    due = moved_beyond(x, state.x_ref, half_skin)
    if every > 0:
        due = due | (state.step - state.last >= every)
    due = any_member(due)  # in a batch of runs: one search for all, a branch rather than both (jaxform.batching)

    def fresh():
        return SearchState(search(x), state.step, x, state.step, state.refreshes + 1)

    new = jax.lax.cond(due, fresh, lambda: state)
    return new._replace(step=state.step + 1)
