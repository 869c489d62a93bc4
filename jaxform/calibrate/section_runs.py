"""The forming runs of the wrinkle-section fit (:mod:`jaxform.calibrate.wrinkle_fit`): the rig built
once, each trial law one ``forming.rollout`` of the whole stroke, batched over
:data:`jaxform.batching.BATCH_AXIS`, the amplitude d_P sampled along the sections, and reverse-mode
gradients of a section loss through the run. A run that fails with the fast fibre mass (no momentum
term) is run again with the term, as :func:`jaxform.forming.run` switches it on. Host results are
cached by law. SI units.
"""
from __future__ import annotations

import dataclasses
import functools
import math
from concurrent.futures import ThreadPoolExecutor
from typing import NamedTuple, Sequence

import jax
import jax.numpy as jnp
import numpy as np

from jaxform import forming, integrate
from jaxform.batching import BATCH_AXIS, cores
from jaxform.calibrate import sections as sec_mod
from jaxform.calibrate.imperfections import imperfections
from jaxform.calibrate.transforms import law_from_q, q_from_law, scaled_shear, voce_start
from jaxform.contact import ToolLoad
from jaxform.forming.fields import state_fields
from jaxform.shell import fibre_curvatures

GRAD_FRAMES = 21  # the fit's rig has this many frames: one checkpoint each in the reverse pass
KAPPA_PERCENTILE = 98.0  # "the curvatures the wrinkles reach": this percentile of |kappa| on the fitted part


class _Steps(NamedTuple):
    """What :func:`jaxform.forming.rollout` reads of a run's info (hashable: a static argument)."""

    n_frames: int
    every: int


def _member(q, dz, rig, lines, static):
    """One forming run with the law ``q`` from the blank perturbed by ``dz``: ``(y, valid, ok, kappa_reach)``."""
    kind, n_plies, steps, ns, checkpoint = static
    model, state, fabric, ply_id, sel, faces = rig
    q = q.astype(state.x.dtype)
    law = law_from_q(q[:3], "voce")
    fab = fabric.replace(bending=(law, law))
    if kind == "voce+shear":
        fab = fab.replace(shear=scaled_shear(fab.shear, jnp.exp(q[3])))
    m = forming.with_fabric(model, fab)
    st = dataclasses.replace(state, x=state.x + dz, u=state.u + dz.T)
    s, _ = forming.rollout(m, st, steps, checkpoint=checkpoint)
    dev = state_fields(m, s, ply_id, n_plies)["deviation"]
    x, d = s.x[sel], dev[sel]
    vals, oks = zip(*(sec_mod.simulated(x, faces, d, a, b, sq, n) for (a, b, sq), n in zip(lines, ns)))
    y = jnp.concatenate(vals)
    kappa = fibre_curvatures(s.x, m.shell.mesh, m.shell.ref)[sel]
    reach = jnp.percentile(jnp.abs(kappa), KAPPA_PERCENTILE)
    return y, jnp.concatenate(oks), (s.bad_step < 0) & jnp.all(jnp.isfinite(y)), reach


@functools.partial(jax.jit, static_argnames=("static",), compiler_options=integrate.COMPILER_OPTIONS)
def _batch(Q, Z, rig, lines, static):
    """:func:`_member` over a batch (one compiled program per rig shape, shared by every fit in a process)."""
    return jax.vmap(lambda q, dz: _member(q, dz, rig, lines, static), axis_name=BATCH_AXIS)(Q, Z)


@functools.partial(jax.jit, static_argnames=("static",), compiler_options=integrate.COMPILER_OPTIONS)
def _grad(q, dz, rig, lines, R, meas, valid, static):
    """Gradient of ``0.5 |R (y - meas)|^2`` (``y`` masked by ``valid``), checkpointed reverse mode."""
    def loss(q):
        r = R @ jnp.where(valid, _member(q, dz, rig, lines, static[:-1] + (True,))[0] - meas, 0.0)
        return 0.5 * jnp.sum(r * r)

    return jax.grad(loss)(q)


def _key(q) -> tuple:
    return tuple(np.round(np.asarray(q, float), 12).tolist())


def parallel(width: int | None, workers: int | None, wide: int) -> tuple[int, int]:
    """``(width, workers)`` of :class:`SectionRuns` where not given: on a CPU one member per batch and
    a batch per core at once (threads: the small programs use a core each), else ``wide`` members
    per batch, one batch at a time (an accelerator runs a batch's members together)."""
    cpu = jax.default_backend() == "cpu"
    return (int(width) if width is not None else 1 if cpu else int(wide),
            int(workers) if workers is not None else cores() if cpu else 1)


def start_law(case):
    """The Voce law a fit of ``case`` starts from (:func:`~jaxform.calibrate.transforms.voce_start` of the
    case's); refuses a membrane-only case."""
    fab = forming.build_fabric(case)
    if fab.bending is None:
        raise ValueError(f"fit_wrinkles: case {case.name!r} is membrane-only; there is no bending law to fit")
    return voce_start(fab.bending[0])


class SectionRuns:
    """The forming rig built once; members ``(q, seed)`` run in batches of fixed width, cached by ``q``;
    ``workers`` batches at a time (threads: a CPU's cores each run one). ``step_b_init`` (N·m): the
    largest ``B_init`` the runs will meet (a fit's box); where it exceeds the start's, the rig's step
    is the one that law allows (a stiffer law raises the shell's bending frequency: on the start's
    step it could outrun the explicit limit and fail, or bias a fit towards soft laws)."""

    def __init__(self, case, sections, param_kind, seeds, imperfection, width, ply, workers=1, step_b_init=None):
        if not 1 <= ply <= case.n_plies:
            raise ValueError(f"fit_wrinkles: ply = {ply}: the case has plies 1..{case.n_plies}")
        self.law0 = start_law(case)
        q0 = q_from_law(self.law0, "voce")
        step_law = None  # the step is built for the stiffest law the runs will meet (tangent at most B_init)
        if step_b_init is not None and float(step_b_init) > math.exp(q0[0]):
            stiff = law_from_q(np.array([math.log(float(step_b_init)), q0[1], q0[2]]), "voce")
            step_law = forming.build_fabric(case).replace(bending=(stiff, stiff))
        rig = forming.build(dataclasses.replace(case, process=dataclasses.replace(case.process, frames=GRAD_FRAMES)),
                            fabric=step_law)
        model, state, info = rig
        fab = model.shell.fabrics[0]
        self.width, self.seeds, self.workers = int(width), int(seeds), int(workers)
        self.dtype = state.x.dtype
        sel = np.asarray(info.ply_id) == ply
        local = np.cumsum(sel) - 1
        faces = local[info.faces[np.all(sel[info.faces], axis=1)]]
        self.rig = (model, state, fab, jnp.asarray(info.ply_id), jnp.asarray(np.flatnonzero(sel)), jnp.asarray(faces))
        exact = forming.with_momentum_term(model)  # a run that fails without it is run again with it (forming.run)
        self.rigs = (self.rig,) if exact is None else (self.rig, (exact,) + self.rig[1:])
        self.exact: set = set()  # the laws (keys) that needed the term
        self.lines = tuple((jnp.asarray(s.start, self.dtype), jnp.asarray(s.end, self.dtype), jnp.asarray(s.s, self.dtype))
                           for s in sections)
        ns = tuple(sec_mod.n_samples(s, case.element_size) for s in sections)
        self.static = (param_kind, case.n_plies, _Steps(info.n_frames, info.every), ns, False)
        clearance = np.min([np.asarray(ld.gap(state.x, state.t, ls), float) for ld, ls in zip(model.loads, state.loads)
                            if isinstance(ld, ToolLoad)] or [np.full(len(info.x0), np.inf)], axis=0)
        self.x0, self.amplitude, self.blank_size, self.clearance = info.x0, imperfection, case.blank_size, clearance
        self.dz = jnp.asarray(imperfections(info.x0, self.seeds, imperfection, case.blank_size, clearance), self.dtype)
        self.cache: dict = {}
        self.runs = 0

    @property
    def round_laws(self) -> int:
        """Laws that one round of runs holds (``workers`` batches of ``width`` members at once, ``seeds``
        members a law): evaluating fewer leaves slots idle."""
        return max(1, self.workers * self.width // self.seeds)

    def cached(self, q) -> bool:
        return _key(q) in self.cache

    def evaluate(self, qs: Sequence[np.ndarray]) -> list:
        """``(y (M,), valid (M,), ok, kappa_reach)`` per ``q``, the mean over the seeds (host)."""
        keys = [_key(q) for q in qs]
        todo = [k for k in dict.fromkeys(keys) if k not in self.cache]
        members = [(k, i) for k in todo for i in range(self.seeds)]
        chunks = [members[a:a + self.width] for a in range(0, len(members), self.width)]
        out: dict = {}
        for chunk, (y, v, ok, reach, *_) in zip(chunks, self._run(chunks)):
            for j, (k, _) in enumerate(chunk):
                out.setdefault(k, []).append((y[j].astype(float), v[j], bool(ok[j]), float(reach[j])))
        for k, rs in out.items():
            self.cache[k] = (np.mean([r[0] for r in rs], axis=0), np.all([r[1] for r in rs], axis=0),
                             all(r[2] for r in rs), float(np.mean([r[3] for r in rs])))
        return [self.cache[k] for k in keys]

    def scatter(self, q, n: int) -> list:
        """``(y (M,), valid (M,), ok)`` of the law ``q`` from ``n`` imperfect blanks other than the
        fit's own (seeds ``seeds .. seeds + n - 1`` of :func:`imperfections`, the same amplitude): how
        much the part scatters where only the blank's imperfections differ (host; not cached)."""
        dz = jnp.asarray(imperfections(self.x0, self.seeds + n, self.amplitude, self.blank_size, self.clearance)[self.seeds:],
                         self.dtype)
        chunks = [[(_key(q), i) for i in range(a, min(a + self.width, n))] for a in range(0, n, self.width)]
        return [(y[j].astype(float), v[j], bool(ok[j])) for c, (y, v, ok, *_) in zip(chunks, self._run(chunks, dz))
                for j in range(len(c))]

    def _run(self, chunks, dz=None) -> list:
        """:meth:`_chunk` of each batch, in a thread pool where there are several batches and workers;
        the runs they took and the laws that needed the momentum term are counted."""
        if self.workers > 1 and len(chunks) > 1:
            with ThreadPoolExecutor(min(self.workers, len(chunks))) as pool:
                done = list(pool.map(lambda c: self._chunk(c, dz), chunks))
        else:
            done = [self._chunk(c, dz) for c in chunks]
        for d in done:
            self.runs += d[4]
            self.exact |= d[5]
        return done

    def _chunk(self, chunk, dz=None):
        """One batch ``[(key, seed), ...]`` (``seed`` indexes ``dz``, default the fit's blanks): host
        ``(y, valid, ok, reach)``, the runs it took and the laws that needed the momentum term (run
        again with it where they failed without)."""
        pad = chunk + [chunk[-1]] * (self.width - len(chunk))
        Q = jnp.asarray(np.array([k for k, _ in pad]), self.dtype)
        Z = (self.dz if dz is None else dz)[np.array([i for _, i in pad])]
        y, v, ok, reach = (np.asarray(t) for t in _batch(Q, Z, self.rig, self.lines, self.static))
        bad = ~ok
        if not (bad[:len(chunk)].any() and len(self.rigs) > 1):
            return y, v, ok, reach, len(chunk), set()
        y, v, ok, reach = (np.where(bad.reshape((-1,) + (1,) * (a.ndim - 1)), np.asarray(b), a) for a, b in
                           zip((y, v, ok, reach), _batch(Q, Z, self.rigs[1], self.lines, self.static)))
        return y, v, ok, reach, 2 * len(chunk), {k for (k, _), b in zip(chunk, bad) if b}

    def gradient_ad(self, q, R, meas, valid) -> np.ndarray:
        """(p,) gradient of the section loss ``0.5 |R (y - meas)|^2`` by checkpointed reverse mode
        through the whole run (one checkpoint per frame; the mean over the seeds)."""
        args = (jnp.asarray(R, self.dtype), jnp.asarray(meas, self.dtype), jnp.asarray(valid))
        rig = self.rigs[-1] if _key(q) in self.exact else self.rig
        g = [np.asarray(_grad(jnp.asarray(q, self.dtype), self.dz[i], rig, self.lines, *args, static=self.static), float)
             for i in range(self.seeds)]
        self.runs += self.seeds
        return np.mean(g, axis=0)


def section_loss(case, sections: Sequence, qs, *, noise: float = sec_mod.NOISE, smoothing: float | None = None, ply: int = 1,
                 gradient_at: Sequence[int] = ()) -> tuple[np.ndarray, dict]:
    """The fit's section loss ``0.5 |R (y - meas)|^2`` at each log-space law ``qs`` (k, 3)
    (:func:`~jaxform.calibrate.transforms.q_from_law`) and its AD gradient (checkpointed reverse mode
    through the run) at the indices ``gradient_at``: ``(losses (k,), {i: (3,)})``; ``inf`` where a
    run fails. The loss along a line in parameter space shows how rough the landscape is."""
    for s in sections:
        sec_mod.check_section(s, case)
    qs = [np.asarray(q, float) for q in qs]
    width, workers = parallel(None, None, len(qs))
    runs = SectionRuns(case, sections, "voce", 1, 0.0, width, ply, workers, step_b_init=math.exp(max(q[0] for q in qs)))
    R = sec_mod.weights(sections, noise, smoothing if smoothing is not None else float(case.element_size))
    meas = np.concatenate([s.amplitude for s in sections])
    evs = runs.evaluate(qs)
    losses = np.array([0.5 * float(np.sum((R @ np.where(v, y - meas, 0.0)) ** 2)) if ok else np.inf
                       for y, v, ok, _ in evs])
    return losses, {i: runs.gradient_ad(qs[i], R, meas, evs[i][1]) for i in gradient_at}


def predict_sections(case, sections: Sequence, law=None, *, shear_scale: float = 1.0, ply: int = 1) -> list:
    """The amplitude d_P (m) the forming run of ``case`` with ``law`` (default the case's) gives at each
    section's points (the fit's own program): ``[(y (m,), valid (m,)), ...]``; a held-out check."""
    kind = "voce" if shear_scale == 1.0 else "voce+shear"
    for s in sections:
        sec_mod.check_section(s, case)
    q_law = None if law is None else q_from_law(voce_start(law), "voce")
    runs = SectionRuns(case, sections, kind, 1, 0.0, 1, ply, step_b_init=None if law is None else math.exp(q_law[0]))
    q = np.append(q_law if law is not None else q_from_law(runs.law0, "voce"),
                  [] if kind == "voce" else [math.log(shear_scale)])
    y, valid, ok, _ = runs.evaluate([q])[0]
    if not ok:
        raise RuntimeError(f"predict_sections: the forming run of case {case.name!r} with this law failed")
    cuts = np.cumsum([0] + [len(s.s) for s in sections])
    return [(y[a:b], valid[a:b]) for a, b in zip(cuts[:-1], cuts[1:])]


def sections_of(case, lines: dict, law=None, *, spacing: float = 1e-3, ply: int = 1) -> list:
    """The sections ``{name: ((x0, y0), (x1, y1))}`` (m, top view) of the part ``case`` forms with
    ``law`` (default the case's): a point every ``spacing`` m, those on the part, d_P as amplitude."""
    raw = []
    for name, (a, b) in lines.items():
        a, b = np.asarray(a, float), np.asarray(b, float)
        n = int(round(float(np.linalg.norm(b - a)) / spacing)) + 1
        raw.append(sec_mod.Section(s=np.linspace(0.0, np.linalg.norm(b - a), n), amplitude=np.zeros(n), start=a, end=b,
                                   name=name))
    return [dataclasses.replace(s, s=s.s[np.asarray(v, bool)], amplitude=np.asarray(y, float)[np.asarray(v, bool)])
            for s, (y, v) in zip(raw, predict_sections(case, raw, law, ply=ply))]


__all__ = ["GRAD_FRAMES", "KAPPA_PERCENTILE", "start_law", "SectionRuns", "section_loss", "predict_sections", "sections_of"]
