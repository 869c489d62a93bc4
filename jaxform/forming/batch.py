"""Batches of forming runs: members that share a mesh run as one vmapped program, sharded over devices.

``simulate_batch(case, overrides_per_member)`` runs one case with a list of ``--set`` overrides per
member (a sweep of friction, holder gap or force, laws, speeds...) and returns one
:class:`~jaxform.forming.driver.FormingResult` per member, each as :func:`jaxform.forming.run`
gives it for that member alone.

How members share a program:

* **Groups.** Members whose rigs have the same structure (the pytree of model and state with its
  static fields, every array's shape and dtype: the mesh, plies, bending-law type, fibre-mass factor,
  self-contact tables) and the same frames run together; a linear bending law joins Voce members
  as the Voce law with ``m0 = 0`` (:func:`common_form`). Members that cannot share a program are
  grouped by that structure and run group after group.
* **A common step count.** Members of different speeds (or different stable steps) take the
  largest step count of their group: each member's step becomes its stroke time over that count
  (shorter than its own, so it stays stable) and its contact stiffness stays the one its own run
  would use (:func:`jaxform.forming.rig.build`'s ``every``). Members of the same speed and step run
  exactly their own programs' steps.
* **One program.** Model leaves equal across the members (the mesh, the reference geometry) are
  passed once; the rest are stacked on a leading member axis. The stretch of steps and the fields
  are ``jax.vmap``-ed over the members (axis :data:`jaxform.batching.BATCH_AXIS`; the contact
  searches refresh together, :mod:`jaxform.batching`) and ``jax.shard_map``-ed over a 1-D device
  mesh of that name: each device runs its share of the members on its own, with no communication
  between devices inside a stretch. The batch is padded to a multiple of the device count with
  parked copies (zero steps).
* **Failures.** The host checks every member after each stretch, as the single-run driver does
  (energy balance, non-finite values, physical bounds). A failed member keeps its frames up to its
  last good one and its reason, and is parked (its initial state, zero steps) while the others go
  on. Where its own run would run the failed chunk again (with the fibre mass's momentum term, a
  cut step, a stiffer contact: :meth:`jaxform.forming.driver.Standing.recover`), the member goes on alone from its
  last good state that way, after the batch (``momentum_term_from`` and ``step_cuts`` of its result).
* **Memory.** A group whose program would not fit in the memory the devices have is split into
  parts that do, run one after the other; ``summary["batch"]`` says so (:func:`plan_parts`).

On a CPU-only machine JAX sees one device unless told otherwise: ``jaxform sweep`` makes one device
per core (``jax_num_cpu_devices``) before JAX starts, so that each core runs its share of the
members (``jaxform.cli.sweep``).
"""
from __future__ import annotations

import dataclasses
import functools
import math
import os
import time
import types
from typing import Callable, Sequence

import jax
import jax.numpy as jnp
import numpy as np
from jax.sharding import Mesh, NamedSharding
from jax.sharding import PartitionSpec as P

from jaxform import integrate
from jaxform.batching import BATCH_AXIS
from jaxform.forming.case import Case, to_dict
from jaxform.forming.driver import BLOWUP_TOL, FormingResult, Recorder, Standing, _floor, drive, may_stiffen_contact
from jaxform.forming.health import failure_reason, out_of_bounds_message, physical_causes
from jaxform.forming.fields import SCALARS, state_fields
from jaxform.forming.presets import apply_overrides, with_element_size
from jaxform.forming.rig import Rig, build
from jaxform.forming.summary import summarize
from jaxform.materials import Fabric, LinearBending, VoceBending

INTERRUPTED = "interrupted (KeyboardInterrupt)"
"""The start of the reason of members stopped by Ctrl-C or SIGTERM (their batch runs no further part)."""
MESH_AXIS = "batch"
"""The axis of the device mesh the members are sharded over (one member axis, vmapped within a
device as :data:`jaxform.batching.BATCH_AXIS`)."""
MEMORY_PER_ARRAY_BYTE = 20.0
"""Bytes a batch program needs per byte of a member's model and state arrays: measured 15 (the
compiled program's memory analysis, arguments, outputs and temporaries, two members of woven
Case A: 31 MB at 8 mm for 2 x 1.04 MB of arrays, 115 MB at 4 mm for 2 x 3.83 MB), 20 with a margin."""
MEMORY_FRACTION = 0.6
"""Share of the devices' free memory a batch program may plan to use (the rest: JAX, the host's
frames, other programs)."""


@dataclasses.dataclass(frozen=True)
class BatchPart:
    """Members run as one program (:func:`plan_parts`).

    Attributes:
        members: indices into the batch's member list; group: the structure group it belongs to;
        part, parts: its number within the group and how many the group was split into;
        devices: devices it is sharded over; why: how it was formed, in words (for the summary).
    """

    members: tuple
    group: int
    part: int
    parts: int
    devices: int
    why: str


def member_cases(case: Case, overrides_per_member: Sequence, *, element_size: float | None = None) -> list[Case]:
    """One case per member: ``case`` (element size first) with the member's ``["section.key=value", ...]``."""
    if element_size is not None:
        case = with_element_size(case, element_size)
    if len(overrides_per_member) == 0:
        raise ValueError("simulate_batch: no members (give one list of overrides per member; [] runs the case itself)")
    out = []
    for i, ov in enumerate(overrides_per_member):
        if isinstance(ov, str):
            raise TypeError(f"simulate_batch: member {i}'s overrides are the string {ov!r}; give a list of "
                            "'section.key=value' strings per member, e.g. [['contact.friction=0.2'], ...]")
        out.append(apply_overrides(case, list(ov)) if ov else case)
    return out


BATCH_FABRIC_NAME = "batch member"
"""The fabric's static label inside a batched program (:func:`common_form`); summaries name the case."""


def common_form(rigs: Sequence) -> list:
    """The rigs with what a batch need not tell apart made one, so that more members share a
    program: the fabric's name (a static label, used by nothing in the run) and, where some member
    bends by a Voce law, a linear law ``M = b kappa`` written as the Voce law ``b_inf = b, m0 = 0``
    (the same moment, stiffness and energy; its numerics were chosen from the linear law, with the
    same ``B_init``). So a fabric's NLBM and LBM members of one mesh (the paper study's four bending
    laws) run as one program; a membrane-only member (no bending) still runs apart. Exceptions
    (members whose rig could not be built) pass through."""
    is_law = lambda x: isinstance(x, (LinearBending, VoceBending))  # noqa: E731
    voce = any(isinstance(x, VoceBending) for r in rigs if not isinstance(r, Exception)
               for x in jax.tree_util.tree_leaves(r.model, is_leaf=is_law))

    def fabric(f):
        if not isinstance(f, Fabric):
            return f
        as_voce = lambda b: b.as_voce() if isinstance(b, LinearBending) else b  # noqa: E731
        bending = f.bending if f.bending is None or not voce else jax.tree_util.tree_map(as_voce, f.bending, is_leaf=is_law)
        return f.replace(name=BATCH_FABRIC_NAME, bending=bending)

    return [r if isinstance(r, Exception) else
            r._replace(model=jax.tree_util.tree_map(fabric, r.model, is_leaf=lambda x: isinstance(x, Fabric)))
            for r in rigs]


def signature(rig: Rig):
    """What members must share to run as one program: the structure and leaf shapes/dtypes of
    model and state (static fields included) and the frames and chunks of the run."""
    model, state, info = rig
    leaves, tree = jax.tree_util.tree_flatten((model, state))
    shapes = tuple((tuple(np.shape(a)), str(jnp.result_type(a))) for a in leaves)
    return tree, shapes, info.n_frames, info.samples_per_frame


def build_members(cases: Sequence[Case], *, dtype=None, samples_per_frame: int | None = None, catch: bool = False):
    """The members' rigs and their structure groups: ``(rigs, groups)``, ``groups`` a list of
    member-index lists. Within a group the steps per frame are made equal (the largest; see the
    module docstring), so each group can run as one program. ``catch``: a member whose rig cannot
    be built gets its exception in place of the rig and no group (the others are built)."""
    rigs = []
    for c in cases:
        try:
            rigs.append(build(c, dtype=dtype, samples_per_frame=samples_per_frame))
        except (ValueError, TypeError) as err:  # the set-up checks of the rig (contact, mass...)
            if not catch:
                raise
            rigs.append(err)
    rigs = common_form(rigs)
    keys, groups = [], []
    for i, r in enumerate(rigs):
        if isinstance(r, Exception):
            continue
        sig = signature(r)
        for k, key in enumerate(keys):
            if key == sig:
                groups[k].append(i)
                break
        else:
            keys.append(sig)
            groups.append([i])
    for g in groups:
        every = max(rigs[i].info.every for i in g)
        for i in g:
            if rigs[i].info.every != every:
                rigs[i] = common_form([build(cases[i], dtype=dtype, samples_per_frame=samples_per_frame,
                                             every=every), rigs[i]])[0]  # rigs[i]: Voce where the batch is
    return rigs, groups


def not_run(case: Case, reason: str) -> FormingResult:
    """The result of a member that never ran (its rig could not be built, or the batch was
    interrupted before its part): no frames, ``complete = False`` and why."""
    summary = {"complete": False, "reason": reason, "case": case.name, "inputs": to_dict(case), "max_ke_ie": None,
               "max_shear_angle_deg": None, "flange_wrinkles": None, "draw_in": None, "wall_time_s": 0.0,
               "frames_written": 0}
    return FormingResult(t=np.zeros(0), x=np.zeros((0, 0, 3)), fields={}, history={}, faces=np.zeros((0, 4), np.int64),
                         ply_id=np.zeros(0, np.int32), info=None, complete=False, reason=reason, wall_time_s=0.0,
                         summary=summary)


def _available_bytes(devices) -> float:
    """Free memory of ``devices`` together, bytes: the accelerators' own, or the host's for CPUs."""
    free = []
    for d in devices:
        stats = d.memory_stats() if hasattr(d, "memory_stats") else None
        if stats and "bytes_limit" in stats:
            free.append(stats["bytes_limit"] - stats.get("bytes_in_use", 0))
    if len(free) == len(devices) and free:
        return float(sum(free))
    try:
        return float(os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):  # no sysconf: assume 8 GB
        return 8.0e9


def member_bytes(rig: Rig) -> float:
    """Estimated memory of one member in a batch program, bytes: :data:`MEMORY_PER_ARRAY_BYTE`
    times its state and model arrays (the temporaries of a step and of the fields dominate)."""
    model, state, _ = rig
    size = sum(int(np.prod(np.shape(a))) * jnp.dtype(jnp.result_type(a)).itemsize
               for a in jax.tree_util.tree_leaves((model, state)))
    return MEMORY_PER_ARRAY_BYTE * size


def plan_parts(rigs, groups, *, devices=None, max_members: int | None = None,
               available_bytes: float | None = None) -> list[BatchPart]:
    """Split each group into parts that fit in memory (and ``max_members``), each sharded over
    as many of ``devices`` (default ``jax.local_devices()``) as it has members."""
    devices = list(jax.local_devices() if devices is None else devices)
    avail = MEMORY_FRACTION * (_available_bytes(devices) if available_bytes is None else float(available_bytes))
    parts = []
    for g, members in enumerate(groups):
        per = member_bytes(rigs[members[0]])
        cap = max(1, int(avail // per))
        why = ""
        if cap < len(members):
            why = (f"split: {len(members)} members need ~{len(members) * per / 1e9:.2g} GB, "
                   f"{avail / 1e9:.2g} GB available ({MEMORY_FRACTION:g} of the free memory): at most {cap} per program")
        if max_members is not None and int(max_members) < min(cap, len(members)):
            cap = int(max_members)
            why = f"split: at most {cap} members per program (max_members)"
        n_parts = math.ceil(len(members) / cap)
        size = math.ceil(len(members) / n_parts)
        for p in range(n_parts):
            chunk = tuple(members[p * size:(p + 1) * size])
            n_dev = min(len(devices), len(chunk))
            parts.append(BatchPart(members=chunk, group=g, part=p, parts=n_parts, devices=n_dev,
                                   why=why or f"{len(chunk)} members in one program"))
    return parts


def _shared_axes(trees):
    """Per leaf: ``None`` when every member has the same value (passed once), else 0 (stacked)."""
    leaves = [jax.tree_util.tree_leaves(t) for t in trees]
    axes = []
    for k, first in enumerate(leaves[0]):
        a0 = np.asarray(first)
        same = all(np.array_equal(a0, np.asarray(lv[k])) for lv in leaves[1:])
        axes.append(None if same else 0)
    return axes


def _stack(trees, axes, mesh, dtype):
    """The members' trees as one: stacked leaves sharded along the batch axis, shared ones replicated.
    Python numbers (weakly typed in a single run) are stacked in ``dtype`` (floats) or int32, so that
    they never promote the run's arithmetic (float64 numbers under ``jax_enable_x64``)."""
    tree = jax.tree_util.tree_structure(trees[0])
    leaves = [jax.tree_util.tree_leaves(t) for t in trees]
    batched, whole = NamedSharding(mesh, P(MESH_AXIS)), NamedSharding(mesh, P())

    def host(a):
        if isinstance(a, (bool, np.bool_)):
            return np.asarray(a)
        if isinstance(a, (int, np.integer)):
            return np.asarray(a, np.int32)
        return np.asarray(a, dtype) if isinstance(a, (float, np.floating)) else np.asarray(a)

    out = [jax.device_put(np.stack([host(lv[k]) for lv in leaves]), batched) if ax == 0
           else jax.device_put(leaves[0][k], whole) for k, ax in enumerate(axes)]
    return jax.tree_util.tree_unflatten(tree, out)


def _member(tree, axes, i):
    """Member ``i`` of a stacked tree (leaves with axis ``None`` are shared)."""
    leaves, tree_def = jax.tree_util.tree_flatten(tree)
    return jax.tree_util.tree_unflatten(tree_def, [a[i] if ax == 0 else a for a, ax in zip(leaves, axes)])


@functools.lru_cache(maxsize=16)
def _program(tree_def, axes: tuple, devices: tuple, n_plies: int):
    """The compiled stretch for a model structure with ``axes`` (per leaf: ``None`` shared, 0
    stacked) on ``devices``: ``(model, state, e0, x_ref, n, floor, ply_id) -> (state, fields)``,
    every member advanced by up to its ``n`` steps, then its fields. Cached: the parts of a sweep
    with the same structure share one program."""
    model_axes = jax.tree_util.tree_unflatten(tree_def, list(axes))
    mesh = Mesh(np.asarray(devices), (MESH_AXIS,))

    def stretch(model, state, e0, x_ref, n, floor, ply_id):
        new = integrate.advance(model, state, n, e0=e0, x_ref=x_ref, blowup_tol=BLOWUP_TOL, energy_floor=floor)
        return new, state_fields(model, new, ply_id, n_plies)

    batched = jax.vmap(stretch, in_axes=(model_axes, 0, 0, 0, 0, None, None), axis_name=BATCH_AXIS)
    spec = jax.tree_util.tree_map(lambda ax: P() if ax is None else P(MESH_AXIS), model_axes,
                                  is_leaf=lambda a: a is None)
    row = P(MESH_AXIS)
    return jax.jit(jax.shard_map(batched, mesh=mesh, in_specs=(spec, row, row, row, row, P(), P()), out_specs=row,
                                 check_vma=False), compiler_options=integrate.COMPILER_OPTIONS)


def _host(tree):
    return jax.tree_util.tree_map(np.asarray, tree)


def run_part(rigs: Sequence[Rig], *, devices=None, on_frame: Callable | None = None,
             on_progress: Callable | None = None, label: str = "") -> list[FormingResult]:
    """Run rigs of one structure group (:func:`build_members`) as one program; one result per rig.

    Args:
        rigs: the members' rigs (same :func:`signature`, same steps per frame).
        devices: the devices to shard over (default: as many local devices as members).
        on_frame: ``on_frame(i, k, t, x, fields)`` after member ``i``'s frame ``k``.
        on_progress: ``on_progress(step, n_steps, t, punch_m, elapsed_s)`` once before the
            program compiles (step 0), then per stretch (the first member still running).
        label: how the part was formed, recorded in each summary's ``batch.why``.

    Never raises for a failed member: its result says ``complete=False`` and why; a
    ``KeyboardInterrupt`` stops every member with that reason.
    """
    t_wall = time.perf_counter()
    infos = [r.info for r in rigs]
    info0 = infos[0]
    if len({signature(r) for r in rigs}) != 1 or len({i.every for i in infos}) != 1:
        raise ValueError("forming.batch.run_part: the rigs differ in structure or steps per frame; "
                         "build them with forming.batch.build_members, which groups them")
    B = len(rigs)
    devices = list(jax.local_devices() if devices is None else devices)[:B]
    D = len(devices)
    Bp = D * math.ceil(B / D)
    pad = [rigs[0]] * (Bp - B)
    models = [r.model for r in rigs] + [r.model for r in pad]
    states0 = [r.state for r in rigs] + [r.state for r in pad]
    mesh = Mesh(np.asarray(devices), (MESH_AXIS,))
    axes = _shared_axes(models)
    dtype = rigs[0].state.x.dtype
    model = _stack(models, axes, mesh, dtype)
    all_axes = [0] * len(jax.tree_util.tree_leaves(states0[0]))
    parked = _stack(states0, all_axes, mesh, dtype)
    state, e0, x_ref = parked, parked.energies, parked.x
    floor = jnp.asarray(_floor(rigs[0].state), rigs[0].state.x.dtype)
    step_prog = _program(jax.tree_util.tree_structure(models[0]), tuple(axes), tuple(devices), info0.case.n_plies)
    ply_id = jax.device_put(np.asarray(info0.ply_id), NamedSharding(mesh, P()))

    def prog(model, state, e0, x_ref, n, floor):
        return step_prog(model, state, e0, x_ref, n, floor, ply_id)

    recs = [Recorder(None if on_frame is None else (lambda k, t, x, f, i=i: on_frame(i, k, t, x, f)))
            for i in range(B)]
    active = np.array([True] * B + [False] * (Bp - B))
    reasons: list = [None] * B
    causes: list = [None] * B  # why a member failed, as the single-run driver words it
    last_good = [None] * B  # host copies of a failed member's last good state (its final state)
    finished: set = set()
    alone: dict = {}  # members that switched their fibre mass's momentum term on: their Standing, run alone
    n_sub = info0.sub_steps

    def view(host_state, fl, i):
        x = None if host_state.x is None else host_state.x[i]
        s = types.SimpleNamespace(t=host_state.t[i], step=host_state.step[i], x=x,
                                  energies=jax.tree_util.tree_map(lambda a: a[i], host_state.energies))
        return s, {k: v[i] for k, v in fl.items()}

    def record(new, fl, frame: bool):
        hs = types.SimpleNamespace(t=np.asarray(new.t), step=np.asarray(new.step),
                                   x=np.asarray(new.x) if frame else None, energies=_host(new.energies))
        hf = {k: np.asarray(fl[k]) for k in (fl if frame else SCALARS)}
        for i in range(B):
            if active[i]:
                s, f = view(hs, hf, i)
                recs[i].sample(s, f)
                if frame:
                    recs[i].frame(s, f)

    def park(new, failed):
        mask = jnp.asarray(np.isin(np.arange(Bp), failed))
        for i in failed:
            last_good[i] = _member(state, all_axes, i)
            active[i] = False
        return jax.tree_util.tree_map(lambda p, s: jnp.where(mask.reshape((-1,) + (1,) * (s.ndim - 1)), p, s),
                                      parked, new)

    try:
        if on_progress is not None:  # step 0: the program is about to compile
            on_progress(0, info0.n_steps, 0.0, 0.0, time.perf_counter() - t_wall)
        state, fl = prog(model, state, e0, x_ref, jnp.zeros((Bp,), jnp.int32), floor)
        record(state, fl, frame=True)
        for _ in range(info0.n_frames - 1):
            for k in range(info0.samples_per_frame):
                n = jnp.asarray(np.where(active, n_sub, 0).astype(np.int32))
                new, fl = prog(model, state, e0, x_ref, n, floor)
                bad = np.asarray(new.bad_step)
                failed = []
                hx, hs = None, None
                for i in np.flatnonzero(active):
                    if bad[i] >= 0:
                        m_i = _member(new, all_axes, i)
                        reasons[i] = ("simulation failed: " + integrate.describe_failure(m_i, _member(model, axes, i))
                                      + " The frames up to the last good one are kept.")
                        causes[i] = integrate.failure_cause(m_i)
                        failed.append(int(i))
                        continue
                    if hx is None:
                        hx, hs = np.asarray(new.x), (np.asarray(new.step), np.asarray(new.t))
                        hfl = {key: np.asarray(fl[key]) for key in SCALARS}
                    out = physical_causes(hx[i], {key: v[i] for key, v in hfl.items()}, infos[i].bounds,
                                          recs[i].hist["max_penetration_m"][-1] if may_stiffen_contact(infos[i]) else np.inf)
                    if out:
                        reasons[i] = failure_reason(out_of_bounds_message(
                            int(hs[0][i]), float(hs[1][i]), float(hfl["punch_displacement"][i]), out))
                        causes[i] = "; ".join(out)
                        failed.append(int(i))
                if failed:
                    new = park(new, failed)
                state = new
                record(state, fl, frame=k == info0.samples_per_frame - 1)
                if on_progress is not None and active.any():
                    i = int(np.flatnonzero(active)[0])
                    on_progress(int(np.asarray(state.step)[i]), info0.n_steps, float(np.asarray(state.t)[i]),
                                float(np.asarray(fl["punch_displacement"])[i]), time.perf_counter() - t_wall)
            if not active[:B].any():
                break
        for i in range(B):  # as its own run would: a failed member goes on alone with what may keep it stable
            at = None if last_good[i] is None else Standing.of(_member(model, axes, i), last_good[i], infos[i])
            if at is None or not at.recover(recs[i], causes[i]):
                continue
            alone[i] = at
            try:
                drive(at, infos[i], recs[i], e0=rigs[i].state.energies, x_ref=rigs[i].state.x, on_progress=on_progress,
                      t_wall=t_wall)
                reasons[i] = None
            except integrate.SimulationError as err:
                reasons[i] = failure_reason(str(err))
            last_good[i] = at.state
            finished.add(i)
    except KeyboardInterrupt as err:
        for i in np.flatnonzero(active[:B]):
            reasons[i] = INTERRUPTED + (f": {err}" if str(err) else "")
            last_good[i] = _member(state, all_axes, i)
        for i in set(alone) - finished:
            reasons[i], last_good[i] = INTERRUPTED + (f": {err}" if str(err) else ""), alone[i].state
    wall = time.perf_counter() - t_wall
    results = []
    for i in range(B):
        rec = recs[i]
        final = last_good[i] if last_good[i] is not None else _member(state, all_axes, i)
        res = FormingResult(
            t=np.asarray(rec.t), x=np.asarray(rec.x), fields={k: np.asarray(v) for k, v in rec.fields.items()},
            history={k: np.asarray(v) for k, v in rec.hist.items()}, faces=infos[i].faces, ply_id=infos[i].ply_id,
            info=infos[i], complete=reasons[i] is None, reason=reasons[i], wall_time_s=wall, summary={},
            final_state=final, model=alone[i].model if i in alone else _member(model, axes, i),
            momentum_term_from=alone[i].switched if i in alone else None, step_cuts=alone[i].cuts if i in alone else [])
        res.summary = summarize(res)
        res.summary["batch"] = {"members": B, "devices": D, "padded_to": Bp, "why": label,
                                "wall_time_is": "the program's, shared by its members"}
        results.append(res)
    return results


def simulate_batch(case: Case, overrides_per_member: Sequence, *, element_size: float | None = None, dtype=None,
                   devices=None, max_members: int | None = None, on_frame: Callable | None = None,
                   on_progress: Callable | None = None, on_part: Callable | None = None) -> list[FormingResult]:
    """Run one case for many members (one list of ``"section.key=value"`` overrides each).

    Args:
        case: a :class:`~jaxform.forming.case.Case` (``jaxform.cases.load``).
        overrides_per_member: e.g. ``[["contact.friction=0.2"], ["contact.friction=0.3"]]``
            (``[]``: the case as it is).
        element_size: overrides ``blank.element_size_mm`` for all (m).
        dtype: overrides ``numerics.dtype``.
        devices: devices to shard over (default ``jax.local_devices()``).
        max_members: at most this many members per program (memory permitting; default: all).
        on_frame: ``on_frame(member, info, k, t, x, fields)`` after each member's frame ``k``
            (``info``: its :class:`~jaxform.forming.rig.RunInfo`).
        on_progress: ``on_progress(part, step, n_steps, t, punch_m, elapsed_s)``.
        on_part: ``on_part(part: BatchPart, results)`` after each part (e.g. to write its outputs).

    Returns:
        one :class:`~jaxform.forming.driver.FormingResult` per member, in order (:func:`not_run`
        for a member whose rig could not be built, or whose part never started because an
        earlier one was interrupted: no frames, ``complete = False`` and why); each
        ``summary["batch"]`` says which group and part ran it, with how many members and devices.
        Each ``wall_time_s`` is its part's (build and run), shared by the part's members.
    """
    if not isinstance(case, Case):
        raise TypeError(f"simulate_batch: case is a {type(case).__name__}; give a Case (jaxform.cases.load(name))")
    t0 = time.perf_counter()
    cases = member_cases(case, overrides_per_member, element_size=element_size)
    rigs, groups = build_members(cases, dtype=dtype, catch=True)
    parts = plan_parts(rigs, groups, devices=devices, max_members=max_members)
    build_s = time.perf_counter() - t0
    devs = list(jax.local_devices() if devices is None else devices)
    results: list = [not_run(c, f"error before the run started: {r}") if isinstance(r, Exception) else None
                     for c, r in zip(cases, rigs)]
    for part in parts:
        t_part = time.perf_counter()
        prog = None if on_progress is None else (lambda *a, p=part: on_progress(p, *a))
        frame = None if on_frame is None else (
            lambda i, *a, p=part: on_frame(p.members[i], rigs[p.members[i]].info, *a))
        out = run_part([rigs[i] for i in part.members], devices=devs[:part.devices], on_frame=frame,
                       on_progress=prog, label=part.why)
        wall = time.perf_counter() - t_part + build_s * len(part.members) / len(cases)
        for i, res in zip(part.members, out):
            res.wall_time_s = wall
            res.summary["wall_time_s"] = wall
            res.summary["batch"].update(group=part.group, part=part.part, parts=part.parts, member=i)
            results[i] = res
        if on_part is not None:
            on_part(part, out)
        if any((r.reason or "").startswith(INTERRUPTED) for r in out):
            break
    return [not_run(c, "not run: the batch was interrupted before its part") if r is None else r
            for c, r in zip(cases, results)]


__all__ = ["INTERRUPTED", "MESH_AXIS", "BATCH_FABRIC_NAME", "common_form", "MEMORY_PER_ARRAY_BYTE", "MEMORY_FRACTION", "BatchPart", "member_cases", "signature", "build_members", "not_run", "member_bytes",
           "plan_parts",
           "run_part", "simulate_batch"]
