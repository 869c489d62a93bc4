"""Explicit central-difference integration of the fabric shell.

``step(model, state) -> state`` advances one time step; :func:`rollout` scans it (``lax.scan``),
saving a frame every ``every`` steps, with ``jax.checkpoint`` on each chunk of ``every`` steps so
that reverse mode through thousands of steps stores only the frames (memory ~ frames + one chunk).
:func:`simulate` is the host-side driver: it jits the rollout, checks the run's health and raises
:class:`SimulationError` (with the frames up to the last good one) when it failed.

Central differences (velocities at half steps), the free dofs carrying the momentum ``p``::

    f_n     = f_int(x_n) + m g + f_loads(x_n, v_{n-1/2}, t_n) - c m v_{n-1/2}
    p*      = p_{n-½} + dt f_n
    p_{n+½} = p* + dt F(p*),      v_{n+½} = C p_{n+½}   (driven dofs: (x_drive(t_{n+1}) - x_n) / dt)
    u_{n+1} = u_n + dt v_{n+½},   x_{n+1} = X + u_{n+1}

``F`` is the friction of the loads that integrate it backward (:mod:`jaxform.model`, the tools and
the plies: :mod:`jaxform.friction`), applied load after load on the trial momentum ``p*``; it is
booked with the loads' work.

``C`` is the inverse mass: ``M^-1`` (lumped), or with a fibre mass (:mod:`jaxform.fibre_mass`)
the polynomial ``C(x_n)``; with its momentum term on, the dependence on the positions adds
``-1/2 d(p_{n-½}^T C p_{n-½})/dx`` to ``f_n`` (Hamilton's equations for a position-dependent mass).
The integrated quantity is the displacement ``u`` from the mesh nodes ``X`` and the shell is
evaluated on it (float32 absolute positions would add rounding noise to every strain).

Energy accounts at step n: elastic parts at ``x_n``; kinetic ``1/2 v_mid . p_mid`` with ``v_mid =
(v_{n-½} + v_{n+½}) / 2`` (``1/2 m |v_mid|^2`` with the lumped mass; it differs from the exactly
balancing ``1/2 m v_{n-½} . v_{n+½}`` by ``m |v_{n+½} - v_{n-½}|^2 / 8``, which stays non-negative
and makes a chattering node show up in the balance); gravity work ``m g . (x_n - x_0)``; load,
damping and boundary (reaction) work by the trapezoidal rule over ``x_{n-1} -> x_n``. The run is
declared failed at the first step where a value is non-finite or the energy balance residual
exceeds ``blowup_tol`` times the largest energy scale seen, or ``energy_floor`` (J) if that is
larger (the signature of an unstable time step). The floor keeps rounding noise from counting as a
blow-up while every energy is still tiny (the start of a forming run in float32).
"""
from __future__ import annotations

import dataclasses
import math
import warnings
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from jaxform import fibre_mass as _fm
from jaxform._pytree import pytree_dataclass
from jaxform.model import Energies, Hold, Model, State
from jaxform.shell import Shell, forces_and_energy_sym
from jaxform.spectrum import stable_time_step


COMPILER_OPTIONS = {"xla_cpu_experimental_ynn_fusion_type": ""}
"""XLA options of the programs that run the step (the forming driver's, a batch's, the section
fits', :func:`simulate`'s): no YNNPACK fusions on CPU. This XLA hands the step's reductions (the three-row dot products,
the energies' sums) to YNNPACK, one library call each, outside XLA's own loop fusions; without
them the 2 mm woven step took 6.7-7.1 ms against 8.3-8.5 ms (the same sums in another order:
positions within 1.1e-6 m after 2,000 steps; ``benchmarks/results/step-pieces-20261207``)."""


class SimulationError(RuntimeError):
    """A run failed; ``frames`` holds the frames up to the last good one, ``step``/``time`` where."""

    def __init__(self, message, *, step, time, cause, frames, state):
        super().__init__(message)
        self.step = step
        self.time = time
        self.cause = cause
        self.frames = frames
        self.state = state


@pytree_dataclass
class Frames:
    """Saved frames (leading axis: frame).

    A frame is the state after its last step: positions ``x_{n+1}``; the energies are those of
    that step (positions ``x_n``, one step earlier).

    Attributes:
        x: (F, N, 3) positions, m.
        v: (F, N, 3) velocities (half step before the frame), m/s.
        t: (F,) times, s.
        step: (F,) step numbers.
        energies: :class:`~jaxform.model.Energies` with (F,) arrays, J.
        extras: tuple (one per load) of dicts of per-frame arrays.
        ok: (F,) bool, the frame was reached before any failure.
    """

    x: Any
    v: Any
    t: Any
    step: Any
    energies: Any
    extras: tuple
    ok: Any


def make_model(shell: Shell, *, dt: float | None = None, safety: float = 0.8, mass_scale: float = 1.0,
               damping: float = 0.0, gravity=(0.0, 0.0, 0.0), fixed=None, drive=None, loads: tuple = (),
               dtype=None, fibre_mass_factor: float = 1.0, fibre_mass_momentum_term: bool = False,
               dt_limit: float | None = None) -> Model:
    """Build a :class:`Model` on the host.

    ``dt`` defaults to ``safety`` times the stable limit (:func:`jaxform.spectrum.stable_time_step`);
    a user ``dt`` above the limit is kept but warned about. ``mass_scale`` multiplies all masses
    (raising the stable step by its square root). ``fibre_mass_factor`` ``s`` > 1 adds inertia to
    fibre stretching only (:mod:`jaxform.fibre_mass`; the membrane limit grows by ``s``). ``fixed``
    (N, 3) bool marks driven dofs (default none), ``drive`` gives their positions (default: held
    where they are); with a fibre mass, the added inertia couples free dofs only (a driven dof's
    motion does not load its free neighbours through it); ``fibre_mass_momentum_term`` adds the
    term the position-dependent fibre mass puts into the momentum equation
    (:func:`jaxform.fibre_mass.geometric_force`). ``dt_limit``: the stable step (safety 1) of
    ``shell`` with these masses where the caller has computed it (:func:`jaxform.forming.build`).
    """
    dtype = dtype or (jnp.float64 if jax.config.jax_enable_x64 else jnp.float32)
    # first: it checks the factor (a clear error before any use of it)
    fm = _fm.fibre_mass(shell, fibre_mass_factor, mass_scale=mass_scale, dtype=dtype,
                        momentum_term=fibre_mass_momentum_term)
    if dt_limit is None:
        dt_limit = stable_time_step(shell, mass_scale=mass_scale, safety=1.0, fibre_mass_factor=fibre_mass_factor)
    if dt is None:
        dt = safety * dt_limit
    elif dt > dt_limit:
        warnings.warn(
            f"time step {dt:.3e} s is above the estimated stable limit {dt_limit:.3e} s "
            "(membrane and bending wave speeds on the smallest element); the run may blow up. "
            "Use a smaller dt, mass scaling, or a coarser mesh.",
            RuntimeWarning,
            stacklevel=2,
        )
    n = shell.mesh.n_nodes
    x0 = jnp.asarray(shell.mesh.nodes, dtype)
    fixed = jnp.zeros((n, 3), bool) if fixed is None else jnp.asarray(fixed, bool)
    if fixed.shape != (n, 3):
        raise ValueError(f"make_model: fixed has shape {fixed.shape}: need ({n}, 3) booleans (driven dofs)")
    drive = Hold(x0) if drive is None else drive
    mass = jnp.asarray(shell.node_masses(mass_scale), dtype)
    return Model(shell=shell, mass=mass, fixed=fixed, drive=drive, gravity=jnp.asarray(gravity, dtype),
                 damping=jnp.asarray(damping, dtype), dt=jnp.asarray(dt, dtype), loads=tuple(loads),
                 mass_scale=mass_scale, fibre_mass=fm)


def init_state(model: Model, x=None, v=None, load_states: tuple | None = None) -> State:
    """The state at t = 0: positions ``x`` (default: the reference), velocities ``v`` (default 0).

    ``v`` is the velocity at t = 0; the kinetic energy account starts from it. With a fibre mass
    it is taken to stretch no fibre (rest, a rigid motion): its momentum is ``M v``.
    """
    dtype = model.mass.dtype
    x = jnp.asarray(model.shell.mesh.nodes if x is None else x, dtype)
    v = jnp.zeros_like(x) if v is None else jnp.asarray(v, dtype)
    u = (x - jnp.asarray(model.shell.mesh.nodes, dtype)).T
    _, parts = forces_and_energy_sym(u, model.shell)
    ke = 0.5 * jnp.sum(model.mass[:, None] * v * v)
    z = jnp.zeros((), dtype)
    e = Energies(ke, parts["tension"], parts["shear"], parts["bending"], z, z, z, z)
    loads = tuple(None for _ in model.loads) if load_states is None else tuple(load_states)
    zero = jnp.zeros_like(x.T)  # SoA (3, N), as the step keeps them
    return State(x=x, v=v, t=jnp.zeros((), dtype), step=jnp.zeros((), jnp.int32), energies=e, loads=loads,
                 f_prev=(zero, zero, zero), bad_step=jnp.asarray(-1, jnp.int32),
                 bad_code=jnp.asarray(0, jnp.int32), scale_max=e.scale(),
                 momentum=jnp.where(model.fixed, 0.0, model.mass[:, None] * v).T, u=u, u_lost=jnp.zeros_like(u))


def compensated_add(total, increment, lost):
    """``total + increment`` by compensated (Kahan) summation: ``(new total, new lost)``, ``lost``
    what rounding took from the earlier increments (start from zeros). A float32 displacement of
    0.05 m has an ulp of 3.7e-9 m; a step adds about 1e-6 m, and nearly equal increments round the
    same way step after step, so the plain sum drifts by up to half an ulp a step (woven Case A at
    8 mm: 0.036 mm of edge draw-in more than float64 over 48,000 steps); here the error stays
    within an ulp or two, whatever the number of steps."""
    y = increment - lost
    new = total + y
    return new, (new - total) - y


def _step(model: Model, state: State, x_ref):
    # The arithmetic runs on structure-of-arrays vectors (3, N) (contiguous rows vectorise on CPU;
    # (N, 3) with its 3-long trailing axis does not); the state and the load interface stay (N, 3).
    dt = model.dt
    m = model.mass[None, :]
    # the shell sees displacements from the reference (ShellRef.edge0): absolute float32
    # positions would add a rounding noise to every strain, every step
    x, v_old, t = state.x, state.v, state.t
    xs, vs_old, us = x.T, v_old.T, state.u
    first = state.step == 0
    f_int, parts = forces_and_energy_sym(us, model.shell)
    f_grav = m * model.gravity[:, None]
    f_damp = -model.damping * m * vs_old
    f_loads = jnp.zeros_like(xs)
    new_loads, extras, supports = [], [], []
    for load, ls in zip(model.loads, state.loads):
        f, ls_new, ex = load.force(x, v_old, t, ls)
        ex = dict(ex)
        supports.append(ex.pop("backward_support", None))
        f_loads = f_loads + f.T
        new_loads.append(ls_new)
        extras.append(ex)
    f_free = f_int + f_grav + f_damp + f_loads
    fixed = model.fixed.T
    fm = model.fibre_mass
    free = jnp.where(fixed, 0.0, 1.0).astype(xs.dtype)
    if fm is not None and fm.geometric:  # the position-dependent mass's own term (Hamilton)
        f_free = f_free + _fm.geometric_force(xs, state.momentum, model.mass, free, fm, model.shell)
    # on the first step the initial velocity is the full-step velocity: advance half a step
    h = jnp.where(first, 0.5 * dt, dt)
    p_new = free * (state.momentum + h * f_free)
    for i, (load, sup) in enumerate(zip(model.loads, supports)):  # contact integrated backward (model.py)
        if sup is not None:
            f_fr, extras[i], new_loads[i] = load.backward(sup, p_new.T, model.mass, h, dt, extras[i], new_loads[i])
            f_fr = free * f_fr.T
            p_new = p_new + h * f_fr
            f_loads = f_loads + f_fr
    if fm is None:
        v_free = p_new / m
    else:
        v_free = _fm.inverse_mass_times(p_new, _fm.fibre_units(xs, fm, model.shell), model.mass, free, fm, model.shell)
    x_drive = model.drive.position(t + dt).T
    v_drive = (x_drive - xs) / dt
    v_new = jnp.where(fixed, v_drive, v_free)
    u_new, u_lost = compensated_add(us, dt * v_new, state.u_lost)
    x_new = jnp.asarray(model.shell.mesh.nodes, xs.dtype).T + u_new
    # (with a fibre mass: the lumped part only; driven dofs move at constant velocity there)
    reaction = jnp.where(fixed, m * (v_new - vs_old) / h - f_free, 0.0)
    # energies at step n: kinetic with the mid velocity, work by the trapezoidal rule over x_{n-1} -> x_n
    v_mid = jnp.where(first, vs_old, 0.5 * (vs_old + v_new))
    dx = jnp.where(first, 0.0, dt * vs_old)
    fl0, fd0, fr0 = state.f_prev
    e_old = state.energies
    # 1/2 v_mid . C^-1 v_mid with C^-1 v = p on the free dofs, the lumped mass on the driven ones
    p_mid = jnp.where(first, state.momentum, 0.5 * (state.momentum + p_new))
    kinetic = 0.5 * jnp.sum(v_mid * jnp.where(fixed, m * v_mid, p_mid))
    e = Energies(
        kinetic=kinetic,
        tension=parts["tension"],
        shear=parts["shear"],
        bending=parts["bending"],
        gravity_work=jnp.sum(f_grav * (xs - x_ref.T)),
        external_work=e_old.external_work + 0.5 * jnp.sum((fl0 + f_loads) * dx),
        boundary_work=e_old.boundary_work + 0.5 * jnp.sum((fr0 + reaction) * dx),
        damping_work=e_old.damping_work - 0.5 * jnp.sum((fd0 + f_damp) * dx),
    )
    return x_new.T, v_new.T, e, tuple(new_loads), tuple(extras), (f_loads, f_damp, reaction), (p_new, u_new, u_lost)


def step(model: Model, state: State, *, e0: Energies | None = None, x_ref=None, blowup_tol: float = 0.5,
         energy_floor: float = 0.0) -> State:
    """Advance one time step (pure). A failed run stays frozen at its last good state."""
    x_ref = model.drive.position(0.0) if x_ref is None else x_ref
    e0 = state.energies if e0 is None else e0
    new, _ = _advance(model, state, x_ref, e0, blowup_tol, energy_floor)
    return _freeze_if_failed(state, new)


def _advance(model, state, x_ref, e0, blowup_tol, energy_floor=0.0):
    """One step and its health check, without freezing: ``(new_state, extras)``.

    ``bad_step``/``bad_code`` record the first failing step; the arrays go on (the caller
    reverts a failed stretch to its start, :func:`_freeze_if_failed`): a per-step select of the
    whole state costs as much as the forces on CPU (it defeats XLA's in-place buffer reuse).
    """
    x_new, v_new, e, loads, extras, fp, (p_new, u_new, u_lost) = _step(model, state, x_ref)
    # every node's position and velocity enters the energies: one non-finite value makes them so
    finite = jnp.isfinite(e.internal) & jnp.isfinite(e.kinetic) & jnp.isfinite(jnp.sum(v_new))
    scale = jnp.maximum(state.scale_max, e.scale())
    tiny = 1e-30 if x_new.dtype == jnp.float64 else 1e-20
    blown = jnp.abs(e.balance(e0)) > blowup_tol * jnp.maximum(scale, energy_floor) + tiny
    code = jnp.where(~finite, 1, jnp.where(blown, 2, 0)).astype(jnp.int32)
    fail_now = (state.bad_step < 0) & (code > 0)
    # t = steps x dt, not t + dt: a float32 sum drifts (-5e-4 of the time after 66,600 steps of 6.3e-6 s)
    new = State(x=x_new, v=v_new, t=(state.step + 1).astype(state.t.dtype) * model.dt, step=state.step + 1, energies=e,
                loads=loads,
                f_prev=fp, bad_step=jnp.where(fail_now, state.step, state.bad_step),
                bad_code=jnp.where(fail_now, code, state.bad_code), scale_max=jnp.where(finite, scale, state.scale_max),
                momentum=p_new, u=u_new, u_lost=u_lost)
    return new, extras


def _freeze_if_failed(start: State, end: State) -> State:
    """``end`` if the stretch ``start -> end`` stayed healthy, else ``start`` (the last good state)
    with ``end``'s step count and failure record."""
    keep = end.bad_step >= 0  # a failure record, once set, is never cleared
    frozen = jax.tree_util.tree_map(lambda a, b: jnp.where(keep, a, b), start, end)
    return dataclasses.replace(frozen, step=end.step, bad_step=end.bad_step, bad_code=end.bad_code)


def run_steps(model: Model, state: State, n: int, *, e0: Energies | None = None, x_ref=None,
              blowup_tol: float = 0.5, energy_floor: float = 0.0, segment: int | None = None):
    """``n`` steps (``lax.scan``; pure, jit-able, differentiable): ``(state, extras of the last step)``.

    A stretch in which a step fails returns its starting state (the last good one) with the
    failing step recorded in ``bad_step``/``bad_code``. ``segment``: the steps run as checkpointed
    segments of that many (the first one shorter where ``segment`` does not divide ``n``), so that
    reverse mode stores a state per segment and one segment's steps, not every step's intermediates
    (same forward result).
    """
    x_ref = model.drive.position(0.0) if x_ref is None else x_ref
    e0 = state.energies if e0 is None else e0

    def one(s, _):
        return _advance(model, s, x_ref, e0, blowup_tol, energy_floor)

    def steps(s, k):
        end, extras = jax.lax.scan(one, s, None, length=k)
        return end, jax.tree_util.tree_map(lambda a: a[-1], extras)

    if segment is None or segment >= n:
        end, last = steps(state, n)
    else:
        # ceil(n / segment) segments, the first one's first `pad` steps skipped (lax.cond on the step
        # index): one compiled step, where a scan of the remaining n % segment steps after the
        # segments was a second copy of the step, its remat and its transpose (woven Case A, 25 mm,
        # 641 steps: the reverse program compiled in 36 s instead of 23 s)
        n_seg = -(-n // segment)
        pad = n_seg * segment - n
        if pad:
            shapes = jax.eval_shape(one, state, None)[1]
            none = jax.tree_util.tree_map(lambda a: jnp.zeros(a.shape, a.dtype), shapes)

            def body(s, j):
                return jax.lax.cond(j >= pad, one, lambda s, _: (s, none), s, None)
        else:
            body = one

        @jax.checkpoint
        def seg(s, first):
            end, extras = jax.lax.scan(body, s, first + jnp.arange(segment))
            return end, jax.tree_util.tree_map(lambda a: a[-1], extras)  # a segment's last step is never skipped

        end, extras = jax.lax.scan(lambda s, first: seg(s, first), state, segment * jnp.arange(n_seg))
        last = jax.tree_util.tree_map(lambda a: a[-1], extras)
    return _freeze_if_failed(state, end), last


def advance(model: Model, state: State, n, *, e0: Energies | None = None, x_ref=None, blowup_tol: float = 0.5,
            energy_floor: float = 0.0) -> State:
    """Up to ``n`` steps, ``n`` an integer that may be traced (a ``lax.while_loop``): one compiled
    program for any number of steps, so a driver's stretches of different lengths (and runs of
    different strokes or frame counts on the same rig) share it. Forward only (a while loop has no
    reverse mode): differentiate through :func:`run_steps`/:func:`rollout`. A failed stretch
    returns its starting state with the failure recorded, as :func:`run_steps`, and stops at the
    failing step: the steps after a blow-up cost the most (non-finite or flying nodes rebuild the
    contact tables every step), and a driver must hear of the failure at once.
    """
    x_ref = model.drive.position(0.0) if x_ref is None else x_ref
    e0 = state.energies if e0 is None else e0
    stop = state.step + jnp.asarray(n, state.step.dtype)
    end = jax.lax.while_loop(lambda s: (s.step < stop) & (s.bad_step < 0),
                             lambda s: _advance(model, s, x_ref, e0, blowup_tol, energy_floor)[0], state)
    return _freeze_if_failed(state, end)


def rollout(model: Model, state: State, n_frames: int, every: int, *, checkpoint: bool = True,
            blowup_tol: float = 0.5, energy_floor: float = 0.0):
    """Run ``n_frames * every`` steps; return ``(final_state, frames)`` (pure, jit-able, differentiable).

    Each chunk of ``every`` steps is a ``lax.scan`` wrapped in ``jax.checkpoint`` (when
    ``checkpoint``), so reverse mode stores one state per frame and recomputes inside chunks, in
    checkpointed segments of about ``sqrt(every)`` steps (:func:`run_steps`): the reverse pass
    holds a state per segment and one segment's step intermediates (woven Case A at 8 mm and the
    quasi-static speed, 2,400 steps a frame: without segments it asked for 38 GB). A failed run is
    frozen at the last good frame (the start of the chunk in which it failed).
    """
    e0 = state.energies
    x_ref = state.x
    segment = math.isqrt(max(every - 1, 0)) + 1 if checkpoint else None

    def chunk(s):
        return run_steps(model, s, every, e0=e0, x_ref=x_ref, blowup_tol=blowup_tol, energy_floor=energy_floor,
                         segment=segment)

    if checkpoint:
        chunk = jax.checkpoint(chunk)

    def outer(s, _):
        s, extras = chunk(s)
        frame = (s.x, s.v, s.t, s.step, s.energies, extras, s.bad_step < 0)
        return s, frame

    s, (x, v, t, stp, en, extras, ok) = jax.lax.scan(outer, state, None, length=n_frames)
    return s, Frames(x=x, v=v, t=t, step=stp, energies=en, extras=extras, ok=ok)


_CAUSES = {
    1: "non-finite positions, velocities or energies",
    2: "energy blow-up (the energy balance no longer holds)",
}


def failure_cause(state: State) -> str | None:
    """Host: the cause recorded at ``state.bad_step`` in words (None if healthy)."""
    return None if int(state.bad_step) < 0 else _CAUSES.get(int(state.bad_code), "unknown")


def describe_failure(state: State, model: Model) -> str:
    """Host: what failed at ``state.bad_step`` and the likely cause, in words (empty if healthy),
    starting ``"step N (t = ...)"``: the callers say it failed (``simulation failed at ...`` here,
    ``simulation failed: ...`` in a forming summary)."""
    bad = int(state.bad_step)
    if bad < 0:
        return ""
    dt = float(model.dt)
    fm = 1.0 if model.fibre_mass is None else model.fibre_mass.factor
    stable = stable_time_step(model.shell, model.mass_scale, safety=1.0, fibre_mass_factor=fm)
    pump = "" if fm == 1.0 or model.fibre_mass.geometric else (
        f" With a fibre mass (x{fm:g}) but not its momentum term, turning elements can also gain energy from "
        "the position-dependent mass: turn the term on (forming cases: numerics.fibre_mass_momentum_term = true) "
        "or lower the factor (numerics.fibre_mass_scaling).")
    return (f"step {bad} (t = {bad * dt:.6e} s): {failure_cause(state)}. "
            f"Likely cause: the time step {dt:.3e} s is too large for the mesh (stable estimate of the "
            f"shell {stable:.3e} s{f', fibre mass x{fm:g}' if fm != 1.0 else ''}; contact stiffness adds to it), "
            "or a distorted/inverted element in the mesh; reduce dt, use mass scaling, or refine/clean the mesh." + pump)


def check(state: State, frames: Frames, model: Model):
    """Host: raise :class:`SimulationError` if the run failed (frames up to the last good one kept)."""
    if int(state.bad_step) < 0:
        return
    bad = int(state.bad_step)
    ok = np.asarray(frames.ok)
    good = jax.tree_util.tree_map(lambda a: a[: int(ok.sum())], frames)
    raise SimulationError(f"simulation failed at {describe_failure(state, model)} {int(ok.sum())} good frames are in .frames.",
                          step=bad, time=bad * float(model.dt), cause=failure_cause(state), frames=good,
                          state=state)


_rollout_jit = jax.jit(rollout, static_argnames=("n_frames", "every", "checkpoint", "blowup_tol"),
                       compiler_options=COMPILER_OPTIONS)
"""One jitted :func:`rollout` for :func:`simulate`: calls with the same model structure and shapes share its
program (a ``jax.jit`` made inside ``simulate`` compiled again on every call)."""


def simulate(model: Model, state: State | None = None, *, n_frames: int, every: int, checkpoint: bool = True,
             blowup_tol: float = 0.5):
    """Host driver: jit + run + health check. Returns ``(final_state, frames)``."""
    state = init_state(model) if state is None else state
    s, frames = _rollout_jit(model, state, n_frames=n_frames, every=every, checkpoint=checkpoint, blowup_tol=blowup_tol)
    check(s, frames, model)
    return s, frames


__all__ = ["make_model", "init_state", "step", "run_steps", "advance", "rollout", "simulate", "check", "failure_cause", "describe_failure", "Frames", "SimulationError"]
