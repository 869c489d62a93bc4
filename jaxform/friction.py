"""Friction laws of the contacts: regularised Coulomb, explicit and integrated backward.

Regularised Coulomb (:func:`regularised_friction`): ``F_t = -mu F_n v_t / sqrt(|v_t|**2 + eps_v**2)``
(:mod:`jaxform.contact` explains its creep and the explicit stick limit of the fabric contacts).

Backward (:func:`backward_friction`, the rigid tools)
    The raised ``eps_v`` gives far less than Coulomb wherever ``mu p n dt / rho_A`` exceeds the slip
    speeds (Case B's clamped flange at 8 mm: 0.28 m/s against 0.03-0.06 m/s of slip, 10-20 % of
    ``mu F_n``). So a :class:`jaxform.contact.ToolLoad` leaves its friction to the integrator
    (its ``friction`` method, :func:`backward_friction`): the same regularised law with the plain
    ``eps_v``, evaluated at the node's *end-of-step* slip velocity, which the node's trial momentum
    (every other force of the step applied) and its lumped mass give in closed form up to one
    scalar equation per node. It is unconditionally stable (no stick limit): a stuck node stops
    within the step, a sliding one feels ``mu F_n``. The tools act one after the other, each on
    the momentum the previous left. With a fibre mass the solve uses the node's lumped mass and its
    momentum (the fibre mass's coupling to the neighbours is not in the solve).
    Between the plies of a stack the same solve acts on each slave node and its point on the other
    ply (:func:`backward_pair_friction`), and in the self-contact of a folded ply
    (:class:`jaxform.self_contact.SelfContactLoad`), whose two passes each solve half a pair.
"""
from __future__ import annotations

import jax
import jax.numpy as jnp

from jaxform.geometry import safe_norm, safe_normalize


def regularised_friction(v_t, normal_force, mu, eps_v):
    """Regularised Coulomb force (3,), N, for slip velocity ``v_t`` (3,) m/s and ``F_n`` >= 0 (N).

    ``-mu F_n v_t / sqrt(|v_t|^2 + eps_v^2)``: magnitude below ``mu F_n``, smooth at zero slip.
    Many nodes in structure of arrays: ``v_t`` (3, N), ``F_n`` and ``eps_v`` (N,) or (), force (3, N).
    """
    return -mu * normal_force * v_t / jnp.sqrt(jnp.sum(v_t * v_t, axis=0) + eps_v * eps_v)


FRICTION_ITERATIONS = 12
"""The most Newton steps :func:`backward_friction` takes (it stops before, :data:`FRICTION_RTOL`):
from its start (:func:`_slip_from_below`) float32 Newton is within 1e-6 of the force from
``a / eps_v = 1e-3`` to ``1e5`` and ``u* / a = 1e-3`` to ``1e3`` after 4 steps."""
FRICTION_RTOL = 16.0
"""Newton stops once no node's slip moves by more than this many units of roundoff
(``jnp.finfo(dtype).eps``) of itself. A converged float32 iteration still steps between two
neighbouring numbers on a few nodes (woven Case A at 4 mm: 2 to 7 nodes at each step sampled),
so an exact fixed point, the stop before, was never reached and the loop ran all its steps; near
the root Newton doubles the digits it has each step, so what this stop leaves is roundoff."""


def _slip_from_below(u_star, a, eps):
    """A lower bound of the end-of-step slip ``u`` of :func:`backward_friction`, close to it in every
    regime (arrays of one shape, m/s): the largest of ``u* - a`` (sliding: the force is below
    ``mu F_n``), ``u* / (1 + a / eps)`` (stick: the law's slope is at most ``mu F_n / eps``) and,
    where the residual is not positive there, ``0.7 eps C sqrt(C / (C + D))`` with ``C = (a /
    (2 eps))**(1/3)`` and ``D = (a - u*) / eps`` (near ``u* = a``, where the other two are far
    below the root: ``1 - u / r >= eps**2 / (2 r**2)`` bounds the root from below by that of
    ``(U + D) (U**2 + 1) = C**3`` in ``U = u / eps``, ``C`` at ``D = 0`` and ``C sqrt(C / D)`` for
    ``D >> C``). From ``max(u* - a, 0)`` alone float32 Newton needed 11 steps at ``u* = a`` and
    ``a / eps = 1e5``; from this, 4 over ``a / eps = 1e-3 .. 1e5`` and ``u* / a = 1e-3 .. 1e3``."""
    below = jnp.maximum(u_star - a, u_star / (1.0 + a / eps))
    c = jnp.cbrt(0.5 * a / eps)
    near = jnp.minimum(0.7 * eps * c * jnp.sqrt(c / jnp.maximum(c + (a - u_star) / eps, 1e-3 * c)), u_star)
    ok = near + a * near / jnp.sqrt(near * near + eps * eps) <= u_star
    return jnp.clip(jnp.where(ok, jnp.maximum(below, near), below), 0.0, u_star)


def backward_friction(p, mass, h, f_normal, mu, eps_v, velocity):
    """Regularised Coulomb friction of a rigid tool on each node, integrated backward (implicitly).

    With ``u*`` the tangential slip speed the trial momentum implies (``(p - m w)_t / m``) and
    ``a = h mu F_n / m`` (the speed friction can remove in the step), the end-of-step slip speed
    ``u`` solves ``u + a u / sqrt(u**2 + eps_v**2) = u*`` (Newton from the lower bound of
    :func:`_slip_from_below` until no node's ``u`` moves by more than :data:`FRICTION_RTOL` units of
    roundoff of it, at most :data:`FRICTION_ITERATIONS` steps; the left side is concave in ``u``, so
    Newton converges from below: the force never exceeds ``mu F_n`` and never reverses the slip).
    The force is the law at ``u``:
    ``-mu F_n u / sqrt(u**2 + eps_v**2)`` along the trial slip. ``eps_v -> 0`` is Coulomb's return
    mapping ``u = max(u* - a, 0)``.

    Args:
        p: (N, 3) trial momentum of each node at the end of the step (every other force applied),
            kg·m/s.
        mass: (N,) lumped node masses, kg.
        h: () the step over which the force acts, s.
        f_normal: (N, 3) normal contact force of the tool on each node, N (zero out of contact).
        mu: () Coulomb coefficient; eps_v: () regularisation velocity, m/s.
        velocity: (3,) the tool's velocity, m/s.

    Returns:
        ``(force (N, 3) N, power (N,) W)``: the friction force and the power it dissipates at
        the end-of-step slip (>= 0).
    """
    # structure of arrays (3, N) inside: the per-node arithmetic runs on contiguous rows
    ps, fs = jnp.asarray(p).T, jnp.asarray(f_normal, p.dtype).T
    fn = safe_norm(fs, axis=0)
    n = safe_normalize(fs, axis=0)
    m = jnp.asarray(mass, p.dtype)
    q = ps - m * jnp.asarray(velocity, p.dtype)[:, None]
    qt = q - jnp.sum(q * n, axis=0) * n
    u_star = safe_norm(qt, axis=0) / m
    a = h * mu * fn / m
    eps = jnp.asarray(eps_v, p.dtype)

    def residual(u):
        return u + a * u / jnp.sqrt(u * u + eps * eps) - u_star

    rtol = FRICTION_RTOL * jnp.finfo(p.dtype).eps

    def solve(g, u0):
        def newton(c):
            i, u, _ = c
            r = jnp.sqrt(u * u + eps * eps)
            un = jnp.clip(u - g(u) / (1.0 + a * eps * eps / (r * r * r)), 0.0, u_star)
            return i + 1, un, jnp.any(jnp.abs(un - u) > rtol * un)

        go = lambda c: (c[0] < FRICTION_ITERATIONS) & c[2]  # noqa: E731
        return jax.lax.while_loop(go, newton, (0, u0, jnp.asarray(True)))[1]

    # derivatives by the implicit function theorem at the root (one scalar equation per node: the
    # tangent solve divides by dg/du), not through the Newton loop: a lighter reverse program
    u = jax.lax.custom_root(residual, _slip_from_below(u_star, a, eps), solve,
                            lambda g, y: y / g(jnp.ones_like(y)))
    mag = mu * fn * u / jnp.sqrt(u * u + eps * eps)
    force = -mag * safe_normalize(qt, fallback=jnp.zeros(3, p.dtype), axis=0)
    return force.T, mag * u


def backward_pair_friction(p, mass, h, slave, master_nodes, w, f_normal, mu, eps_v, share=1.0):
    """:func:`backward_friction` between each slave node and its point on the other ply's triangle.

    The pair's slip is the slave's trial velocity minus the point's (``sum_j w_j p_j / m_j``); its
    mass ``1 / (1/m_s + sum_j w_j / m_j)`` counts each master node fully where a lone pair would
    count ``w_j**2``: the pairs are solved together (Jacobi), and a master node carries about one
    slave's worth of pairs (its weights over the slaves sum to about 1 on plies of like meshes),
    so that in a uniform stick the pairs stop the slip in one step rather than reverse it.
    ``share``: the part of the pair's mass one pass may use where every node is a slave and a
    master at once (``1/2`` in a symmetric two-sided contact: its two passes, each from a layer's
    nodes to the other layer's faces, together stop the slip once; with ``1`` each they would
    reverse it, stick then chattering).

    Args:
        p: (N, 3) trial momenta, kg·m/s; mass: (N,) lumped masses, kg; h: () step, s.
        slave: (S,) int; master_nodes: (S, 3) int; w: (S, 3) barycentric weights of the points.
        f_normal: (S, 3) normal force on each slave node, N; mu: (); eps_v: () m/s.
        share: () in (0, 1], default 1.

    Returns:
        ``(force (S, 3) on each slave node N (minus ``w`` times it on its master nodes), power (S,) W)``.
    """
    m = jnp.asarray(mass, p.dtype)
    v = p / m[:, None]
    v_rel = v[slave] - jnp.sum(w[:, :, None] * v[master_nodes], axis=1)
    m_pair = share / (1.0 / m[slave] + jnp.sum(w / m[master_nodes], axis=1))
    return backward_friction(m_pair[:, None] * v_rel, m_pair, h, f_normal, mu, eps_v, jnp.zeros(3, p.dtype))


__all__ = ["regularised_friction", "backward_friction", "backward_pair_friction", "FRICTION_ITERATIONS", "FRICTION_RTOL"]
