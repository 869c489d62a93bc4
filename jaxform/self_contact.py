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

Candidates come from the cell grid of :mod:`jaxform.broadphase`, refreshed when a node has moved
by half the skin. Differentiable where it is smooth, like the tool contact; the side and the
candidate table are integers of the state (no gradient).
"""
from __future__ import annotations

from typing import Any

import jax.numpy as jnp
import numpy as np

from jaxform import broadphase
from jaxform._pytree import pytree_dataclass, static_field
from jaxform.contact import ply_contact
from jaxform.geometry import closest_point_triangle, point_triangle_sqdist

__all__ = ["SelfContactLoad", "self_contact_load"]


@pytree_dataclass
class SelfContactLoad:
    """Two-sided fabric–fabric contact of all nodes against all triangles, as an external load.

    ``load_state`` is a :class:`jaxform.broadphase.SearchState`; with ``slave``, ``triangles``,
    ``gap0``, ``area``, ``params`` and ``load_state[0]`` it evaluates like a
    :class:`jaxform.contact.PlyLoad` (:func:`jaxform.contact.ply_contact`).

    Attributes:
        slave: (N,) int32 all nodes; triangles: (F, 3) int32 all triangles; gap0: () contact
            distance h, m; area: (N,) half the tributary area, m²; params: ContactParams.
        group: (N,) int32 ply of each node; tri_group: (F,) int32 ply of each triangle.
        pair_ok: (G, G) bool: plies whose nodes and triangles may touch here.
        x0: (N, 3) reference positions, m; c0: (F, 3) reference centroids, m;
        exclusion: () own-neighbourhood distance, m.
        fallback: (N,) int32 a triangle each node may touch, far away in the reference.
        skin: () m; k, refresh_every, cap: static ints.
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
    skin: Any
    k: int = static_field(default=8)
    refresh_every: int = static_field(default=200)
    cap: int = static_field(default=32)

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

    def search(self, x):
        """``(candidates (N, k) int32 with sides, overflow ())`` for positions ``x`` (N, 3)."""
        tri_x = x[self.triangles]
        ids, _, over = broadphase.candidates(x, tri_x, self.k, self.gap0 + self.skin, mask=self.plausible,
                                             refine=self.allowed, fallback=self.fallback, cap=self.cap)
        t = tri_x[ids]  # (N, k, 3, 3)
        q, _ = closest_point_triangle(x[:, None, :], t[..., 0, :], t[..., 1, :], t[..., 2, :])
        nrm = jnp.cross(t[..., 1, :] - t[..., 0, :], t[..., 2, :] - t[..., 0, :])
        front = jnp.sum((x[:, None, :] - q) * nrm, axis=-1) >= 0
        return jnp.where(front, ids, ~ids).astype(jnp.int32), over

    def initial_state(self, x):
        """The load state for the initial positions ``x`` (N, 3)."""
        return broadphase.initial_search_state(jnp.asarray(x), self.search)

    def force(self, x, v, t, load_state):
        st = broadphase.refreshed(load_state, x, self.search, 0.5 * self.skin, self.refresh_every)
        res = ply_contact(x, v, self.slave, self.triangles, st.candidates, self.gap0, self.area, self.params)
        extras = {"contact_energy": res.energy, "friction_power": res.friction_power,
                  "max_pressure": jnp.max(res.pressure), "refreshes": st.refreshes, "search_overflow": st.overflow,
                  "min_gap": jnp.min(res.gap)}
        return res.force, st, extras


def self_contact_load(x0, tris, node_area, group, thickness, params, *, pair_ok=None, exclusion=None,
                      skin=None, k: int = 8, refresh_every: int = 200, cap: int = 32, dtype=jnp.float32):
    """Build a :class:`SelfContactLoad` on the host from the reference mesh.

    Args:
        x0: (N, 3) reference positions, m; tris: (F, 3) int triangles (all plies);
        node_area: (N,) tributary areas, m²; group: (N,) int ply of each node (0- or 1-based);
        thickness: ply thickness h, m (the contact distance); params: ContactParams (fabric–fabric).
        pair_ok: (G, G) bool plies allowed to touch (default all; index by ``group``).
        exclusion: own-neighbourhood distance, m (default ``2 h``).
        skin: search margin beyond ``h``, m (default ``h``): refresh when a node moved ``skin / 2``.
        k, refresh_every, cap: see :class:`SelfContactLoad`.
    """
    x0 = np.asarray(x0, np.float64)
    tris = np.asarray(tris, np.int64)
    group = np.asarray(group, np.int64)
    h = float(thickness)
    n_groups = int(group.max()) + 1
    ok = np.ones((n_groups, n_groups), bool) if pair_ok is None else np.asarray(pair_ok, bool)
    c0 = x0[tris].mean(axis=1)
    tg = group[tris[:, 0]]
    # fallback: of the four extreme triangles of the node's own ply (corners of the blank), the
    # farthest from the node in the reference
    fallback = np.zeros(len(x0), np.int64)
    best = np.full(len(x0), -1.0)
    for g in np.unique(group):
        ids = np.nonzero(tg == g)[0]
        nodes = np.nonzero(group == g)[0]
        for s in ((1, 1), (1, -1), (-1, 1), (-1, -1)):
            t = ids[np.argmax(s[0] * c0[ids, 0] + s[1] * c0[ids, 1])]
            d = np.linalg.norm(x0[nodes] - c0[t], axis=1)
            better = d > best[nodes]
            best[nodes[better]] = d[better]
            fallback[nodes[better]] = t
    as_f = lambda a: jnp.asarray(a, dtype)  # noqa: E731
    return SelfContactLoad(
        slave=jnp.arange(len(x0), dtype=jnp.int32), triangles=jnp.asarray(tris, jnp.int32), gap0=as_f(h),
        area=as_f(0.5 * np.asarray(node_area, np.float64)), params=params, group=jnp.asarray(group, jnp.int32),
        tri_group=jnp.asarray(tg, jnp.int32), pair_ok=jnp.asarray(ok), x0=as_f(x0), c0=as_f(c0),
        exclusion=as_f(2.0 * h if exclusion is None else exclusion), fallback=jnp.asarray(fallback, jnp.int32),
        skin=as_f(h if skin is None else skin), k=k, refresh_every=refresh_every, cap=cap)
