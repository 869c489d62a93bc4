"""Bending-law fits to cantilever side profiles, through a differentiable forward model.

The forward model is the shell cantilever, ``jaxform.cantilever.simulate(law, overhang=...,
areal_mass=...)`` (any function with that signature returning ``x``, ``z`` in m, clamp to tip, can
be passed as ``simulate``). The residual of a profile is the simulated ``z`` interpolated (cubic
Hermite, second-order slopes) at each measured ``x`` minus the measured ``z``; ``rmse`` is the RMS
of exactly these numbers at the fitted law. Every overhang is solved on one reference strip of
``L_REF`` by similarity (:mod:`jaxform.calibrate.transforms`), so one compiled solve serves every
profile and every fit in a process.

Reaching the global optimum (issue 18). Parameters ``q = (log B_init, log B_inf/B_init, log
kappa0)`` with bounds tied to the data (:func:`bounds`): ``B_init`` from 1/4 to 300 times the
profile's Peirce stiffness, the ratio from 1e-3 to 1, ``kappa0`` from 0.02/L to 2000/L. Starting
points (:func:`initial_guess`) from the profile itself: Peirce's linear stiffness ``B_lin`` (the
bending length) and the clamp moment ``M_c`` read off the data (``M_c / B_lin`` is the clamp
curvature a linear strip would have), a grid of ``B_init`` multiples of ``B_lin`` and ``kappa0``
fractions of that curvature. Every start is scored with one solve of an *exploration* model (for
the shell: 20 elements instead of 40, about 7x cheaper), the best ``n_starts`` are optimised on it
(``explore_iter`` evaluations each), and the best results are polished on the full model until one
reaches the noise (at most ``n_polish``). Optimiser: ``scipy.optimize.least_squares`` (trust-region
reflective, bounds) on the host with the Jacobian ``dr/dq`` from JAX (forward mode through the
implicit-function gradient of the solve; reverse mode where the model defines only a VJP). A trial
law whose solve does not converge is a non-finite residual, which ``trf`` answers by shrinking its
trust region.

No quiet failures: the measurement noise ``sigma`` is estimated from the profile
(:func:`jaxform.calibrate.cantilever_data.estimate_noise`); the fit is ``trustworthy`` only when the
optimiser converged, the fitted simulation is an equilibrium, and ``rmse <= rmse_limit * sigma``
(default 2); otherwise ``reason`` says why. Converged: ``least_squares`` met one of its tolerances,
or the chi-square (``SSR / sigma^2``) a bounded Gauss-Newton step would still remove
(``gn_decrease``, ``scipy.optimize.lsq_linear`` on the last Jacobian) is under ``GN_TOL`` (1: the
law is inside the one-sd confidence region of the optimum, further steps change nothing the data
can tell). A polish run that ran out of evaluations above that is restarted once from where it
stopped (a fresh trust region: round-trip case 19, a 195 mm strip at 1.3 ``kappa0`` creeping along
the ``B_inf/B_init``-``kappa0`` valley, stopped 1.2 chi-square units short).

Uncertainty (Fisher information): ``cov(q) = s^2 (J^T J)^-1`` with ``s^2 = SSR / (n - p)``, mapped
to ``(b_inf, m0, kappa0, b_init)`` by the delta method. ``B_inf`` is determined where its relative
standard deviation is below ``DETERMINED_SD`` (10 %) and the fitted strip reaches ``DETERMINED_RATIO``
(5) times ``kappa0``. ``B_init`` is determined where its relative standard deviation is below
``B_INIT_DETERMINED_SD`` (1 %, so that 3 % is three standard deviations): on a short strip bent
well past ``kappa0`` near the clamp (round-trip case 8: 40 mm, chord 27°, clamp at 15 ``kappa0``)
``B_init`` and ``kappa0`` trade against each other (correlation -0.99) and the profile pins
``B_init`` only to ~7-10 %; the noisy data then fit a law 20 % off better than the true one, which
no optimiser can fix, so the fit says so instead. SI units throughout: m, 1/m, N·m, N, kg/m².
"""
from __future__ import annotations

import dataclasses
import functools
import math
import time
import warnings
from typing import Any, Callable, NamedTuple, Sequence

import jax
import jax.numpy as jnp
import numpy as np
from scipy.optimize import least_squares, lsq_linear

from jaxform import cantilever
from jaxform.calibrate.cantilever_data import chord, clamp_moment, estimate_noise, peirce_b
from jaxform.calibrate.profiles import discrete_curvature, interp_profile
from jaxform.calibrate.transforms import LAW_KINDS, _physical, law_from_q, q_from_law
from jaxform.units import GRAVITY

DETERMINED_RATIO = 5.0  # B_inf is determined where the fitted strip reaches this many kappa0 ...
DETERMINED_SD = 0.10  # ... and the Fisher standard deviation of B_inf is below this fraction of it
B_INIT_DETERMINED_SD = 0.01  # B_init is determined where its Fisher sd is below this fraction of it
GN_TOL = 1.0  # converged where a Gauss-Newton step would lower the chi-square by less than this
L_REF = 0.1  # m, the reference strip every overhang is solved on (similarity)
_RES_SCALE = 1.0e-3  # residuals in mm inside the optimiser (conditioning only)


@dataclasses.dataclass(frozen=True)
class Profile:
    """One measured cantilever side profile.

    Attributes:
        x: (n,) horizontal distance from the clamp edge, m, increasing.
        z: (n,) height, m, negative downwards (z <= 0 for a hanging strip).
        overhang: arc length of the free strip, m.
    """

    x: np.ndarray
    z: np.ndarray
    overhang: float


@dataclasses.dataclass(frozen=True)
class CantileverFit:
    """Result of :func:`fit_cantilever` (host values, SI).

    Attributes:
        law: the fitted bending law (``VoceBending`` or ``LinearBending``).
        law_kind: ``"voce"`` or ``"linear"``.
        b_inf, m0, kappa0, b_init: fitted parameters, N·m, N, 1/m, N·m (linear: ``b_inf = b_init =
            B``, ``m0 = 0``, ``kappa0`` reported as ``nan``).
        sigma: Fisher standard deviations, same keys (``"b_inf"``, ``"m0"``, ``"kappa0"``, ``"b_init"``).
        covariance: (p, p) covariance of ``q``.
        rmse: RMS of the z-residual at the measured x over all profiles, m.
        rmse_per_profile: (n_profiles,) m.
        noise: measurement noise on z estimated from the profiles themselves (or given), m.
        kappa_max: largest curvature of the fitted simulations, 1/m.
        kappa_max_over_kappa0: ``kappa_max / kappa0``.
        b_inf_determined: bool (module docstring).
        b_init_determined: bool, the Fisher sd of ``B_init`` under ``B_INIT_DETERMINED_SD`` of it.
        b_41_5: simulated standard-test stiffness of the fitted law, N·m (``nan`` if not computed).
        iterations: optimiser iterations (Jacobian evaluations, all stages).
        n_simulations: distinct forward (+ derivative) solves, all stages and models.
        wall_time: seconds.
        converged: whether the final optimiser run met one of its tolerances (status > 0) or
            ``gn_decrease < GN_TOL``.
        gn_decrease: the chi-square a bounded Gauss-Newton step from the fitted law would remove.
        simulated: list of ``(x, z)`` arrays (m) of the fitted simulation for each profile.
        residuals: list of (n_i,) z-residuals, m.
        solver_residual: (n_profiles,) relative out-of-balance force of the fitted simulations.
        solver_converged: whether every fitted simulation met ``max_solver_residual``.
        n_evaluations: residual evaluations the optimiser asked for (all stages).
        trustworthy: converged, an equilibrium, and ``rmse <= rmse_limit * noise``.
        reason: why the fit is not trustworthy ("" when it is).
        starts: ``(q, cost)`` of every starting point scored on the exploration model.
    """

    law: Any
    law_kind: str
    b_inf: float
    m0: float
    kappa0: float
    b_init: float
    sigma: dict
    covariance: np.ndarray
    rmse: float
    rmse_per_profile: np.ndarray
    kappa_max: float
    kappa_max_over_kappa0: float
    b_inf_determined: bool
    b_41_5: float
    iterations: int
    n_simulations: int
    wall_time: float
    converged: bool
    simulated: list
    residuals: list
    solver_residual: np.ndarray = dataclasses.field(default_factory=lambda: np.zeros(0))
    solver_converged: bool = True
    n_evaluations: int = 0
    noise: float = float("nan")
    trustworthy: bool = True
    reason: str = ""
    starts: list = dataclasses.field(default_factory=list)
    b_init_determined: bool = True
    gn_decrease: float = 0.0

    def as_dict(self) -> dict:
        """JSON-ready summary with the SPEC's key names (``b_inf_Nm``, ``rmse_mm``, ...)."""
        s = self.sigma
        return {
            "law": self.law_kind, "b_inf_Nm": self.b_inf, "m0_N": self.m0, "kappa0_per_m": self.kappa0,
            "b_init_Nm": self.b_init, "b_41_5_Nm": self.b_41_5, "rmse_mm": self.rmse * 1e3,
            "rmse_mm_per_profile": [float(v) * 1e3 for v in self.rmse_per_profile],
            "noise_mm": self.noise * 1e3, "rmse_over_noise": self.rmse / self.noise if self.noise > 0 else float("nan"),
            "sigma_b_inf_Nm": s["b_inf"], "sigma_m0_N": s["m0"], "sigma_kappa0_per_m": s["kappa0"],
            "sigma_b_init_Nm": s["b_init"], "b_init_sd_pct": 100.0 * s["b_init"] / self.b_init,
            "b_init_determined": bool(self.b_init_determined), "kappa_max_per_m": self.kappa_max,
            "kappa_max_over_kappa0": self.kappa_max_over_kappa0, "b_inf_determined": bool(self.b_inf_determined),
            "iterations": int(self.iterations), "n_simulations": int(self.n_simulations),
            "n_evaluations": int(self.n_evaluations), "wall_time_s": self.wall_time,
            "converged": bool(self.trustworthy), "optimiser_converged": bool(self.converged),
            "gn_decrease_chi2": self.gn_decrease, "reason": self.reason,
            "solver_residual_max": float(np.max(self.solver_residual, initial=0.0)),
            "solver_converged": bool(self.solver_converged), "gravity_m_s2": GRAVITY,
        }


class FitProgress(NamedTuple):
    """What :func:`fit_cantilever` hands its ``callback`` after each optimiser iteration."""

    iteration: int  # optimiser iterations so far (all stages)
    n_evaluations: int  # residual evaluations so far
    rmse: float  # RMS z-residual at the current law, m
    law: Any  # the current bending law
    stage: str = "polish"  # "explore" (cheap model, several starts) or "polish" (the full model)


def _as_profiles(profiles) -> list[Profile]:
    out = [p if isinstance(p, Profile) else Profile(np.asarray(p[0], float), np.asarray(p[1], float), float(p[2]))
           for p in profiles]
    if not out:
        raise ValueError("fit_cantilever: no profiles given")
    return out


def _features(profiles, areal_mass, g):
    """``(B_lin, kappa_lin, L_max)``: median Peirce stiffness (N·m), the clamp curvature a linear strip
    of that stiffness would have under the measured clamp moment (1/m), the longest overhang (m)."""
    b = [peirce_b(p.overhang, min(max(chord(p.x, p.z), 1e-3), 1.5), areal_mass, g) for p in profiles]
    k = [clamp_moment(p.x, p.z, p.overhang, areal_mass, g) / bi for p, bi in zip(profiles, b)]
    return float(np.median(b)), float(max(k)), max(p.overhang for p in profiles)


def bounds(profiles: Sequence[Profile], areal_mass: float, law_kind: str = "voce", g: float = GRAVITY):
    """``(lower, upper)`` of ``q`` tied to the data (module docstring)."""
    b, _, L = _features(_as_profiles(profiles), areal_mass, g)
    lo, hi = [math.log(b / 4.0)], [math.log(300.0 * b)]
    if law_kind == "voce":
        lo += [math.log(1e-3), math.log(0.02 / L)]
        hi += [0.0, math.log(2000.0 / L)]
    return np.asarray(lo), np.asarray(hi)


def initial_guess(profiles: Sequence[Profile], areal_mass: float, law_kind: str = "voce",
                  g: float = GRAVITY) -> list[np.ndarray]:
    """Starting points ``q`` from the profiles themselves (module docstring): ``B_init`` 1, 2 and 5
    times Peirce's ``B_lin``, ``kappa0`` 1/10, 1/3 and 1 times ``M_c / B_lin``, ``B_inf/B_init`` 0.05."""
    b, k, _ = _features(_as_profiles(profiles), areal_mass, g)
    if law_kind == "linear":
        return [np.array([math.log(b)])]
    return [np.array([math.log(fb * b), math.log(0.05), math.log(fk * k)]) for fb in (1.0, 2.0, 5.0)
            for fk in (0.1, 1.0 / 3.0, 1.0)]


# ---------------------------------------------------------------------------------------------
# Forward model on the reference strip, and the data residual
# ---------------------------------------------------------------------------------------------


@functools.partial(jax.jit, static_argnames=("law_kind", "simulate", "kw", "reverse"))
def _forward(q, scale, areal_mass, *, law_kind, simulate, kw, reverse=False):
    """Profile ``(2, n)`` (m) of the strip of overhang ``L_REF / scale``, its Jacobian ``(2, n, p)``
    in ``q`` and the model's own residual; one compile per (model, kwargs, law kind)."""

    def prof(q):
        o = simulate(law_from_q(q, law_kind, scale), overhang=L_REF, areal_mass=areal_mass, **dict(kw))
        xz = jnp.stack([o.x, o.z]) / scale
        return xz, (xz, jax.lax.stop_gradient(jnp.asarray(getattr(o, "residual", 0.0), xz.dtype).reshape(())))

    dxz, (xz, res) = (jax.jacrev if reverse else jax.jacfwd)(prof, has_aux=True)(q)
    return xz, dxz, res


@jax.jit
def _data_residual(xm, zm, xz, dxz):
    """z-residual at the measured ``xm`` (m) and its Jacobian in ``q`` (chain rule through the interpolation)."""
    f = lambda xs, zs: interp_profile(xm, xs, zs) - zm  # noqa: E731
    r = f(xz[0], xz[1])
    J = jax.vmap(lambda dx, dz: jax.jvp(f, (xz[0], xz[1]), (dx, dz))[1], in_axes=(-1, -1), out_axes=-1)(dxz[0], dxz[1])
    return r, J


class _Evaluation(NamedTuple):
    """Host values at one ``q``: residual (m), its Jacobian, the model's residuals, whether they
    all met ``max_solver_residual``, and the simulated profiles."""

    r: np.ndarray
    J: np.ndarray
    solver_residual: np.ndarray
    converged: bool
    profiles: list


class _Model:
    """One forward model applied to the profiles, with a per-fit cache of evaluations keyed by ``q``."""

    def __init__(self, profiles, law_kind, simulate, kw, areal_mass, max_solver_residual, dtype):
        self.profiles, self.dtype, self.max_res = profiles, dtype, max_solver_residual
        self.static = dict(law_kind=law_kind, simulate=simulate, kw=tuple(sorted(kw.items())))
        self.mass = jnp.asarray(areal_mass, dtype)
        q0 = jnp.zeros(3 if law_kind == "voce" else 1, dtype)
        try:  # forward mode unless the model defines only a custom VJP (found while tracing, no solve)
            jax.eval_shape(functools.partial(_forward, **self.static), q0, jnp.asarray(1.0, dtype), self.mass)
            self.static["reverse"] = False
        except TypeError:
            self.static["reverse"] = True
        self.evaluate = functools.lru_cache(maxsize=64)(self._evaluate)

    def _evaluate(self, q: tuple) -> _Evaluation:
        rs, Js, sres, xzs = [], [], [], []
        for p in self.profiles:
            xz, dxz, res = _forward(jnp.asarray(q, self.dtype), jnp.asarray(L_REF / p.overhang, self.dtype),
                                    self.mass, **self.static)
            r, J = _data_residual(jnp.asarray(p.x, self.dtype), jnp.asarray(p.z, self.dtype), xz, dxz)
            rs.append(np.asarray(r, float))
            Js.append(np.asarray(J, float))
            sres.append(float(res))
            xzs.append((np.asarray(xz[0], float), np.asarray(xz[1], float)))
        sres = np.asarray(sres)
        ok = bool(np.all(sres <= self.max_res))
        return _Evaluation(np.concatenate(rs), np.concatenate(Js), sres, ok, xzs)

    def rows(self, q) -> np.ndarray:
        """Residuals the optimiser sees (mm): ``inf`` where the solve is not an equilibrium."""
        e = self.evaluate(tuple(np.asarray(q, float).tolist()))
        ok = e.converged and np.all(np.isfinite(e.r)) and np.all(np.isfinite(e.J))
        return e.r / _RES_SCALE if ok else np.full_like(e.r, np.inf)

    def jac(self, q) -> np.ndarray:
        return self.evaluate(tuple(np.asarray(q, float).tolist())).J / _RES_SCALE

    def cost(self, q) -> float:
        r = self.rows(q)
        return float(r @ r)

    def solves(self) -> int:
        return self.evaluate.cache_info().misses

    def gn_decrease(self, q, lo, hi, sigma) -> float:
        """Chi-square (``SSR / sigma^2``) a bounded Gauss-Newton step from ``q`` would remove."""
        q = np.asarray(q, float)
        e = self.evaluate(tuple(q.tolist()))
        if not (e.converged and np.all(np.isfinite(e.J))):
            return float("inf")
        d = lsq_linear(e.J, -e.r, bounds=(lo - q, hi - q)).x
        return float((e.r @ e.r - np.sum((e.r + e.J @ d) ** 2)) / sigma**2)


ProfileModel = _Model
"""The profiles' residual model (``rows(q)`` in mm, ``jac(q)``): shared with the joint wrinkle fit."""


# ---------------------------------------------------------------------------------------------
# The fit
# ---------------------------------------------------------------------------------------------


def fit_cantilever(
    profiles,
    *,
    areal_mass: float,
    law: str = "voce",
    simulate: Callable | None = None,
    simulate_kwargs: dict | None = None,
    explore_kwargs: dict | None = None,
    init=None,
    max_iter: int = 60,
    explore_iter: int = 15,
    n_starts: int = 3,
    n_polish: int = 2,
    chi2_tol: float = 0.01,
    tol: float = 1e-8,
    noise: float | None = None,
    rmse_limit: float = 2.0,
    compute_b41_5: bool = True,
    g: float = GRAVITY,
    max_solver_residual: float = 1e-5,
    callback: Callable[[FitProgress], Any] | None = None,
) -> CantileverFit:
    """Fit a bending law to one or more cantilever side profiles of one material (one side).

    Args:
        profiles: sequence of :class:`Profile` or ``(x, z, overhang)`` tuples (m; x increasing from
            the clamp, z negative downwards). One profile suffices; several overhangs add information.
        areal_mass: kg/m².
        law: ``"voce"`` or ``"linear"``.
        simulate: forward model ``simulate(law, overhang=, areal_mass=, **simulate_kwargs)`` returning
            ``x``, ``z`` (m, clamp to tip) and optionally ``residual``; default the shell
            ``jaxform.cantilever.simulate``. Differentiable with JAX; called at ``overhang=L_REF``.
        simulate_kwargs: keyword arguments of the full model (hashable values).
        explore_kwargs: keyword arguments of the exploration model (default: the shell with 20
            elements when ``simulate`` is the default, else ``simulate_kwargs``).
        init: a starting bending law (optional; added to :func:`initial_guess`'s grid).
        max_iter: residual evaluations of each optimiser run (``max_nfev``).
        explore_iter: residual evaluations of each exploration run (at most ``max_iter``).
        n_starts: starting points optimised on the exploration model (the best-scoring ones).
        n_polish: exploration results polished on the full model, best first, until one reaches
            the noise.
        chi2_tol: the optimiser stops when a step lowers the chi-square (``SSR / noise^2``, about
            the number of points at the optimum) by less than this (``ftol = chi2_tol / n``): a
            statistically meaningless change, where a flat valley (``kappa0`` against ``B_inf/B_init``
            on a strip that barely passes ``kappa0``) used to be crept along for 80 iterations.
        tol: ``xtol`` and ``gtol`` of ``least_squares``.
        noise: measurement noise on z, m (default: estimated from the profiles).
        rmse_limit: a fit is trustworthy only with ``rmse <= rmse_limit * noise``.
        compute_b41_5: also simulate the standard 41.5° test with the fitted law.
        g: gravity, m/s² (the simulation's own gravity must match).
        max_solver_residual: largest acceptable ``residual`` of a forward simulation; a trial law
            above it is a failed evaluation (the optimiser backs off).
        callback: called with a :class:`FitProgress` after each optimiser iteration.

    Returns:
        :class:`CantileverFit`; ``trustworthy`` and ``reason`` say whether to use it.
    """
    t0 = time.perf_counter()
    if law not in LAW_KINDS:
        raise ValueError(f"fit_cantilever: law = {law!r}: must be 'voce' or 'linear'")
    profiles = _as_profiles(profiles)
    kw = dict(simulate_kwargs or {})
    if explore_kwargs is None:
        explore_kwargs = {**kw, "n_elements": min(20, int(kw.get("n_elements", 40)))} if simulate is None else kw
    simulate = simulate or cantilever.simulate
    dtype = jnp.result_type(float)  # float64 when x64 is on
    n_data = sum(int(p.x.size) for p in profiles)
    sigma = float(noise) if noise is not None else float(np.sqrt(np.mean(
        [estimate_noise(p.x, p.z) ** 2 for p in profiles])))
    full = _Model(profiles, law, simulate, kw, areal_mass, max_solver_residual, dtype)
    coarse = full if dict(explore_kwargs) == kw else _Model(profiles, law, simulate, dict(explore_kwargs), areal_mass,
                                                          max_solver_residual, dtype)
    lo, hi = bounds(profiles, areal_mass, law, g)
    inside = lambda q: np.clip(q, lo + 1e-9 * (hi - lo), hi - 1e-9 * (hi - lo))  # noqa: E731
    cands = initial_guess(profiles, areal_mass, law, g) + ([q_from_law(init, law)] if init is not None else [])
    cands = [inside(np.asarray(c, float)) for c in cands]
    counts = {"nit": 0, "nfev": 0}

    def run(model, q0, nfev, stage):
        def report(intermediate_result):  # scipy passes the OptimizeResult to a parameter of this name
            it = intermediate_result
            rmse = _RES_SCALE * math.sqrt(2.0 * float(it.cost) / n_data)
            callback(FitProgress(counts["nit"] + int(it.nit), counts["nfev"] + int(it.nfev), rmse,
                                 law_from_q(jnp.asarray(it.x, dtype), law), stage))

        opt = least_squares(model.rows, q0, jac=model.jac, bounds=(lo, hi), method="trf", ftol=chi2_tol / n_data, xtol=tol, gtol=tol,
                            x_scale=1.0, max_nfev=nfev, callback=report if callback is not None else None)
        counts["nit"] += int(opt.njev or 0)
        counts["nfev"] += int(opt.nfev)
        return opt

    scored = sorted(((coarse.cost(c), i) for i, c in enumerate(cands)), key=lambda t: t[0])
    starts = [(cands[i].tolist(), c) for c, i in scored]
    if not np.isfinite(scored[0][0]):
        raise RuntimeError("fit_cantilever: the simulation failed (non-finite or not converged) at every "
                           "starting point")
    explored = []
    for c, i in scored[: max(1, n_starts if law == "voce" else 1)]:
        if not np.isfinite(c):
            continue
        q = run(coarse, cands[i], min(explore_iter, max_iter), "explore").x
        explored.append((coarse.cost(q), q))
    explored.sort(key=lambda t: t[0])
    best = None
    tried = 0
    for _, q in explored + [(c, cands[i]) for c, i in scored]:  # explored first; raw starts if none solves
        if tried >= max(1, n_polish) or not np.isfinite(full.cost(inside(q))):
            continue  # the full model may not reach equilibrium where the exploration model did
        tried += 1
        opt = run(full, inside(q), max_iter, "polish")
        if opt.status == 0 and not full.gn_decrease(opt.x, lo, hi, sigma) < GN_TOL:
            opt = run(full, inside(opt.x), max_iter, "polish")  # out of evaluations: once more, fresh trust region
        cost = full.cost(opt.x)
        if best is None or cost < best[0]:
            best = (cost, opt)
        if math.sqrt(cost / n_data) * _RES_SCALE <= rmse_limit * sigma:
            break
    if best is None:
        raise RuntimeError("fit_cantilever: the full simulation failed (non-finite or not converged) at every "
                           "explored and starting point")
    opt = best[1]
    q = np.asarray(opt.x, float)
    final = full.evaluate(tuple(q.tolist()))
    if not final.converged:  # a safety net: the optimiser accepts only converged points
        warnings.warn(f"fit_cantilever: forward simulation residual {final.solver_residual.max():.2e} > "
                      f"{max_solver_residual:.1e} at the fitted law; the fit is not trustworthy", RuntimeWarning)
    fitted = law_from_q(jnp.asarray(q, dtype), law)
    b41 = float("nan")
    if compute_b41_5:
        b41 = float(cantilever.standard_test(fitted, areal_mass=areal_mass, model=simulate, g=g, **kw).b_41_5)
    gn = full.gn_decrease(q, lo, hi, sigma)
    return _summarise(profiles, law, q, final, fitted, n_data, dtype, b41, sigma, rmse_limit, opt, max_iter, gn,
                      iterations=counts["nit"], n_simulations=full.solves() + (coarse.solves() if coarse is not full else 0),
                      n_evaluations=counts["nfev"], wall_time=time.perf_counter() - t0, starts=starts)


def _verdict(converged, solver_ok, solver_residual, rmse, noise, rmse_limit, nfev, max_iter, lo_hi_hit, gn) -> str:
    """Why a fit is not one to use ("" when it is)."""
    reasons = []
    if not converged:
        reasons.append(f"the optimiser stopped after {nfev} evaluations (max_iter {max_iter}) without meeting "
                       f"its tolerances, a Gauss-Newton step would still lower the chi-square by {gn:.3g} "
                       f"(converged: under {GN_TOL:g})")
    if not solver_ok:
        reasons.append(f"the forward simulation at the fitted law did not reach equilibrium (residual "
                       f"{float(np.max(solver_residual, initial=np.nan)):.2e})")
    if not rmse <= rmse_limit * noise:
        reasons.append(f"rmse {1e3 * rmse:.4f} mm is {rmse / noise:.1f} x the profile's noise {1e3 * noise:.4f} mm "
                       f"(limit {rmse_limit:g} x): no law of this kind reproduces the profile (check the overhang, "
                       f"the areal mass and the profile itself){'; the fit ended on a bound: ' + lo_hi_hit if lo_hi_hit else ''}")
    return "; ".join(reasons)


def _summarise(profiles, law, q, final: _Evaluation, fitted, n_data, dtype, b41, noise, rmse_limit, opt, max_iter, gn,
               **counts) -> CantileverFit:
    """Fisher covariance, per-profile residuals, curvature reach, the determined flag and the verdict."""
    r_data, J_data = final.r, final.J
    p = q.size
    s2 = float(np.dot(r_data, r_data)) / max(n_data - p, 1)
    cov_q = s2 * np.linalg.pinv(J_data.T @ J_data)
    phys = np.asarray(_physical(jnp.asarray(q, dtype), law), float)
    T = np.asarray(jax.jacfwd(lambda v: _physical(v, law))(jnp.asarray(q, dtype)), float)
    if law == "linear":
        T = np.nan_to_num(T, nan=0.0, posinf=0.0)
    sig = np.sqrt(np.clip(np.diag(T @ cov_q @ T.T), 0.0, None))
    simulated = final.profiles
    bounds_ = np.cumsum([0] + [prof.x.size for prof in profiles])
    residuals = [r_data[a:b] for a, b in zip(bounds_[:-1], bounds_[1:])]
    kappa_max = max(float(np.max(np.abs(discrete_curvature(jnp.asarray(x), jnp.asarray(z))))) for x, z in simulated)
    b_inf, m0, kappa0, b_init = (float(v) for v in phys)
    if law == "linear":
        m0, kappa0 = 0.0, float("nan")
        ratio, determined = float("nan"), True
    else:
        ratio = kappa_max / kappa0
        rel = sig[0] / b_inf if b_inf > 0 else np.inf
        determined = bool(ratio >= DETERMINED_RATIO and rel < DETERMINED_SD)
    b_init_determined = bool(sig[3] < B_INIT_DETERMINED_SD * b_init)
    rmse = math.sqrt(float(np.mean(r_data**2)))
    names = ["B_init", "B_inf/B_init", "kappa0"][:p]
    lo_hi = ", ".join(n for n, a in zip(names, np.asarray(opt.active_mask)) if a != 0)
    converged = bool(opt.status > 0 or gn < GN_TOL)
    reason = _verdict(converged, final.converged, final.solver_residual, rmse, noise, rmse_limit,
                      int(opt.nfev), max_iter, lo_hi, gn)
    return CantileverFit(
        law=fitted, law_kind=law, b_inf=b_inf, m0=m0, kappa0=kappa0, b_init=b_init,
        sigma={"b_inf": float(sig[0]), "m0": float(sig[1]), "kappa0": float(sig[2]) if law != "linear" else float("nan"),
               "b_init": float(sig[3])},
        covariance=cov_q, rmse=rmse, rmse_per_profile=np.asarray([math.sqrt(float(np.mean(rr**2))) for rr in residuals]),
        kappa_max=kappa_max, kappa_max_over_kappa0=ratio, b_inf_determined=determined, b_41_5=b41,
        b_init_determined=b_init_determined, gn_decrease=gn,
        simulated=simulated, residuals=residuals, solver_residual=final.solver_residual, converged=converged,
        solver_converged=final.converged, noise=noise, trustworthy=not reason, reason=reason, **counts)


__all__ = ["Profile", "ProfileModel", "CantileverFit", "FitProgress", "peirce_b", "bounds",
           "initial_guess", "fit_cantilever", "estimate_noise", "L_REF", "B_INIT_DETERMINED_SD"]
