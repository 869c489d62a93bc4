"""Nodal fields of a forming state (pure, jit-able): shear, fibre strain and moments, contact
pressure, deviation from the tools, punch and holder forces."""
from __future__ import annotations

import jax
import jax.numpy as jnp

from jaxform import contact
from jaxform.forming.rig import DIE, HOLDER, PUNCH
from jaxform.metrics.wrinkles import rms_fibre_moment
from jaxform.shell import fibre_curvatures, fibre_vectors, shear_angle

SCALARS = ("punch_force", "punch_displacement", "holder_force", "holder_dz", "contact_energy", "friction_power",
           "max_fibre_strain", "max_node_speed", "max_penetration")
"""Keys of :func:`state_fields` that are scalars (sampled as histories, not written as frames)."""
ENERGY_KEYS = ("kinetic", "tension", "shear", "bending", "gravity_work", "external_work", "boundary_work",
               "damping_work")
"""Energy accounts of a state (:class:`jaxform.model.Energies`, J) sampled as histories."""
HISTORY_KEYS = {"t": "t_s", "step": "step", "punch_force": "punch_force_N", "punch_displacement": "punch_displacement_m",
                "holder_force": "holder_force_N", "holder_dz": "holder_dz_m", "contact_energy": "contact_energy_J",
                "friction_power": "friction_power_W", "max_fibre_strain": "max_fibre_strain",
                "max_node_speed": "max_node_speed_m_per_s", "max_penetration": "max_penetration_m", **{k: f"{k}_J" for k in ENERGY_KEYS}}
"""Sampled quantity -> its key in a run's history (``FormingResult.history``, ``summary.json``): name_unit."""


def node_average(values, mesh, n: int):
    """(T, ...) triangle values -> (N, ...) node averages over the adjacent triangles."""
    t = mesh.tris
    ids = jnp.concatenate([t[:, 0], t[:, 1], t[:, 2]])
    w = jnp.ones(ids.shape, values.dtype)
    vals = jnp.concatenate([values, values, values], axis=0)
    num = jnp.zeros((n,) + values.shape[1:], values.dtype).at[ids].add(vals)
    den = jnp.zeros((n,), values.dtype).at[ids].add(w)
    return num / den.reshape((n,) + (1,) * (values.ndim - 1))


def _tool_pose(load, t, ls):
    if load.force_controlled:
        return ls.dz, jnp.stack([0.0 * ls.vz, 0.0 * ls.vz, ls.vz])
    return contact.tool_pose(load.tool, t)


def _moments(x, shell, dtype):
    """(N, 2) bending moment per fibre family, N (zero for a membrane-only ply)."""
    mesh = shell.mesh
    kappa = fibre_curvatures(x, mesh, shell.ref) - jnp.asarray(shell.ref.kappa0, dtype)
    moments = []
    for (a, b), fab in zip(mesh.ply_nodes, shell.fabrics):
        if fab.bending is None:
            moments.append(jnp.zeros((b - a, 2), dtype))
        else:
            moments.append(jnp.stack([fab.bending[0].moment(kappa[a:b, 0]), fab.bending[1].moment(kappa[a:b, 1])], 1))
    return jnp.concatenate(moments, axis=0)


def state_fields(model, state, ply_id, n_plies: int):
    """Fields of a state on the nodes (pure, jit-able).

    Returns a dict: ``displacement`` (N, 3) m; ``shear_angle`` (N,) rad (mean of the adjacent
    triangles); ``fibre_strain`` (N, 2) (``|g_f| - 1``); ``bending_moment`` (N, 2) N (= N·m/m);
    ``M_f_rms`` (N,) N; ``contact_pressure`` (N,) Pa (tools plus ply–ply); ``deviation`` (N,) m:
    distance from the ply's face to the forming tool surface it conforms to (punch for ply 1's
    side, die for ply n's side), ``min(phi_punch - (i - 1/2) h, phi_die - (n - i + 1/2) h)``;
    ``punch_force`` () N (vertical reaction on the punch, positive resisting its descent),
    ``punch_displacement`` () m (downwards positive), ``holder_force`` () N, ``holder_dz`` () m,
    ``contact_energy`` () J, ``friction_power`` () W, ``max_fibre_strain`` () largest ``|g_f| - 1``
    of any element, ``max_node_speed`` () m/s, ``max_penetration`` () m: the deepest penetration of
    a node into a tool (from its gap) or a ply (its pressure over the stiffness) (the run's physical
    health, :mod:`jaxform.forming.driver`).
    """
    shell = model.shell
    mesh = shell.mesh
    x = state.x
    n = x.shape[0]
    dtype = x.dtype
    g = fibre_vectors(x, mesh, shell.ref)
    stretch = jnp.sqrt(jnp.sum(g * g, axis=-1)) - 1.0  # |g| ~ 1: never near the zero of sqrt
    M = _moments(x, shell, dtype)
    out = {"displacement": x - jnp.asarray(mesh.nodes, dtype),
           "shear_angle": node_average(shear_angle(g, shell.ref), mesh, n),
           "fibre_strain": node_average(stretch, mesh, n),
           "bending_moment": M,
           "M_f_rms": rms_fibre_moment(M[:, 0], M[:, 1]),
           "max_fibre_strain": jnp.max(jnp.abs(stretch)),
           "max_node_speed": jnp.sqrt(jnp.max(jnp.sum(state.v * state.v, axis=-1)))}
    pressure = jnp.zeros((n,), dtype)
    phis, tool = [], {}
    pen = jnp.zeros((), dtype)
    for i, (load, ls) in enumerate(zip(model.loads[:3], state.loads[:3])):
        dz, vel = _tool_pose(load, state.t, ls)
        res = contact.tool_contact(load.tool, x, state.v, load.offset, load.area, load.law, dz=dz,
                                   tool_velocity=vel, active=load.active)
        pressure = pressure + res.pressure
        pen = jnp.maximum(pen, jnp.max(jnp.where(jnp.asarray(load.active) > 0, -res.gap, 0.0)))
        phis.append(res.gap + load.offset)
        tool[i] = (res, dz)
    for load, ls in zip(model.loads[3:], state.loads[3:]):
        slave, p = load.node_pressure(x, state.v, ls)
        pressure = pressure.at[slave].add(p)
        pen = jnp.maximum(pen, jnp.max(p) / load.params.stiffness)
    out["contact_pressure"] = pressure
    out["max_penetration"] = pen
    h = jnp.asarray(shell.fabrics[0].thickness, dtype)
    i = jnp.asarray(ply_id, dtype)
    out["deviation"] = jnp.minimum(phis[PUNCH] - (i - 0.5) * h, phis[DIE] - (n_plies - i + 0.5) * h)
    out["punch_force"] = tool[PUNCH][0].reaction[2]
    out["punch_displacement"] = -tool[PUNCH][1]
    out["holder_force"] = tool[HOLDER][0].reaction[2]
    out["holder_dz"] = jnp.asarray(tool[HOLDER][1], dtype)
    out["contact_energy"] = sum(r.energy for r, _ in tool.values())
    out["friction_power"] = sum(r.friction_power for r, _ in tool.values())
    return out


fields_jit = jax.jit(state_fields, static_argnames=("n_plies",))
""":func:`state_fields` compiled (one program per rig shape)."""

__all__ = ["SCALARS", "ENERGY_KEYS", "HISTORY_KEYS", "node_average", "state_fields", "fields_jit"]
