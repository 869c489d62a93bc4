"""Normal contact integrated backward: a penalty whose stiffness does not limit the explicit step.

An explicit penalty ``k`` (Pa/m) on a node of areal mass ``rho_A`` oscillates at ``omega^2 = k /
rho_A`` and, stacked four deep, takes ``4 k dt^2 / rho_A`` of the step's budget: on coarse meshes it,
not the fabric, sets the step (woven Case A at 8 mm: 1.75e-5 s against the shell's 2.36e-5 s; Case B,
clamped at 1e5 Pa: 6.9e-6 s). Here the normal force of each contact *row* acts at the end of the
step instead (linearly implicit, the same place as the backward friction of :mod:`jaxform.friction`).

A row is a contact between up to ``K`` nodes along a unit normal ``n``: a node against a rigid tool
(``K = 1``), a node against its point on a triangle (``K = 4``: the node with weight 1, the
triangle's nodes with minus their barycentric weights), an edge against an edge (``K = 4``: ``1 -
s, s, -(1 - t), -t``). Its normal velocity is ``u = (sum_i w_i v_i - v_tool) . n`` and its gap at the
start of the step ``g`` (negative: penetration). The pressure is the penalty law at the *end* of the
step, ``p(u) = k (-(g + dt u)) - c u`` (clamped >= 0), with ``u`` the end-of-step normal velocity.
With the trial momentum ``P`` (every other force applied, :mod:`jaxform.model`) and the row's mass
``m_r``, ``u = u* + h A p(u) / m_r``, linear in ``u``, so in closed form::

    F = A max(p(u*), 0) / (1 + h A (k dt + c) / m_r)

(``u*`` the trial normal velocity; ``F`` the row's normal force, N). For one node on a tool this is
the central-difference step with the spring at ``x_{n+1}``: its amplification has modulus
``1 / sqrt(1 + k dt^2 / rho_A)`` for any ``k``, so it never limits the step, and it damps the
contact's own ringing (the stiffer, the more), which the quasi-static runs want. At rest the
pressure is exactly ``k delta``: the static penetration is the explicit penalty's.

Rows that share a node are solved together (Jacobi) with *split masses*: row ``r`` may use, of
node ``i``, the share ``|w_ri| / S_i`` of its mass, ``S_i = sum over the active rows of |w_ri|``
(the rows whose trial pressure is positive), so ``1 / m_r = sum_i |w_ri| S_i / m_i``. By Cauchy-
Schwarz ``sum_r m_r (a_r . v)^2 <= v^T M v``: the rows' correction of the momentum together never
exceeds what the lumped masses hold, so the update is a contraction in the kinetic-energy norm
however many rows press a node (a fold several layers deep, the plies of a stack). Loads act one
after the other (the integrator's order), each on the momentum the previous left.

With a fibre mass (:mod:`jaxform.fibre_mass`) the solve uses the lumped masses, as the backward
friction does. Differentiable (``max`` at the contact's edge, like the explicit penalty).
"""
from __future__ import annotations

import jax.numpy as jnp


def row_forces(p, mass, h, dt, nodes, weights, normal, gap, area, stiffness, damping, velocity=None):
    """The rows' normal forces at the end of the step (module docstring).

    Args:
        p: (N, 3) trial momenta at the end of the step, kg·m/s; mass: (N,) lumped masses, kg.
        h: () the step over which the force acts (half a step on the first), s; dt: () the step
            that moves the positions, s.
        nodes: (R, K) int node indices of each row; weights: (R, K) their weights ``w`` (0 for an
            unused slot); both ``None``: row ``r`` is node ``r`` alone with weight 1 (``R = N``: a
            node on a rigid tool), the same arithmetic without the gathers and the scatter-adds
            (woven Case A at 4 mm, three tools: a whole run 148.3 s through them, 125.4 s without).
        normal: (R, 3) unit normals (the force on the row's first node points along it).
        gap: (R,) gaps at the start of the step, m; area: (R,) areas, m² (0: the row is off).
        stiffness: () penalty ``k``, Pa/m; damping: () normal damping ``c``, Pa·s/m.
        velocity: optional (R, 3) velocity of the other side (a moving tool), m/s.

    Returns:
        ``(F (R,) N >= 0, force (N, 3) N)``: each row's normal force and their sum on the nodes
        (``F w_ri n_r`` on node ``i``).
    """
    m = jnp.asarray(mass, p.dtype)
    v = p / m[:, None]
    one = nodes is None  # one node a row, weight 1: w = S_i = 1 where the row is on, so 1 / m_r = 1 / m_r's node
    if one:
        u_star = jnp.sum(v * normal, axis=1)
    else:
        vn = jnp.einsum("rkc,rc->rk", v[nodes], normal)  # (R, K) each node's velocity along the row's normal
        u_star = jnp.sum(weights * vn, axis=1)
    if velocity is not None:
        u_star = u_star - jnp.sum(velocity * normal, axis=1)
    p_star = -stiffness * (gap + dt * u_star) - damping * u_star
    on = (p_star > 0) & (area > 0)
    if one:
        inv_m = jnp.where(on, 1.0 / m, 0.0)
    else:
        aw = jnp.where(on[:, None], jnp.abs(weights), 0.0)
        split = jnp.zeros_like(m).at[nodes.reshape(-1)].add(aw.reshape(-1))  # S_i
        inv_m = jnp.sum(aw * split[nodes] / m[nodes], axis=1)  # 1 / m_r (0 for rows that are off)
    f = jnp.where(on, area * p_star / (1.0 + h * area * (stiffness * dt + damping) * inv_m), 0.0)
    if one:
        return f, f[:, None] * normal
    force = jnp.zeros_like(p).at[nodes.reshape(-1)].add(
        ((f[:, None] * weights)[:, :, None] * normal[:, None, :]).reshape(-1, 3))
    return f, force


def pair_rows(slave, masters, w, normal, gap, area):
    """The rows of slave nodes (S,) against their points on master faces (``masters`` (S, 3) int,
    barycentric ``w`` (S, 3)), normals (S, 3) from the face to the node: ``(nodes (S, 4), weights
    (S, 4), normal, gap (S,), area (S,))`` for :func:`row_forces`."""
    nodes = jnp.concatenate([jnp.asarray(slave)[:, None], masters], axis=1)
    return nodes, jnp.concatenate([jnp.ones_like(w[:, :1]), -w], axis=1), normal, gap, area


__all__ = ["row_forces", "pair_rows"]
