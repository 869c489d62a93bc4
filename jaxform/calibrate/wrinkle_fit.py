"""The bending law (and optionally a shear-law scale) from wrinkle-amplitude sections of a formed
part, through the forming run itself; jointly with cantilever side profiles when given.

Parameters (log space): ``q = (log B_init, log B_inf/B_init, log kappa0)`` of one symmetric Voce
law on both fibre families (:mod:`jaxform.calibrate.transforms`, the cantilever fit's), and with
``params="voce+shear"`` a fourth, ``log s``, that scales the case's shear law (force times ``s``).
Bounds: ``B_init`` and ``kappa0`` within a factor :data:`SPAN` of the starting law, the ratio in
``[1e-3, 1]``, ``s`` within a factor 3.

Residual: per section, the Gaussian-smoothed difference of simulated and measured amplitude in
units of the smoothed noise (:mod:`jaxform.calibrate.sections`: tolerant of small wrinkle shifts),
and with profiles the cantilever fit's z-residuals in units of their noise. The forming rig is
built once; each trial law is one ``forming.rollout`` of the whole stroke, in batches vmapped over
:data:`jaxform.batching.BATCH_AXIS` (1 wide on a CPU; an anonymous vmap ran both branches of the
contact's ``lax.cond`` every step: 206 s against 4.9 s per 16 mm run); a run that fails without the
fibre mass's momentum term is run again with it, as ``forming.run`` would
(:mod:`jaxform.calibrate.section_runs`).

Why not plain gradients. Reverse mode through the run is exact (it equals central differences at
``h = 1e-8``), but the buckled flange is chaotically sensitive to the law: over a whole stroke
the exact derivative grows like ``e^{lambda t}`` and says nothing about the loss over any finite
step (woven Case A in float64: about 1e277 against central differences of 1e6 at 8 mm and
500 mm/s; at the automatic 62.5 mm/s, 8x the steps, it overflows to NaN already at 16 mm). So the
fit (1) checks at the start the AD gradient of the actual loss against central differences with
its step ``fd_step`` (0.05 in log space) and records both, (2) uses the AD Jacobian only where
they agree within :data:`GRAD_RTOL` (else forward differences with ``fd_step``, said in
``gradient_check``; the profiles' rows exactly, by the cantilever's own AD), (3) scores the starting law, a
seeded Latin hypercube around it (box :data:`START_HALF_WIDTH`, one run each) and, with profiles,
the law the cantilever profiles alone give (:func:`~jaxform.calibrate.fit_cantilever`, no forming
run: on the joint benchmark it is within 2.5 % in B_init where the joint fit from the best
hypercube law stopped 15 % off; the hypercube is then centred on it, :data:`CANTILEVER_SDS`), and
(4) runs ``scipy.optimize.least_squares`` (trust-region
reflective, bounds) from the best; (5) where a probe of the final Jacobian at the best law fits
better by more than :data:`MOVE_RTOL` (the optimiser stopped on a rough wall), it moves there and
probes again (``moves_after_optimiser``); (6) where the result fails the misfit test below (a local
minimum), it runs (4)-(5) again from the next-best starts, at most ``restarts`` more, and keeps the
best (``local_fits`` lists each). Fit at a
quasi-static speed (the presets' automatic one): on woven Case A at 8 mm and 500 mm/s (8x that
speed) the loss is multimodal, a law with 1.9x the true B_init fitting two sections to loss 1,715
(truth 260) behind a barrier of 54,000 on the straight line between them at every smoothing width
from 8 to 40 mm (the inertia-driven buckling branch changes); at the automatic 62.5 mm/s the same
line has no barrier (28,336 falling to 51 at the truth, one bump of 1,100). Optional
``seeds > 1`` averages each evaluation over seeded imperfections of the blank (a smooth random
out-of-plane field of amplitude ``imperfection``, tapered to 0 near the tools), batched.

Uncertainty (Laplace / Gauss-Newton): ``cov(q) = c (J^T J)^-1`` with ``J`` the Jacobian used,
``c`` the reduced chi-square (at least 1) times the ratio of section rows to independent section
residuals (smoothing correlates neighbouring rows), mapped to ``(b_inf, m0, kappa0, b_init)`` by the
delta method, then checked against the loss along the covariance's principal axes (two sds either
side, then further out while the loss stays flatter than modelled, each probe profiled over the
other axes: :mod:`jaxform.calibrate.uncertainty`, 4 p to about 16 p runs) and widened where it rises
less than the model says. Where a probe fits better than the fit by more than :data:`MOVE_RTOL`,
the fit moves there and checks again (at most :data:`CHECK_MOVES` times; ``sigma_check.moved_from``):
before, the round trip at 8 mm (noise seed 17) reported chi-square 310 and B_init -15 % while its
check had run a law at 118 and -2.8 %. Then the fitted law is run from ``scatter_seeds`` imperfect blanks and the
scatter of its part is added (:func:`~jaxform.calibrate.uncertainty.scatter_covariance`: what the
blank's imperfections, in the model and in the measured part, move the fit by; ``chi_squares`` tell
where the fit has fitted its own blank's chaotic detail). A parameter is *determined* where its sd is under :data:`DETERMINED_SD` of
its value and no ``open`` axis dominates it, and the Voce split (``b_inf``, ``m0``, ``kappa0``) only where
the part bends to ``DETERMINED_RATIO`` kappa0 (the cantilever fit's rule): wrinkles fix ``M(kappa)`` up
to ``kappa_reach`` (``moment_band``), not the asymptote. A fit is *converged* where its optimiser
stopped there or a Gauss-Newton step would remove under ``GN_TOL`` (1) of the chi-square in the noise's
degrees of freedom (``misfit``'s ``scale``: 18.8 raw on the 8 mm round trip, whose moved fit read 7.2
raw), and the noise would leave its chi-square at the true law with probability at least
:data:`~jaxform.calibrate.uncertainty.MISFIT_P`, with profiles each block apart too (``block_misfit``):
at 62.5 mm/s a joint fit stopped 15 % off in B_init (sd 0.8 %; chi-square 1,114 against 205 +- 75, the
truth's 191), and with a finer step one 5.8 % off passed as a whole (401, p = 0.014) while its profile
alone did not (156 on 60 rows). SI units throughout.
"""
from __future__ import annotations

import dataclasses
import math
import time
from typing import Any, Callable, NamedTuple, Sequence

import jax
import jax.numpy as jnp
import numpy as np
from scipy.optimize import least_squares, lsq_linear, minimize

from jaxform import cantilever
from jaxform.calibrate import sections as sec_mod
from jaxform.calibrate.cantilever_data import estimate_noise
from jaxform.calibrate.cantilever_fit import DETERMINED_RATIO, GN_TOL, ProfileModel
from jaxform.calibrate.imperfections import imperfections
from jaxform.calibrate.starts import cantilever_start, hypercube
from jaxform.calibrate.section_runs import SectionRuns, parallel, predict_sections, section_loss, sections_of, start_law
from jaxform.calibrate.transforms import _physical, law_from_q, moment_band, q_from_law, scaled_shear, voce_start
from jaxform.calibrate.uncertainty import (EXTEND_ROUNDS, block_misfit, checked_covariance, describe_axis, open_share,
                                           scatter_covariance)
from jaxform.metrics import section_nrmse

PARAM_KINDS = ("voce", "voce+shear")
NOISE = sec_mod.NOISE
FD_STEP = 0.05  # log-space step of the finite differences (the gradient check and the FD Jacobian)
GRAD_RTOL = 0.3  # AD agrees with central differences where |g_ad - g_fd| <= GRAD_RTOL * |g_fd| (each, and the norm)
SPAN = 10.0  # B_init and kappa0 are searched within this factor of the starting law
SHEAR_SPAN = 3.0
DETERMINED_SD = 0.10
BAND = (0.25, 0.5, 0.75, 1.0)  # the moment band's curvatures, fractions of kappa_reach
SCATTER_SEEDS = 4  # imperfect blanks run at the fitted law for the uncertainty (uncertainty.scatter_covariance)
MOVE_RTOL = 0.01  # the fit moves to a probe of its final Jacobian that lowers the loss by more than this fraction
CHECK_MOVES = 2  # ... and as often to a probe of its sigma check (each move: a Jacobian and a check, ~17 runs)
NAMES = ("B_init", "B_inf/B_init", "kappa0", "shear scale")
START_HALF_WIDTH = (math.log(2.0), math.log(3.0), math.log(3.0), math.log(1.5))  # global phase box, log space
CANTILEVER_SDS = 3.0
"""With profiles the global phase's box is centred on the law the profiles give alone, its B_init
half-width this many of that fit's standard deviations (at least ``fd_step``; the profiles pin
B_init), the others :data:`START_HALF_WIDTH`'s: the laws the profiles do not reject. Around the
case's law instead (its B_init 1.4x the truth's on the joint benchmark) the restarts ended at
loss 557 and 6,220 where the profiles' own law led to 326 (record 20261204T-qs-joint-cstart)."""


@dataclasses.dataclass(frozen=True)
class WrinkleFit:
    """Result of :func:`fit_wrinkles` (host values, SI; :meth:`as_dict` for ``params.json``)."""

    law: Any
    law_initial: Any
    shear_scale: float
    q: np.ndarray
    values: dict  # b_inf, m0, kappa0, b_init
    sigma: dict
    determined: dict
    loss_initial: float
    loss_final: float
    rms_per_section: list  # m, unsmoothed, at the fitted law
    rms_initial_per_section: list
    nrmse_per_section: list  # fractions (section_nrmse), at the fitted law
    profile_rmse: float | None  # m, the cantilever profiles' z-residual (joint fit)
    kappa_reach: float  # 1/m, section_runs.KAPPA_PERCENTILE of |kappa| on the fitted part
    gradient_check: dict
    jacobian: str  # "ad" or "fd"
    iterations: int
    moves: int  # to a better probe of the final Jacobian, after the optimiser (fit_wrinkles, step 5)
    gn_decrease: float  # the chi-square a bounded Gauss-Newton step from the fit would remove
    forming_runs: int
    wall_time: float
    converged: bool
    reason: str
    starts: list  # (q, loss) of the global phase
    fitted: list  # (m,) simulated amplitude per section at the fitted law, m
    initial: list  # the same at the starting law
    covariance: np.ndarray  # of q, checked (sigma_check)
    sigma_check: dict = dataclasses.field(default_factory=dict)  # jaxform.calibrate.uncertainty.checked_covariance
    scatter: dict = dataclasses.field(default_factory=dict)  # jaxform.calibrate.uncertainty.scatter_covariance
    misfit: dict = dataclasses.field(default_factory=dict)  # jaxform.calibrate.uncertainty.misfit at the fitted law
    local_fits: list = dataclasses.field(default_factory=list)  # steps (4)-(5) from each start tried (fit_wrinkles, step 6)
    cantilever_start: dict | None = None  # the law of the profiles alone (joint fit), a start of step (3)
    moment_band: dict = dataclasses.field(default_factory=dict)  # M(kappa) and its sd up to kappa_reach

    def as_dict(self) -> dict:
        v, s = self.values, {k: (x if math.isfinite(x) else None) for k, x in self.sigma.items()}
        out = {"b_inf_Nm": v["b_inf"], "m0_N": v["m0"], "kappa0_per_m": v["kappa0"], "b_init_Nm": v["b_init"],
               "shear_scale": self.shear_scale,
               "sigma_b_inf_Nm": s["b_inf"], "sigma_m0_N": s["m0"], "sigma_kappa0_per_m": s["kappa0"],
               "sigma_b_init_Nm": s["b_init"], "sigma_shear_scale": s.get("shear_scale"),
               "determined": self.determined, "loss_initial": self.loss_initial, "loss_final": self.loss_final,
               "rms_mm_per_section": [1e3 * r for r in self.rms_per_section],
               "rms_initial_mm_per_section": [1e3 * r for r in self.rms_initial_per_section],
               "nrmse_per_section": self.nrmse_per_section, "kappa_reach_per_m": self.kappa_reach,
               "gradient_check": self.gradient_check, "jacobian": self.jacobian, "iterations": self.iterations,
               "moves_after_optimiser": self.moves, "gn_decrease_chi2": self.gn_decrease,
               "gn_decrease_dof": self.gn_decrease / self.misfit["scale"] if self.misfit else None,
               "forming_runs": self.forming_runs, "wall_time_s": self.wall_time, "converged": self.converged,
               "reason": self.reason, "starts": [{"q": list(map(float, q)), "loss": c} for q, c in self.starts],
               "sigma_check": self.sigma_check, "scatter": self.scatter, "misfit": self.misfit, "local_fits": self.local_fits,
               "cantilever_start": self.cantilever_start, "moment_band": self.moment_band}
        if self.profile_rmse is not None:
            out["profile_rmse_mm"] = 1e3 * self.profile_rmse
        return out


class Progress(NamedTuple):
    """What :func:`fit_wrinkles` hands its ``callback``: the stage and the best loss so far."""

    stage: str  # "start", "gradient check", "cantilever", "global", "fit"
    forming_runs: int
    loss: float
    q: tuple


def _bounds(q0, kind):
    lo = np.array([q0[0] - math.log(SPAN), math.log(1e-3), q0[2] - math.log(SPAN)])
    hi = np.array([q0[0] + math.log(SPAN), 0.0, q0[2] + math.log(SPAN)])
    if kind == "voce+shear":
        lo, hi = np.append(lo, -math.log(SHEAR_SPAN)), np.append(hi, math.log(SHEAR_SPAN))
    return lo, hi


def fit_wrinkles(case, sections: Sequence, *, params: str = "voce", profiles: Sequence | None = None,
                 areal_mass: float | None = None, noise: float = NOISE, profile_noise: float | None = None,
                 smoothing: float | None = None, ply: int = 1, n_starts: int = 8, max_iter: int = 8, restarts: int = 2,
                 fd_step: float = FD_STEP, gradient_check: bool = True, seeds: int = 1, check_rounds: int = EXTEND_ROUNDS,
                 scatter_seeds: int = SCATTER_SEEDS,
                 imperfection: float | None = None, batch_width: int | None = None, workers: int | None = None,
                 profile_kwargs: dict | None = None, callback: Callable[[Progress], Any] | None = None) -> WrinkleFit:
    """Fit the bending law of ``case`` to measured wrinkle sections (module docstring).

    Args:
        case: a resolved :class:`~jaxform.forming.Case` (the rig, the mesh and the starting law).
        sections: :class:`~jaxform.calibrate.sections.Section` list (m).
        params: ``"voce"`` or ``"voce+shear"``.
        profiles: cantilever :class:`~jaxform.calibrate.Profile` list of the same fabric (joint
            fit; needs ``areal_mass``, kg/m²); ``profile_noise`` (m) default: read off the profiles.
        noise: the sections' measurement noise, m.
        smoothing: width of the residual's smoothing, m (default: the element size).
        ply: the ply whose amplitude was measured (1 touches the punch).
        n_starts: laws scored in the global phase: the starting law and a Latin hypercube of
            ``n_starts - 1`` laws in the box :data:`START_HALF_WIDTH` around it (seeded: repeatable);
            with profiles around the law they give alone (:data:`CANTILEVER_SDS`), which is scored too.
        max_iter: residual evaluations of the optimiser (``max_nfev``).
        restarts: local fits from the next-best starts where a fit fails the misfit test (step 6).
        fd_step: log-space step of the finite differences.
        check_rounds: the sigma check's further probes per axis at most (``checked_covariance``'s ``rounds``).
        scatter_seeds: imperfect blanks run at the fitted law for the run's own scatter
            (:func:`~jaxform.calibrate.uncertainty.scatter_covariance`; 0: none).
        gradient_check: compare AD with central differences at the start (else: FD Jacobian).
        seeds: imperfect blanks averaged per evaluation (1: the perfect blank only).
        imperfection: their amplitude, m (default a tenth of the ply thickness).
        batch_width: members per compiled batch (default 1 on a CPU, ``2 p`` otherwise).
        workers: batches run at once, in threads (default one per core on a CPU, 1 otherwise).
        profile_kwargs: keyword arguments of the cantilever model (``jaxform.cantilever.simulate``).
        callback: called with a :class:`Progress` at each stage and evaluation.
    Returns:
        :class:`WrinkleFit`; ``converged`` and ``reason`` say whether to use it.
    """
    t0 = time.perf_counter()
    if params not in PARAM_KINDS:
        raise ValueError(f"fit_wrinkles: params = {params!r}: must be one of {', '.join(PARAM_KINDS)}")
    sections = list(sections)
    if not sections:
        raise ValueError("fit_wrinkles: no sections given")
    for s in sections:
        sec_mod.check_section(s, case)
    for name, v, ok in (("noise", noise, noise > 0), ("fd_step", fd_step, 0 < fd_step < 1),
                        ("seeds", seeds, int(seeds) >= 1), ("n_starts", n_starts, int(n_starts) >= 1),
                        ("max_iter", max_iter, int(max_iter) >= 1), ("restarts", restarts, int(restarts) >= 0),
                        ("workers", workers, workers is None or int(workers) >= 1),
                        ("smoothing", smoothing, smoothing is None or smoothing >= 0),
                        ("check_rounds", check_rounds, int(check_rounds) >= 0),
                        ("scatter_seeds", scatter_seeds, int(scatter_seeds) >= 0)):
        if not ok:
            raise ValueError(f"fit_wrinkles: {name} = {v!r} is out of range")
    if profiles and not (areal_mass and areal_mass > 0):
        raise ValueError("fit_wrinkles: profiles need the fabric's areal_mass (kg/m² > 0)")
    width = smoothing if smoothing is not None else float(case.element_size)
    p = 3 if params == "voce" else 4
    batch_width, workers = parallel(batch_width, workers, 2 * p)
    imperfection = 0.1 * case.ply_thickness if imperfection is None else float(imperfection)
    runs = SectionRuns(case, sections, params, int(seeds), imperfection, batch_width, ply, workers,
                       step_b_init=SPAN * math.exp(q_from_law(start_law(case), "voce")[0]))  # the box's stiffest
    R = sec_mod.weights(sections, noise, width)  # (rows, M): y -> section rows
    cuts = np.cumsum([0] + [len(s.s) for s in sections])
    meas = np.concatenate([s.amplitude for s in sections])
    prof = pn = None
    if profiles:
        prof = ProfileModel(list(profiles), "voce", cantilever.simulate, dict(profile_kwargs or {}), areal_mass, 1e-5,
                            jnp.result_type(float))
        pn = profile_noise if profile_noise is not None else float(np.sqrt(np.mean(
            [estimate_noise(pr.x, pr.z) ** 2 for pr in prof.profiles])))
    n_rows = len(meas) + _n_prof(prof)
    mean, var = sec_mod.chi_square_moments(R, noise)
    blocks = [("sections", slice(0, R.shape[0]), mean, var)]  # the chi-square's moments at the true law, per block
    if prof is not None:
        blocks.append(("profiles", slice(R.shape[0], None), float(_n_prof(prof)), 2.0 * _n_prof(prof)))
    q0 = np.append(q_from_law(runs.law0, "voce"), [0.0] * (p - 3))
    lo, hi = _bounds(q0, params)
    best = {"loss": math.inf, "q": q0}  # of the whole fit (the callback's)
    here = {"loss": math.inf, "q": q0}  # of the current local fit

    def report(stage, q, value):
        for b in (best, here):
            if value < b["loss"]:
                b.update(loss=value, q=np.asarray(q, float))
        if callback is not None:
            callback(Progress(stage, runs.runs, best["loss"], tuple(best["q"].tolist())))

    def rows(q, stage="fit"):
        y, valid, ok, _ = runs.evaluate([q])[0]
        r = [R @ np.where(valid, y - meas, 0.0)] + ([prof.rows(q[:3]) * 1e-3 / pn] if prof is not None else [])
        r = np.concatenate(r)
        if not (ok and np.all(np.isfinite(r))):
            return np.full(n_rows, np.inf)
        report(stage, q, 0.5 * float(r @ r))
        return r

    def loss(q, stage="fit"):
        r = rows(q, stage)
        return 0.5 * float(r @ r)

    def scatter_rows(q):  # the rows of the law q from other imperfect blanks, less its own; and how many were run
        y, valid = runs.evaluate([q])[0][:2]
        return [np.pad(R @ np.where(v & valid, ys - y, 0.0), (0, n_rows - R.shape[0]))
                for ys, v, ok in runs.scatter(q, int(scatter_seeds)) if ok] if scatter_seeds else [], int(scatter_seeds)

    def prof_jac(q):
        return prof.jac(q[:3]) * 1e-3 / pn

    def grad_ad(q):
        """AD gradient of the loss: the sections' by reverse mode through the run, the profiles' exact."""
        g = runs.gradient_ad(q, R, meas, runs.evaluate([q])[0][1])
        if prof is not None:
            g[:3] += prof_jac(q).T @ (prof.rows(q[:3]) * 1e-3 / pn)
        return g

    def fd_points(q):
        q = np.asarray(q, float)
        steps = [fd_step if q[i] + fd_step <= hi[i] else -fd_step for i in range(p)]
        return [q + h * e for h, e in zip(steps, np.eye(p))], steps

    def fd_jac(q):
        q = np.asarray(q, float)
        pts, steps = fd_points(q)
        runs.evaluate([q] + pts)  # one batch
        r0 = rows(q)
        J = np.stack([(rows(x) - r0) / h for x, h in zip(pts, steps)], axis=1)
        if prof is not None:  # the profiles' rows exactly (the cantilever's own AD), not a secant over fd_step
            J[R.shape[0]:] = np.pad(prof_jac(q), ((0, 0), (0, p - 3)))
        return J

    # the starting law: the case's rig must produce every section
    ev0 = runs.evaluate([q0])[0]
    if not ev0[2]:
        raise RuntimeError(f"fit_wrinkles: the forming run with the starting law failed (non-finite or blown up); "
                           f"case {case.name!r} does not run as given")
    for s, a, b in zip(sections, cuts[:-1], cuts[1:]):
        off = 1.0 - float(np.mean(ev0[1][a:b]))
        if off > sec_mod.MAX_OFF_PART:
            raise ValueError(f"section {s.name or '?'}: {100 * off:.0f} % of its points lie off the part formed with the "
                             f"starting law (more than {100 * sec_mod.MAX_OFF_PART:.0f} %); the rig of case "
                             f"{case.name!r} cannot produce this section (it draws the blank in past it)")
    loss0 = loss(q0, "start")

    # (1) the gradient check and (2) the safeguard
    check: dict = {"done": False}
    mode = "fd"
    if gradient_check:
        g_ad = grad_ad(q0)
        runs.evaluate([q0 + s * fd_step * e for e in np.eye(p) for s in (1.0, -1.0)])
        g_fd = np.array([(loss(q0 + fd_step * e, "gradient check") - loss(q0 - fd_step * e, "gradient check"))
                         / (2 * fd_step) for e in np.eye(p)])
        agree = bool(np.all(np.isfinite(g_ad)) and np.all(np.abs(g_ad - g_fd) <= GRAD_RTOL * np.abs(g_fd)))
        mode = "ad" if agree else "fd"
        check = {"done": True, "parameters": list(NAMES[:p]), "ad": g_ad.tolist(), "fd": g_fd.tolist(),
                 "fd_step": fd_step, "rel_error": (np.abs(g_ad - g_fd) / np.maximum(np.abs(g_fd), 1e-300)).tolist(),
                 "agree": agree,
                 "action": ("the fit follows the AD gradient (L-BFGS-B)" if agree else
                            (f"AD disagrees with central differences over a log step of {fd_step:g} (the run is "
                             "chaotically sensitive to the law)" if np.all(np.isfinite(g_ad)) else
                             f"the AD gradient is not finite (in {np.dtype(runs.dtype).name} the exact sensitivity of "
                             "the buckled run overflows)") + ": the fit uses Gauss-Newton with a forward-difference "
                            "Jacobian of that step instead")}

    # (3) the global phase: the best of a few laws around the starting one, or with profiles around
    # the law they give alone (which the global phase then also scores)
    cands, centre, half, cant = [q0], q0, np.array(START_HALF_WIDTH[:p]), None
    if prof is not None:
        cant = cantilever_start(prof, areal_mass, profile_kwargs, pn, p, lo, hi)
        report("cantilever", q0, best["loss"])
        centre = np.asarray(cant["q"], float)
        if math.isfinite(cant["sd_q"][0]):  # else (B_init undetermined by the profiles) the usual width
            half[0] = min(half[0], max(CANTILEVER_SDS * cant["sd_q"][0], fd_step))
        cands.append(centre)
    if n_starts > 1:
        cands += hypercube(centre, half, int(n_starts) - 1, lo, hi)
    runs.evaluate(cands)
    starts = [(c, loss(c, "global")) for c in cands]

    def trial_rows(q):
        """The rows at the optimiser's trial law, its forward-difference laws run alongside in the slots
        the trial leaves idle (a CPU's second core, a GPU batch's other members): where the trial is
        accepted its Jacobian then costs that many runs less (two cores: 2 rounds of runs a step, not 3)."""
        spare = runs.round_laws - 1
        if spare > 0 and not runs.cached(q):
            runs.evaluate([np.asarray(q, float)] + fd_points(q)[0][:spare])
        return rows(q)

    # (4) the gradient phase and (5) the probe moves, from one start
    def local(x0):
        x0 = np.clip(x0, lo + 1e-9, hi - 1e-9)
        here.update(loss=math.inf, q=x0)
        if mode == "ad":
            opt = minimize(lambda q: (loss(q), grad_ad(q)), x0, jac=True, method="L-BFGS-B", bounds=list(zip(lo, hi)),
                           options={"maxfun": int(max_iter)})
            opt.ok = bool(opt.success)
        else:
            opt = least_squares(trial_rows, x0, jac=fd_jac, bounds=(lo, hi), method="trf", max_nfev=int(max_iter), x_scale=1.0,
                                ftol=1e-3, xtol=1e-3, gtol=1e-8)
            opt.ok = bool(opt.status > 0)
        # the best law seen; where the probes of its final Jacobian fit better still (the optimiser
        # stopped on a rough wall), move to the best probe and probe again, at most max_iter moves
        q, moves = np.asarray(here["q"], float), 0
        J = fd_jac(q)
        while here["loss"] < (1.0 - MOVE_RTOL) * loss(q) and moves < int(max_iter):
            q, moves = np.asarray(here["q"], float), moves + 1
            J = fd_jac(q)
        r = rows(q)
        opt.moves = moves
        return q, r, J, opt, block_misfit(r, blocks)

    # (6) from the next-best starts while the result is a local minimum (fails the misfit test)
    order = sorted(range(len(starts)), key=lambda i: starts[i][1])
    fits, chosen = [], None
    for i in order:
        if len(fits) > int(restarts) or not math.isfinite(starts[i][1]) or (chosen and chosen[4]["consistent"]):
            break
        if any(np.max(np.abs(starts[i][0] - f["q_final"])) < fd_step for f in fits):
            continue  # where an earlier local fit ended: it would end there again
        out = local(starts[i][0])
        fits.append({"start": i, "q_start": list(map(float, starts[i][0])), "loss_start": starts[i][1],
                     "q_final": np.asarray(out[0], float), "loss_final": 0.5 * float(out[1] @ out[1]),
                     "misfit_p": out[4]["p_value"], "misfit_failed": out[4]["failed"], "forming_runs": runs.runs})
        # the best: consistent with the data before inconsistent (a joint fit's lower loss can hide a
        # block it misses), then the lower loss
        if chosen is None or (out[4]["consistent"], -fits[-1]["loss_final"]) > (chosen[4]["consistent"],
                                                                                -0.5 * float(chosen[1] @ chosen[1])):
            chosen = out
    q, r, J, opt, _ = chosen
    local_fits = [dict(f, q_final=list(map(float, f["q_final"]))) for f in fits]
    return _summarise(q, r, J, runs, prof, pn, params, sections, cuts, width, loss0, check, mode, opt, lo, hi,
                      starts, q0, t0, rows, blocks, local_fits, cant, int(check_rounds), scatter_rows, fd_jac)


def _n_prof(prof) -> int:
    return 0 if prof is None else sum(len(pr.x) for pr in prof.profiles)


def _summarise(q, r, J, runs, prof, pn, params, sections, cuts, width, loss0, check, mode, opt, lo, hi, starts, q0,
               t0, rows, blocks, local_fits, cant, check_rounds, scatter_rows, jac) -> WrinkleFit:
    p, n_sec = len(q), int(cuts[-1])
    n_eff = sum(sec_mod.independent_points(s, width) for s in sections) + _n_prof(prof)
    moved = []  # where the sigma check's probes fit better by more than MOVE_RTOL: the fit moves there, checks again
    while True:
        chi2 = float(r @ r)
        c = max(1.0, chi2 / max(n_eff - p, 1)) * (n_sec + _n_prof(prof)) / n_eff
        cov, sigma_check = checked_covariance(rows, q, r, J, c * np.linalg.pinv(J.T @ J), lo, hi, names=NAMES[:p],
                                              prefetch=runs.evaluate, rounds=check_rounds)
        low = sigma_check["lower"]
        if low is None or not low["chi_square"] < (1.0 - MOVE_RTOL) * chi2 or len(moved) >= CHECK_MOVES:
            break
        moved.append({"q": q.tolist(), "chi_square": chi2, "to_chi_square": low["chi_square"]})
        q = np.asarray(low["q"], float)
        J, r = jac(q), rows(q)
    sigma_check["moved_from"] = moved
    y, valid, ok, reach = runs.evaluate([q])[0]
    y0 = runs.evaluate([q0])[0][0]
    dev, asked = scatter_rows(q)
    cov, scatter = scatter_covariance(J, dev, cov, r)
    scatter["failed"] = asked - len(dev)  # imperfect blanks whose run failed (left out)
    dtype = jnp.result_type(float)
    phys = np.asarray(_physical(jnp.asarray(q[:3], dtype), "voce"), float)
    T = np.asarray(jax.jacfwd(lambda v: _physical(v, "voce"))(jnp.asarray(q[:3], dtype)), float)
    sig = np.sqrt(np.clip(np.diag(T @ cov[:3, :3] @ T.T), 0.0, None))
    keys = ("b_inf", "m0", "kappa0", "b_init")
    values = dict(zip(keys, map(float, phys)))
    sigma = dict(zip(keys, map(float, sig)))
    shear = float(math.exp(q[3])) if p == 4 else 1.0
    if p == 4:
        sigma["shear_scale"] = float(shear * math.sqrt(max(cov[3, 3], 0.0)))
    # determined: a small sd that no open axis of the sigma check dominates, and for the Voce split
    # (b_inf, m0, kappa0) a part bent to DETERMINED_RATIO kappa0 (the asymptote each depends on)
    Tp = np.zeros((len(sigma), p))
    Tp[:4, :3] = T
    if p == 4:
        Tp[4, 3] = shear
    split = reach >= DETERMINED_RATIO * values["kappa0"]
    determined = {k: bool(sigma[k] < DETERMINED_SD * abs(values[k]) and o < 0.5 and (split or k in ("b_init", "shear_scale")))
                  for k, o in zip(sigma, open_share(sigma_check, Tp))}
    m, sm, G = moment_band(q, cov, reach * np.array(BAND))
    band = {"kappa_per_m": (reach * np.array(BAND)).tolist(), "moment_N": m.tolist(), "sd_N": sm.tolist(),
            "determined": bool(np.all(sm < DETERMINED_SD * np.abs(m)) and np.all(
                open_share(sigma_check, np.pad(G, ((0, 0), (0, p - 3)))) < 0.5))}
    fitted = [y[a:b] for a, b in zip(cuts[:-1], cuts[1:])]
    init = [y0[a:b] for a, b in zip(cuts[:-1], cuts[1:])]
    rms = [float(np.sqrt(np.mean((f - s.amplitude) ** 2))) for f, s in zip(fitted, sections)]
    rms0 = [float(np.sqrt(np.mean((f - s.amplitude) ** 2))) for f, s in zip(init, sections)]
    nrmse = [float(section_nrmse(s.s, s.amplitude, s.s, f, None, valid[a:b]))
             for f, s, a, b in zip(fitted, sections, cuts[:-1], cuts[1:])]
    gn, fit_misfit = float("inf"), block_misfit(r, blocks)
    if np.all(np.isfinite(J)):
        d = lsq_linear(J, -r, bounds=(lo - q, hi - q)).x
        gn = float(chi2 - np.sum((r + J @ d) ** 2))
    gn_dof = gn / fit_misfit["scale"]  # in the noise's degrees of freedom: the cantilever fit's GN_TOL holds as there
    converged = bool((opt.ok and not moved) or gn_dof < GN_TOL)  # the optimiser stopped elsewhere where the check moved
    loss = 0.5 * chi2
    reasons = []
    if not converged:
        reasons.append(("the fit moved to a better law its sigma check had run, where a Gauss-Newton step still removes "
                        if moved else f"the optimiser ({mode}) ran out of evaluations ({opt.nfev}) with a Gauss-Newton "
                        "step still removing ") + f"{gn:.3g} of the chi-square ({gn_dof:.3g} degrees of freedom of the "
                       f"noise's, {fit_misfit['scale']:.3g} each; converged under {GN_TOL:g})")
    if not loss < loss0:
        reasons.append("no law lowered the loss below the starting law's")
    at = [NAMES[i] for i in range(p) if q[i] <= lo[i] + 1e-6 or (q[i] >= hi[i] - 1e-6 and i != 1)]
    if at:
        reasons.append(f"{', '.join(at)} at the search bound")
    low = sigma_check["lower"]
    if low is not None and low["significant"]:
        reasons.append(f"a law {low['step_sds']:.3g} sds from the fit along the covariance's axis "
                       f"{describe_axis(low['direction'], NAMES[:p])} fits better (chi-square {low['chi_square']:.4g} against "
                       f"{chi2:.4g}, more than the loss's roughness {sigma_check['roughness']:.3g} explains)")
    if not fit_misfit["consistent"]:
        worst = [(k, fit_misfit["blocks"][k]) for k in fit_misfit["failed"]] or [("", fit_misfit)]
        reasons.append("the fit misses the data by more than the noise explains (" + "; ".join(
                       f"{k + ': ' if k else ''}chi-square {m['chi_square']:.4g} where the true law would leave "
                       f"{m['expected']:.4g} +- {m['sd']:.3g}; p = {m['p_value']:.2g}, limit {m['limit']:g}"
                       for k, m in worst) + "): a local minimum of the rough loss "
                       f"after {len(local_fits)} local fit(s) from the best starts (a better law may exist; the standard "
                       "deviations describe this minimum only), a law of another form, or more noise than given")
    return WrinkleFit(
        law=law_from_q(jnp.asarray(q[:3], dtype), "voce"), law_initial=runs.law0, shear_scale=shear, q=q, values=values, sigma=sigma,
        determined=determined, loss_initial=loss0, loss_final=loss, rms_per_section=rms, rms_initial_per_section=rms0,
        nrmse_per_section=nrmse, profile_rmse=(float(np.sqrt(np.mean((prof.rows(q[:3]) * 1e-3) ** 2)))
                                               if prof is not None else None),
        kappa_reach=reach, gradient_check=check, jacobian=mode, iterations=int(opt.get("njev") or opt.get("nit") or 0),
        moves=opt.moves, gn_decrease=gn, forming_runs=runs.runs,
        wall_time=time.perf_counter() - t0, converged=converged and not reasons, reason="; ".join(reasons),
        starts=[(list(map(float, s)), c) for s, c in starts], fitted=fitted, initial=init, covariance=cov,
        sigma_check=sigma_check, scatter=scatter, misfit=fit_misfit, local_fits=local_fits, cantilever_start=cant, moment_band=band)


__all__ = ["WrinkleFit", "Progress", "fit_wrinkles", "predict_sections", "sections_of", "section_loss", "voce_start", "scaled_shear", "imperfections", "PARAM_KINDS",
           "NOISE", "FD_STEP", "GRAD_RTOL"]
