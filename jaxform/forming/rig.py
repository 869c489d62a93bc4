"""The rig of a forming run, built once: Case -> (Model, State, RunInfo).

Rig (see :mod:`jaxform.tools`): z up, die top face at z = 0, the stack lies on the die (ply 1 on
top, at :func:`jaxform.forming.case.ply_heights`), the holder above it (fixed gap, or
force-controlled in Case B), the punch apex on the stack moving down by the stroke.

Loads, in ``model.loads`` order: punch, die, holder (:class:`jaxform.contact.ToolLoad`), then one
:class:`jaxform.contact.PlyLoad` per neighbouring ply pair (the upper ply's nodes against the lower
ply's upward-facing triangles, gap ``h``, fabric–fabric friction), then, with
``contact.self_contact`` (default), one :class:`jaxform.self_contact.SelfContactLoad`: every ply
with itself and with the plies not next to it, two-sided, gap ``h``. Ply 1 touches punch and holder,
ply n the die, middle plies only their neighbours. Every tool contact acts at the ply's face
(offset ``h / 2``) with each node's tributary area.

Numerics (documented choices):
* time step and contact stiffness chosen together (:func:`jaxform.forming.numerics.contact_numerics`): ``dt_safety`` (0.75
  with explicit contact normals, 0.9 with backward ones, the default for one ply under a holder at a gap)
  times the shell's stable estimate, unless a contact stiff enough to keep the penetration below
  10% of the ply at the case's expected pressure (1e4 Pa with a holder at a gap, 1e5 Pa clamped:
  :func:`jaxform.forming.numerics.expected_pressure`), stable with four contacts pressing one node
  (a fold under the holder), needs a smaller step; rounded down so that a whole number of steps fills each frame interval;
* gravity :data:`jaxform.units.GRAVITY` along -z, divided by the mass scaling so the physical
  weight is kept;
* friction regularisation speed ``contact.slip_velocity_fraction`` times the punch speed; every
  contact's friction (tools, plies, self-contact) is integrated backward (:mod:`jaxform.friction`);
* optional fibre-selective mass scaling ``numerics.fibre_mass_scaling`` (:mod:`jaxform.fibre_mass`):
  the step's membrane limit grows by that factor (the contact then often sets the step);
* Case B holder: mass ``holder.mass_kg``, critically damped on its contact stiffness.
"""
from __future__ import annotations

import dataclasses
import math
import warnings
from typing import Any, NamedTuple

import jax
import jax.numpy as jnp
import numpy as np

from jaxform import contact, integrate, penalty, units
from jaxform.forming.case import LBM_VARIANTS, Case, ply_heights
from jaxform.forming.health import HealthBounds, health_bounds
from jaxform.forming.numerics import (AUTO_SAFETY, STACKED_CONTACTS, ContactNumerics, auto_fibre_mass,
                                      contact_numerics, expected_pressure)
from jaxform.mesh import Mesh
from jaxform.self_contact import self_contact_load
from jaxform.shell import Shell
from jaxform.spectrum import ply_frequencies, stable_time_step

PUNCH, DIE, HOLDER = 0, 1, 2
"""Indices of the three tools in ``model.loads``."""


@dataclasses.dataclass(frozen=True)
class RunInfo:
    """Host-side facts about a built run (numpy arrays, plain numbers).

    Attributes:
        case: the :class:`~jaxform.forming.case.Case`.
        dt: time step, s; every: steps per frame interval; samples_per_frame: host chunks per frame.
        n_frames: frames including the initial one; n_steps: total steps; stroke_time: s.
        faces: (F, 4) quads of all plies (node indices, for output); ply_id: (N,) 1-based ply of each node.
        x0: (N, 3) initial positions, m.
        edge_mid: (4,) node indices of ply 1's edge mid-sides (+x, -x, +y, -y); corners: (4,).
        n_ply_loads: number of ply–ply loads (after the three tools).
        stable_dt: stable estimate of the shell alone, s.
        bounds: :class:`HealthBounds` the driver checks after every chunk.
        numerics: the step and contact stiffness chosen (:class:`ContactNumerics`).
        fibre_mass_factor: the fibre-mass factor used (the case's, or
            :func:`jaxform.forming.numerics.auto_fibre_mass`).
    """

    case: Any
    dt: float
    every: int
    samples_per_frame: int
    n_frames: int
    n_steps: int
    stroke_time: float
    faces: np.ndarray
    ply_id: np.ndarray
    x0: np.ndarray
    edge_mid: np.ndarray
    corners: np.ndarray
    n_ply_loads: int
    stable_dt: float
    bounds: HealthBounds
    numerics: ContactNumerics | None = None
    fibre_mass_factor: float = 1.0

    @property
    def sub_steps(self) -> int:
        return self.every // self.samples_per_frame

    def __repr__(self) -> str:
        return (f"RunInfo(case={self.case.name!r}, nodes={len(self.x0)}, dt={self.dt:.3e} s, "
                f"n_steps={self.n_steps}, n_frames={self.n_frames})")


class Rig(NamedTuple):
    """A built run: fixed :class:`~jaxform.model.Model`, initial :class:`~jaxform.model.State`,
    host facts :class:`RunInfo` (unpacks as ``model, state, info``)."""

    model: Any
    state: Any
    info: RunInfo


# ---------------------------------------------------------------------------------------------
# Pieces of the rig
# ---------------------------------------------------------------------------------------------


def grid_quads(nx: int, ny: int, plies: int = 1) -> np.ndarray:
    """(Q, 4) counter-clockwise quads (p, q, s, r) of an ``nx`` x ``ny`` node grid, per ply stacked."""
    idx = np.arange(nx * ny).reshape(ny, nx)
    p, q = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    r, s = idx[1:, :-1].ravel(), idx[1:, 1:].ravel()
    one = np.stack([p, q, s, r], 1)
    return np.concatenate([one + k * nx * ny for k in range(plies)]).astype(np.int64)


def grid_triangles(n: int, plies: int = 1) -> np.ndarray:
    """(2Q, 3) int64 triangles of :func:`grid_quads` ``(n, n, plies)``, quad ``q`` split into
    ``2q, 2q + 1`` along alternating diagonals (union jack; :func:`build_mesh`)."""
    quads = grid_quads(n, n)
    i, j = np.meshgrid(np.arange(n - 1), np.arange(n - 1), indexing="xy")
    even = ((i + j) % 2 == 0).ravel()
    p, q, s, r = quads[:, 0], quads[:, 1], quads[:, 2], quads[:, 3]
    t1 = np.where(even[:, None], np.stack([p, q, s], 1), np.stack([p, q, r], 1))
    t2 = np.where(even[:, None], np.stack([p, s, r], 1), np.stack([q, s, r], 1))
    one = np.stack([t1, t2], 1).reshape(-1, 3)
    return np.concatenate([one + k * n * n for k in range(plies)]).astype(np.int64)


def build_mesh(case: Case) -> Mesh:
    """The blank: one ``blank_size`` square of about ``element_size`` quads per ply, ply 1 on top (m).

    Each quad is split into two triangles along alternating diagonals ("union jack"), with an even
    number of quads along each side (the element size is rounded to make it so): the triangulation
    is then mirror-symmetric about both blank axes, like the fabric and the rig. (A single diagonal
    direction makes the +45° and -45° directions respond differently and the shear map loses its
    mirror symmetry.) ``mesh.faces`` gives triangles; :func:`grid_quads` the quads for output.
    """
    n = case.n_plies
    nq = 2 * max(1, int(round(case.blank_size / (2.0 * case.element_size))))
    xs = np.linspace(-0.5 * case.blank_size, 0.5 * case.blank_size, nq + 1)
    mesh = Mesh.grid(xs, xs, plies=n, ply_spacing=0.0)
    nodes = np.array(mesh.nodes, dtype=np.float64)
    for (a, b), z in zip(mesh.ply_nodes, ply_heights(case)):
        nodes[a:b, 2] = z
    tris = grid_triangles(nq + 1, n).astype(np.int32)
    e1 = nodes[tris[:, 1]] - nodes[tris[:, 0]]
    e2 = nodes[tris[:, 2]] - nodes[tris[:, 0]]
    area = 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1)
    node_area = np.zeros(len(nodes))
    np.add.at(node_area, tris.ravel(), np.repeat(area / 3.0, 3))
    return mesh.replace(nodes=nodes, tris=tris, node_area=node_area, quads=False)


def build_fabric(case: Case):
    """The :class:`jaxform.materials.Fabric` of the case (preset, overrides, bending model)."""
    from jaxform import materials

    fab = materials.preset(case.fabric.preset)
    f = case.fabric
    changes = {}
    if f.thickness is not None:
        changes["thickness"] = f.thickness
    if f.areal_mass is not None:
        changes["areal_mass"] = f.areal_mass
    if f.friction_tool is not None:
        changes["friction_tool"] = f.friction_tool
    if f.friction_fabric is not None:
        changes["friction_fabric"] = f.friction_fabric
    if f.voce is not None:
        law = materials.VoceBending(b_inf=f.voce[0], m0=f.voce[1], kappa0=f.voce[2])
        changes["bending"] = (law, law)
    if f.shear_poly is not None:
        changes["shear"] = materials.PolynomialShear(list(f.shear_poly))
    if changes:
        fab = fab.replace(**changes)
    if f.bending == "membrane":
        return materials.membrane_only(fab)
    if f.bending in LBM_VARIANTS:
        return materials.lbm_variant(fab, LBM_VARIANTS[f.bending])
    return fab


def ply_fabrics(case: Case, fabric=None) -> tuple:
    """One fabric per ply: the case's (or ``fabric``) with fibre angles rotated by the orientations."""
    fab = build_fabric(case) if fabric is None else fabric
    return tuple(fab.replace(fibre_angles=tuple(float(t) + float(a) for t in fab.fibre_angles))
                 for a in case.orientations)


def punch_motion(case: Case):
    """The punch's :class:`jaxform.tools.VerticalMotion`: down by ``stroke`` at ``speed`` with a
    linear speed ramp over ``ramp_fraction`` of the stroke time."""
    from jaxform import tools

    p = case.process
    return tools.VerticalMotion(velocity=-p.speed, ramp_time=p.ramp_fraction * p.stroke / p.speed, stroke=p.stroke)


def stroke_time(case: Case) -> float:
    """Simulated time to complete the stroke, s (speed ramp included); builds no tool."""
    return punch_motion(case).time_to_stroke()


def build_tools(case: Case):
    """The rig as :class:`jaxform.tools.FormingTools` in the reference pose.

    Die top face at ``z = 0``; the stack (``n`` plies of thickness ``h``) on it, ply mid-surfaces
    at ``z = (n - i + 1/2) h`` for ply ``i`` (ply 1 on top, touching the punch); holder lower face
    at ``z = gap`` (gap mode) or on the stack, ``z = n h`` (force mode); punch apex on the stack's
    upper surface, moving as :func:`punch_motion`. A mesh punch is read and sampled here (once per run).
    """
    from jaxform import tools

    t = case.tools
    stack = case.stack_thickness
    motion = punch_motion(case)
    if t.punch_mesh is not None:
        from jaxform.io.tool_mesh import load_tool_sdf

        punch = load_tool_sdf(t.punch_mesh, cell=t.punch_mesh_cell, units=t.punch_mesh_units, motion=motion)
    else:
        punch = tools.Punch(radius=t.punch_radius, apex_z=stack, motion=motion)
    die = tools.Die(opening_radius=t.die_opening_radius, fillet_radius=t.die_fillet, thickness=t.die_thickness,
                    top_z=0.0)
    bottom = case.holder.gap if case.holder.mode == "gap" else stack
    holder = tools.BlankHolder(opening_radius=t.holder_opening_radius, edge_radius=t.holder_edge_radius,
                               thickness=t.holder_thickness, bottom_z=bottom)
    return tools.FormingTools(punch=punch, die=die, holder=holder)


def _edge_nodes(mesh: Mesh, n0: int):
    nx, ny = mesh.shape
    j_mid, i_mid = ny // 2, nx // 2
    mid = [j_mid * nx + nx - 1, j_mid * nx, (ny - 1) * nx + i_mid, i_mid]
    corners = [0, nx - 1, (ny - 1) * nx, ny * nx - 1]
    return np.asarray(mid) + n0, np.asarray(corners) + n0


def _blank_edges(mesh: Mesh) -> np.ndarray:
    """The node indices of every ply's outer edge (the plies are grids of ``mesh.shape``)."""
    nx, ny = mesh.shape
    j, i = np.divmod(np.arange(nx * ny), nx)
    edge = np.flatnonzero((i == 0) | (i == nx - 1) | (j == 0) | (j == ny - 1))
    return np.concatenate([edge + n0 for n0, _ in mesh.ply_nodes])


def _time_step(case: Case, numerics: ContactNumerics, samples_per_frame: int):
    """``(dt, every, stroke time)``: the largest step up to ``numerics.dt_max`` filling each frame
    interval with a whole number of host chunks."""
    T = stroke_time(case)
    n_int = int(case.process.frames) - 1
    every = samples_per_frame * max(1, math.ceil(T / numerics.dt_max / (n_int * samples_per_frame)))
    return T / (n_int * every), every, T


def _loads(case: Case, mesh: Mesh, fabrics, dt: float, jdtype, safety: float | None = None,
           implicit_normal: bool = False):
    """The contact loads in ``model.loads`` order and their initial holder state; ``implicit_normal``
    as chosen by :func:`jaxform.forming.numerics.contact_numerics`."""
    tools_rig = build_tools(case)
    h = float(case.ply_thickness)
    fab0 = fabrics[0]
    rho = float(np.max(np.asarray(fab0.areal_mass))) * float(case.mass_scaling)
    c = case.contact
    speed = float(case.process.speed)
    k = c.penalty_stiffness
    if implicit_normal and k is None and safety is not None:  # any stiffness is stable: no bound on the safety
        k = safety * rho / dt**2
    common = dict(slip_velocity=c.slip_velocity_fraction * speed, stiffness=k,
                  expected_pressure=expected_pressure(case)[0],
                  damping_ratio=c.damping_ratio, safety=AUTO_SAFETY if safety is None else safety, interfaces=0)
    params_tool = penalty.contact_params(rho, dt, h, friction=float(fab0.friction_tool), **common)
    # (no stick limit, interfaces=0: every contact's friction is integrated backward, the loads' friction hooks)
    params_ply = penalty.contact_params(rho, dt, h, friction=float(fab0.friction_fabric), two_sided=True, **common)

    area = np.asarray(mesh.node_area, np.float64)
    ply_id = _ply_ids(mesh)
    top = (ply_id == 1).astype(np.float64)
    bottom = (ply_id == case.n_plies).astype(np.float64)
    as_arr = lambda a: jnp.asarray(a, jdtype)  # noqa: E731
    imp = dict(implicit_normal=bool(implicit_normal))
    face = dict(params=params_tool, offset=as_arr(h / 2), area=as_arr(area), **imp)
    punch = contact.ToolLoad(tool=tools_rig.punch, active=as_arr(top), **face)
    die = contact.ToolLoad(tool=tools_rig.die, active=as_arr(bottom), **face)
    holder_state = None
    if case.holder.mode == "force":
        r = np.hypot(mesh.nodes[:, 0], mesh.nodes[:, 1])
        ring = float(np.sum(area * top * (r > float(case.tools.holder_opening_radius))))
        k_ring = float(params_tool.stiffness) * ring
        m_h = float(case.holder.mass)
        holder = contact.ToolLoad(tool=tools_rig.holder, active=as_arr(top), clamp_force=as_arr(case.holder.force),
                                  mass=as_arr(m_h), damping=as_arr(2.0 * math.sqrt(k_ring * m_h)), dt=as_arr(dt),
                                  force_controlled=True, **face)
        holder_state = contact.HolderState(dz=jnp.zeros((), jdtype), vz=jnp.zeros((), jdtype))
    else:
        holder = contact.ToolLoad(tool=tools_rig.holder, active=as_arr(top), **face)
    loads = [punch, die, holder]
    tris = np.asarray(mesh.tris)
    for i in range(case.n_plies - 1):
        (a, b), (t0, t1) = mesh.ply_nodes[i], mesh.ply_tris[i + 1]
        loads.append(contact.PlyLoad(slave=jnp.asarray(np.arange(a, b), jnp.int32),
                                     triangles=jnp.asarray(tris[t0:t1], jnp.int32), gap0=as_arr(h),
                                     area=as_arr(area[a:b]), params=params_ply, skin=as_arr(_skin(case)), **imp))
    if c.self_contact:
        n = case.n_plies
        pair_ok = np.abs(np.arange(n + 1)[:, None] - np.arange(n + 1)[None, :]) != 1  # neighbours: PlyLoad
        loads.append(self_contact_load(mesh.nodes, tris, area, ply_id, h, params_ply, pair_ok=pair_ok,
                                       skin=_skin(case), dtype=jdtype, **imp))
    return tuple(loads), holder_state


def _skin(case: Case) -> float:
    """Search margin of the fabric contacts beyond the contact distance, m: the larger of the ply
    thickness and a quarter element. Candidates are rebuilt when the nodes may have moved against
    each other by it, so the refresh follows the largest relative node speed
    (:func:`jaxform.broadphase.refreshed`)."""
    return max(float(case.ply_thickness), 0.25 * float(case.element_size))


def _ply_ids(mesh: Mesh) -> np.ndarray:
    ply_id = np.zeros(mesh.n_nodes, np.int32)
    for i, (a, b) in enumerate(mesh.ply_nodes):
        ply_id[a:b] = i + 1
    return ply_id


# ---------------------------------------------------------------------------------------------
# The rig
# ---------------------------------------------------------------------------------------------


MIN_SAMPLES = 200
"""Default number of history samples over the stroke (punch force curve, energies): at least this many."""


def build(case: Case, *, dtype=None, dt: float | None = None, dt_safety: float | None = None,
          samples_per_frame: int | None = None, fabric=None, damping: float = 0.0, every: int | None = None) -> Rig:
    """Build a forming run once: mesh, fabrics, shell, tools, contact loads, time step, initial state.

    Args:
        case: a :class:`~jaxform.forming.case.Case` (``jaxform.cases.load(NAME)``, normalised with
            :func:`jaxform.cases.resolve`).
        dtype: ``"float32"``/``"float64"`` (default: the case's ``numerics.dtype``).
        dt: time step, s (default ``dt_safety`` times the stable estimate); rounded down to fill
            frame intervals with whole steps.
        dt_safety: the step's fraction of the shell's stable step (default 0.75 with the contacts'
            normal forces explicit, 0.9 backward: :func:`jaxform.forming.numerics.contact_numerics`).
        samples_per_frame: host chunks per frame interval (progress and force-curve samples; default
            at least 10 and enough for :data:`MIN_SAMPLES` samples over the stroke).
        fabric: a :class:`~jaxform.materials.Fabric` replacing the case's (e.g. custom laws).
        damping: mass-proportional damping, 1/s (default none).
        every: steps per frame interval, at least the chosen step's and a multiple of
            ``samples_per_frame``: the step shortened to share a step count with other runs (a
            batch, :func:`jaxform.forming.batch.simulate_batch`); the contact stiffness stays that
            of the step chosen, so only the step differs from the run built without it.

    Returns:
        :class:`Rig` ``(model, state, info)``.
    """
    dtype_name = dtype or case.dtype
    if dtype_name not in ("float32", "float64"):
        raise ValueError(f"forming.build: dtype = {dtype_name!r}: must be 'float32' or 'float64'")
    if dtype_name == "float64" and not jax.config.jax_enable_x64:
        raise ValueError("forming.build: dtype float64 needs jax.config.update('jax_enable_x64', True) "
                         "before anything else runs (or use numerics.dtype = 'float32')")
    jdtype = jnp.float64 if dtype_name == "float64" else jnp.float32
    if int(case.process.frames) < 2:
        raise ValueError(f"case key 'process.frames' = {case.process.frames}: need at least 2 (start and end)")
    n_int = int(case.process.frames) - 1
    if samples_per_frame is None:
        samples_per_frame = max(10, math.ceil(MIN_SAMPLES / n_int))
    samples_per_frame = int(samples_per_frame)
    if samples_per_frame < 1:
        raise ValueError("forming.build: samples_per_frame must be >= 1")

    mesh = build_mesh(case)
    fabrics = ply_fabrics(case, fabric)
    shell = Shell.build(mesh, fabrics, shear_reading=case.fabric.shear_reading)
    ms = float(case.mass_scaling)
    freqs = ply_frequencies(shell, ms)  # once: the bending eigenvalue is a sparse solve (about 1 s at 1 mm)
    fms = (auto_fibre_mass(shell, ms, momentum_term=case.fibre_mass_momentum_term, frequencies=freqs)
           if case.fibre_mass_scaling is None else float(case.fibre_mass_scaling))
    stable = stable_time_step(shell, mass_scale=ms, safety=1.0, fibre_mass_factor=fms, frequencies=freqs)
    numerics = contact_numerics(case, fabrics, stable, dt, dt_safety)
    if numerics.budget > 1.0:
        warnings.warn(f"forming.build: the time step and contact stiffness given make a node between "
                      f"{STACKED_CONTACTS} contacts unstable (omega dt / 2 = {numerics.budget:.2f} > 1); folds pressed "
                      "under the holder may blow up. Use contact.safety = 'auto' or a smaller step.", RuntimeWarning,
                      stacklevel=2)
    dt, every_own, T = _time_step(case, numerics, samples_per_frame)
    safety = numerics.safety
    if every is not None and int(every) != every_own:
        if int(every) < every_own or int(every) % samples_per_frame:
            raise ValueError(f"forming.build: every = {every}: need a multiple of samples_per_frame "
                             f"({samples_per_frame}) of at least {every_own} (the step chosen for this case)")
        dt_own, dt = dt, T / (n_int * int(every))
        if safety is not None:  # the same stiffness k = safety rho / dt^2 at the shorter step
            safety = safety * (dt / dt_own) ** 2
        # omega^2 dt^2 of shell and contacts both scale with dt^2 at a kept stiffness: the budget with dt
        numerics = dataclasses.replace(numerics, budget=numerics.budget * dt / dt_own, safety=safety,
                                       why=f"{numerics.why}; the step shortened from {dt_own:.3g} s to "
                                           f"{dt:.3g} s to share {every} steps per frame with a batch")
    every = every_own if every is None else int(every)
    loads, holder_state = _loads(case, mesh, fabrics, dt, jdtype, safety, numerics.implicit_normal)
    model = integrate.make_model(shell, dt=dt, mass_scale=ms, damping=damping,
                                 gravity=(0.0, 0.0, -units.GRAVITY / ms), loads=loads, dtype=jdtype,
                                 fibre_mass_factor=fms, fibre_mass_momentum_term=case.fibre_mass_momentum_term,
                                 dt_limit=stable)
    x0 = jnp.asarray(mesh.nodes, jdtype)
    # jitted: eager (op-by-op) evaluation of the shell forces and of the contact searches costs
    # seconds to minutes (each operation compiled on its own)
    state = _init_state(model, holder_state, x0)
    mid, corners = _edge_nodes(mesh, mesh.ply_nodes[0][0])
    info = RunInfo(case=case, dt=dt, every=every, samples_per_frame=samples_per_frame, n_frames=n_int + 1,
                   n_steps=n_int * every, stroke_time=T, faces=grid_quads(*mesh.shape, plies=case.n_plies),
                   ply_id=_ply_ids(mesh), x0=np.asarray(mesh.nodes), edge_mid=mid, corners=corners,
                   n_ply_loads=case.n_plies - 1, stable_dt=stable, bounds=health_bounds(case, _blank_edges(mesh)), numerics=numerics,
                   fibre_mass_factor=fms)
    return Rig(model, state, info)


@jax.jit
def _init_state(model, holder_state, x0):
    load_states = (None, None, holder_state) + tuple(ld.initial_state(x0) for ld in model.loads[3:])
    return integrate.init_state(model, load_states=load_states)


def with_fabric(model, fabric):
    """The model with ``fabric``'s laws on every ply (fibre angles of each ply kept). Pure: use it
    inside a differentiated function to take gradients w.r.t. the fabric's parameters."""
    fabs = tuple(fabric.replace(fibre_angles=f.fibre_angles) for f in model.shell.fabrics)
    return model.replace(shell=model.shell.replace(fabrics=fabs))


__all__ = ["PUNCH", "DIE", "HOLDER", "RunInfo", "HealthBounds", "health_bounds", "Rig", "build", "build_mesh", "grid_quads", "build_fabric",
           "ply_fabrics", "punch_motion", "stroke_time", "build_tools", "with_fabric"]
