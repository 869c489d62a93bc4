"""Bending-law fits to cantilever side profiles, through a differentiable forward model.

The forward model is the shell cantilever, ``jaxform.cantilever.simulate(law, overhang=...,
areal_mass=...)`` (any function with that signature returning ``x``, ``z`` in m, clamp to tip, can
be passed as ``simulate``). The residual of a profile is the simulated ``z`` interpolated (cubic
Hermite, second-order slopes) at each measured ``x`` minus the measured ``z`` — the SPEC's
``rmse`` is the RMS of exactly these numbers at the fitted law. Parameters are the unconstrained
``q`` of :mod:`jaxform.calibrate.transforms`.

Optimiser: ``scipy.optimize.least_squares`` (trust-region reflective, ``method="trf"``) on the
host, with the Jacobian ``dr/dq`` from JAX. Every residual evaluation is a cantilever solve (a
jitted Newton continuation of a few hundred dofs, about a second), so the optimiser's own work is
negligible and a host-side driver costs nothing; what matters is that one compiled call gives the
residual *and* its Jacobian (forward mode, three tangents through the implicit-function gradient
of the solve; reverse mode where the model defines only a VJP), and that a trial law whose solve
does not converge can be refused. ``trf`` treats a non-finite residual as a failed step and
shrinks its trust region, which is how an unconverged solve is reported to it (MINPACK's ``"lm"``
cannot back off like that, and an optimistix solver inside ``jit`` would have to trace the whole
solve into its loop and recompile per fit). The residual and Jacobian at a point come from one
cached call (``functools.lru_cache`` keyed by ``q``), so ``trf`` asking for ``fun`` then ``jac``
at an accepted point costs one solve. The fit runs in offsets ``d = q - q0`` from the starting
point, so ``trf``'s first trust radius is 1 in ``q`` (a factor ``e`` in ``B_init``, ``kappa0``).
A tiny ridge ``prior_weight * d`` keeps directions the data do not see (``b_inf`` when the strip
never bends well past ``kappa0``) finite instead of drifting.

Uncertainty: Gauss–Newton / Laplace covariance ``sigma^2 (J^T J)^-1`` in ``q`` with
``sigma^2 = SSR / (n - p)``, mapped to ``(b_inf, m0, kappa0, b_init)`` by the delta method. ``B_inf``
is reported as determined only where the fitted simulation reaches a curvature of at least
``5 kappa0`` (``kappa_max_over_kappa0``) and its relative standard error is below 25 %.
SI units throughout: m, 1/m, N·m, N, kg/m².
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
from scipy.optimize import least_squares

from jaxform import cantilever
from jaxform.calibrate.transforms import LAW_KINDS, _physical, law_from_q, q_from_law
from jaxform.units import GRAVITY

DETERMINED_RATIO = 5.0  # B_inf is determined where the data reach this many kappa0
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
        sigma: standard errors, same keys as above (``"b_inf"``, ``"m0"``, ``"kappa0"``, ``"b_init"``).
        covariance: (p, p) covariance of the unconstrained parameters ``q``.
        rmse: RMS of the z-residual at the measured x over all profiles, m.
        rmse_per_profile: (n_profiles,) m.
        kappa_max: largest curvature of the fitted simulations, 1/m.
        kappa_max_over_kappa0: ``kappa_max / kappa0`` (how well ``B_inf`` is determined).
        b_inf_determined: bool, see the module docstring.
        b_41_5: simulated standard-test stiffness of the fitted law, N·m (``nan`` if not computed).
        iterations: optimiser iterations (Jacobian evaluations of ``least_squares``, ``njev``).
        n_simulations: distinct forward (+ derivative) solves of the simulation, starting points included.
        wall_time: seconds.
        converged: whether the optimiser met one of its tolerances (``least_squares`` status > 0).
        simulated: list of ``(x, z)`` arrays (m) of the fitted simulation for each profile.
        residuals: list of (n_i,) z-residuals, m.
        solver_residual: (n_profiles,) relative out-of-balance force the forward model reported
            at the fitted law (``residual`` of the cantilever result; 0 where the model gives none).
        solver_converged: whether every fitted simulation met ``max_solver_residual``; a fit with
            ``False`` here is not trustworthy (the profile it matched is not an equilibrium).
        n_evaluations: residual evaluations the optimiser asked for (``least_squares`` ``nfev``).
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

    def as_dict(self) -> dict:
        """JSON-ready summary with the SPEC's key names (``b_inf_Nm``, ``rmse_mm``, ...)."""
        s = self.sigma
        return {
            "law": self.law_kind,
            "b_inf_Nm": self.b_inf,
            "m0_N": self.m0,
            "kappa0_per_m": self.kappa0,
            "b_init_Nm": self.b_init,
            "b_41_5_Nm": self.b_41_5,
            "rmse_mm": self.rmse * 1e3,
            "rmse_mm_per_profile": [float(v) * 1e3 for v in self.rmse_per_profile],
            "sigma_b_inf_Nm": s["b_inf"],
            "sigma_m0_N": s["m0"],
            "sigma_kappa0_per_m": s["kappa0"],
            "sigma_b_init_Nm": s["b_init"],
            "kappa_max_per_m": self.kappa_max,
            "kappa_max_over_kappa0": self.kappa_max_over_kappa0,
            "b_inf_determined": bool(self.b_inf_determined),
            "iterations": int(self.iterations),
            "n_simulations": int(self.n_simulations),
            "n_evaluations": int(self.n_evaluations),
            "wall_time_s": self.wall_time,
            "converged": bool(self.converged),
            "solver_residual_max": float(np.max(self.solver_residual, initial=0.0)),
            "solver_converged": bool(self.solver_converged),
            "gravity_m_s2": GRAVITY,
        }


class FitProgress(NamedTuple):
    """What :func:`fit_cantilever` hands its ``callback`` after each optimiser iteration."""

    iteration: int  # optimiser iterations so far
    n_evaluations: int  # residual evaluations so far
    rmse: float  # RMS z-residual at the current law, m
    law: Any  # the current bending law


# ---------------------------------------------------------------------------------------------
# Profile geometry
# ---------------------------------------------------------------------------------------------


def interp_profile(xq, xs, zs):
    """Cubic Hermite interpolation of a simulated profile ``zs(xs)`` at ``xq``; jit/grad-able.

    Args:
        xq: (m,) query abscissae, m.
        xs: (n,) simulated x, m, increasing (n >= 3); outside ``[xs[0], xs[-1]]`` the end cubic
            is extrapolated (a measured tip beyond the simulated tip still gives a residual that
            pulls the fit the right way).
        zs: (n,) simulated z, m.
    Returns:
        (m,) z at xq, m. Slopes are second-order three-point estimates, so the interpolation error
        is O(h^3) in the node spacing h.
    """
    h = jnp.diff(xs)
    sl = jnp.diff(zs) / h
    d_in = (h[1:] * sl[:-1] + h[:-1] * sl[1:]) / (h[:-1] + h[1:])
    d0 = ((2 * h[0] + h[1]) * sl[0] - h[0] * sl[1]) / (h[0] + h[1])
    dn = ((2 * h[-1] + h[-2]) * sl[-1] - h[-1] * sl[-2]) / (h[-1] + h[-2])
    d = jnp.concatenate([d0[None], d_in, dn[None]])
    i = jnp.clip(jnp.searchsorted(xs, xq, side="right") - 1, 0, xs.shape[0] - 2)
    x0, hh = xs[i], h[i]
    t = (xq - x0) / hh
    h00 = 2 * t**3 - 3 * t**2 + 1
    h10 = t**3 - 2 * t**2 + t
    h01 = -2 * t**3 + 3 * t**2
    h11 = t**3 - t**2
    return h00 * zs[i] + h10 * hh * d[i] + h01 * zs[i + 1] + h11 * hh * d[i + 1]


def discrete_curvature(xs, zs):
    """(n-2,) curvature at interior nodes of a polyline (turning angle over mean segment length), 1/m.

    Positive for a drooping strip (angle below horizontal increasing along the strip).
    """
    ang = jnp.arctan2(-jnp.diff(zs), jnp.diff(xs))
    seg = jnp.hypot(jnp.diff(xs), jnp.diff(zs))
    return jnp.diff(ang) / (0.5 * (seg[:-1] + seg[1:]))


def peirce_b(overhang, chord_angle, areal_mass, g: float = GRAVITY):
    """Peirce's linear-elastica estimate ``B = w L^3 cos(theta/2) / (8 tan theta)`` (N·m).

    ``theta`` is the chord angle clamp→tip below horizontal (rad). At 41.5° this is the ISO
    ``w (L/2)^3`` to within 0.1 %.
    """
    return areal_mass * g * overhang**3 * np.cos(0.5 * chord_angle) / (8.0 * np.tan(chord_angle))


def _as_profiles(profiles) -> list[Profile]:
    out = [p if isinstance(p, Profile) else Profile(np.asarray(p[0], float), np.asarray(p[1], float), float(p[2]))
           for p in profiles]
    if not out:
        raise ValueError("fit_cantilever: no profiles given")
    return out


def initial_guess(profiles: Sequence[Profile], areal_mass: float, law_kind: str = "voce",
                  g: float = GRAVITY) -> list[np.ndarray]:
    """Candidate starting points ``q`` from Peirce's formula on each profile's chord (host).

    For the Voce law: ``B_init`` of 1.5x and 3x the stiffest Peirce estimate, ``kappa0`` at 1/3 and 1x
    a characteristic curvature ``M_clamp / B_peirce`` of the data, ``b_inf = 5 % B_init``.
    """
    b_eq, k_char = [], []
    for p in profiles:
        chord = min(max(float(cantilever.chord_angle(p)), 1e-3), 1.5)
        b = peirce_b(p.overhang, chord, areal_mass, g)
        b_eq.append(b)
        # clamp moment ~ w * L * (mean x): weight of the strip times its mean lever arm
        m_clamp = areal_mass * g * p.overhang * 0.5 * float(p.x[-1])
        k_char.append(m_clamp / b)
    b0, kc = max(b_eq), max(k_char)
    if law_kind == "linear":
        return [np.array([math.log(float(np.median(b_eq)))])]
    logit = math.log(0.05 / 0.95)
    return [np.array([math.log(fb * b0), math.log(fk * kc), logit]) for fb in (1.5, 3.0) for fk in (1.0 / 3.0, 1.0)]


# ---------------------------------------------------------------------------------------------
# The fit
# ---------------------------------------------------------------------------------------------


class _Evaluation(NamedTuple):
    """Host values of one forward solve at ``q``: data residual (mm), its Jacobian, the model's own
    residuals, whether they all met ``max_solver_residual``, and the simulated profiles."""

    r: np.ndarray
    J: np.ndarray
    solver_residual: np.ndarray
    converged: bool
    profiles: list


def _residual_fn(profiles, law_kind, simulate, areal_mass, kw, dtype):
    """``q -> (r, (r, aux))``: data residuals in mm and (stop-gradient) solver residuals + profiles."""
    xs = [jnp.asarray(p.x, dtype) for p in profiles]
    zs = [jnp.asarray(p.z, dtype) for p in profiles]

    def res(q):
        bl = law_from_q(q, law_kind)
        outs = [simulate(bl, overhang=p.overhang, areal_mass=areal_mass, **kw) for p in profiles]
        r = jnp.concatenate([(interp_profile(x, o.x, o.z) - z) / _RES_SCALE for x, o, z in zip(xs, outs, zs)])
        sres = jnp.stack([jnp.asarray(getattr(o, "residual", 0.0), dtype).reshape(()) for o in outs])
        return r, (r, jax.lax.stop_gradient((sres, [(o.x, o.z) for o in outs])))

    return res


def _jacobian(res, q):
    """The jitted ``q -> (J, (r, aux))`` that works for this model.

    Forward mode (three tangents cost little next to the solve, and the forward-only graph is never
    compiled: the compile dominates a fit's wall time); reverse mode where the model defines only
    a custom VJP (forward mode then raises ``TypeError`` while tracing, which ``eval_shape`` finds
    without running a solve).
    """
    fwd = jax.jit(jax.jacfwd(res, has_aux=True))
    try:
        jax.eval_shape(fwd, q)
        return fwd
    except TypeError:
        return jax.jit(jax.jacrev(res, has_aux=True))


def fit_cantilever(
    profiles,
    *,
    areal_mass: float,
    law: str = "voce",
    simulate: Callable | None = None,
    simulate_kwargs: dict | None = None,
    init=None,
    method: str = "trf",
    max_iter: int = 60,
    tol: float = 1e-9,
    prior_weight: float = 1e-4,
    compute_b41_5: bool = True,
    g: float = GRAVITY,
    max_solver_residual: float = 1e-5,
    callback: Callable[[FitProgress], Any] | None = None,
) -> CantileverFit:
    """Fit a bending law to one or more cantilever side profiles of one material (one side).

    Args:
        profiles: sequence of :class:`Profile` or ``(x, z, overhang)`` tuples (m; x increasing from
            the clamp, z negative downwards). Several overhangs constrain the law better.
        areal_mass: kg/m².
        law: ``"voce"`` or ``"linear"``.
        simulate: forward model ``simulate(law, overhang=, areal_mass=, **simulate_kwargs)``
            returning an object with ``x``, ``z`` (m, clamp to tip); default
            ``jaxform.cantilever.simulate``. Must be differentiable with JAX.
        init: a starting bending law (optional; default :func:`initial_guess`, best of several).
        method: ``least_squares`` method, ``"trf"`` (default) or ``"dogbox"`` (both back off from
            a failed evaluation).
        max_iter: largest number of residual evaluations of the optimiser (``max_nfev``).
        tol: ``ftol`` and ``xtol`` of ``least_squares`` (relative cost decrease and step).
        prior_weight: weight of the ridge toward the starting point (mm-equivalent per unit of q).
        compute_b41_5: also simulate the standard 41.5° test with the fitted law.
        g: gravity, m/s² (the SPEC fixes 9.81; the simulation's own gravity must match).
        max_solver_residual: largest acceptable ``residual`` of a forward simulation (relative
            out-of-balance force; the shell cantilever converges to ~1e-7). A trial law whose
            simulation stops above it counts as a failed evaluation (the optimiser backs off);
            at the fitted law it sets ``solver_converged = False`` and a warning.
        callback: called with a :class:`FitProgress` after each optimiser iteration (progress
            display; the fit itself prints nothing).

    Returns:
        :class:`CantileverFit`.
    """
    t0 = time.perf_counter()
    if law not in LAW_KINDS:
        raise ValueError(f"fit_cantilever: law = {law!r}: must be 'voce' or 'linear'")
    if method not in ("trf", "dogbox"):
        raise ValueError(f"fit_cantilever: method = {method!r}: must be 'trf' or 'dogbox'")
    profiles = _as_profiles(profiles)
    kw = dict(simulate_kwargs or {})
    dtype = jnp.result_type(float)  # float64 when x64 is on
    n_data = sum(int(p.x.size) for p in profiles)
    res = _residual_fn(profiles, law, simulate or cantilever.simulate, areal_mass, kw, dtype)
    cands = [q_from_law(init, law)] if init is not None else initial_guess(profiles, areal_mass, law, g)
    jac = _jacobian(res, jnp.asarray(cands[0], dtype))

    @functools.lru_cache(maxsize=len(cands) + 4)
    def evaluate(q: tuple) -> _Evaluation:
        J, (r, (sres, xz)) = jac(jnp.asarray(q, dtype))
        sres = np.asarray(sres, float)
        return _Evaluation(np.asarray(r, float), np.asarray(J, float), sres, bool(np.all(sres <= max_solver_residual)), xz)

    def data_residual(q):
        """The data rows the optimiser sees: ``inf`` where the solve is not an equilibrium (a failed step)."""
        e = evaluate(tuple(np.asarray(q, float).tolist()))
        return e.r if e.converged and np.all(np.isfinite(e.r)) else np.full_like(e.r, np.inf)

    def cost(q):
        r = data_residual(q)
        return float(r @ r)

    q0 = np.asarray(min(cands, key=cost), float)  # the best starting point (each one solve)
    if not np.isfinite(cost(q0)):
        raise RuntimeError("fit_cantilever: the simulation failed (non-finite or not converged) at every "
                           "starting point")
    ridge = prior_weight * np.eye(q0.size)

    def fun(d):
        return np.concatenate([data_residual(q0 + d), prior_weight * d])

    def jacobian(d):
        return np.concatenate([evaluate(tuple((q0 + d).tolist())).J, ridge])

    def report(intermediate_result):  # scipy passes the OptimizeResult to a parameter of this name
        it = intermediate_result
        rmse = _RES_SCALE * math.sqrt(2.0 * float(it.cost) / n_data)
        callback(FitProgress(int(it.nit), int(it.nfev), rmse, law_from_q(jnp.asarray(q0 + it.x, dtype), law)))

    opt = least_squares(fun, np.zeros_like(q0), jac=jacobian, method=method, ftol=tol, xtol=tol,
                        max_nfev=max_iter, callback=report if callback is not None else None)
    q = q0 + opt.x
    final = evaluate(tuple(q.tolist()))  # cached: the optimiser evaluated its last iterate
    n_solves = evaluate.cache_info().misses
    solver_ok = final.converged
    if not solver_ok:  # a safety net: the optimiser accepts only converged points
        warnings.warn(f"fit_cantilever: forward simulation residual {final.solver_residual.max():.2e} > "
                      f"{max_solver_residual:.1e} at the fitted law; the fit is not trustworthy", RuntimeWarning)
    fitted = law_from_q(jnp.asarray(q, dtype), law)
    b41 = float("nan")
    if compute_b41_5:
        b41 = float(cantilever.standard_test(fitted, areal_mass=areal_mass, model=simulate, g=g, **kw).b_41_5)
    return _summarise(profiles, law, q, final, fitted, n_data, prior_weight, dtype, b41,
                      iterations=int(opt.njev), n_simulations=n_solves, n_evaluations=int(opt.nfev),
                      wall_time=time.perf_counter() - t0, converged=bool(opt.status > 0), solver_converged=solver_ok)


def _summarise(profiles, law, q, final: _Evaluation, fitted, n_data, prior_weight, dtype, b41, **counts) -> CantileverFit:
    """Covariance, per-profile residuals, curvature reach and the determined flag at the fitted ``q``."""
    r_data, J_data = final.r * _RES_SCALE, final.J * _RES_SCALE
    p = q.size
    s2 = float(np.dot(r_data, r_data)) / max(n_data - p, 1)
    JtJ = J_data.T @ J_data + (prior_weight * _RES_SCALE) ** 2 * np.eye(p)
    cov_q = s2 * np.linalg.pinv(JtJ)
    phys = np.asarray(_physical(jnp.asarray(q, dtype), law), float)
    T = np.asarray(jax.jacfwd(lambda v: _physical(v, law))(jnp.asarray(q, dtype)), float)
    if law == "linear":
        T = np.nan_to_num(T, nan=0.0, posinf=0.0)
    sig = np.sqrt(np.clip(np.diag(T @ cov_q @ T.T), 0.0, None))
    simulated = [(np.asarray(x, float), np.asarray(z, float)) for x, z in final.profiles]
    bounds = np.cumsum([0] + [prof.x.size for prof in profiles])
    residuals = [r_data[a:b] for a, b in zip(bounds[:-1], bounds[1:])]
    kappa_max = max(float(np.max(np.abs(discrete_curvature(jnp.asarray(x), jnp.asarray(z))))) for x, z in simulated)
    b_inf, m0, kappa0, b_init = (float(v) for v in phys)
    if law == "linear":
        m0, kappa0 = 0.0, float("nan")
        ratio, determined = float("nan"), True
    else:
        ratio = kappa_max / kappa0
        rel = sig[0] / b_inf if b_inf > 0 else np.inf
        determined = bool(ratio >= DETERMINED_RATIO and rel < 0.25)
    return CantileverFit(
        law=fitted, law_kind=law, b_inf=b_inf, m0=m0, kappa0=kappa0, b_init=b_init,
        sigma={"b_inf": float(sig[0]), "m0": float(sig[1]), "kappa0": float(sig[2]) if law != "linear" else float("nan"),
               "b_init": float(sig[3])},
        covariance=cov_q, rmse=math.sqrt(float(np.mean(r_data**2))),
        rmse_per_profile=np.asarray([math.sqrt(float(np.mean(rr**2))) for rr in residuals]), kappa_max=kappa_max,
        kappa_max_over_kappa0=ratio, b_inf_determined=determined, b_41_5=b41, simulated=simulated,
        residuals=residuals, solver_residual=final.solver_residual, **counts)


__all__ = ["Profile", "CantileverFit", "FitProgress", "interp_profile", "discrete_curvature", "peirce_b",
           "initial_guess", "fit_cantilever"]
