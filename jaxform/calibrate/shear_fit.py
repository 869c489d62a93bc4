"""Shear-law fits to picture-frame data, and the check of a fitted law on the shell's frame.

Odd polynomial ``F(g) = sum_i c_i g^i`` (i = 1..n) by linear least squares subject to
``dF/dg >= 0`` on a dense grid of the fitted range (SLSQP); optionally the NCF form, yarn
polynomial (monotone) plus a positive-only stitch hat ``(g_a, 0) - (g_p, f_p) - (g_b, 0)`` whose
knots are found by an outer Nelder–Mead search around the inner constrained least squares. (The
stitch term drops after its peak — stitch rupture — so the constraint applies to the yarn part.)
SI units: shear angle rad, normalised shear force N/m, frame side m.
"""
from __future__ import annotations

import dataclasses
from typing import Any

import jax.numpy as jnp
import numpy as np
from scipy.optimize import minimize

from jaxform import frame_tests
from jaxform.materials import PolynomialShear, ncf_shear


@dataclasses.dataclass(frozen=True)
class ShearFit:
    """Result of :func:`fit_shear_polynomial` / :func:`fit_shear_ncf`.

    Attributes:
        law: the fitted shear law (``PolynomialShear`` or the NCF ``CompositeShear``).
        kind: ``"polynomial"`` or ``"ncf"``.
        coeffs: (n,) polynomial (yarn) coefficients of g^1..g^n, N/m.
        stitch_gamma_knots, stitch_force_knots: (3,) rad, N/m (NCF only, else None).
        gamma_range: (2,) fitted range, rad.
        rmse: RMS force residual, N/m.
        monotone: whether the (yarn) polynomial is non-decreasing on the range (checked densely).
        scatter: the data's own scatter, N/m (robust estimate from each point's deviation from the
            line through its neighbours in gamma; :func:`data_scatter`).
        converged: whether the fit is one to use: the optimiser finished, the requested
            non-decreasing constraint holds and ``rmse`` is within ``RMSE_OVER_SCATTER`` of the
            scatter (floored at 0.5 % of the peak force). ``False`` comes with ``reason``.
        reason: why ``converged`` is ``False`` ("" otherwise).
    """

    law: Any
    kind: str
    coeffs: np.ndarray
    stitch_gamma_knots: np.ndarray | None
    stitch_force_knots: np.ndarray | None
    gamma_range: tuple
    rmse: float
    monotone: bool
    scatter: float = float("nan")
    converged: bool = True
    reason: str = ""

    def as_dict(self) -> dict:
        d = {"kind": self.kind, "coeffs_N_per_m": [float(c) for c in self.coeffs],
             "gamma_range_rad": [float(v) for v in self.gamma_range], "rmse_N_per_m": self.rmse,
             "monotone": bool(self.monotone), "scatter_N_per_m": float(self.scatter),
             "converged": bool(self.converged), "reason": self.reason}
        if self.stitch_gamma_knots is not None:
            d["stitch_gamma_knots_rad"] = [float(v) for v in self.stitch_gamma_knots]
            d["stitch_force_knots_N_per_m"] = [float(v) for v in self.stitch_force_knots]
        return d


MAX_DEGREE = 9
"""Largest polynomial degree a fit accepts: odd powers of a shear angle up to ~1 rad beyond this
only follow noise (and the least squares is ill-conditioned)."""
RMSE_OVER_SCATTER = 4.0
"""A fit whose rmse exceeds this many times the data's scatter (floored at ``SCATTER_FLOOR`` of the
peak force) does not describe the data and is reported ``converged = False``."""
SCATTER_FLOOR = 0.005


def data_scatter(gamma, force) -> float:
    """Robust scatter (standard deviation) of picture-frame data about a smooth curve, N/m.

    Each interior point (sorted by gamma) is compared with the straight line through its two
    neighbours; for independent noise of deviation ``s`` that difference has variance
    ``s^2 (1 + w^2 + (1 - w)^2)`` (``w`` the interpolation weight); the mean of the scaled squares
    without their largest 5 % (kinks, outliers), over 0.759 (that trimmed mean for Gaussian noise),
    estimates ``s^2``. The mean, not the median, so noise that grows with the force (a relative
    error) counts as much as a fit's rmse does. 0 for fewer than 3 distinct angles.
    """
    order = np.argsort(gamma, kind="stable")
    g, f = np.asarray(gamma, float)[order], np.asarray(force, float)[order]
    if g.size < 3:
        return 0.0
    g0, g1, g2 = g[:-2], g[1:-1], g[2:]
    ok = g2 > g0
    if not np.any(ok):
        return 0.0
    w = (g2[ok] - g1[ok]) / (g2[ok] - g0[ok])
    e = f[1:-1][ok] - (w * f[:-2][ok] + (1.0 - w) * f[2:][ok])
    q = np.sort(e**2 / (1.0 + w**2 + (1.0 - w) ** 2))
    kept = q[: max(1, int(np.ceil(0.95 * q.size)))]
    return float(np.sqrt(np.mean(kept) / 0.759))


def _check_degree(degree, n_angles: int, extra: int, form: str) -> int:
    """``degree`` as an int in ``1..MAX_DEGREE`` with more distinct angles than unknowns."""
    if isinstance(degree, bool) or not isinstance(degree, (int, np.integer)) or not 1 <= degree <= MAX_DEGREE:
        raise ValueError(f"shear fit: degree = {degree!r}: must be an integer from 1 to {MAX_DEGREE} "
                         "(odd polynomial without a constant term; 7 suits woven data, 5 the NCF yarn part)")
    unknowns = int(degree) + extra
    if n_angles <= unknowns:
        raise ValueError(
            f"shear fit: {n_angles} distinct shear angles for {unknowns} unknowns (the {form} form of degree "
            f"{degree}{' has 4 more: the stitch peak and 3 knots' if extra else ''}); the fit needs more points than "
            f"unknowns — use degree <= {max(n_angles - 1 - extra, 0)} or more data"
        )
    return int(degree)


def _verdict(gamma, force, rmse, *, monotone_wanted, monotone, solver_ok, solver_message) -> tuple[float, bool, str]:
    """``(scatter, converged, reason)`` of a finished fit."""
    scatter = data_scatter(gamma, force)
    allowed = RMSE_OVER_SCATTER * max(scatter, SCATTER_FLOOR * float(np.max(np.abs(force))))
    reasons = []
    if not solver_ok:
        reasons.append(f"the optimiser stopped without converging ({solver_message})")
    if monotone_wanted and not monotone:
        reasons.append("the non-decreasing constraint could not be met (dF/dg < 0 on part of the range): "
                       "try a lower degree, or check the data for a drop")
    if not np.isfinite(rmse) or rmse > allowed:
        reasons.append(f"rmse {rmse:.4g} N/m is far above the data's scatter {scatter:.3g} N/m (allowed "
                       f"{allowed:.3g} N/m): the fitted law does not follow the data — try another degree or form")
    return scatter, not reasons, "; ".join(reasons)


def _check_shear_data(gamma, force):
    gamma = np.asarray(gamma, float).ravel()
    force = np.asarray(force, float).ravel()
    if gamma.shape != force.shape or gamma.size < 3:
        raise ValueError(f"shear fit: gamma {gamma.shape} and force {force.shape} must be 1-D of equal length >= 3")
    if not (np.all(np.isfinite(gamma)) and np.all(np.isfinite(force))):
        raise ValueError("shear fit: gamma and force must be finite")
    if np.max(np.abs(gamma)) > 1.5:
        raise ValueError(
            f"shear fit: |gamma| reaches {np.max(np.abs(gamma)):.3g} rad (> 1.5 rad = 86°): give the shear angle "
            "in radians (jaxform is SI)"
        )
    return gamma, force


def _constrained_lsq(A, y, C, n_free_sign: int = 0):
    """min |A c - y|^2 subject to C c >= 0 (SLSQP on column-scaled variables) → ``(c, ok, message)``."""
    scale = np.linalg.norm(A, axis=0)
    scale[scale == 0] = 1.0
    As = A / scale
    Cs = C / scale if C is not None and C.size else None
    c0, *_ = np.linalg.lstsq(As, y, rcond=None)
    ynorm = max(float(np.linalg.norm(y)), 1e-300)
    if Cs is None or np.all(Cs @ c0 >= -1e-12 * np.linalg.norm(Cs, axis=1) * np.linalg.norm(c0)):
        return c0 / scale, True, ""

    def f(c):
        r = As @ c - y
        return float(r @ r) / ynorm**2

    def grad(c):
        return 2.0 * As.T @ (As @ c - y) / ynorm**2

    cnorm = np.linalg.norm(Cs, axis=1, keepdims=True)
    Cn = Cs / cnorm
    res = minimize(f, c0, jac=grad, method="SLSQP",
                   constraints=[{"type": "ineq", "fun": lambda c: Cn @ c, "jac": lambda c: Cn}],
                   options={"maxiter": 500, "ftol": 1e-14})
    return res.x / scale, bool(res.success), f"SLSQP: {res.message}"


def _monotone_rows(degree: int, gmax: float, n: int = 1000):
    g = np.linspace(0.0, gmax, n)
    i = np.arange(1, degree + 1)
    return i[None, :] * g[:, None] ** (i[None, :] - 1)  # dF/dg rows


def _is_monotone(c, gmax, force) -> bool:
    """dF/dg >= 0 on [0, gmax] (4000 points; tolerance 1e-4 of the mean slope max|F|/gmax)."""
    slope = _monotone_rows(len(c), gmax, 4000) @ c
    return bool(np.all(slope >= -1e-4 * np.max(np.abs(force)) / gmax))


def fit_shear_polynomial(gamma, force, *, degree: int = 7, monotone: bool = True) -> ShearFit:
    """Fit ``F(g) = sign(g) sum_{i=1}^{degree} c_i |g|^i`` (N/m) to picture-frame data.

    Args:
        gamma: (n,) shear angles, rad (negative values use the odd symmetry).
        force: (n,) normalised shear force, N/m.
        degree: polynomial degree (no constant term), 1 to ``MAX_DEGREE``, below the number of
            distinct angles.
        monotone: constrain ``dF/dg >= 0`` on ``[0, max |gamma|]``.

    Raises ``ValueError`` for invalid data or degree. A fit that ran but is not to be used (the
    constraint not met, rmse far above the data's scatter) is returned with ``converged = False``
    and a ``reason``.
    """
    gamma, force = _check_shear_data(gamma, force)
    degree = _check_degree(degree, np.unique(np.abs(gamma)).size, 0, "polynomial")
    a, s = np.abs(gamma), np.where(gamma < 0, -1.0, 1.0)
    i = np.arange(1, degree + 1)
    A = s[:, None] * a[:, None] ** i[None, :]
    gmax = float(a.max())
    C = _monotone_rows(degree, gmax) if monotone else None
    c, ok, msg = _constrained_lsq(A, force, C)
    law = PolynomialShear(c)
    rmse = float(np.sqrt(np.mean((A @ c - force) ** 2)))
    mono = _is_monotone(c, gmax, force)
    verdict = _verdict(gamma, force, rmse, monotone_wanted=monotone, monotone=mono, solver_ok=ok, solver_message=msg)
    return ShearFit(law, "polynomial", c, None, None, (float(gamma.min()), float(gamma.max())), rmse, mono, *verdict)


def _hat(g, knots):
    """(n,) positive-only hat basis through (k0, 0), (k1, 1), (k2, 0)."""
    k0, k1, k2 = knots
    up = np.where((g >= k0) & (g < k1), (g - k0) / (k1 - k0), 0.0)
    down = np.where((g >= k1) & (g < k2), (k2 - g) / (k2 - k1), 0.0)
    return up + down


def fit_shear_ncf(gamma, force, *, degree: int = 5, monotone: bool = True, knots_init=(0.06, 0.5, 0.75)) -> ShearFit:
    """Fit the NCF form: odd yarn polynomial + positive-only stitch hat (SPEC section 3).

    ``F(g) = sign(g) sum c_i |g|^i + [g >= 0] f_p hat(g; g_a, g_p, g_b)``. For fixed knots the
    problem is linear in ``(c, f_p)`` (solved with the yarn polynomial constrained non-decreasing);
    the knots are found by Nelder–Mead on the residual. Data on both signs of shear separate the
    yarn and stitch terms best; positive-only data work when the stitch loads a part of the range.
    """
    gamma, force = _check_shear_data(gamma, force)
    degree = _check_degree(degree, np.unique(gamma).size, 4, "ncf")
    a, s = np.abs(gamma), np.where(gamma < 0, -1.0, 1.0)
    i = np.arange(1, degree + 1)
    P = s[:, None] * a[:, None] ** i[None, :]
    gmax = float(a.max())
    C_poly = _monotone_rows(degree, gmax) if monotone else np.zeros((0, degree))
    C = np.concatenate([C_poly, np.zeros((C_poly.shape[0], 1))], axis=1)
    C = np.concatenate([C, np.eye(1, degree + 1, degree)], axis=0)  # f_p >= 0

    def knots_of(u):
        # u unconstrained -> 0 <= k0 < k1 < k2 <= gmax (cumulative softplus)
        sp = np.log1p(np.exp(u))
        k = np.cumsum(sp)
        return k * (gmax / max(k[-1], 1e-12)) if k[-1] > gmax else k

    def solve(u):
        k = knots_of(u)
        A = np.concatenate([P, np.where(gamma >= 0, _hat(gamma, k), 0.0)[:, None]], axis=1)
        c, ok, msg = _constrained_lsq(A, force, C)
        r = A @ c - force
        return float(r @ r), c, k, ok, msg

    def inv_softplus(v):
        return np.log(np.expm1(max(v, 1e-6)))

    k0 = np.asarray(knots_init, float)
    u0 = np.array([inv_softplus(k0[0]), inv_softplus(k0[1] - k0[0]), inv_softplus(k0[2] - k0[1])])
    best = minimize(lambda u: solve(u)[0], u0, method="Nelder-Mead",
                    options={"xatol": 1e-6, "fatol": 1e-10 * float(force @ force), "maxiter": 2000})
    _, c, k, ok, msg = solve(best.x)
    if not best.success:
        ok, msg = False, f"Nelder-Mead on the stitch knots: {best.message}" + (f"; {msg}" if msg else "")
    coeffs, fp = c[:degree], float(c[degree])
    law = ncf_shear(coeffs, k, [0.0, fp, 0.0])
    pred = np.asarray(law.force(jnp.asarray(gamma)))
    rmse = float(np.sqrt(np.mean((pred - force) ** 2)))
    mono = _is_monotone(coeffs, gmax, force)
    verdict = _verdict(gamma, force, rmse, monotone_wanted=monotone, monotone=mono, solver_ok=ok, solver_message=msg)
    return ShearFit(law, "ncf", coeffs, np.asarray(k), np.array([0.0, fp, 0.0]),
                    (float(gamma.min()), float(gamma.max())), rmse, mono, *verdict)


def picture_frame_normalised_force(force, gamma, frame_side):
    """Raw frame force (N) → normalised shear force ``F / (2 L cos(pi/4 - gamma/2))`` (N/m).

    ``L`` is the frame side (pin to pin), m. This normalisation makes ``F_norm`` power-conjugate
    to ``gamma`` per unit current area of a fabric filling the frame.
    """
    return np.asarray(force, float) / (2.0 * frame_side * np.cos(0.25 * np.pi - 0.5 * np.asarray(gamma, float)))


def picture_frame_shear_angle(displacement, frame_side):
    """Shear angle (rad) from the crosshead displacement ``d`` (m): ``pi/2 - 2 arccos(1/sqrt2 + d/(2L))``."""
    d = np.asarray(displacement, float)
    return 0.5 * np.pi - 2.0 * np.arccos(np.sqrt(0.5) + d / (2.0 * frame_side))


def check_shear_fit(fit: ShearFit, *, gamma_max: float | None = None, **rig_kwargs) -> dict:
    """Simulate the picture frame (:func:`jaxform.frame_tests.picture_frame`, the shell's rig) with
    the fitted law and compare with the law.

    ``rig_kwargs`` go to the rig (``side``, ``n``, ``n_points``, ...). Returns a dict with the
    simulated and expected normalised force and their largest difference relative to the law's peak.
    """
    gmax = gamma_max if gamma_max is not None else float(fit.gamma_range[1])
    out = frame_tests.picture_frame(fit.law, gamma_max=gmax, **rig_kwargs)
    g = np.asarray(out.gamma, float)
    sim = np.asarray(out.f_norm, float)
    exp = np.asarray(fit.law.force(jnp.asarray(g)))
    scale = max(float(np.max(np.abs(exp))), 1e-12)
    return {"gamma": g, "simulated": sim, "expected": exp, "max_rel_diff": float(np.max(np.abs(sim - exp)) / scale)}


__all__ = ["ShearFit", "MAX_DEGREE", "data_scatter", "fit_shear_polynomial", "fit_shear_ncf", "picture_frame_normalised_force",
           "picture_frame_shear_angle", "check_shear_fit"]
