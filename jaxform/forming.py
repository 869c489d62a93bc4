"""Hemisphere forming runs end to end: a :class:`jaxform.cases.Case` -> model -> frames and a summary.

``build(case) -> (model, state, info)`` wires the pieces (mesh per ply, fabric, rigid tools,
contact loads, time step); ``simulate(case) -> FormingResult`` runs it on the host in chunks (a
jitted ``lax.scan`` of ``every / samples_per_frame`` steps at a time) so a caller can show progress
and write each frame as it comes; :func:`rollout` is the pure, differentiable counterpart (frames
as arrays, gradients w.r.t. anything in the model, e.g. the fabric's laws).

Rig (see :mod:`jaxform.tools`): z up, die top face at z = 0, the stack lies on the die (ply 1 on
top, at ``cases.ply_heights``), the holder above it (fixed gap, or force-controlled in Case B),
the punch apex on the stack moving down by the stroke.

Loads, in ``model.loads`` order: punch, die, holder (:class:`jaxform.contact.ToolLoad`), then one
:class:`jaxform.contact.PlyLoad` per neighbouring ply pair (the upper ply's nodes against the lower
ply's upward-facing triangles, gap ``h``, fabric–fabric friction). Ply 1 touches punch and holder,
ply n the die, middle plies only their neighbours. Every tool contact acts at the ply's face
(offset ``h / 2``) with each node's tributary area.

Numerics (documented choices):
* time step: ``dt_safety`` (0.75) times the shell's stable estimate, rounded down so that a whole
  number of steps fills each frame interval;
* gravity ``-9.81 m/s²`` along z, divided by the mass scaling so the physical weight is kept;
* friction regularisation speed ``contact.slip_velocity_fraction`` times the punch speed, raised
  under high pressure so that explicit stick stays stable (:mod:`jaxform.contact`);
* optional fibre-selective mass scaling ``numerics.fibre_mass_scaling`` (:mod:`jaxform.fibre_mass`):
  the step's membrane limit grows by that factor (the contact cap then usually needs a larger
  ``contact.safety``);
* Case B holder: mass ``holder.mass_kg``, critically damped on its contact stiffness.

Quasi-static check (issue 4 item 1; woven Case A, NLBM, 8 mm elements, float32): at the preset
500 mm/s, halving the punch speed changes the edge draw-in by < 1% but the full shear map by 2.3°
(p95 of the nodes), and 4.1° (250 -> 125 mm/s), 1.2° (125 -> 62.5), all of it in the flange. The
unclamped flange lifts into the 7 mm gap through a sequence of buckling events (mid-side bumps, a
lifted ring, the ring falling back at the diagonals) that lag the punch by a roughly constant
time: the only forces against its out-of-plane motion are its weight (~2 Pa) and its bending
stiffness, so its inertia matters down to slow punch speeds. Not the cause: the friction
regularisation (0.1°), float32 vs float64 (0.14°); mass damping (50 1/s) drags the draw-in (-3%)
without closing the gap. Uniform mass scaling ``s`` at speed ``v`` is exactly the run at speed
``v sqrt(s)``, so it buys nothing here. What works: 62.5 mm/s against 31.25 mm/s changes the map
by 0.51° (p95) and the draw-in by 0.23%, with fibre-selective mass scaling 3
(``numerics.fibre_mass_scaling``, which leaves the flange's inertia alone) and
``contact.safety = 0.5``: 153k steps, 118 s on one core (the 31.25 mm/s run: 232 s).
"""
from __future__ import annotations

import dataclasses
import math
import time
from typing import Any, Callable

import jax
import jax.numpy as jnp
import numpy as np

from jaxform import cases as _cases
from jaxform import contact, integrate
from jaxform.mesh import Mesh
from jaxform.shell import Shell, fibre_curvatures, fibre_vectors, shear_angle, stable_time_step

GRAVITY = 9.81
ENERGY_FLOOR = {"float32": 1e-3, "float64": 1e-8}
"""J: an energy-balance residual below this never counts as a blow-up (float32 rounding noise of
the accounts; the shell itself works on displacements, see :class:`jaxform.shell.ShellRef`)."""
PUNCH, DIE, HOLDER = 0, 1, 2


# ---------------------------------------------------------------------------------------------
# Building a run
# ---------------------------------------------------------------------------------------------


@dataclasses.dataclass(frozen=True)
class RunInfo:
    """Host-side facts about a built run (numpy arrays, plain numbers).

    Attributes:
        case: the :class:`~jaxform.cases.Case`.
        dt: time step, s; every: steps per frame interval; samples_per_frame: host chunks per frame.
        n_frames: frames including the initial one; n_steps: total steps; stroke_time: s.
        faces: (F, 4) quads of all plies (node indices, for output); ply_id: (N,) 1-based ply of each node.
        x0: (N, 3) initial positions, m.
        edge_mid: (4,) node indices of ply 1's edge mid-sides (+x, -x, +y, -y); corners: (4,).
        n_ply_loads: number of ply–ply loads (after the three tools).
        stable_dt: stable estimate of the shell alone, s.
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

    @property
    def sub_steps(self) -> int:
        return self.every // self.samples_per_frame


def build_mesh(case) -> Mesh:
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
    for (a, b), z in zip(mesh.ply_nodes, _cases.ply_heights(case)):
        nodes[a:b, 2] = z
    quads = grid_quads(nq + 1, nq + 1)
    i, j = np.meshgrid(np.arange(nq), np.arange(nq), indexing="xy")
    even = ((i + j) % 2 == 0).ravel()
    p, q, s, r = quads[:, 0], quads[:, 1], quads[:, 2], quads[:, 3]
    t1 = np.where(even[:, None], np.stack([p, q, s], 1), np.stack([p, q, r], 1))
    t2 = np.where(even[:, None], np.stack([p, s, r], 1), np.stack([q, s, r], 1))
    tris1 = np.stack([t1, t2], 1).reshape(-1, 3)
    npp = (nq + 1) ** 2
    tris = np.concatenate([tris1 + k * npp for k in range(n)]).astype(np.int32)
    e1 = nodes[tris[:, 1]] - nodes[tris[:, 0]]
    e2 = nodes[tris[:, 2]] - nodes[tris[:, 0]]
    area = 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1)
    node_area = np.zeros(len(nodes))
    np.add.at(node_area, tris.ravel(), np.repeat(area / 3.0, 3))
    return mesh.replace(nodes=nodes, tris=tris, node_area=node_area, quads=False)


def grid_quads(nx: int, ny: int, plies: int = 1) -> np.ndarray:
    """(Q, 4) counter-clockwise quads (p, q, s, r) of an ``nx`` x ``ny`` node grid, per ply stacked."""
    idx = np.arange(nx * ny).reshape(ny, nx)
    p, q = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel()
    r, s = idx[1:, :-1].ravel(), idx[1:, 1:].ravel()
    one = np.stack([p, q, s, r], 1)
    return np.concatenate([one + k * nx * ny for k in range(plies)]).astype(np.int64)


def ply_fabrics(case, fabric=None) -> tuple:
    """One fabric per ply: the case's (or ``fabric``) with fibre angles rotated by the orientations."""
    fab = _cases.build_fabric(case) if fabric is None else fabric
    out = []
    for a in case.orientations:
        out.append(fab.replace(fibre_angles=tuple(float(t) + float(a) for t in fab.fibre_angles)))
    return tuple(out)


def _edge_nodes(mesh: Mesh, n0: int):
    nx, ny = mesh.shape
    j_mid, i_mid = ny // 2, nx // 2
    mid = [j_mid * nx + nx - 1, j_mid * nx, (ny - 1) * nx + i_mid, i_mid]
    corners = [0, nx - 1, (ny - 1) * nx, ny * nx - 1]
    return np.asarray(mid) + n0, np.asarray(corners) + n0


def build(case, *, dtype=None, dt: float | None = None, dt_safety: float = 0.75, samples_per_frame: int = 10,
          fabric=None, damping: float = 0.0):
    """Wire a forming run.

    Args:
        case: a :class:`~jaxform.cases.Case` (``jaxform.cases.load(NAME)``).
        dtype: ``"float32"``/``"float64"`` (default: the case's ``numerics.dtype``).
        dt: time step, s (default ``dt_safety`` times the stable estimate); rounded down to fill
            frame intervals with whole steps.
        samples_per_frame: host chunks per frame interval (progress and force-curve samples).
        fabric: a :class:`~jaxform.materials.Fabric` replacing the case's (e.g. custom laws).
        damping: mass-proportional damping, 1/s (default none).

    Returns:
        ``(model, state, info)``: :class:`~jaxform.model.Model`, initial
        :class:`~jaxform.model.State`, :class:`RunInfo`.
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
    samples_per_frame = int(samples_per_frame)
    if samples_per_frame < 1:
        raise ValueError("forming.build: samples_per_frame must be >= 1")

    mesh = build_mesh(case)
    fabrics = ply_fabrics(case, fabric)
    shell = Shell.build(mesh, fabrics)
    ms = float(case.mass_scaling)
    fms = float(case.fibre_mass_scaling)
    stable = stable_time_step(shell, mass_scale=ms, safety=1.0, fibre_mass_factor=fms)
    dt_max = dt_safety * stable if dt is None else float(dt)
    # the automatic penalty stiffness k = safety rho_A / dt^2 must keep the penetration under
    # 1e5 Pa below 10% of the ply (contact_params checks it): on coarse meshes that caps dt
    c = case.contact
    if c.penalty_stiffness is None and dt is None:
        rho_a = float(np.max(np.asarray(fabrics[0].areal_mass))) * float(case.mass_scaling)
        dt_contact = math.sqrt(c.safety * rho_a * 0.1 * float(case.ply_thickness) / 1.0e5)
        dt_max = min(dt_max, 0.98 * dt_contact)
    T = _cases.stroke_time(case)
    n_int = int(case.process.frames) - 1
    every = samples_per_frame * max(1, math.ceil(T / dt_max / (n_int * samples_per_frame)))
    dt = T / (n_int * every)

    rig = _cases.build_tools(case)
    h = float(case.ply_thickness)
    fab0 = fabrics[0]
    rho = float(np.max(np.asarray(fab0.areal_mass))) * ms
    c = case.contact
    speed = float(case.process.speed)
    mu_tool = float(fab0.friction_tool)
    mu_fab = float(fab0.friction_fabric)
    n_if = 2 if case.n_plies > 1 else 1  # frictional contacts per node (stack: tool + ply, or two plies)
    params_tool = contact.contact_params(rho, dt, h, friction=mu_tool, slip_velocity=c.slip_velocity_fraction * speed,
                                         stiffness=c.penalty_stiffness, damping_ratio=c.damping_ratio, safety=c.safety,
                                         interfaces=n_if)
    params_ply = contact.contact_params(rho, dt, h, friction=mu_fab, slip_velocity=c.slip_velocity_fraction * speed,
                                        stiffness=c.penalty_stiffness, damping_ratio=c.damping_ratio, safety=c.safety,
                                        two_sided=True, interfaces=n_if)

    n = mesh.n_nodes
    area = np.asarray(mesh.node_area, np.float64)
    ply_id = np.zeros(n, np.int32)
    for i, (a, b) in enumerate(mesh.ply_nodes):
        ply_id[a:b] = i + 1
    top = (ply_id == 1).astype(np.float64)
    bottom = (ply_id == case.n_plies).astype(np.float64)
    as_arr = lambda a: jnp.asarray(a, jdtype)  # noqa: E731
    punch = contact.ToolLoad(tool=rig.punch, params=params_tool, offset=as_arr(h / 2), area=as_arr(area),
                             active=as_arr(top))
    die = contact.ToolLoad(tool=rig.die, params=params_tool, offset=as_arr(h / 2), area=as_arr(area),
                           active=as_arr(bottom))
    holder_state = None
    if case.holder.mode == "force":
        r = np.hypot(mesh.nodes[:, 0], mesh.nodes[:, 1])
        ring = float(np.sum(area * top * (r > float(case.tools.holder_opening_radius))))
        k_ring = float(params_tool.stiffness) * ring
        m_h = float(case.holder.mass)
        holder = contact.ToolLoad(tool=rig.holder, params=params_tool, offset=as_arr(h / 2), area=as_arr(area),
                                  active=as_arr(top), clamp_force=as_arr(case.holder.force), mass=as_arr(m_h),
                                  damping=as_arr(2.0 * math.sqrt(k_ring * m_h)), dt=as_arr(dt), force_controlled=True)
        holder_state = contact.HolderState(dz=jnp.zeros((), jdtype), vz=jnp.zeros((), jdtype))
    else:
        holder = contact.ToolLoad(tool=rig.holder, params=params_tool, offset=as_arr(h / 2), area=as_arr(area),
                                  active=as_arr(top))
    loads = [punch, die, holder]
    tris = np.asarray(mesh.tris)
    for i in range(case.n_plies - 1):
        (a, b), (t0, t1) = mesh.ply_nodes[i], mesh.ply_tris[i + 1]
        loads.append(contact.PlyLoad(slave=jnp.asarray(np.arange(a, b), jnp.int32),
                                     triangles=jnp.asarray(tris[t0:t1], jnp.int32), gap0=as_arr(h),
                                     area=as_arr(area[a:b]), params=params_ply))

    model = integrate.make_model(shell, dt=dt, mass_scale=ms, damping=damping,
                                 gravity=(0.0, 0.0, -GRAVITY / ms), loads=tuple(loads), dtype=jdtype,
                                 fibre_mass_factor=fms)
    x0 = jnp.asarray(mesh.nodes, jdtype)
    load_states = [None, None, holder_state] + [ld.initial_state(x0) for ld in loads[3:]]
    # jitted: eager (op-by-op) evaluation of the shell forces costs seconds
    state = _init_state(model, tuple(load_states))
    mid, corners = _edge_nodes(mesh, mesh.ply_nodes[0][0])
    info = RunInfo(case=case, dt=dt, every=every, samples_per_frame=samples_per_frame, n_frames=n_int + 1,
                   n_steps=n_int * every, stroke_time=T, faces=grid_quads(*mesh.shape, plies=case.n_plies), ply_id=ply_id,
                   x0=np.asarray(mesh.nodes), edge_mid=mid, corners=corners, n_ply_loads=case.n_plies - 1,
                   stable_dt=stable)
    return model, state, info


@jax.jit
def _init_state(model, load_states):
    return integrate.init_state(model, load_states=load_states)


def with_fabric(model, fabric):
    """The model with ``fabric``'s laws on every ply (fibre angles of each ply kept). Pure: use it
    inside a differentiated function to take gradients w.r.t. the fabric's parameters."""
    fabs = tuple(fabric.replace(fibre_angles=f.fibre_angles) for f in model.shell.fabrics)
    return model.replace(shell=model.shell.replace(fabrics=fabs))


# ---------------------------------------------------------------------------------------------
# Pure pieces: chunks of steps, fields of a state
# ---------------------------------------------------------------------------------------------


def run_steps(model, state, e0, x_ref, n: int, blowup_tol: float = 1e30):
    """``n`` integrator steps (pure; :func:`jaxform.integrate.run_steps`: a failed stretch returns
    its starting state with the failing step recorded).

    The integrator's own energy-blow-up guard is off by default (``blowup_tol`` huge): at the
    start of a forming run every energy is at the float32 noise floor (~1e-9 J) and that guard,
    relative to the largest energy seen, fires on rounding. Non-finite values still stop the run;
    :func:`simulate` checks the energy balance per chunk against a floor (:data:`ENERGY_FLOOR`).
    """

    return integrate.run_steps(model, state, n, e0=e0, x_ref=x_ref, blowup_tol=blowup_tol)[0]


_run_steps_jit = jax.jit(run_steps, static_argnames=("n", "blowup_tol"))


def _tool_pose(load, t, ls):
    if load.force_controlled:
        return ls.dz, jnp.stack([0.0 * ls.vz, 0.0 * ls.vz, ls.vz])
    return contact.tool_pose(load.tool, t)


def _node_average(values, mesh, n):
    """(T, ...) triangle values -> (N, ...) node averages over the adjacent triangles."""
    t = mesh.tris
    ids = jnp.concatenate([t[:, 0], t[:, 1], t[:, 2]])
    w = jnp.ones(ids.shape, values.dtype)
    vals = jnp.concatenate([values, values, values], axis=0)
    num = jnp.zeros((n,) + values.shape[1:], values.dtype).at[ids].add(vals)
    den = jnp.zeros((n,), values.dtype).at[ids].add(w)
    return num / den.reshape((n,) + (1,) * (values.ndim - 1))


def state_fields(model, state, ply_id, n_plies: int):
    """Fields of a state on the nodes (pure, jit-able).

    Returns a dict: ``displacement`` (N, 3) m; ``shear_angle`` (N,) rad (mean of the adjacent
    triangles); ``fibre_strain`` (N, 2) (``|g_f| - 1``); ``bending_moment`` (N, 2) N (= N·m/m);
    ``M_f_rms`` (N,) N; ``contact_pressure`` (N,) Pa (tools plus ply–ply); ``deviation`` (N,) m:
    distance from the ply's face to the forming tool surface it conforms to (punch for ply 1's
    side, die for ply n's side), ``min(phi_punch - (i - 1/2) h, phi_die - (n - i + 1/2) h)``;
    ``punch_force`` () N (vertical reaction on the punch, positive resisting its descent),
    ``punch_displacement`` () m (downwards positive), ``holder_force`` () N, ``holder_dz`` () m.
    """
    shell = model.shell
    mesh = shell.mesh
    x = state.x
    n = x.shape[0]
    dtype = x.dtype
    g = fibre_vectors(x, mesh, shell.ref)
    gam = shear_angle(g, shell.ref)
    stretch = jnp.sqrt(jnp.sum(g * g, axis=-1)) - 1.0
    out = {"displacement": x - jnp.asarray(mesh.nodes, dtype),
           "shear_angle": _node_average(gam, mesh, n),
           "fibre_strain": _node_average(stretch, mesh, n)}
    kappa = fibre_curvatures(x, mesh, shell.ref) - jnp.asarray(shell.ref.kappa0, dtype)
    moments = []
    for (a, b), fab in zip(mesh.ply_nodes, shell.fabrics):
        if fab.bending is None:
            moments.append(jnp.zeros((b - a, 2), dtype))
        else:
            moments.append(jnp.stack([fab.bending[0].moment(kappa[a:b, 0]), fab.bending[1].moment(kappa[a:b, 1])], 1))
    M = jnp.concatenate(moments, axis=0)
    out["bending_moment"] = M
    out["M_f_rms"] = jnp.sqrt(0.5 * jnp.sum(M * M, axis=1))
    pressure = jnp.zeros((n,), dtype)
    phis = []
    t = state.t
    extras = {}
    for i, (load, ls) in enumerate(zip(model.loads[:3], state.loads[:3])):
        dz, vel = _tool_pose(load, t, ls)
        res = contact.tool_contact(load.tool, x, state.v, load.offset, load.area, load.params, dz=dz,
                                   tool_velocity=vel, active=load.active)
        pressure = pressure + res.pressure
        phis.append(res.gap + load.offset)
        extras[i] = (res, dz)
    for load, ls in zip(model.loads[3:], state.loads[3:]):
        res = contact.ply_contact(x, state.v, load.slave, load.triangles, ls[0], load.gap0, load.area, load.params)
        pressure = pressure.at[load.slave].add(res.pressure)
    out["contact_pressure"] = pressure
    h = jnp.asarray(shell.fabrics[0].thickness, dtype)
    i = jnp.asarray(ply_id, dtype)
    out["deviation"] = jnp.minimum(phis[PUNCH] - (i - 0.5) * h, phis[DIE] - (n_plies - i + 0.5) * h)
    out["punch_force"] = extras[PUNCH][0].reaction[2]
    out["punch_displacement"] = -extras[PUNCH][1]
    out["holder_force"] = extras[HOLDER][0].reaction[2]
    out["holder_dz"] = jnp.asarray(extras[HOLDER][1], dtype)
    out["contact_energy"] = sum(r.energy for r, _ in extras.values())
    out["friction_power"] = sum(r.friction_power for r, _ in extras.values())
    return out


_fields_jit = jax.jit(state_fields, static_argnames=("n_plies",))


def rollout(model, state, info: RunInfo, *, n_frames: int | None = None, checkpoint: bool = True,
            blowup_tol: float = 1e30):
    """Pure, differentiable run of ``n_frames - 1`` frame intervals (default: the whole stroke).

    Returns ``(final_state, frames)`` (:class:`jaxform.integrate.Frames`, the initial frame not
    included). Use inside ``jax.grad``/``jax.jit`` (``info`` is static: close over it). The
    integrator's relative blow-up guard is off by default (see :func:`run_steps`); check
    ``final_state.bad_step < 0`` and the finiteness of what you use.
    """
    nf = info.n_frames if n_frames is None else int(n_frames)
    return integrate.rollout(model, state, nf - 1, info.every, checkpoint=checkpoint, blowup_tol=blowup_tol)


# ---------------------------------------------------------------------------------------------
# Host driver
# ---------------------------------------------------------------------------------------------


@dataclasses.dataclass
class FormingResult:
    """Outcome of :func:`simulate` (numpy arrays; frames written so far if incomplete).

    Attributes:
        t: (F,) frame times, s; x: (F, N, 3) positions, m; fields: dict of (F, N, ...) nodal
            fields (see :func:`state_fields`); history: dict of (S,) sampled time series (``t``,
            ``punch_displacement``, ``punch_force``, ``holder_force``, energies...);
        faces, ply_id: mesh connectivity (F, 4) and (N,) ply numbers; info: :class:`RunInfo`;
        complete: bool; reason: why it stopped early (None when complete); wall_time_s; summary:
        dict (see :func:`summarize`); final_state: last :class:`~jaxform.model.State`; model: the
        :class:`~jaxform.model.Model` that ran.
    """

    t: np.ndarray
    x: np.ndarray
    fields: dict
    history: dict
    faces: np.ndarray
    ply_id: np.ndarray
    info: RunInfo
    complete: bool
    reason: str | None
    wall_time_s: float
    summary: dict
    final_state: Any = None
    model: Any = None

    @property
    def shear_angle_deg(self) -> np.ndarray:
        """(F, N) shear angle per node, degrees."""
        return np.degrees(self.fields["shear_angle"])


_FIELD_SCALARS = ("punch_force", "punch_displacement", "holder_force", "holder_dz", "contact_energy",
                  "friction_power")
_ENERGY_KEYS = ("kinetic", "tension", "shear", "bending", "gravity_work", "external_work", "boundary_work",
                "damping_work")


def simulate(case, *, dtype=None, element_size: float | None = None, overrides=(), on_frame: Callable | None = None,
             on_progress: Callable | None = None, catch: bool = False, fabric=None, samples_per_frame: int = 10,
             damping: float = 0.0, dt: float | None = None, build_only: bool = False) -> FormingResult:
    """Run a forming case on the host, chunk by chunk.

    Args:
        case: a :class:`~jaxform.cases.Case`, a preset name or a ``.toml`` path.
        dtype: overrides the case's ``numerics.dtype``.
        element_size: overrides ``blank.element_size_mm`` (m).
        overrides: ``["section.key=value", ...]`` (:func:`jaxform.cases.apply_overrides`).
        on_frame: ``on_frame(k, t, x (N,3), fields dict)`` called after each frame (frame 0: start).
        on_progress: ``on_progress(step, n_steps, t, punch_displacement_m, elapsed_s)`` per chunk.
        catch: return an incomplete result (``complete=False`` and ``reason``) instead of raising
            on failure or ``KeyboardInterrupt``.
        fabric, samples_per_frame, damping, dt: see :func:`build`.

    Returns:
        :class:`FormingResult`.
    """
    t_wall = time.perf_counter()
    if not isinstance(case, _cases.Case):
        case = _cases.load(case)
    if element_size is not None:
        case = _cases.with_element_size(case, element_size)
    if overrides:
        case = _cases.apply_overrides(case, list(overrides))
    model, state, info = build(case, dtype=dtype, fabric=fabric, samples_per_frame=samples_per_frame,
                               damping=damping, dt=dt)
    ply_id = info.ply_id
    ply_arr = jnp.asarray(ply_id)
    fields_fn = lambda m, s: _fields_jit(m, s, ply_arr, n_plies=case.n_plies)  # noqa: E731
    chunk_fn = _run_steps_jit
    e0, x_ref = state.energies, state.x
    floor = ENERGY_FLOOR["float64" if state.x.dtype == jnp.float64 else "float32"]

    frames_t, frames_x, frames_f = [], [], {}
    hist: dict[str, list] = {k: [] for k in ("t", "step") + _FIELD_SCALARS + _ENERGY_KEYS}

    def sample(s, fl):
        hist["t"].append(float(s.t))
        hist["step"].append(int(s.step))
        for k in _FIELD_SCALARS:
            hist[k].append(float(fl[k]))
        for k in _ENERGY_KEYS:
            hist[k].append(float(getattr(s.energies, k)))

    def frame(s, fl):
        k = len(frames_t)
        host = {kk: np.asarray(v) for kk, v in fl.items() if kk not in _FIELD_SCALARS}
        frames_t.append(float(s.t))
        frames_x.append(np.asarray(s.x))
        for kk, v in host.items():
            frames_f.setdefault(kk, []).append(v)
        if on_frame is not None:
            on_frame(k, float(s.t), frames_x[-1], host)

    complete, reason = False, None
    try:
        fl = fields_fn(model, state)
        sample(state, fl)
        frame(state, fl)
        if not build_only:
            for k in range(info.n_frames - 1):
                for j in range(info.samples_per_frame):
                    new = chunk_fn(model, state, e0, x_ref, n=info.sub_steps)
                    if int(new.bad_step) >= 0:
                        integrate.check(new, _single_frame(new), model)
                    resid = abs(float(new.energies.balance(e0)))
                    if resid > 0.5 * max(float(new.scale_max), floor):
                        raise integrate.SimulationError(
                            f"simulation failed near step {int(new.step)} (t = {float(new.t):.6e} s): energy "
                            f"blow-up (balance residual {resid:.3e} J). Likely cause: time step {info.dt:.3e} s too "
                            "large for the contact or mesh; lower the time step or add mass scaling.",
                            step=int(new.step), time=float(new.t), cause="energy blow-up",
                            frames=_single_frame(state), state=state)
                    state = new
                    fl = fields_fn(model, state)
                    sample(state, fl)
                    if on_progress is not None:
                        on_progress(int(state.step), info.n_steps, float(state.t), float(fl["punch_displacement"]),
                                    time.perf_counter() - t_wall)
                frame(state, fl)
            complete = True
    except KeyboardInterrupt:
        if not catch:
            raise
        reason = "interrupted by the user (KeyboardInterrupt)"
    except integrate.SimulationError as err:
        if not catch:
            raise
        reason = f"simulation failed: {err}"
    except Exception as err:  # noqa: BLE001 - reported in the summary, re-raised unless catch
        if not catch:
            raise
        reason = f"error: {type(err).__name__}: {err}"
    if build_only:
        complete, reason = False, "build only"
    wall = time.perf_counter() - t_wall
    result = FormingResult(
        t=np.asarray(frames_t), x=np.asarray(frames_x),
        fields={k: np.asarray(v) for k, v in frames_f.items()},
        history={k: np.asarray(v) for k, v in hist.items()}, faces=info.faces, ply_id=ply_id, info=info,
        complete=complete, reason=reason, wall_time_s=wall, summary={}, final_state=state, model=model)
    result.summary = summarize(result)
    return result


def _single_frame(s):
    return integrate.Frames(x=s.x[None], v=s.v[None], t=s.t[None], step=s.step[None],
                            energies=jax.tree_util.tree_map(lambda a: a[None], s.energies), extras=(),
                            ok=jnp.zeros((1,), bool))


# ---------------------------------------------------------------------------------------------
# Post-processing (numpy)
# ---------------------------------------------------------------------------------------------


def draw_in(x, info: RunInfo) -> dict:
    """Blank-edge draw-in of ply 1, m: mean over the four edge mid-sides and the four corners.

    Mid-side: the reduction of the distance to the punch axis along the edge normal; corner: the
    reduction of the radial distance.
    """
    x = np.asarray(x)
    x0 = info.x0
    mid, cor = info.edge_mid, info.corners
    axis = np.array([0, 0, 1, 1])
    d_mid = np.abs(x0[mid, axis]) - np.abs(x[mid, axis])
    d_cor = np.hypot(x0[cor, 0], x0[cor, 1]) - np.hypot(x[cor, 0], x[cor, 1])
    return {"edge_mid_m": float(np.mean(d_mid)), "corner_m": float(np.mean(d_cor)),
            "edge_mid_each_m": d_mid.tolist(), "corner_each_m": d_cor.tolist()}


def flange_mask(x_ref, case) -> np.ndarray:
    """(N,) nodes initially on the flange (outside the die opening and its fillet)."""
    r = np.hypot(x_ref[:, 0], x_ref[:, 1])
    return r > float(case.tools.die_opening_radius + case.tools.die_fillet)


def flange_profile(x, deviation, radius: float, n_samples: int = 720):
    """Deviation (m) along a circle of ``radius`` (m) about the punch axis, current configuration:
    ``(angles (n,) rad, values (n,))``, linearly interpolated in the top view of the nodes ``x``
    (give one ply's nodes; nearest node where the circle leaves the blank)."""
    from scipy.interpolate import griddata

    x = np.asarray(x, dtype=np.float64)
    dev = np.asarray(deviation, dtype=np.float64)
    th = np.linspace(0, 2 * np.pi, n_samples, endpoint=False)
    pts = np.stack([radius * np.cos(th), radius * np.sin(th)], 1)
    vals = griddata(x[:, :2], dev, pts, method="linear")
    bad = ~np.isfinite(vals)
    if np.any(bad):
        vals[bad] = griddata(x[:, :2], dev, pts[bad], method="nearest")
    return th, vals


def wrinkle_count(x, deviation, case, *, radius: float | None = None, prominence: float = 0.5e-3,
                  n_samples: int = 720) -> int:
    """Number of discrete out-of-plane waves around the flange: peaks of the deviation along a
    circle of ``radius`` (default 10 mm outside the die fillet) standing out by more than
    ``prominence`` (m) from the troughs beside them. A flange lifted uniformly counts 0."""
    from scipy.signal import find_peaks

    rad = float(case.tools.die_opening_radius + case.tools.die_fillet) + 10e-3 if radius is None else radius
    _, prof = flange_profile(x, deviation, rad, n_samples)
    prof = np.round(prof, 9)  # no peaks from float noise on flat stretches
    ext = np.concatenate([prof, prof, prof])
    peaks, _ = find_peaks(ext, prominence=prominence)
    return int(np.sum((peaks >= n_samples) & (peaks < 2 * n_samples)))


def symmetry_error(x_ref, values, *, odd: bool = False) -> dict:
    """Mirror symmetry of a nodal field about the x and y axes of the blank.

    Returns ``{"x": e_x, "y": e_y}``: ``max |v - s v_mirror| / max |v|`` with the mirror node found
    by reference position and ``s = -1`` for fields that change sign under a mirror (``odd``: the
    shear angle of a 0/90° fabric), else 1.
    """
    x_ref = np.asarray(x_ref)
    v = np.asarray(values)
    sign = -1.0 if odd else 1.0
    key = np.round(x_ref[:, :2] * 1e6).astype(np.int64)
    lut = {(a, b): i for i, (a, b) in enumerate(map(tuple, key))}
    out = {}
    for name, sx, sy in (("x", 1, -1), ("y", -1, 1)):
        idx = np.array([lut.get((sx * a, sy * b), i) for i, (a, b) in enumerate(map(tuple, key))])
        out[name] = float(np.max(np.abs(v - sign * v[idx])) / max(np.max(np.abs(v)), 1e-30))
    return out


def summarize(result: FormingResult) -> dict:
    """The summary (SPEC section 6 keys and more; JSON-ready)."""
    import jaxform

    info = result.info
    case = info.case
    h = result.history
    ie = h["tension"] + h["shear"] + h["bending"] if len(h["t"]) else np.zeros(0)
    ke = h["kinetic"] if len(h["t"]) else np.zeros(0)
    T = info.stroke_time
    late = h["t"] >= 0.2 * T if len(h["t"]) else np.zeros(0, bool)
    ratio = np.where(ie > 0, ke / np.maximum(ie, 1e-300), np.inf) if len(ie) else ie
    max_ke_ie = float(np.max(ratio[late])) if np.any(late) else None
    if max_ke_ie is not None and not math.isfinite(max_ke_ie):
        max_ke_ie = None  # no internal energy yet (JSON has no inf)
    gam = result.fields.get("shear_angle")
    max_shear = float(np.degrees(np.max(np.abs(gam)))) if gam is not None and gam.size else None
    di = draw_in(result.x[-1], info) if len(result.x) else None
    dev = result.fields.get("deviation")
    flange = flange_mask(info.x0, case)
    max_dev = float(np.max(dev[-1][flange])) if dev is not None and len(dev) else None
    s = {
        "complete": bool(result.complete),
        "reason": result.reason,
        "case": case.name,
        "inputs": _cases.to_dict(case),
        "numerics": {"dt_s": info.dt, "stable_dt_s": info.stable_dt, "n_steps": info.n_steps,
                     "steps_done": int(h["step"][-1]) if len(h["step"]) else 0, "stroke_time_s": T,
                     "nodes": int(len(info.x0)), "mass_scaling": float(case.mass_scaling),
                     "fibre_mass_scaling": float(case.fibre_mass_scaling),
                     # products with the fibre-tension stiffness per step: degree - 1
                     "fibre_mass_degree": getattr(getattr(result.model, "fibre_mass", None), "degree", None),
                     "dtype": case.dtype,
                     "punch_speed_m_per_s": float(case.process.speed)},
        "max_ke_ie": max_ke_ie,
        "max_shear_angle_deg": max_shear,
        "max_flange_deviation_m": max_dev,
        "flange_wrinkles": (wrinkle_count(result.x[-1][result.ply_id == 1], dev[-1][result.ply_id == 1], case)
                            if dev is not None and len(dev) else None),
        "draw_in": di,
        "wall_time_s": result.wall_time_s,
        "frames_written": int(len(result.t)),
        "frame_times_s": result.t.tolist(),
        "history": {
            "t_s": h["t"].tolist(),
            "punch_displacement_m": h["punch_displacement"].tolist(),
            "punch_force_N": h["punch_force"].tolist(),
            "holder_force_N": h["holder_force"].tolist(),
            "energies_J": {k: h[k].tolist() for k in _ENERGY_KEYS},
            "internal_energy_J": ie.tolist(),
            "ke_ie": [None if not np.isfinite(r) else float(r) for r in ratio],
            "contact_energy_J": h["contact_energy"].tolist(),
            "friction_power_W": h["friction_power"].tolist(),
        },
        "versions": {"jaxform": jaxform.__version__, "jax": jax.__version__, "numpy": np.__version__},
    }
    return s


__all__ = ["build", "build_mesh", "grid_quads", "ply_fabrics", "with_fabric", "run_steps", "state_fields", "rollout", "simulate",
           "FormingResult", "RunInfo", "draw_in", "flange_mask", "wrinkle_count", "flange_profile", "symmetry_error", "summarize"]
