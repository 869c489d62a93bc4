"""Running a built rig: pure chunks of steps and a differentiable rollout, and the host driver
that writes frames as they come (callbacks for progress and output).

``simulate(case)`` = ``run(build(case))``: the rig is built once. The run's health is checked by the integrator itself, every step (non-finite values, or an
energy-balance residual above half the largest energy seen, with a floor of :data:`ENERGY_FLOOR`
so that float32 rounding at the start of a run never counts); the driver reads that record and
checks after every chunk that the run stays physical (fibre strain, node speeds, the part inside
the rig, the blank's edge outside the die: :mod:`jaxform.forming.health`). A run that fails either way stops with
``complete = False``, the step, time and cause, and the frames up to the last good one. Before
that, a failing chunk is run again from its start with what may keep it stable (:func:`run`):
with a fibre mass but not its momentum term, with the term; where the step was chosen
automatically, with the step halved (down to 1/:data:`MAX_STEP_CUT`), and where a node
penetrated too deep an automatic contact, with the contact stiffened as well.
"""
from __future__ import annotations

import dataclasses
import functools
import math
import time
from typing import Any, Callable

import jax
import jax.numpy as jnp
import numpy as np

from jaxform import integrate
from jaxform.penalty import rescaled_load
from jaxform.forming.case import Case
from jaxform.forming.fields import ENERGY_KEYS, HISTORY_KEYS, SCALARS, fields_jit
from jaxform.forming.health import (DEEPER, PENETRATED, drawn_in, failure_reason, out_of_bounds_message, penetrated,
                                    physical_causes)
from jaxform.forming.numerics import CONTACT_RAMP, CONTACT_STIFFEN
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


@functools.partial(jax.jit, compiler_options=integrate.COMPILER_OPTIONS)
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
        step_cuts: where the driver cut the step (the same keys, ``cut``: from that chunk on
            the step was the run's over ``cut``, and ``contact_stiffness``: the contacts' penalty
            went to the run's times this), in order (:func:`run`).
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


def _check_health(state, fl, info: RunInfo, last_good, stiffen_above: float = np.inf) -> None:
    """Raise :class:`~jaxform.integrate.SimulationError` when the run left the physical bounds of
    ``info.bounds`` (:func:`physical_causes`, ``stiffen_above`` as there)."""
    causes = physical_causes(state.x, fl, info.bounds, stiffen_above)
    if not causes:
        return
    step, t = int(state.step), float(state.t)
    raise integrate.SimulationError(out_of_bounds_message(step, t, float(fl["punch_displacement"]), causes),
                                    step=step, time=t, cause="; ".join(causes), frames=_single_frame(last_good),
                                    state=last_good)


def rescaled(model, *, step: float = 1.0, stiffness: float = 1.0):
    """``model`` with a time step ``step`` times as long and its contacts ``stiffness`` times as
    stiff (:func:`jaxform.penalty.rescaled_load`: the stick limits and a force-controlled holder
    follow the step): the same pytree structure, so the same compiled program runs it."""
    return dataclasses.replace(model, dt=model.dt * step,
                               loads=tuple(rescaled_load(ld, step=step, stiffness=stiffness) for ld in model.loads))


def _cut_advance(model, state, e0, x_ref, n_sub, floor, cut: int):
    """``n_sub`` steps of ``model.dt`` as ``cut`` times as many of ``model.dt / cut`` (the same
    compiled program: :func:`rescaled`). The integrator's time is its step count
    times its step, so the count runs in cut steps inside and in the run's steps outside (the
    chunk ends on a whole step of the run; a failing step is reported as the run's step it falls in)."""
    if cut == 1:
        return _advance_jit(model, state, e0, x_ref, n_sub, floor)
    fine = rescaled(model, step=1.0 / cut)
    new = _advance_jit(fine, dataclasses.replace(state, step=state.step * cut), e0, x_ref, n_sub * cut, floor)
    bad = jnp.where(new.bad_step >= 0, new.bad_step // cut, new.bad_step)
    return dataclasses.replace(new, step=new.step // cut, bad_step=bad)


def _chunk(model, state, e0, x_ref, n_sub, floor, ply_arr, info: RunInfo, cut: int = 1,
           stiffen_above: float = np.inf):
    """One host chunk of ``n_sub`` steps from ``state`` (with the step cut to ``1/cut``):
    ``(new_state, fields)``, or :class:`~jaxform.integrate.SimulationError` when a step failed
    or the run left its bounds (``stiffen_above``: :func:`physical_causes`)."""
    new = _cut_advance(model, state, e0, x_ref, n_sub, floor, cut)
    if int(new.bad_step) >= 0:
        raise integrate.SimulationError(
            integrate.describe_failure(new, model) + " The frames up to the last good one are kept.",
            step=int(new.bad_step), time=int(new.bad_step) * info.dt, cause=integrate.failure_cause(new),
            frames=_single_frame(new), state=new)
    fl = fields_jit(model, new, ply_arr, n_plies=info.case.n_plies)
    _check_health(new, fl, info, state, stiffen_above)
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
    switched the fibre mass's momentum term on (``FormingResult.momentum_term_from``) and cut the
    step (``cuts``). Kept current by :func:`drive`, so that a run that raises still has its last
    good state. ``may_cut``: the step was chosen automatically; ``may_stiffen``: so was the
    contact's stiffness (:meth:`of`)."""

    model: Any
    state: Any
    switched: dict | None = None
    may_cut: bool = True
    may_stiffen: bool = False
    backward_normal: bool = False
    cuts: list = dataclasses.field(default_factory=list)
    applied: float = 1.0
    armed: bool = True

    @classmethod
    def of(cls, model, state, info: RunInfo) -> "Standing":
        """A run's start: what the driver may change follows from what the user gave (a step is
        never cut, nor a penalty stiffness raised, where the user gave it)."""
        return cls(model, state, may_cut=may_cut_step(info), may_stiffen=may_stiffen_contact(info),
                   backward_normal=bool(getattr(getattr(info, "numerics", None), "implicit_normal", False)))

    @property
    def cut(self) -> int:
        """The step runs at the run's over this (1 until :meth:`recover` cuts it)."""
        return self.cuts[-1]["cut"] if self.cuts else 1

    @property
    def stiffness(self) -> float:
        """The contacts' penalty goes to the run's times this (1 until :meth:`recover` stiffens it;
        ``applied``: where it is, :meth:`ramp`)."""
        return self.cuts[-1]["contact_stiffness"] if self.cuts else 1.0

    def ramp(self) -> None:
        """Before a chunk: the contact a factor of at most :data:`~jaxform.forming.numerics.CONTACT_RAMP`
        closer to :attr:`stiffness` (a stiffer contact at once kicks the nodes it holds: 4x on a node
        pressed 0.1 mm deep sends it off at about ``0.75 omega delta``: metres per second at 8 mm, by estimate)."""
        if self.applied < self.stiffness * (1.0 - 1e-9):
            f = min(self.stiffness / self.applied, CONTACT_RAMP)
            self.model, self.applied = rescaled(self.model, stiffness=f), self.applied * f

    @property
    def can_stiffen(self) -> bool:
        """Whether :meth:`recover` may still stiffen the contact (and halve the step with it, where
        the contact is explicit): as often as the step may be halved (:data:`MAX_STEP_CUT`)."""
        if self.backward_normal:
            return self.may_stiffen and self.stiffness < CONTACT_STIFFEN ** math.log2(MAX_STEP_CUT) * (1.0 - 1e-9)
        return self.may_stiffen and self.cut < MAX_STEP_CUT

    def stiffen_above(self, rec: "Recorder") -> float:
        """m: the next chunk counts a penetration beyond ``stiffen_penetration`` as a cause where
        it is also deeper than this (:func:`physical_causes`): the penetration at the chunk's start
        (a growing one), where the contact can still be stiffened; else ``inf``. After a
        stiffening, not before the contact has reached its new stiffness (:meth:`ramp`) and the
        penetration has healed below the bound (:meth:`accept`: a stiffer contact takes a few of
        its periods to push the nodes out, and the chunks meanwhile would stiffen it again)."""
        return rec.hist["max_penetration_m"][-1] if self.can_stiffen and self.armed else np.inf

    def accept(self, new, fl, bounds) -> None:
        """A chunk ended well in ``new`` (its fields ``fl``): it is where the run stands."""
        self.state = new
        settled = self.applied >= self.stiffness * (1.0 - 1e-9) and float(fl["max_penetration"]) <= bounds.stiffen_penetration
        self.armed = self.armed or settled

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
        good state; False where nothing is left to change, or where the blank's edge went into the
        die (:func:`~jaxform.forming.health.drawn_in`: the forming failed). A penetration (:func:`penetrated`):
        half the step, and the contact on its way to :data:`~jaxform.forming.numerics.CONTACT_STIFFEN`
        times as stiff (:meth:`ramp`; at once beyond half the ply), an automatic contact only: a
        step cut alone never helps there; where the contacts' normal forces are integrated
        backward (``numerics.implicit_normal``: stable at any stiffness and damping,
        :mod:`jaxform.backward_normal`) the step stays. Else: the momentum
        term (:meth:`switch`), else half the step (down to 1/:data:`MAX_STEP_CUT`, an automatic
        step only)."""
        if drawn_in(cause):
            return False
        if penetrated(cause):
            if not self.can_stiffen:
                return False
            self.cuts.append({**self._where(rec, cause), "cut": self.cut if self.backward_normal else 2 * self.cut,
                              "contact_stiffness": CONTACT_STIFFEN * self.stiffness})
            self.armed = False
            if DEEPER not in cause:  # beyond half the ply: at once (the chunk failed; ramp() otherwise)
                self.model, self.applied = rescaled(self.model, stiffness=self.stiffness / self.applied), self.stiffness
            return True
        if self.switch(rec, cause):
            return True
        if not self.may_cut or self.cut >= MAX_STEP_CUT:
            return False
        self.cuts.append({**self._where(rec, cause), "cut": 2 * self.cut, "contact_stiffness": self.stiffness})
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
            at.ramp()
            try:
                new, fl = _chunk(at.model, at.state, e0, x_ref, n_sub, floor, ply_arr, info, at.cut,
                                 at.stiffen_above(rec))
                break
            except integrate.SimulationError as err:
                if not at.recover(rec, err.cause):
                    if at.cut > 1 and not drawn_in(err.cause):
                        raise integrate.SimulationError(
                            f"{err} It failed also with the step cut to 1/{at.cut}.", step=err.step, time=err.time,
                            cause=err.cause, frames=err.frames, state=err.state) from err
                    raise
        at.accept(new, fl, info.bounds)
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
    :meth:`Standing.recover` finds something to change (the README's modelling choices tell the
    runs that made each remedy needed). With a fibre mass but not its momentum term: with the
    term from there (``momentum_term_from`` of the result; without it the position-dependent mass
    can pump energy into elements that turn fast; the term costs about a step's cost again, so it
    is paid only from where it is needed). Where the step was chosen automatically
    (:func:`may_cut_step`): with half the step, then a quarter, then an eighth
    (:data:`MAX_STEP_CUT`; a snap-through is not the quasi-static run the step was chosen for),
    the rest of the run too (``step_cuts`` of the result, ``numerics.step_cuts`` of the summary).
    A node deeper in a tool or ply than :data:`~jaxform.forming.numerics.STIFFEN_PENETRATION` of
    the ply at a chunk's end, and deeper than at its start, where the contact's stiffness was
    chosen automatically (:func:`may_stiffen_contact`): the chunk again with half the step (the
    step stays where the normal forces are integrated backward), and
    the contact :data:`~jaxform.forming.numerics.CONTACT_STIFFEN` times as stiff over the next 8
    chunks (:meth:`Standing.ramp`; at once beyond half the ply), not again before the
    penetration has healed (the automatic contact is chosen for an expected pressure; the fabric
    decides the real one: NCF Case A presses the die's entry radius with 23-46 kPa at 8 mm).

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
    at = Standing.of(model, state, info)
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
        reason = failure_reason(str(err))
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


def may_stiffen_contact(info: RunInfo) -> bool:
    """Whether the driver may stiffen the run's contact (:meth:`Standing.recover`): not where the
    user gave the step or the penalty stiffness (a given ``contact.safety`` is kept: the stiffness
    grows as the step shrinks)."""
    return may_cut_step(info) and info.case.contact.penalty_stiffness is None


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


__all__ = ["BLOWUP_TOL", "ENERGY_FLOOR", "MAX_STEP_CUT", "may_cut_step", "may_stiffen_contact", "run_steps", "rollout", "FormingResult", "Standing", "drive", "with_momentum_term", "run", "simulate", "physical_causes",
           "out_of_bounds_message", "PENETRATED", "penetrated", "rescaled"]
