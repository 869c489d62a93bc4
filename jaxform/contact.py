"""Penalty contact with regularised Coulomb friction: fabric nodes against rigid tools and plies.

Everything here is a pure function of arrays, written for one node and ``vmap``-ed; shapes are
fixed (nodes out of contact get zero force through ``jnp.where``, never by filtering).

Normal force (per node, on the fabric)
    The ply's mid-surface nodes carry the contact: the gap is ``g = phi - offset`` where ``phi`` is
    the tool's signed distance at the node and ``offset`` is half the ply thickness (for a ply in a
    stack, the distance from its mid-surface to the face that touches that tool: also ``h / 2``
    when each ply only touches the tools next to it). The penetration ``delta(g)`` is
    ``max(-g, 0)``, or, with ``smooth_width = w > 0``, the C1 ramp ``g**2 / (2 w)`` for
    ``-w < g < 0`` and ``-g - w/2`` beyond. The normal force is ``A * (k * delta + c * <-v_n>)``
    along the tool normal (clamped >= 0: the damping never pulls), with ``A`` the node's
    tributary area (m²), ``k`` the penalty stiffness **per unit area** (Pa/m: pressure per metre
    of penetration) and ``c`` an optional damping (Pa·s/m). The contact pressure is therefore
    ``k * delta`` (+ damping), independent of the mesh.

Friction (regularised Coulomb)
    ``F_t = -mu * F_n * v_t / sqrt(|v_t|**2 + eps_v**2)`` with ``v_t`` the tangential slip velocity
    (node minus tool, or minus the other ply's point). It equals Coulomb's ``mu F_n`` once
    ``|v_t| >> eps_v``, is continuous, and its derivative at zero slip is finite
    (``-mu F_n / eps_v``). The price is creep: a node held by a tangential load ``F < mu F_n``
    slides at ``v = eps_v r / sqrt(1 - r**2)``, ``r = F / (mu F_n)``. Choose ``eps_v`` small
    against the process speed (``jaxform.cases`` uses 1% of the punch speed).
    In stick that slope acts on the node as a viscous damper ``c = mu p A / eps_v``. Integrated
    explicitly (``implicit_friction=False``), it is stable only while
    ``c dt / m < 2``, i.e. ``mu p dt / (eps_v rho_A) < 2`` (independent of the mesh). Under a clamped holder (Case B, ~15 kPa) with a 1% regularisation that ratio
    reached 5-8 and the tangential velocity flipped sign every step (chatter, then a blow-up).
    So ``eps_v`` is raised where needed to ``mu p * stick_limit`` with ``stick_limit = n dt /
    rho_A`` (tools) or ``2 n dt / rho_A`` (ply on ply: two nodes share the slip), ``n`` the number
    of frictional interfaces a node can have at once (2 in a stack: holder above, ply below), which
    holds the summed ratio at 1: more creep under high pressure and large steps, never an
    unstable stick (an 8 mm Case B stack blew up with the per-interface limit alone).

The tools', the plies' and the self-contact's friction is integrated backward by default
(:class:`ToolLoad`, :class:`PlyLoad`, :class:`jaxform.self_contact.SelfContactLoad`,
:mod:`jaxform.friction`), with the plain ``eps_v`` and no stick limit: the raised ``eps_v`` gave
far less than Coulomb under a clamping pressure.

The automatic penalty stiffness and its checks: :mod:`jaxform.penalty`.

The blank holder under force control is a 1-DOF rigid body (:func:`holder_step`) advanced with
the same central-difference (leapfrog) scheme as the fabric.
"""
from __future__ import annotations

import dataclasses
from typing import Any

import jax
import jax.numpy as jnp

from jaxform import backward_normal, broadphase, tools, validate
from jaxform._pytree import as_leaf, is_concrete, pytree_dataclass, static_field
from jaxform.friction import backward_friction, backward_pair_friction, regularised_friction
from jaxform.holder import HolderState, holder_step  # noqa: F401  (re-exported)
from jaxform.geometry import (  # noqa: F401  (quads_to_triangles re-exported)
    closest_point_triangle,
    quads_to_triangles,
    safe_norm,
    safe_normalize,
)


@pytree_dataclass
class ContactParams:
    """Parameters of one contact interface (all leaves, so they can be differentiated).

    Attributes:
        stiffness: penalty stiffness per unit area ``k``, Pa/m.
        friction: Coulomb coefficient ``mu`` (-); 0.23 tool–fabric, 0.36 fabric–fabric.
        slip_velocity: regularisation velocity ``eps_v`` of the friction law, m/s.
        damping: normal damping per unit area ``c``, Pa·s/m (0: none).
        smooth_width: width ``w`` of the C1 penetration ramp, m (0: plain ``max(-g, 0)``).
        stick_limit: ``dt / rho_A`` (per unit of ``mu p``), s·m²/kg: the regularisation velocity
            is at least ``mu p stick_limit`` so that explicit stick stays stable (0: no limit).
    """

    stiffness: Any
    friction: Any = 0.23
    slip_velocity: Any = 1.0e-3
    damping: Any = 0.0
    smooth_width: Any = 0.0
    stick_limit: Any = 0.0

    def __post_init__(self):
        vals = (self.stiffness, self.friction, self.slip_velocity, self.damping, self.smooth_width, self.stick_limit)
        if is_concrete(*vals):
            validate.positive("ContactParams", "stiffness", self.stiffness, "Pa/m")
            validate.nonnegative("ContactParams", "friction", self.friction)
            validate.positive("ContactParams", "slip_velocity", self.slip_velocity, "m/s")
            validate.nonnegative("ContactParams", "damping", self.damping, "Pa·s/m")
            validate.nonnegative("ContactParams", "smooth_width", self.smooth_width, "m")
            validate.nonnegative("ContactParams", "stick_limit", self.stick_limit, "s·m²/kg")
            for n in ("stiffness", "friction", "slip_velocity", "damping", "smooth_width", "stick_limit"):
                object.__setattr__(self, n, as_leaf(getattr(self, n)))


@pytree_dataclass
class ContactResult:
    """Outcome of one contact evaluation.

    Attributes:
        force: (N, 3) force on each fabric node, N.
        reaction: (3,) total force on the tool (minus the sum of ``force``), N; for ply–ply
            contact, zero (the forces are internal to the stack).
        pressure: (N,) normal contact pressure at each (slave) node, Pa.
        gap: (N,) gap ``g`` (negative: penetration), m.
        energy: () penalty energy stored, J (``damping`` and friction excluded).
        friction_power: () power dissipated by friction, W (>= 0).
    """

    force: Any
    reaction: Any
    pressure: Any
    gap: Any
    energy: Any
    friction_power: Any


# ---------------------------------------------------------------------------------------------
# One node
# ---------------------------------------------------------------------------------------------


def penetration(g, width):
    """Penetration ``delta(g)``, m, and its energy density ``e = int_0^{-g} delta``, m², for gap g (m)."""
    w = jnp.asarray(width)
    ws = jnp.where(w > 0, w, 1.0)
    p = -g
    deep = p >= w
    ramp = (p > 0) & ~deep
    delta = jnp.where(deep, p - 0.5 * w, jnp.where(ramp, 0.5 * p * p / ws, 0.0))
    energy = jnp.where(deep, w * w / 6.0 + 0.5 * (p * p - w * w) - 0.5 * w * (p - w),
                       jnp.where(ramp, p**3 / (6.0 * ws), 0.0))
    return delta, energy


def node_contact(phi, normal, v_rel, offset, area, params: ContactParams, *, friction: bool = True):
    """Contact force on a node against a rigid surface: one node, or many in structure of arrays.

    Args:
        phi: () signed distance of the node to the tool, m.
        normal: (3,) outward unit normal of the tool at the node.
        v_rel: (3,) node velocity minus the tool's, m/s.
        offset: () distance from the node (mid-surface) to the contacting face, m (``h / 2``).
        area: () tributary area of the node, m².
        params: :class:`ContactParams`.
        friction: static; ``False``: the normal force alone (the friction integrated backward
            elsewhere), its power 0.

    Many nodes: ``phi``, ``offset``, ``area`` (N,) and ``normal``, ``v_rel`` (3, N) (the vectors'
    components along the first axis), the results likewise.

    Returns:
        ``(force (3,) N, pressure () Pa, gap () m, energy () J, friction_power () W)``.
    """
    g = phi - offset
    delta, e = penetration(g, params.smooth_width)
    in_contact = delta > 0
    v_n = jnp.sum(v_rel * normal, axis=0)
    p_elastic = params.stiffness * delta
    p_damp = jnp.where(in_contact, -params.damping * v_n, 0.0)
    pressure = jnp.maximum(p_elastic + p_damp, 0.0)
    f_n = pressure * area
    energy = area * params.stiffness * e
    if not friction:
        return f_n * normal, pressure, g, energy, jnp.zeros_like(g)
    v_t = v_rel - v_n * normal
    eps_v = jnp.maximum(params.slip_velocity, params.friction * pressure * params.stick_limit)
    f_t = regularised_friction(v_t, f_n, params.friction, eps_v)
    return f_n * normal + f_t, pressure, g, energy, -jnp.sum(f_t * v_t, axis=0)


def tool_contact(tool, x, v, offset, area, params: ContactParams, *, dz, tool_velocity, active=None,
                 friction: bool = True) -> ContactResult:
    """Contact of all fabric nodes with one rigid tool.

    Args:
        tool: a tool pytree (:mod:`jaxform.tools`).
        x: (N, 3) node positions, m; v: (N, 3) node velocities, m/s.
        offset: () or (N,) mid-surface-to-face distance, m (``h / 2`` for a single ply).
        area: () or (N,) tributary area per node, m².
        params: :class:`ContactParams`.
        dz: () vertical displacement of the tool, m (:func:`jaxform.tools.displacement`, or the
            holder state in force mode).
        tool_velocity: (3,) tool velocity, m/s.
        active: optional (N,) 0/1 weights: which nodes may touch this tool (e.g. only the ply
            next to it in a stack).
        friction: static; ``False``: the normal force alone (:func:`node_contact`).

    Returns:
        :class:`ContactResult`.
    """
    xs = jnp.asarray(x).T  # structure of arrays (3, N): the law runs on contiguous rows
    n = xs.shape[1]
    phi, normal = tools.sdf_soa(tool, xs, dz)
    offset = jnp.broadcast_to(jnp.asarray(offset, xs.dtype), (n,))
    area = jnp.broadcast_to(jnp.asarray(area, xs.dtype), (n,))
    if active is not None:
        area = area * jnp.asarray(active, xs.dtype)
    v_rel = jnp.asarray(v, xs.dtype).T - jnp.asarray(tool_velocity, xs.dtype)[:, None]
    f, p, g, e, pw = node_contact(phi, normal, v_rel, offset, area, params, friction=friction)
    if active is not None:  # (the area already zeroes force, energy and power; the pressure too)
        p = p * jnp.asarray(active, xs.dtype)
    return ContactResult(force=f.T, reaction=-jnp.sum(f, axis=1), pressure=p, gap=g, energy=jnp.sum(e),
                         friction_power=jnp.sum(pw))


def tool_pose(tool, t):
    """``(dz, velocity (3,))`` of a tool under its prescribed motion at time ``t``."""
    return tools.displacement(tool, t), tools.velocity(tool, t)


# ---------------------------------------------------------------------------------------------
# Ply–ply contact (node to surface)
# ---------------------------------------------------------------------------------------------


def nearest_faces(x, slave, triangles, k: int, chunk: int = 1024):
    """Candidate table for ply–ply contact: the ``k`` triangles with the nearest centroids.

    Cost ``O(N_s F)`` (``chunk`` slave nodes at a time, :func:`jaxform.broadphase.nearest_centroids`):
    refresh it every so many steps, not every step (plies slide by less than an element between
    refreshes). The plies move, so the host-built certified index of
    :func:`jaxform.geometry.closest_triangle` does not apply here.

    Args:
        x: (N, 3) all node positions, m.
        slave: (N_s,) int indices of the slave nodes (the ply on top).
        triangles: (F, 3) int node indices of the master ply's triangles.
        k: candidates per slave node (static).

    Returns:
        (N_s, k) int32 triangle indices.
    """
    x = jnp.asarray(x)
    cen = jnp.mean(x[jnp.asarray(triangles)], axis=1)
    return broadphase.nearest_centroids(x[jnp.asarray(slave)], cen, k, chunk)


def _ply_node(p, vp, tri_x, tri_v, side, gap0, area, params):
    """One slave node against its K candidate triangles ((K, 3, 3) positions and velocities;
    ``side`` (K,) +1, or -1 where the node faces the triangle's back)."""
    q, w = jax.vmap(closest_point_triangle, in_axes=(None, 0, 0, 0))(p, tri_x[:, 0], tri_x[:, 1], tri_x[:, 2])
    d2 = jnp.sum((p - q) ** 2, axis=-1)
    j = jnp.argmin(d2)
    a, b, c = tri_x[j]
    n = side[j] * safe_normalize(jnp.cross(b - a, c - a))
    d = p - q[j]
    dist = safe_norm(d)
    # behind the triangle only within 60 degrees of -n: a node level with it (beside an edge)
    # is not behind it whichever way rounding tips the plane test
    signed = jnp.where(jnp.dot(d, n) < -0.5 * dist, -dist, dist)
    v_master = w[j] @ tri_v[j]
    force, pressure, g, e, pw = node_contact(signed, n, vp - v_master, gap0, area, params)
    return force, w[j], j, pressure, g, e, pw, n


def ply_contact(x, v, slave, triangles, candidates, gap0, area, params: ContactParams, *, pairs: bool = False):
    """Node-to-surface contact between two plies of a stack, with friction.

    Each slave node (of the upper ply) is tested against its candidate triangles of the master
    (lower) ply; the gap is the distance to the closest point, negative when the node lies behind
    the master triangle (within 60 degrees of its back normal; the front is the side of ``(b - a)
    x (c - a)``: orient the master's faces towards the slave ply), minus ``gap0`` (mid-surface to mid-surface distance of touching plies, ``(h_1
    + h_2) / 2``). The force on a slave node is applied, with the opposite sign, to the three
    nodes of the master triangle with the barycentric weights of the closest point, so momentum
    is conserved. A node beyond the master ply's edge sees a lateral distance, hence no contact.
    Two-sided contact (self-contact, :mod:`jaxform.self_contact`): a candidate stored as ``~t``
    (``-t - 1``) is triangle ``t`` seen from its back side (the side the node was on when the
    table was built), so its normal is reversed.

    Args:
        x, v: (N, 3) all node positions (m) and velocities (m/s).
        slave: (N_s,) int slave node indices.
        triangles: (F, 3) int master triangles (:func:`quads_to_triangles` for quad meshes).
        candidates: (N_s, K) int candidate triangles per slave (:func:`jaxform.broadphase.candidates`;
            ``~t`` for triangle ``t`` from its back side).
        gap0: () contact distance between mid-surfaces, m.
        area: () or (N_s,) tributary area of each slave node, m².
        params: :class:`ContactParams` (``friction`` 0.36 fabric–fabric).

    Returns:
        :class:`ContactResult` with ``force`` (N, 3) on all nodes, ``pressure``/``gap`` (N_s,); with
        ``pairs``, also ``(f (N_s, 3) on each slave, master_nodes (N_s, 3) int, weights (N_s, 3),
        normals (N_s, 3))`` (the normal points from the master face to the slave).
    """
    x, v = jnp.asarray(x), jnp.asarray(v)
    slave = jnp.asarray(slave)
    tri = jnp.asarray(triangles)
    cand = jnp.asarray(candidates)
    ns = slave.shape[0]
    area = jnp.broadcast_to(jnp.asarray(area, x.dtype), (ns,))
    side = jnp.where(cand >= 0, 1.0, -1.0).astype(x.dtype)
    tri_c = tri[jnp.where(cand >= 0, cand, ~cand)]  # (N_s, K, 3) node indices
    f, w, j, p, g, e, pw, nrm = jax.vmap(_ply_node, in_axes=(0, 0, 0, 0, 0, None, 0, None))(
        x[slave], v[slave], x[tri_c], v[tri_c], side, jnp.asarray(gap0, x.dtype), area, params
    )
    master_nodes = jnp.take_along_axis(tri_c, j[:, None, None], axis=1)[:, 0, :]  # (N_s, 3)
    res = ContactResult(force=pair_forces(x, slave, master_nodes, w, f), reaction=jnp.zeros(3, x.dtype), pressure=p,
                        gap=g, energy=jnp.sum(e), friction_power=jnp.sum(pw))
    return (res, (f, master_nodes, w, nrm)) if pairs else res


def pair_forces(x, slave, master_nodes, w, f):
    """(N, 3) nodal forces of slave–surface pairs: ``f`` (N_s, 3) on each slave node, ``-w f`` on
    its master triangle's nodes ``master_nodes`` (N_s, 3) with the barycentric weights ``w``."""
    force = jnp.zeros_like(x).at[slave].add(f)
    return force.at[master_nodes.reshape(-1)].add((-w[:, :, None] * f[:, None, :]).reshape(-1, 3))


# ---------------------------------------------------------------------------------------------
# Loads for the integrator's external-force hook (jaxform.model: load.force(x, v, t, state))
# ---------------------------------------------------------------------------------------------


def force_params(load) -> ContactParams:
    """The parameters a fabric contact load's ``force`` evaluates (plies, self-contact): without
    friction where the integrator adds it backward (``load.implicit_friction``; a
    :class:`ToolLoad` leaves the friction out of :func:`tool_contact` instead)."""
    return dataclasses.replace(load.params, friction=0.0) if load.implicit_friction else load.params


@pytree_dataclass
class ToolLoad:
    """One rigid tool's contact as an external load of :class:`jaxform.model.Model`.

    ``force(x, v, t, load_state) -> (f (N, 3), new_load_state, extras)``. With
    ``force_controlled=False`` the tool follows its prescribed motion and ``load_state`` is
    ``None``; with ``True`` (the Case B holder) ``load_state`` is a :class:`HolderState`, advanced
    by :func:`holder_step` under ``clamp_force`` with the contact reaction of the same step.

    Attributes:
        tool: a tool pytree.
        params: :class:`ContactParams`.
        offset: () or (N,) mid-surface-to-face distance, m.
        area: () or (N,) tributary area, m².
        active: (N,) 0/1 weights of the nodes that may touch this tool (ones for a single ply).
        clamp_force, mass, damping, dt: holder control (N, kg, N·s/m, s); unused when prescribed.
        force_controlled: static.
        implicit_friction: static; ``True`` (default): ``force`` returns the normal force and the
            integrator adds the friction through :meth:`backward` (:func:`backward_friction`);
            ``False``: the explicit law with ``params.stick_limit``, inside ``force``.
        implicit_normal: static; ``True``: the normal force too acts at the end of the step
            (:mod:`jaxform.backward_normal`: any stiffness is stable), and the friction with it
            backward whatever ``implicit_friction`` says; a force-controlled holder then moves in
            :meth:`backward`, with the reaction of the step.
    """

    tool: Any
    params: Any
    offset: Any
    area: Any
    active: Any
    clamp_force: Any = 0.0
    mass: Any = 1.0
    damping: Any = 0.0
    dt: Any = 0.0
    force_controlled: bool = static_field(default=False)
    implicit_friction: bool = static_field(default=True)
    implicit_normal: bool = static_field(default=False)

    @property
    def law(self) -> ContactParams:
        """The parameters whose law, at a node's velocity after a step, gives the force this load
        applied in it (:func:`tool_contact` of a frame): with the implicit friction, the plain
        regularisation (no stick limit)."""
        return dataclasses.replace(self.params, stick_limit=0.0) if self.implicit_friction else self.params

    def gap(self, x, t, load_state):
        """(N,) the gap of each node's contacting face to the tool at time ``t``, m (``inf`` for nodes
        that may not touch it)."""
        dz = load_state.dz if self.force_controlled else tool_pose(self.tool, t)[0]
        phi, _ = tools.sdf(self.tool, x, dz)
        g = phi - jnp.broadcast_to(jnp.asarray(self.offset, x.dtype), phi.shape)
        return jnp.where(jnp.broadcast_to(jnp.asarray(self.active), phi.shape) > 0, g, jnp.inf)

    def _pose(self, t, load_state):
        if self.force_controlled:
            return load_state.dz, jnp.stack([0.0 * load_state.vz, 0.0 * load_state.vz, load_state.vz])
        return tool_pose(self.tool, t)

    def force(self, x, v, t, load_state):
        dz, vel = self._pose(t, load_state)
        if self.implicit_normal:  # the force at the end of the step (backward); here the gap, and the penalty's state
            phi, normal = tools.sdf(self.tool, x, dz)
            act = jnp.broadcast_to(jnp.asarray(self.active, x.dtype), phi.shape)
            area = jnp.broadcast_to(jnp.asarray(self.area, x.dtype), phi.shape) * act
            g = phi - jnp.broadcast_to(jnp.asarray(self.offset, x.dtype), phi.shape)
            delta, e = penetration(g, self.params.smooth_width)
            extras = {"reaction": jnp.zeros(3, x.dtype), "dz": jnp.asarray(dz),
                      "contact_energy": jnp.sum(area * self.params.stiffness * e),
                      "friction_power": jnp.zeros((), x.dtype), "max_pressure": jnp.max(self.params.stiffness * delta * act),
                      "backward_support": (g, normal, area, vel)}
            return jnp.zeros_like(x), load_state, extras
        res = tool_contact(self.tool, x, v, self.offset, self.area, self.params, dz=dz, tool_velocity=vel,
                           active=self.active, friction=not self.implicit_friction)
        new = load_state
        if self.force_controlled:
            new = holder_step(load_state, res.reaction[2], mass=self.mass, force=self.clamp_force, dt=self.dt,
                              damping=self.damping)
        extras = {"reaction": res.reaction, "dz": jnp.asarray(dz), "contact_energy": res.energy,
                  "friction_power": res.friction_power, "max_pressure": jnp.max(res.pressure)}
        if self.implicit_friction:
            extras["backward_support"] = (res.force, vel)
        return res.force, new, extras

    def backward(self, support, p, mass, h, dt, extras, load_state):
        """The contact's part of this step integrated backward (the integrator's hook, :mod:`jaxform.model`):
        ``(force (N, 3) N, extras, load_state)`` for the trial momentum ``p`` (N, 3), lumped ``mass``
        (N,), the step ``h`` the force acts over and the step ``dt``: with ``implicit_normal`` the
        normal force (:func:`jaxform.backward_normal.row_forces`, one row a node), then the friction
        (:func:`backward_friction`) on the momentum it leaves; the extras' reaction and friction power
        include them, and a force-controlled holder with an implicit normal moves here."""
        f_n = jnp.zeros_like(p)
        if self.implicit_normal:
            g, normal, area, vel = support
            _, f_n = backward_normal.row_forces(p, mass, h, dt, None, None, normal, g, area, self.params.stiffness,
                                                self.params.damping, jnp.broadcast_to(vel, p.shape))
            p, f_normal = p + h * f_n, f_n
        else:
            f_normal, vel = support
        f, pw = backward_friction(p, mass, h, f_normal, self.params.friction, self.params.slip_velocity, vel)
        reaction = extras["reaction"] - jnp.sum(f + f_n, axis=0)
        if self.implicit_normal and self.force_controlled:
            load_state = holder_step(load_state, reaction[2], mass=self.mass, force=self.clamp_force, dt=self.dt,
                                     damping=self.damping)
        return f + f_n, dict(extras, reaction=reaction, friction_power=jnp.sum(pw)), load_state


@pytree_dataclass
class PlyLoad:
    """Ply–ply contact between two plies of a stack as an external load.

    ``load_state`` is a :class:`jaxform.broadphase.SearchState` (its ``candidates`` first): the
    ``k`` candidates per slave node come from the cell grid of :func:`jaxform.broadphase.candidates`
    within ``gap0 + skin``, rebuilt inside ``lax.cond`` when the nodes may have moved against each
    other by the skin since the last refresh (:func:`jaxform.broadphase.refreshed`; also after
    ``refresh_every`` calls where that is > 0).

    Attributes:
        slave: (N_s,) int; triangles: (F, 3) int; gap0: () m; area: () or (N_s,) m²;
        params: :class:`ContactParams`; skin: () m (default ``gap0``);
        k, refresh_every, cap (triangles read per grid cell and page): static ints.
        implicit_friction: static; ``True`` (default): the friction is integrated backward
            (:meth:`backward`, :func:`jaxform.friction.backward_pair_friction`); ``False``: the
            explicit law with ``params.stick_limit``.
        implicit_normal: static; ``True``: the normal force too acts at the end of the step
            (:mod:`jaxform.backward_normal`, a row per slave node and its point on the master
            face), the friction with it backward.
    """

    slave: Any
    triangles: Any
    gap0: Any
    area: Any
    params: Any
    skin: Any = None
    k: int = static_field(default=8)
    refresh_every: int = static_field(default=0)
    cap: int = static_field(default=8)
    implicit_friction: bool = static_field(default=True)
    implicit_normal: bool = static_field(default=False)

    def _skin(self):
        return self.gap0 if self.skin is None else self.skin

    def search(self, x):
        """``candidates (N_s, k) int32`` for positions ``x`` (N, 3)."""
        reach = self.gap0 + self._skin()
        return broadphase.candidates(x[self.slave], x[self.triangles], self.k, reach, cap=self.cap)[0]

    def initial_state(self, x):
        """The load state for the initial positions ``x`` (N, 3)."""
        return broadphase.initial_state_of(self, jnp.asarray(x))

    def node_pressure(self, x, v, load_state):
        """``(slave (S,) int, pressure (S,) Pa)``: the contact pressure of the slave nodes at the
        state's candidates (the nodal contact-pressure field of a frame)."""
        res = ply_contact(x, v, self.slave, self.triangles, load_state.candidates, self.gap0, self.area, self.params)
        return self.slave, res.pressure

    def force(self, x, v, t, load_state):
        st = broadphase.refreshed(load_state, x, self.search, 0.5 * self._skin(), self.refresh_every)
        res, (f, masters, w, nrm) = ply_contact(x, v, self.slave, self.triangles, st.candidates, self.gap0, self.area,
                                                force_params(self), pairs=True)
        extras = {"contact_energy": res.energy, "friction_power": res.friction_power,
                  "max_pressure": jnp.max(res.pressure), "refreshes": st.refreshes}
        if self.implicit_normal:
            area = jnp.broadcast_to(jnp.asarray(self.area, x.dtype), res.gap.shape)
            extras["backward_support"] = backward_normal.pair_rows(self.slave, masters, w, nrm, res.gap, area)
            return jnp.zeros_like(x), st, extras
        if self.implicit_friction:
            extras["backward_support"] = (f, masters, w)
        return res.force, st, extras

    def backward(self, support, p, mass, h, dt, extras, load_state):
        """This step's contact integrated backward (the integrator's hook, :mod:`jaxform.model`):
        ``(force (N, 3) N, extras, load_state)``: with ``implicit_normal`` the normal forces
        (:func:`jaxform.backward_normal.row_forces`), then the friction
        (:func:`jaxform.friction.backward_pair_friction`) on the momentum they leave."""
        f_n = jnp.zeros_like(p)
        if self.implicit_normal:
            F, f_n = backward_normal.row_forces(p, mass, h, dt, *support, self.params.stiffness, self.params.damping)
            p = p + h * f_n
            f_normal, masters, w = F[:, None] * support[2], support[0][:, 1:], -support[1][:, 1:]
        else:
            f_normal, masters, w = support
        f, pw = backward_pair_friction(p, mass, h, self.slave, masters, w, f_normal, self.params.friction,
                                       self.params.slip_velocity)
        return pair_forces(p, self.slave, masters, w, f) + f_n, dict(extras, friction_power=jnp.sum(pw)), load_state


__all__ = ["ContactParams", "ContactResult", "HolderState", "penetration", "force_params", "pair_forces",
           "node_contact", "tool_contact", "tool_pose", "ply_contact", "nearest_faces",
           "quads_to_triangles", "holder_step", "ToolLoad", "PlyLoad"]
