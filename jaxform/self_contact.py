"""Self-contact of the fabric: every ply with itself and with the plies not next to it (issue 19).

A fold must lie on itself, not pass through itself. :class:`SelfContactLoad` is the stack
contact of :func:`jaxform.contact.ply_contact` (the one node-to-surface kernel: penalty and
regularised Coulomb friction, ``mu`` fabric–fabric) applied to every node against every triangle
of the blank, with three differences:

* two-sided: the side a node is on is stored with each candidate when the table is built (a
  candidate ``~t`` is triangle ``t`` seen from its back), so a layer is pushed back to the side it
  came from; the contact distance is the ply thickness ``h`` (mid-surface to mid-surface);
* symmetric: every node is a slave, so both layers of a fold push on each other; each pass acts
  with half the node's tributary area, the two together with the stiffness of one contact;
* own neighbourhood excluded: a node never touches the triangles of its own ply closer than
  ``exclusion`` (default ``2 h``) to it in the reference configuration, its own triangles
  included: ordinary bending is not contact. On a fine mesh (elements below ``h``) that is the
  arc of a hairpin fold of radius ``h / 2`` (``pi h / 2`` long), on a coarse one just the
  triangles around the node, so a fold one element wide is still held apart. Pairs of
  neighbouring plies of a stack are left to their :class:`jaxform.contact.PlyLoad`.
* edge against edge as well (:func:`edge_contact`): the distance between two triangles is the
  least of their vertex–face and edge–edge distances, and on a coarse mesh a fold kinks within
  one element, where an edge passes through the other layer's edge with both its ends well away
  from that layer (the one-element kinks of Case A at 4 mm: ends 1–9 h from the face crossed).
  Each edge is a slave against its nearest edge (not sharing a node, not in its reference
  neighbourhood), pushed apart along the line of the closest points below ``h`` (the edges as
  cylinders of diameter ``h``, as in explicit codes' edge-to-edge shell contact): unsigned, a
  conservative penalty (force ``-grad`` of the energy, linear and angular momentum kept),
  without friction (sliding friction of a layer on a layer is the node–face contact's), each
  pass with half of the edge's share (a third of each triangle beside it) of the area.

The node-to-face friction is integrated backward, as between the plies of a stack
(:meth:`SelfContactLoad.friction`: no stick limit), each of a fold's two passes solving half of
each pair.

Candidates come from the cell grid of :mod:`jaxform.broadphase`, refreshed when the nodes may
have moved against each other by the skin. Differentiable where it is smooth, like the tool
contact; the side and the candidate table are integers of the state (no gradient).
"""
from __future__ import annotations

import dataclasses
from typing import Any, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from jaxform import broadphase
from jaxform._pytree import pytree_dataclass, static_field
from jaxform.batching import any_member
from jaxform import backward_normal
from jaxform.contact import ContactResult, force_params, node_contact, pair_forces, ply_contact
from jaxform.friction import backward_pair_friction
from jaxform.geometry import (closest_point_triangle, closest_points_segments, point_triangle_sqdist, safe_norm,
                              safe_normalize, segments_sqdist)

__all__ = ["SelfContactLoad", "Candidates", "self_contact_load", "edge_contact", "mesh_edges", "near_edges"]


class Candidates(NamedTuple):
    """The self-contact's candidate table (fixed shapes), rebuilt with the search.

    Attributes:
        nodes: (N, k) int32 triangles per node (``~t``: triangle ``t`` from its back).
        edges: (E, edge_k) int32 edges per edge.
        active_nodes: (A,) int32, active_edges: (B,) int32: the nodes and edges with a candidate
            within ``h + skin`` at the refresh, -1 padded: the only ones that can touch before the
            next (the Verlet criterion), so the only ones evaluated each step.
        overflow: () bool more of them than ``A`` or ``B``: then every node and edge is evaluated.
    """

    nodes: Any
    edges: Any
    active_nodes: Any
    active_edges: Any
    overflow: Any


def near_edges(x0, edges, group, exclusion, *, chunk: int = 1 << 18) -> np.ndarray:
    """(E, X) int32, -1 padded (X >= 1): for each edge of ``edges`` (E, 2) int on nodes ``x0``
    (N, 3) m, the edges of its own ply (``group`` (E,) int) closer than ``exclusion`` (m) that
    share no node with it: the pairs self-contact ignores (ordinary bending is not contact).
    Host: a k-d tree on the edge midpoints (radius ``exclusion`` plus the longest edge), then the
    exact segment distance of the pairs it returns."""
    from scipy.spatial import cKDTree

    x0, edges, group = np.asarray(x0, np.float64), np.asarray(edges, np.int64), np.asarray(group)
    mid = x0[edges].mean(axis=1)
    length = np.linalg.norm(x0[edges[:, 1]] - x0[edges[:, 0]], axis=1)
    pairs = cKDTree(mid).query_pairs(float(exclusion) + float(length.max()), output_type="ndarray")
    keep = group[pairs[:, 0]] == group[pairs[:, 1]]
    keep &= ~np.any(edges[pairs[:, 0]][:, :, None] == edges[pairs[:, 1]][:, None, :], axis=(1, 2))
    pairs = pairs[keep]
    # padded to a power of two: a handful of compiled shapes serve every mesh (a compile per mesh
    # cost 0.2-0.6 s per rig built)
    size = min(chunk, max(4096, 1 << int(np.ceil(np.log2(max(len(pairs), 1))))))
    padded = np.zeros((-(-len(pairs) // size) * size, 2), np.int64)
    padded[:len(pairs)] = pairs
    d2 = np.concatenate([np.asarray(_segments_sqdist_host(*(x0[edges[padded[i:i + size, j], c]] for j in (0, 1)
                                                                   for c in (0, 1))))
                         for i in range(0, len(padded), size)] or [np.zeros(0)])[:len(pairs)]
    pairs = pairs[d2 < float(exclusion) ** 2]
    both = np.concatenate([pairs, pairs[:, ::-1]]) if len(pairs) else np.zeros((0, 2), np.int64)
    count = np.bincount(both[:, 0], minlength=len(edges))
    out = np.full((len(edges), max(1, int(count.max(initial=0)))), -1, np.int32)
    order = np.argsort(both[:, 0], kind="stable")
    both = both[order]
    slot = np.arange(len(both)) - np.repeat(np.cumsum(count) - count, count)
    out[both[:, 0], slot] = both[:, 1]
    return out


_segments_sqdist_host = jax.jit(segments_sqdist)


def _compact(mask, size: int):
    """``(ids (size,) int32, -1 padded; overflow () bool)``: the indices where ``mask`` holds."""
    ids = jnp.nonzero(mask, size=size, fill_value=-1)[0].astype(jnp.int32)
    return ids, jnp.sum(mask) > size


def _edge_pair(pa, va, qb, vb, gap0, area, params):
    """One edge (ends ``pa`` (2, 3), velocities ``va``) against its K candidate edges ``qb``, ``vb``
    (K, 2, 3): the nearest pushed apart along the line of closest points."""
    s, t = closest_points_segments(pa[0], pa[1], qb[:, 0], qb[:, 1])
    ca = pa[0] + s[:, None] * (pa[1] - pa[0])
    cb = qb[:, 0] + t[:, None] * (qb[:, 1] - qb[:, 0])
    j = jnp.argmin(jnp.sum((ca - cb) ** 2, axis=-1))
    s, t, d = s[j], t[j], ca[j] - cb[j]
    v_rel = (1.0 - s) * va[0] + s * va[1] - (1.0 - t) * vb[j, 0] - t * vb[j, 1]
    n = safe_normalize(d)
    f, p, g, e, _ = node_contact(safe_norm(d), n, v_rel, gap0, area, params)
    return f, s, t, j, p, g, e, n


def edge_contact(x, v, edges, candidates, gap0, area, params, slave=None, rows: bool = False):
    """Edge-to-edge contact: each edge of ``edges`` (E, 2) int (or of its subset ``slave`` (S,)
    int) against the nearest of its ``candidates`` (E or S, K) int edges, pushed apart below the
    distance ``gap0`` (m) along the line of the closest points, with the penalty and normal
    damping of ``params`` (friction ignored).

    Args:
        x, v: (N, 3) node positions (m) and velocities (m/s); area: () or (E or S,) m² per edge.

    Returns:
        :class:`jaxform.contact.ContactResult` with ``force`` (N, 3), ``pressure``/``gap`` (E or S,);
        with ``rows``, also ``(nodes (E or S, 4) int, weights (E or S, 4), normal (E or S, 3))``: each
        edge's contact as a row of :func:`jaxform.backward_normal.row_forces`.
    """
    edges = jnp.asarray(edges)
    e = edges if slave is None else edges[slave]
    cand = jnp.asarray(candidates)
    area = jnp.broadcast_to(jnp.asarray(area, x.dtype), e.shape[:1])
    nofric = dataclasses.replace(params, friction=0.0)
    eb = edges[cand]  # (E, K, 2)
    f, s, t, j, p, g, en, nrm = jax.vmap(_edge_pair, in_axes=(0, 0, 0, 0, None, 0, None))(
        x[e], v[e], x[eb], v[eb], jnp.asarray(gap0, x.dtype), area, nofric)
    other = jnp.take_along_axis(eb, j[:, None, None], axis=1)[:, 0]  # (E, 2)
    w = jnp.stack([1.0 - s, s, t - 1.0, -t], axis=1)  # a0, a1 get +f; b0, b1 get -f
    idx = jnp.concatenate([e, other], axis=1)
    force = jnp.zeros_like(x).at[idx.reshape(-1)].add((w[:, :, None] * f[:, None, :]).reshape(-1, 3))
    res = ContactResult(force=force, reaction=jnp.zeros(3, x.dtype), pressure=p, gap=g, energy=jnp.sum(en),
                        friction_power=jnp.zeros((), x.dtype))
    return (res, (idx, w, nrm)) if rows else res


def mesh_edges(tris, tri_area):
    """``(edges (E, 2) int64, share (E,), tri_edges (F, 3) int64)``: the unique edges of triangles
    ``tris`` (F, 3), a third of the area ``tri_area`` (F,) of each triangle beside them (shares sum
    to the area), and the edges of each triangle."""
    tris = np.asarray(tris, np.int64)
    all_e = np.sort(np.concatenate([tris[:, [0, 1]], tris[:, [1, 2]], tris[:, [2, 0]]]), axis=1)
    edges, inv = np.unique(all_e, axis=0, return_inverse=True)
    share = np.bincount(inv.reshape(-1), weights=np.tile(np.asarray(tri_area, np.float64) / 3.0, 3),
                        minlength=len(edges))
    return edges, share, inv.reshape(3, -1).T


@pytree_dataclass
class SelfContactLoad:
    """Two-sided fabric–fabric contact of all nodes against all triangles, as an external load.

    ``load_state`` is a :class:`jaxform.broadphase.SearchState` whose ``candidates`` are
    :class:`Candidates`; with ``slave``, ``triangles``, ``gap0``, ``area``, ``params`` and
    ``load_state.candidates.nodes`` its node-to-face part evaluates like a
    :class:`jaxform.contact.PlyLoad` (:func:`jaxform.contact.ply_contact`).

    Attributes:
        slave: (N,) int32 all nodes; triangles: (F, 3) int32 all triangles; gap0: () contact
            distance h, m; area: (N,) half the tributary area, m²; params: ContactParams.
        group: (N,) int32 ply of each node; tri_group: (F,) int32 ply of each triangle.
        pair_ok: (G, G) bool: plies whose nodes and triangles may touch here.
        x0: (N, 3) reference positions, m; c0: (F, 3) reference centroids, m;
        exclusion: () own-neighbourhood distance, m.
        fallback: (N,) int32 a triangle each node may touch, far away in the reference.
        edges: (E, 2) int32 the edges of ``triangles``; edge_area: (E,) half their area share, m²;
        edge_group: (E,) int32 ply; edge_fallback: (E,) int32 a far edge of the same ply;
        edge_near: (E, X) int32 the edges of the same ply closer than ``exclusion`` to each edge in
            the reference and sharing no node with it, -1 padded (:func:`near_edges`, host-built:
            a fixed table, so a refresh tests membership instead of reference distances);
        tri_edges: (F, 3) int32 the edges of each triangle.
        skin: () m; k (candidate triangles per node), edge_k (candidate edges per edge),
        refresh_every, cap, active_cap, edge_active_cap (room in :class:`Candidates`): static ints.
        implicit_friction: static; ``True`` (default): the node-to-face friction is integrated
            backward (:meth:`backward`); ``False``: the explicit law with ``params.stick_limit``.
        implicit_normal: static; ``True``: the normal forces too act at the end of the step
            (:meth:`backward`, :mod:`jaxform.backward_normal`), the friction with them backward.
    """

    slave: Any
    triangles: Any
    gap0: Any
    area: Any
    params: Any
    group: Any
    tri_group: Any
    pair_ok: Any
    x0: Any
    c0: Any
    exclusion: Any
    fallback: Any
    edges: Any
    edge_area: Any
    edge_group: Any
    edge_fallback: Any
    edge_near: Any
    tri_edges: Any
    skin: Any
    k: int = static_field(default=8)
    edge_k: int = static_field(default=4)
    active_cap: int = static_field(default=1024)
    edge_active_cap: int = static_field(default=3072)
    refresh_every: int = static_field(default=0)
    cap: int = static_field(default=8)
    implicit_friction: bool = static_field(default=True)
    implicit_normal: bool = static_field(default=False)

    def plausible(self, nodes, tris):
        """(B, M) bool, cheap: the plies may touch and the reference centroid is not closer than
        ``exclusion`` (the closest point is no farther than the centroid)."""
        g, tg = self.group[nodes][:, None], self.tri_group[tris]
        d2 = jnp.sum((self.x0[nodes][:, None, :] - self.c0[tris]) ** 2, axis=-1)
        return self.pair_ok[g, tg] & ~((g == tg) & (d2 < self.exclusion**2))

    def allowed(self, nodes, tris):
        """(B, M) bool: node ``nodes`` (B,) may touch triangle ``tris`` (B, M)."""
        g, tg = self.group[nodes][:, None], self.tri_group[tris]
        t0 = self.x0[self.triangles[tris]]  # (B, M, 3, 3)
        d2 = point_triangle_sqdist(self.x0[nodes][:, None, :], t0[..., 0, :], t0[..., 1, :], t0[..., 2, :])
        near = (g == tg) & (d2 < self.exclusion**2)
        return self.pair_ok[g, tg] & ~near

    def _seg_d2(self, x, a, b):
        """(B, M) squared distances at ``x`` (N, 3) of edges ``a`` (B,) and ``b`` (B, M), m²
        (structure of arrays: a trailing axis of 3 does not vectorise on CPU)."""
        xs = x.T
        ea, eb = self.edges[a], self.edges[b]  # (B, 2), (B, M, 2)
        return segments_sqdist(xs[:, ea[:, 0]][:, :, None], xs[:, ea[:, 1]][:, :, None], xs[:, eb[..., 0]],
                               xs[:, eb[..., 1]], axis=0)

    def edge_allowed(self, a, b):
        """(B, M) bool: edges ``a`` (B,) and ``b`` (B, M) may touch: their plies may, they share no
        node, and they are not closer than ``exclusion`` in the reference (same ply: not in
        ``edge_near``)."""
        ea, eb = self.edges[a][:, None, :, None], self.edges[b][:, :, None, :]
        g, gb = self.edge_group[a][:, None], self.edge_group[b]
        near = jnp.any(b[..., None] == self.edge_near[a][:, None, :], axis=-1)
        return self.pair_ok[g, gb] & ~jnp.any(ea == eb, axis=(2, 3)) & ~near

    def edge_candidates(self, x, node_ids):
        """``(ids (E, edge_k) int32, d2 (E,))``: for each edge, the nearest (exact distance at ``x``
        (N, 3)) of the edges of the triangles that are candidates (``node_ids`` (N, k), unsided) of
        its two ends, and its squared distance to the nearest, m²: the node search's grid serves
        the edges too (an edge within reach of another lies in a triangle near one of its ends)."""
        e = jnp.arange(self.edges.shape[0], dtype=jnp.int32)
        tri = node_ids[self.edges].reshape(e.shape[0], -1)  # (E, 2k)
        cand = self.tri_edges[tri].reshape(e.shape[0], -1)  # (E, 6k)
        d2 = jnp.where(self.edge_allowed(e, cand), self._seg_d2(x, e, cand), jnp.inf)
        neg, j = jax.lax.top_k(-d2, self.edge_k)
        best = jnp.take_along_axis(cand, j, axis=1)
        return jnp.where(jnp.isfinite(neg), best, self.edge_fallback[:, None]).astype(jnp.int32), -neg[:, 0]

    def search(self, x):
        """:class:`Candidates` for positions ``x`` (N, 3)."""
        tri_x = x[self.triangles]
        ids, _ = broadphase.candidates(x, tri_x, self.k, self.gap0 + self.skin, mask=self.plausible,
                                       refine=self.allowed, fallback=self.fallback, cap=self.cap)
        eids, e_d2 = self.edge_candidates(x, ids)
        t = tri_x[ids]  # (N, k, 3, 3)
        q, _ = closest_point_triangle(x[:, None, :], t[..., 0, :], t[..., 1, :], t[..., 2, :])
        nrm = jnp.cross(t[..., 1, :] - t[..., 0, :], t[..., 2, :] - t[..., 0, :])
        front = jnp.sum((x[:, None, :] - q) * nrm, axis=-1) >= 0
        reach2 = (self.gap0 + self.skin) ** 2
        act_n, full_n = _compact(jnp.min(jnp.sum((x[:, None, :] - q) ** 2, axis=-1), axis=1) <= reach2, self.active_cap)
        act_e, full_e = _compact(e_d2 <= reach2, self.edge_active_cap)
        return Candidates(jnp.where(front, ids, ~ids).astype(jnp.int32), eids, act_n, act_e, full_n | full_e)

    def initial_state(self, x):
        """The load state for the initial positions ``x`` (N, 3)."""
        return broadphase.initial_state_of(self, jnp.asarray(x))

    def node_pressure(self, x, v, load_state):
        """``(slave (N,) int, pressure (N,) Pa)``: the node-to-face contact pressure at the state's
        candidates (the nodal contact-pressure field of a frame; edge pairs carry no nodal pressure)."""
        res = ply_contact(x, v, self.slave, self.triangles, load_state.candidates.nodes, self.gap0, self.area,
                          self.params)
        return self.slave, res.pressure

    def force(self, x, v, t, load_state):
        st = broadphase.refreshed(load_state, x, self.search, 0.5 * self.skin, self.refresh_every)
        c = st.candidates

        def part(nodes, edges):  # the contacts of these nodes and edges (-1: a padding slot)
            wn, we = nodes >= 0, edges >= 0
            nodes, edges = jnp.maximum(nodes, 0), jnp.maximum(edges, 0)
            res, (f_n, masters, w, nrm) = ply_contact(x, v, nodes, self.triangles, c.nodes[nodes], self.gap0,
                                                      self.area[nodes] * wn, force_params(self), pairs=True)
            ee, (e_nodes, e_w, e_nrm) = edge_contact(x, v, self.edges, c.edges[edges], self.gap0,
                                                     self.edge_area[edges] * we, self.params, slave=edges, rows=True)
            inf = jnp.asarray(jnp.inf, x.dtype)
            extras = {
                "contact_energy": res.energy + ee.energy, "friction_power": res.friction_power,
                "max_pressure": jnp.maximum(jnp.max(res.pressure * wn), jnp.max(ee.pressure * we)),
                "min_gap": jnp.min(jnp.where(wn, res.gap, inf)), "min_edge_gap": jnp.min(jnp.where(we, ee.gap, inf))}
            # the pairs by slave node and edge, whatever the room (the rooms' shapes differ); padding slots dropped
            at, at_e = jnp.where(wn, nodes, x.shape[0]), jnp.where(we, edges, self.edges.shape[0])

            def by(ids, n, a):
                return jnp.zeros((n,) + a.shape[1:], a.dtype).at[ids].set(a, mode="drop")

            n, ne = x.shape[0], self.edges.shape[0]
            if self.implicit_normal:
                nodes4, w4, _, gap, area = backward_normal.pair_rows(nodes, masters, w, nrm, res.gap, self.area[nodes] * wn)
                extras["backward_support"] = (
                    tuple(by(at, n, a) for a in (nodes4, w4, nrm, gap, area)),
                    tuple(by(at_e, ne, a) for a in (e_nodes, e_w, e_nrm, ee.gap, self.edge_area[edges] * we)))
                return jnp.zeros_like(x), extras
            if self.implicit_friction:
                extras["backward_support"] = tuple(by(at, n, a) for a in (f_n, masters, w))
            return res.force + ee.force, extras

        # the smallest of three rooms that holds the active nodes and edges: one slot (none active: a
        # flat or smoothly bent ply), the active lists, or everything when they overflow (each room is
        # one more compiled copy of the contact: a fourth, an eighth of the lists, cost 16 % more
        # compile time for little); in a batch of runs every member takes the larger room when one
        # needs it (jaxform.batching)
        none = ~any_member(~((c.active_nodes[1] < 0) & (c.active_edges[1] < 0)))
        f, extras = jax.lax.cond(
            any_member(c.overflow), lambda: part(self.slave, jnp.arange(self.edges.shape[0])),
            lambda: jax.lax.cond(none, lambda: part(c.active_nodes[:1], c.active_edges[:1]),
                                 lambda: part(c.active_nodes, c.active_edges)))
        extras.update(refreshes=st.refreshes, active_overflow=c.overflow.astype(jnp.int32))
        return f, st, extras

    def backward(self, support, p, mass, h, dt, extras, load_state):
        """This step's contact integrated backward (the integrator's hook, :mod:`jaxform.model`):
        ``(force (N, 3) N, extras, load_state)``. With ``implicit_normal`` the normal forces of the
        node-to-face and edge-to-edge rows, solved together (:func:`jaxform.backward_normal.row_forces`:
        the two passes of a fold and its edges share the nodes' masses); then the node-to-face friction,
        :func:`jaxform.friction.backward_pair_friction` on each node and its point on the other layer.
        Both layers of a fold are slaves of each other's faces (two passes, each with half the normal
        force), so each pass solves with half the pair's mass (``share = 1/2``): together they stop a
        stuck slip in the step, not reverse it. Skipped (``lax.cond``) while no node touches."""
        zero = (jnp.zeros_like(p), jnp.zeros((), p.dtype))

        def friction(p, f_normal, masters, w):
            f, pw = backward_pair_friction(p, mass, h, self.slave, masters, w, f_normal, self.params.friction,
                                           self.params.slip_velocity, share=0.5)
            return pair_forces(p, self.slave, masters, w, f), jnp.sum(pw)

        if not self.implicit_normal:
            f_normal, masters, w = support
            force, power = jax.lax.cond(any_member(jnp.any(f_normal != 0)), lambda: friction(p, f_normal, masters, w),
                                        lambda: zero)
            return force, dict(extras, friction_power=power), load_state
        (nodes, w4, nrm, gap, area), (e_nodes, e_w, e_nrm, e_gap, e_area) = support

        def solve():
            rows = [jnp.concatenate(a) for a in ((nodes, e_nodes), (w4, e_w), (nrm, e_nrm), (gap, e_gap), (area, e_area))]
            F, f_n = backward_normal.row_forces(p, mass, h, dt, *rows, self.params.stiffness, self.params.damping)
            f_fr, power = friction(p + h * f_n, F[:nodes.shape[0], None] * nrm, nodes[:, 1:], -w4[:, 1:])
            return f_n + f_fr, power

        force, power = jax.lax.cond(any_member(jnp.any(area > 0) | jnp.any(e_area > 0)), solve, lambda: zero)
        return force, dict(extras, friction_power=power), load_state


def self_contact_load(x0, tris, node_area, group, thickness, params, *, pair_ok=None, exclusion=None,
                      skin=None, k: int = 8, edge_k: int = 4, refresh_every: int = 0, cap: int = 8,
                      active_fraction: float = 0.125, implicit_friction: bool = True, implicit_normal: bool = False,
                      dtype=jnp.float32):
    """Build a :class:`SelfContactLoad` on the host from the reference mesh.

    Args:
        x0: (N, 3) reference positions, m; tris: (F, 3) int triangles (all plies);
        node_area: (N,) tributary areas, m²; group: (N,) int ply of each node (0- or 1-based);
        thickness: ply thickness h, m (the contact distance); params: ContactParams (fabric–fabric).
        pair_ok: (G, G) bool plies allowed to touch (default all; index by ``group``).
        exclusion: own-neighbourhood distance, m (default ``2 h``).
        skin: search margin beyond ``h``, m (default ``h``): refresh when the nodes may have moved
            against each other by ``skin`` (:func:`jaxform.broadphase.refreshed`).
        k, edge_k, refresh_every, cap: see :class:`SelfContactLoad`.
        active_fraction: room for the nodes and edges near a candidate at a refresh (evaluated each
            step; when more are near, all are evaluated).
        implicit_friction, implicit_normal: see :class:`SelfContactLoad`.
    """
    x0 = np.asarray(x0, np.float64)
    tris = np.asarray(tris, np.int64)
    group = np.asarray(group, np.int64)
    h = float(thickness)
    n_groups = int(group.max()) + 1
    ok = np.ones((n_groups, n_groups), bool) if pair_ok is None else np.asarray(pair_ok, bool)
    c0 = x0[tris].mean(axis=1)
    tg = group[tris[:, 0]]
    edges, share, tri_edges = mesh_edges(tris, 0.5 * np.linalg.norm(np.cross(x0[tris[:, 1]] - x0[tris[:, 0]],
                                                                  x0[tris[:, 2]] - x0[tris[:, 0]]), axis=1))
    m0 = x0[edges].mean(axis=1)
    eg = group[edges[:, 0]]
    excl = 2.0 * h if exclusion is None else float(exclusion)
    as_f = lambda a: jnp.asarray(a, dtype)  # noqa: E731
    as_i = lambda a: jnp.asarray(a, jnp.int32)  # noqa: E731
    return SelfContactLoad(
        slave=jnp.arange(len(x0), dtype=jnp.int32), triangles=as_i(tris), gap0=as_f(h),
        area=as_f(0.5 * np.asarray(node_area, np.float64)), params=params, group=as_i(group),
        tri_group=as_i(tg), pair_ok=jnp.asarray(ok), x0=as_f(x0), c0=as_f(c0),
        exclusion=as_f(excl), fallback=as_i(_far(x0, group, c0, tg)),
        edges=as_i(edges), edge_area=as_f(0.5 * share), edge_group=as_i(eg),
        edge_fallback=as_i(_far(m0, eg, m0, eg)), edge_near=as_i(near_edges(x0, edges, eg, excl)),
        tri_edges=as_i(tri_edges), skin=as_f(h if skin is None else skin),
        k=k, edge_k=edge_k, refresh_every=refresh_every, cap=cap,
        active_cap=max(64, int(np.ceil(active_fraction * len(x0)))),
        edge_active_cap=max(64, int(np.ceil(active_fraction * len(edges)))), implicit_friction=implicit_friction,
        implicit_normal=implicit_normal)


def _far(p, pg, c, cg):
    """(P,) int: for each point ``p`` (P, 3) of ply ``pg``, the farthest in the reference of the four
    extreme (corner) items of its own ply (centres ``c`` (M, 3), plies ``cg``): a fallback candidate
    that is beyond reach whenever a slot is empty."""
    out = np.zeros(len(p), np.int64)
    best = np.full(len(p), -1.0)
    for g in np.unique(pg):
        ids = np.nonzero(cg == g)[0]
        pts = np.nonzero(pg == g)[0]
        for sx, sy in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
            t = ids[np.argmax(sx * c[ids, 0] + sy * c[ids, 1])]
            d = np.linalg.norm(p[pts] - c[t], axis=1)
            better = d > best[pts]
            best[pts[better]] = d[better]
            out[pts[better]] = t
    return out
