"""Running a built rig: pure chunks of steps and a differentiable rollout, and the host driver
that writes frames as they come (callbacks for progress and output).

``simulate(case)`` = ``run(build(case))``: the rig is built once. The run's health is checked by the integrator itself, every step (non-finite values, or an
energy-balance residual above half the largest energy seen, with a floor of :data:`ENERGY_FLOOR`
so that float32 rounding at the start of a run never counts); the driver reads that record and
checks after every chunk that the run stays physical (fibre strain, node speeds, the part inside
the rig: :class:`~jaxform.forming.rig.HealthBounds`). A run that fails either way stops with
``complete = False``, the step, time and cause, and the frames up to the last good one. Before
that, a failing chunk is run again from its start with what may keep it stable (:func:`run`):
with a fibre mass but not its momentum term, with the term; where the step was chosen
automatically, with the step halved (down to 1/:data:`MAX_STEP_CUT`).
"""
from __future__ import annotations

import dataclasses
import time
from typing import Any, Callable

import jax
import jax.numpy as jnp
import numpy as np

from jaxform import integrate
from jaxform.forming.case import Case
from jaxform.forming.fields import ENERGY_KEYS, HISTORY_KEYS, SCALARS, fields_jit
from jaxform.forming.presets import apply_overrides, with_element_size
from jaxform.forming.rig import Rig, RunInfo, build
from jaxform.forming.summary import summarize

BLOWUP_TOL = 0.5
"""An energy-balance residual above this fraction of the largest energy seen is a blow-up."""
ENERGY_FLOOR = {"float32": 1e-3, "float64": 1e-8}
"""J: an energy-balance residual below this never counts as a blow-up (float32 rounding noise of
the accounts; the shell itself works on displacements, see :class:`jaxform.shell.ShellRef`)."""


MAX_STEP_CUT = 8
"""The driver cuts an automatic step down to this fraction at most (halving it three times) for a
chunk that fails at the run's step, e.g. a fold snapping through at metres per second in a
quasi-static run: the step is chosen for the run's quasi-static state, and a dynamic event (faster
contacts, the fibre mass's momentum term growing with the square of the speed) may need less. The
cut stays for the rest of the run: a step that grew an unstable mode slowly enough to pass the
energy check leaves its spurious energy in the accounts, and a later chunk then fails at any step
(measured: a 25 mm rig at 1.6x its stable estimate, going back up after each cut chunk, failed
again six steps later even with 1/8 of the step). A step the user gave is never cut."""


def _floor(state) -> float:
    return ENERGY_FLOOR["float64" if state.x.dtype == jnp.float64 else "float32"]


def run_steps(model, state, e0, x_ref, n: int, energy_floor: float | None = None):
    """``n`` integrator steps (pure; :func:`jaxform.integrate.run_steps` with the forming health
    check, the floor by default :data:`ENERGY_FLOOR` of the state's dtype: a failed stretch returns
    its starting state with the failing step recorded)."""
    floor = _floor(state) if energy_floor is None else energy_floor
    return integrate.run_steps(model, state, n, e0=e0, x_ref=x_ref, blowup_tol=BLOWUP_TOL, energy_floor=floor)[0]


@jax.jit
def _advance_jit(model, state, e0, x_ref, n, energy_floor):
    """The host driver's stretch of ``n`` steps (traced: one program for a rig, whatever its
    stroke, frame count or sampling), forward only (:func:`jaxform.integrate.advance`)."""
    return integrate.advance(model, state, n, e0=e0, x_ref=x_ref, blowup_tol=BLOWUP_TOL, energy_floor=energy_floor)


def rollout(model, state, info: RunInfo, *, n_frames: int | None = None, checkpoint: bool = True):
    """Pure, differentiable run of ``n_frames - 1`` frame intervals (default: the whole stroke).

    Returns ``(final_state, frames)`` (:class:`jaxform.integrate.Frames`, the initial frame not
    included). Use inside ``jax.grad``/``jax.jit`` (``info`` is static: close over it). A failed
    run is frozen at its last good frame: check ``final_state.bad_step < 0``.
    """
    nf = info.n_frames if n_frames is None else int(n_frames)
    return integrate.rollout(model, state, nf - 1, info.every, checkpoint=checkpoint, blowup_tol=BLOWUP_TOL,
                             energy_floor=_floor(state))


@dataclasses.dataclass
class FormingResult:
    """Outcome of :func:`run` (numpy arrays; frames written so far if incomplete).

    Attributes:
        t: (F,) frame times, s; x: (F, N, 3) positions, m; fields: dict of (F, N, ...) nodal
            fields (see :func:`jaxform.forming.fields.state_fields`); history: dict of (S,) sampled
            time series, keys named with their unit as in ``summary.json`` (``t_s``,
            ``punch_displacement_m``, ``punch_force_N``, ``kinetic_J``...:
            :data:`jaxform.forming.fields.HISTORY_KEYS`);
        faces, ply_id: mesh connectivity (F, 4) and (N,) ply numbers; info: :class:`RunInfo`;
        complete: bool; reason: why it stopped early (None when complete); wall_time_s; summary:
        dict (see :func:`jaxform.forming.summary.summarize`); final_state: last
        :class:`~jaxform.model.State`; model: the :class:`~jaxform.model.Model` that ran;
        momentum_term_from: where the driver switched the fibre mass's momentum term on
        (``step``, ``t_s``, ``punch_displacement_m``, the ``cause`` of the chunk that failed
        without it), None if it did not (:func:`run`).
        step_cuts: where the driver cut the step (the same keys and ``cut``: from that chunk on
            the step was the run's over ``cut``), in order (:func:`run`).
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
    momentum_term_from: dict | None = None
    step_cuts: list = dataclasses.field(default_factory=list)

    @property
    def shear_angle_deg(self) -> np.ndarray:
        """(F, N) shear angle per node, degrees."""
        return np.degrees(self.fields["shear_angle"])

    def __repr__(self) -> str:
        state = "complete" if self.complete else f"incomplete: {self.reason}"
        if self.info is None:  # a member of a batch that never ran (jaxform.forming.batch.not_run)
            return f"FormingResult(case={self.summary.get('case')!r}, {state}, frames=0)"
        return (f"FormingResult(case={self.info.case.name!r}, {state}, frames={len(self.t)}, "
                f"nodes={len(self.info.x0)}, wall_time_s={self.wall_time_s:.1f})")


def _single_frame(s):
    return integrate.Frames(x=s.x[None], v=s.v[None], t=s.t[None], step=s.step[None],
                            energies=jax.tree_util.tree_map(lambda a: a[None], s.energies), extras=(),
                            ok=jnp.zeros((1,), bool))


class Recorder:
    """Host-side frames and sampled histories of a run."""

    def __init__(self, on_frame):
        self.on_frame = on_frame
        self.t, self.x, self.fields = [], [], {}
        self.hist: dict[str, list] = {k: [] for k in HISTORY_KEYS.values()}

    def sample(self, s, fl):
        self.hist["t_s"].append(float(s.t))
        self.hist["step"].append(int(s.step))
        for k in SCALARS:
            self.hist[HISTORY_KEYS[k]].append(float(fl[k]))
        for k in ENERGY_KEYS:
            self.hist[HISTORY_KEYS[k]].append(float(getattr(s.energies, k)))

    def frame(self, s, fl):
        k = len(self.t)
        host = {kk: np.asarray(v) for kk, v in fl.items() if kk not in SCALARS}
        self.t.append(float(s.t))
        self.x.append(np.asarray(s.x))
        for kk, v in host.items():
            self.fields.setdefault(kk, []).append(v)
        if self.on_frame is not None:
            self.on_frame(k, float(s.t), self.x[-1], host)


def physical_causes(x, fl, bounds) -> list[str]:
    """Host: how a state (positions ``x`` (N, 3) m, its fields ``fl``) left the physical bounds of
    a run (:class:`~jaxform.forming.rig.HealthBounds`), in words; empty when it did not. A run can
    blow up without a NaN or an energy-balance jump: nodes flung away by an over-damped contact
    still balance their energy."""
    b = bounds
    x = np.asarray(x)
    strain, speed = float(fl["max_fibre_strain"]), float(fl["max_node_speed"])
    causes = []
    if not strain <= b.fibre_strain:
        causes.append(f"fibre strain {strain:.3g} beyond {b.fibre_strain:g} (the fibres carry < 0.01)")
    if not speed <= b.speed:
        causes.append(f"a node moves at {speed:.3g} m/s, beyond {b.speed:.3g} m/s (100 x the punch speed)")
    pen = float(fl.get("max_penetration", 0.0))
    if not pen <= b.penetration:
        causes.append(f"a node penetrated a tool or ply by {pen * 1e3:.3g} mm, beyond {b.penetration * 1e3:.3g} mm "
                      "(half the ply): the contact is too soft for this case's pressures (raise "
                      "contact.expected_pressure_Pa)")
    lo, hi = x.min(axis=0), x.max(axis=0)
    if not (np.all(lo >= np.asarray(b.box_lo)) and np.all(hi <= np.asarray(b.box_hi))):
        far = max(float(np.max(np.asarray(b.box_lo) - lo)), float(np.max(hi - np.asarray(b.box_hi))))
        causes.append(f"the part left the rig (nodes {far * 1e3:.3g} mm outside the box of twice the blank)")
    return causes


def out_of_bounds_message(step: int, t: float, punch_m: float, causes) -> str:
    """The words of a run that left its physical bounds (:func:`physical_causes`)."""
    return (f"the run left its physical bounds near step {step} (t = {t:.6e} s, punch {punch_m * 1e3:.2f} "
            f"mm): {'; '.join(causes)}. Likely cause: an unstable or badly set-up run (time step, contact stiffness or "
            "damping, mass scaling); the frames up to the last good one are kept.")


def _check_health(state, fl, info: RunInfo, last_good) -> None:
    """Raise :class:`~jaxform.integrate.SimulationError` when the run left the physical bounds of
    ``info.bounds`` (:func:`physical_causes`)."""
    causes = physical_causes(state.x, fl, info.bounds)
    if not causes:
        return
    step, t = int(state.step), float(state.t)
    raise integrate.SimulationError(out_of_bounds_message(step, t, float(fl["punch_displacement"]), causes),
                                    step=step, time=t, cause="; ".join(causes), frames=_single_frame(last_good),
                                    state=last_good)


def _cut_advance(model, state, e0, x_ref, n_sub, floor, cut: int):
    """``n_sub`` steps of ``model.dt`` as ``cut`` times as many of ``model.dt / cut`` (the same
    compiled program: the step is a leaf of the model). The integrator's time is its step count
    times its step, so the count runs in cut steps inside and in the run's steps outside (the
    chunk ends on a whole step of the run; a failing step is reported as the run's step it falls in)."""
    if cut == 1:
        return _advance_jit(model, state, e0, x_ref, n_sub, floor)
    fine = dataclasses.replace(model, dt=model.dt / cut)
    new = _advance_jit(fine, dataclasses.replace(state, step=state.step * cut), e0, x_ref, n_sub * cut, floor)
    bad = jnp.where(new.bad_step >= 0, new.bad_step // cut, new.bad_step)
    return dataclasses.replace(new, step=new.step // cut, bad_step=bad)


def _chunk(model, state, e0, x_ref, n_sub, floor, ply_arr, info: RunInfo, cut: int = 1):
    """One host chunk of ``n_sub`` steps from ``state`` (with the step cut to ``1/cut``):
    ``(new_state, fields)``, or :class:`~jaxform.integrate.SimulationError` when a step failed
    or the run left its bounds."""
    new = _cut_advance(model, state, e0, x_ref, n_sub, floor, cut)
    if int(new.bad_step) >= 0:
        raise integrate.SimulationError(
            integrate.describe_failure(new, model) + " The frames up to the last good one are kept.",
            step=int(new.bad_step), time=int(new.bad_step) * info.dt, cause=integrate.failure_cause(new),
            frames=_single_frame(new), state=new)
    fl = fields_jit(model, new, ply_arr, n_plies=info.case.n_plies)
    _check_health(new, fl, info, state)
    return new, fl


def with_momentum_term(model):
    """``model`` with its fibre mass's momentum term on (:func:`jaxform.fibre_mass.geometric_force`),
    or ``None`` where it has no fibre mass or has the term already."""
    fm = model.fibre_mass
    if fm is None or fm.geometric:
        return None
    return dataclasses.replace(model, fibre_mass=dataclasses.replace(fm, geometric=True))


@dataclasses.dataclass
class Standing:
    """Where a host run stands: the model running, the last good state, and where the driver
    switched the fibre mass's momentum term on (``FormingResult.momentum_term_from``). Kept
    current by :func:`drive`, so that a run that raises still has its last good state."""

    model: Any
    state: Any
    switched: dict | None = None
    may_cut: bool = True
    cuts: list = dataclasses.field(default_factory=list)

    @property
    def cut(self) -> int:
        """The step runs at the run's over this (1 until :meth:`recover` cuts it)."""
        return self.cuts[-1]["cut"] if self.cuts else 1

    def _where(self, rec: "Recorder", cause: str) -> dict:
        return {"step": int(self.state.step), "t_s": float(self.state.t),
                "punch_displacement_m": float(rec.hist["punch_displacement_m"][-1]), "cause": cause}

    def switch(self, rec: "Recorder", cause: str) -> bool:
        """Switch the momentum term on from the last good state because a chunk failed with
        ``cause``; False (nothing changed) where the model has no fast fibre mass to switch."""
        exact = with_momentum_term(self.model)
        if exact is None:
            return False
        self.model = exact
        self.switched = self._where(rec, cause)
        return True

    def recover(self, rec: "Recorder", cause: str) -> bool:
        """What to change before the chunk that failed with ``cause`` runs again from the last
        good state: the momentum term (:meth:`switch`), else half the step (down to
        1/:data:`MAX_STEP_CUT`, an automatic step only); False where nothing is left to change."""
        if self.switch(rec, cause):
            return True
        if not self.may_cut or self.cut >= MAX_STEP_CUT:
            return False
        self.cuts.append({**self._where(rec, cause), "cut": 2 * self.cut})
        return True


def drive(at: Standing, info: RunInfo, rec: "Recorder", *, e0, x_ref, on_progress: Callable | None = None,
          t_wall: float | None = None) -> None:
    """Run the chunks of ``info`` still to do from ``at.state`` (its step says how many are done),
    sampling and writing frames into ``rec``. A chunk that fails is run again from its start
    with what :meth:`Standing.recover` changes (:func:`run`), and so is the rest. Raises
    :class:`~jaxform.integrate.SimulationError` on a failure nothing is left to change for;
    ``at`` then holds the last good state."""
    t_wall = time.perf_counter() if t_wall is None else t_wall
    ply_arr = jnp.asarray(info.ply_id)
    floor = jnp.asarray(_floor(at.state), at.state.x.dtype)
    n_sub = jnp.asarray(info.sub_steps, jnp.int32)
    for c in range(int(at.state.step) // info.sub_steps, (info.n_frames - 1) * info.samples_per_frame):
        while True:
            try:
                new, fl = _chunk(at.model, at.state, e0, x_ref, n_sub, floor, ply_arr, info, at.cut)
                break
            except integrate.SimulationError as err:
                if not at.recover(rec, err.cause):
                    if at.cut > 1:
                        raise integrate.SimulationError(
                            f"{err} It failed also with the step cut to 1/{at.cut}.", step=err.step, time=err.time,
                            cause=err.cause, frames=err.frames, state=err.state) from err
                    raise
        at.state = new
        rec.sample(new, fl)
        if on_progress is not None:
            on_progress(int(new.step), info.n_steps, float(new.t), float(fl["punch_displacement"]),
                        time.perf_counter() - t_wall)
        if (c + 1) % info.samples_per_frame == 0:
            rec.frame(new, fl)


def run(rig: Rig, *, on_frame: Callable | None = None, on_progress: Callable | None = None, catch: bool = False,
        build_only: bool = False) -> FormingResult:
    """Run a built rig on the host, chunk by chunk (``info.sub_steps`` steps per jitted call).

    A chunk that fails (a step, or the run's bounds) is run again from its start, as often as
    :meth:`Standing.recover` finds something to change. With a fibre mass but not its momentum
    term, first with the term, and so is the rest of the run
    (``momentum_term_from`` of the result, ``numerics.fibre_mass_momentum_term_choice`` of the
    summary). Without the term the position-dependent mass can pump energy into elements that
    turn fast (a whipping corner, a snapping wrinkle) within a few hundred steps; the term removes
    that at about twice a step's cost, so it is paid only from where it was needed. Measured:
    woven Case A LBM B_inf, 4 mm, blew up at 90 % of the stroke within one chunk (the energy
    residual was 0.3 % of the largest energy at the chunk's start). Then, where the step was
    chosen automatically (:func:`may_cut_step`), with half the step, then a quarter, then an
    eighth (:data:`MAX_STEP_CUT`): the chunk's steps are run as two, four or eight steps each, and
    so are the rest of the run's (``step_cuts`` of the result, ``numerics.step_cuts`` of the
    summary). Why: ``case-a-ncf-nlbm`` at 4 mm and the quasi-static 31.25 mm/s blew up at
    95 % of the stroke after a sudden event (node speeds 0.8 -> 7.9 m/s at a 0.031 m/s punch); a
    step chosen for the quasi-static run need not hold through a snap.

    Args:
        rig: :func:`jaxform.forming.build`'s ``(model, state, info)``.
        on_frame: ``on_frame(k, t, x (N,3), fields dict)`` called after each frame (frame 0: start).
        on_progress: ``on_progress(step, n_steps, t, punch_displacement_m, elapsed_s)`` per chunk.
        catch: return an incomplete result (``complete=False`` and ``reason``) instead of raising
            on failure or ``KeyboardInterrupt``.
        build_only: write the initial frame only.

    Returns:
        :class:`FormingResult` (its ``summary`` filled by :func:`jaxform.forming.summary.summarize`).
    """
    t_wall = time.perf_counter()
    model, state, info = rig
    at = Standing(model, state, may_cut=may_cut_step(info))
    rec = Recorder(on_frame)
    complete, reason = False, None
    try:
        fl = fields_jit(model, state, jnp.asarray(info.ply_id), n_plies=info.case.n_plies)
        rec.sample(state, fl)
        rec.frame(state, fl)
        if not build_only:
            drive(at, info, rec, e0=state.energies, x_ref=state.x, on_progress=on_progress, t_wall=t_wall)
            complete = True
    except KeyboardInterrupt as err:
        if not catch:
            raise
        reason = str(err) or "interrupted by the user (KeyboardInterrupt)"
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
    result = FormingResult(
        t=np.asarray(rec.t), x=np.asarray(rec.x), fields={k: np.asarray(v) for k, v in rec.fields.items()},
        history={k: np.asarray(v) for k, v in rec.hist.items()}, faces=info.faces, ply_id=info.ply_id, info=info,
        complete=complete, reason=reason, wall_time_s=time.perf_counter() - t_wall, summary={}, final_state=at.state,
        model=at.model, momentum_term_from=at.switched, step_cuts=at.cuts)
    result.summary = summarize(result)
    return result


def may_cut_step(info: RunInfo) -> bool:
    """Whether the driver may cut the run's step (:data:`MAX_STEP_CUT`): not where the user gave it."""
    return getattr(getattr(info, "numerics", None), "governed_by", None) != "user"


def simulate(case: Case, *, dtype=None, element_size: float | None = None, overrides=(),
             on_frame: Callable | None = None, on_progress: Callable | None = None, catch: bool = False, fabric=None,
             samples_per_frame: int | None = None, damping: float = 0.0, dt: float | None = None,
             build_only: bool = False) -> FormingResult:
    """Run a forming case: apply the overrides once, build the rig once, run it (:func:`run`).

    Args:
        case: a :class:`~jaxform.forming.case.Case` (``jaxform.cases.load(name_or_toml)``;
            ``jaxform.simulate`` also takes the name or path itself).
        dtype: overrides the case's ``numerics.dtype``.
        element_size: overrides ``blank.element_size_mm`` (m).
        overrides: ``["section.key=value", ...]`` (:func:`jaxform.forming.presets.apply_overrides`).
        on_frame, on_progress, catch, build_only: see :func:`run`.
        fabric, samples_per_frame, damping, dt: see :func:`jaxform.forming.build`.

    Returns:
        :class:`FormingResult`; its ``wall_time_s`` includes building the rig.
    """
    if not isinstance(case, Case):
        raise TypeError(f"forming.simulate: case is a {type(case).__name__}; give a Case "
                        "(jaxform.cases.load(name_or_toml)) or call jaxform.simulate, which takes names and paths")
    t_wall = time.perf_counter()
    if element_size is not None:
        case = with_element_size(case, element_size)
    if overrides:
        case = apply_overrides(case, list(overrides))
    rig = build(case, dtype=dtype, fabric=fabric, samples_per_frame=samples_per_frame, damping=damping, dt=dt)
    result = run(rig, on_frame=on_frame, on_progress=on_progress, catch=catch, build_only=build_only)
    result.wall_time_s = time.perf_counter() - t_wall
    result.summary["wall_time_s"] = result.wall_time_s
    return result


__all__ = ["BLOWUP_TOL", "ENERGY_FLOOR", "MAX_STEP_CUT", "may_cut_step", "run_steps", "rollout", "FormingResult", "Standing", "drive", "with_momentum_term", "run", "simulate", "physical_causes",
           "out_of_bounds_message"]
