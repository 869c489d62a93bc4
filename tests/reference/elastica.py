"""Independent reference solutions for the cantilever, bias-extension and picture-frame tests.

numpy/scipy only. This module shares no code with ``jaxform`` (it must never import it): it is the
yardstick the shell and the calibration are measured against. SI units throughout: lengths m,
curvature 1/m, moment per unit width N (= N·m/m), bending stiffness N·m, areal mass kg/m²,
normalised shear force N/m, angles rad.

Cantilever (heavy elastica)
---------------------------
A strip of arc length ``L`` (the overhang), clamped horizontally at ``s = 0``, hangs under its own
weight ``w = areal_mass * g`` (N/m² — per unit width, N per m of strip per m of width). With
``theta(s)`` the angle of the tangent *below* the horizontal and ``kappa = dtheta/ds`` (positive
when the strip droops, SPEC section 2 with the ply normal up)::

    x' = cos(theta),   z' = -sin(theta)               (z negative downwards)
    M(kappa(s)) = m(s) = ∫_s^L w (x(s') - x(s)) ds'    (moment of the weight beyond s)
    =>  m' = -w (L - s) cos(theta),  m(L) = 0,  theta(0) = 0,  x(0) = z(0) = 0.

Two independent numerical methods solve this two-point problem:

* ``method="shooting"`` (default): state ``(theta, m, x, z)`` integrated with ``solve_ivp``
  (DOP853, ``rtol`` ~1e-12) from the clamp, ``kappa = M^-1(m)`` by a scalar safeguarded Newton
  solve (warm-started), and the clamp moment ``m(0)`` found by ``brentq`` such that ``m(L) = 0``.
  ``m(0) = w L^2 / 2`` (the horizontal strip's, the largest possible) always leaves ``m(L) >= 0``,
  so the bracket's upper end is guaranteed.
* ``method="bvp"``: ``scipy.integrate.solve_bvp`` (collocation) on ``(theta, m, x, z)`` with
  ``kappa = M^-1(m)`` found by a vectorised safeguarded Newton/bisection solve of the monotone law.

Bias extension and picture frame
--------------------------------
Closed-form kinematics of the pin-jointed net (inextensible fibres, rotation at the crossovers)
and the force from a normalised shear-force law ``F_norm(gamma)`` (N/m) by virtual work, with the
convention that ``F_norm`` is power-conjugate to ``gamma`` per unit *current* area: the power of
shearing an area ``A0`` (initial) is ``A0 cos(gamma) F_norm(gamma) dgamma/dt``. Under that
convention the classical picture-frame normalisation ``F_norm = F / (2 L cos(phi))`` holds exactly
(see :func:`picture_frame_force`).
"""
from __future__ import annotations

import math
from typing import Callable

import numpy as np
from scipy.integrate import solve_bvp, solve_ivp
from scipy.optimize import brentq

GRAVITY = 9.81  # m/s², SPEC section 6
PEIRCE_ANGLE = math.radians(41.5)  # BS EN ISO 9073-7 / Peirce: chord clamp-to-tip below horizontal


# ---------------------------------------------------------------------------------------------
# Moment laws (numpy callables; odd in kappa)
# ---------------------------------------------------------------------------------------------


class MomentLaw:
    """A monotone bending law ``M(kappa)`` (N for kappa in 1/m) with its stiffness ``dM/dkappa`` (N·m).

    Callable: ``law(kappa) -> M``. ``law.stiffness(kappa) -> B``. ``law.inverse(m) -> kappa``
    (vectorised safeguarded Newton/bisection; the law must be strictly increasing).
    """

    def __init__(self, moment: Callable, stiffness: Callable, name: str = "law", b_init: float | None = None):
        self._moment = moment
        self._stiffness = stiffness
        self.name = name
        self.b_init = float(stiffness(np.float64(0.0))) if b_init is None else float(b_init)

    def __call__(self, kappa):
        return self._moment(np.asarray(kappa, dtype=np.float64))

    def stiffness(self, kappa):
        return self._stiffness(np.asarray(kappa, dtype=np.float64))

    def inverse(self, m, *, rtol: float = 1e-14, max_iter: int = 200):
        """Curvature (1/m) at which the law's moment equals ``m`` (N); any shape."""
        return invert_moment(self, m, rtol=rtol, max_iter=max_iter)

    def __repr__(self) -> str:
        return f"MomentLaw({self.name})"


def linear_moment(b: float) -> MomentLaw:
    """``M = b kappa`` (b in N·m)."""
    b = float(b)
    if not b > 0:
        raise ValueError(f"linear_moment: b = {b}: must be > 0 (N·m)")
    law = MomentLaw(lambda k: b * k, lambda k: b * np.ones_like(k), name=f"linear(b={b:g})", b_init=b)
    law.linear = True  # one equilibrium: the shooting needs no scan
    return law


def voce_moment(b_inf: float, m0: float, kappa0: float) -> MomentLaw:
    """``M = b_inf k + sign(k) m0 (1 - exp(-|k|/kappa0))`` (b_inf N·m, m0 N, kappa0 1/m)."""
    b_inf, m0, kappa0 = float(b_inf), float(m0), float(kappa0)
    if b_inf < 0 or m0 < 0 or not kappa0 > 0 or b_inf + m0 / kappa0 <= 0:
        raise ValueError(f"voce_moment: b_inf={b_inf}, m0={m0}, kappa0={kappa0}: need b_inf, m0 >= 0, kappa0 > 0")

    def moment(k):
        return b_inf * k + np.sign(k) * m0 * -np.expm1(-np.abs(k) / kappa0)

    def stiffness(k):
        return b_inf + m0 / kappa0 * np.exp(-np.abs(k) / kappa0)

    return MomentLaw(moment, stiffness, name=f"voce(b_inf={b_inf:g}, m0={m0:g}, kappa0={kappa0:g})",
                     b_init=b_inf + m0 / kappa0)


def as_moment_law(moment_or_b) -> MomentLaw:
    """A :class:`MomentLaw` from a law, a number (linear stiffness, N·m) or a plain callable."""
    if isinstance(moment_or_b, MomentLaw):
        return moment_or_b
    if np.isscalar(moment_or_b):
        return linear_moment(moment_or_b)
    if callable(moment_or_b):
        f = moment_or_b
        stiff = getattr(f, "stiffness", None)
        if stiff is None:
            def stiff(k):  # central difference; adequate for smooth laws
                k = np.asarray(k, dtype=np.float64)
                h = 1e-6 * np.maximum(np.abs(k), 1.0)
                return (f(k + h) - f(k - h)) / (2 * h)
        return MomentLaw(f, stiff, name=getattr(f, "__name__", "callable"))
    raise TypeError(f"expected a moment law, a callable or a stiffness in N·m, got {moment_or_b!r}")


def invert_moment(law: MomentLaw, m, *, rtol: float = 1e-14, max_iter: int = 200):
    """Vectorised safeguarded Newton (falls back to bisection) for ``law(kappa) = m``."""
    m = np.asarray(m, dtype=np.float64)
    sgn = np.where(m < 0, -1.0, 1.0)
    target = np.abs(m)
    # Bracket [0, hi] on |kappa| (odd law): grow hi until M(hi) >= target.
    lo = np.zeros_like(target)
    hi = np.where(target > 0, target / law.b_init, 0.0) + 1e-300
    for _ in range(200):
        short = law(hi) < target
        if not np.any(short):
            break
        hi = np.where(short, 2.0 * hi, hi)
    else:
        raise ValueError(f"invert_moment: {law!r} never reaches moment {float(target.max())} N (saturating law)")
    k = np.where(target > 0, np.minimum(target / law.b_init, hi), 0.0)
    for _ in range(max_iter):
        f = law(k) - target
        lo = np.where(f <= 0, np.maximum(lo, k), lo)
        hi = np.where(f >= 0, np.minimum(hi, k), hi)
        step = f / law.stiffness(k)
        k_new = k - step
        bad = ~((k_new > lo) & (k_new < hi)) | ~np.isfinite(k_new)
        k_new = np.where(bad, 0.5 * (lo + hi), k_new)
        done = np.abs(k_new - k) <= rtol * np.maximum(np.abs(k_new), 1e-300)
        k = k_new
        if np.all(done | (target == 0)):
            break
    return sgn * np.where(target > 0, k, 0.0)


# ---------------------------------------------------------------------------------------------
# The heavy elastica
# ---------------------------------------------------------------------------------------------


def _check(overhang, areal_mass, g):
    for name, v in (("overhang", overhang), ("areal_mass", areal_mass), ("g", g)):
        if not (np.isfinite(v) and v > 0):
            raise ValueError(f"solve_cantilever: {name} = {v}: must be finite and > 0")


def _invert_scalar(law: MomentLaw, m: float, k: float, rtol: float = 1e-15) -> float:
    """Scalar safeguarded Newton for ``law(k) = m`` from the warm start ``k``."""
    if m == 0.0:
        return 0.0
    sgn = 1.0 if m > 0 else -1.0
    target, k = abs(m), abs(k)
    lo, hi = 0.0, math.inf
    for _ in range(100):
        f = float(law(k)) - target
        if f <= 0:
            lo = max(lo, k)
        if f >= 0:
            hi = min(hi, k)
        if f == 0.0:
            break
        k_new = k - f / float(law.stiffness(k))
        if not (lo < k_new < hi) or not math.isfinite(k_new):
            k_new = 0.5 * (lo + hi) if math.isfinite(hi) else 2.0 * max(k, target / law.b_init)
        if abs(k_new - k) <= rtol * abs(k_new):
            k = k_new
            break
        k = k_new
    return sgn * k


def _shoot(law: MomentLaw, L: float, w: float, rtol: float):
    """Shooting on the clamp moment ``m(0)``, state ``(theta, m, x, z)``, ``kappa = M^-1(m)``.

    ``m(L) >= 0`` at ``m(0) = w L^2/2`` for any shape (``cos(theta) <= 1``), so the bracket's upper
    end always holds; the lower end is found by halving ``m(0)`` until the tip moment is negative.
    """
    m_max = 0.5 * w * L**2
    last = [0.0]

    def kappa_of(m):
        last[0] = _invert_scalar(law, m, last[0])
        return last[0]

    def rhs(s, y):
        theta, m = y[0], y[1]
        c = math.cos(theta)
        return [kappa_of(m), -w * (L - s) * c, c, -math.sin(theta)]

    atol = [rtol * 1e-2, rtol * 1e-2 * m_max, rtol * 1e-2 * L, rtol * 1e-2 * L]

    def run(m0, t_eval=None):
        last[0] = float(law.inverse(m0))
        return solve_ivp(rhs, (0.0, L), [0.0, m0, 0.0, 0.0], method="DOP853", rtol=rtol, atol=atol,
                         t_eval=t_eval)

    def miss(mu, tol=None):
        sol = run(mu * m_max) if tol is None else solve_ivp(
            rhs, (0.0, L), [0.0, mu * m_max, 0.0, 0.0], method="DOP853", rtol=tol, atol=[a * tol / rtol for a in atol])
        return sol.y[1, -1] / m_max  # tip moment, should be 0

    if getattr(law, "linear", False):
        hi, lo = 1.0, 0.5
        while miss(lo) > 0:
            hi, lo = lo, 0.5 * lo
            if lo < 1e-12:
                raise RuntimeError("solve_cantilever: could not bracket the clamp moment")
        brackets = [(lo, hi)]
    else:
        # A softening law may allow several equilibria: scan the clamp moment for every sign change.
        grid = np.unique(np.concatenate([np.geomspace(1e-6, 0.02, 8), np.linspace(0.02, 1.0, 50)]))
        vals = np.array([miss(mu, 1e-7) for mu in grid])
        idx = np.nonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))[0]
        if idx.size == 0:
            raise RuntimeError("solve_cantilever: could not bracket the clamp moment")
        brackets = [(grid[i], grid[i + 1]) for i in idx]
    roots = [brentq(miss, lo, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=200) for lo, hi in brackets]
    return [mu * m_max for mu in roots], run


def _potential_energy(law: MomentLaw, sol, w: float) -> float:
    """Total potential energy per unit width (J/m) of a sampled equilibrium: bending + gravity."""
    kappa = law.inverse(sol.y[1])
    s = sol.t
    # Stored energy density ∫_0^kappa M dk by Gauss-Legendre on each node's curvature.
    xg, wg = np.polynomial.legendre.leggauss(16)
    kq = 0.5 * kappa[:, None] * (xg[None, :] + 1.0)
    stored = 0.5 * kappa * np.sum(wg[None, :] * law(kq), axis=1)
    from scipy.integrate import simpson
    return float(simpson(stored, x=s) + w * simpson(sol.y[3], x=s))


def solve_cantilever(moment, overhang: float, areal_mass: float, g: float = GRAVITY, n: int = 201,
                     *, rtol: float = 1e-12, method: str = "shooting", branch: str = "least_droop") -> dict:
    """Large-deflection inextensible elastica of a strip hanging under its own weight.

    Args:
        moment: bending law ``M(kappa)`` per unit width (a :class:`MomentLaw`, a callable, or a
            number = linear stiffness in N·m).
        overhang: arc length ``L`` of the free strip, m.
        areal_mass: kg/m² (weight per area ``w = areal_mass * g``).
        g: gravity, m/s².
        n: number of output points, uniform in arc length from clamp to tip.
        rtol: ODE / collocation tolerance.
        method: ``"shooting"`` (solve_ivp + brentq) or ``"bvp"`` (solve_bvp), independent methods.
        branch: strongly softening laws (Voce with a small ``b_inf``) can hold a long strip in
            several equilibria (``n_solutions`` in the result). ``"least_droop"`` (default) is the
            one with the largest clamp moment, reached by ramping gravity from a flat strip or by
            sliding the strip out (the standard test); ``"most_droop"`` the other extreme;
            ``"min_energy"`` the global minimum of bending + gravitational energy. Linear laws have
            one equilibrium. (``bvp`` finds one equilibrium by load continuation.)

    Returns:
        dict of numpy arrays, clamp to tip, shape (n,): ``s`` (m), ``x`` (m), ``z`` (m, <= 0),
        ``theta`` (rad below horizontal), ``kappa`` (1/m), ``moment`` (N); scalars ``tip_angle``
        (rad, = theta(L)), ``chord_angle`` (rad, chord clamp→tip below horizontal),
        ``clamp_moment`` (N), ``n_solutions`` (equilibria found).
    """
    _check(overhang, areal_mass, g)
    law = as_moment_law(moment)
    L, w = float(overhang), float(areal_mass) * float(g)
    s = np.linspace(0.0, L, int(n))
    if method == "shooting":
        m0s, run = _shoot(law, L, w, rtol)
        # Several equilibria (strongly softening laws): pick one branch.
        m0s.sort(reverse=True)  # least droop (largest clamp moment) first
        if branch == "least_droop":
            m0 = m0s[0]
        elif branch == "most_droop":
            m0 = m0s[-1]
        elif branch == "min_energy":
            dense = np.linspace(0.0, L, 2001)
            m0 = min(m0s, key=lambda m0: _potential_energy(law, run(m0, dense), w))
        else:
            raise ValueError(f"solve_cantilever: branch = {branch!r}: least_droop, most_droop or min_energy")
        n_solutions = len(m0s)
        theta, m, x, z = run(m0, s).y
        kappa = law.inverse(m)
    elif method == "bvp":
        theta, kappa, x, z, m = _bvp(law, L, w, rtol, s)
        n_solutions = 1
    else:
        raise ValueError(f"solve_cantilever: method = {method!r}: must be 'shooting' or 'bvp'")
    return {
        "s": s, "x": x, "z": z, "theta": theta, "kappa": kappa, "moment": m,
        "tip_angle": float(theta[-1]),
        "chord_angle": float(math.atan2(-z[-1], x[-1])),
        "clamp_moment": float(m[0]),
        "n_solutions": n_solutions,
    }


def _bvp(law: MomentLaw, L: float, w: float, tol: float, s_out):
    """Collocation on sigma = s/L in [0, 1] with unknowns theta, m/(w L^2), x/L, z/L.

    Large deflections are reached by continuation in the load (w scaled from small to full), each
    step starting from the previous converged solution.
    """
    scale_m = w * L**2

    def make(lam):
        def f(sig, y):
            theta, mu = y[0], y[1]
            kappa = invert_moment(law, mu * scale_m, rtol=1e-15)
            c, sn = np.cos(theta), np.sin(theta)
            return np.vstack([L * kappa, -lam * (1.0 - sig) * c, c, -sn])
        return f

    def bc(ya, yb):
        return np.array([ya[0], yb[1], ya[2], ya[3]])

    sig = np.linspace(0.0, 1.0, 41)
    y = np.vstack([np.zeros_like(sig), 0.5 * (1.0 - sig) ** 2, sig, np.zeros_like(sig)])
    lams = [1.0]
    res, res_lam = None, 0.0  # the last solved load factor (0: none yet)
    while lams:
        lam = lams[0]
        trial = solve_bvp(make(lam), bc, sig, y, tol=max(tol, 1e-10), bc_tol=1e-13, max_nodes=20000)
        if trial.success:
            res, sig, y = trial, trial.x, trial.y
            lams.pop(0)
        else:
            prev = res_lam
            if lam - prev < 1e-3:
                raise RuntimeError(f"solve_bvp did not converge: {trial.message}")
            lams.insert(0, 0.5 * (prev + lam))
            continue
        res_lam = lam
    ys = res.sol(s_out / L)
    theta, mu, xs, zs = ys
    m = mu * scale_m
    kappa = invert_moment(law, m)
    return theta, kappa, xs * L, zs * L, m


# ---------------------------------------------------------------------------------------------
# The standard cantilever test (Peirce, BS EN ISO 9073-7)
# ---------------------------------------------------------------------------------------------


def small_deflection_tip(b: float, overhang: float, areal_mass: float, g: float = GRAVITY) -> float:
    """Tip deflection (m, positive down) of a uniformly loaded linear cantilever: ``w L^4 / (8 B)``."""
    return areal_mass * g * overhang**4 / (8.0 * b)


def standard_test_b(overhang: float, areal_mass: float, g: float = GRAVITY) -> float:
    """BS EN ISO 9073-7 bending stiffness from the 41.5° overhang: ``c = L/2``, ``B = w c^3`` (N·m)."""
    return areal_mass * g * (0.5 * overhang) ** 3


def peirce_overhang(moment_or_b, areal_mass: float, g: float = GRAVITY, *, angle: float = PEIRCE_ANGLE,
                    rtol: float = 1e-12, branch: str = "least_droop") -> float:
    """Overhang ``L`` (m) at which the chord clamp→tip lies ``angle`` (default 41.5°) below horizontal.

    Found with the shooting solver and ``brentq`` on ``L``. Along the ``least_droop`` branch (the
    strip slid out over the edge, as in the test) the chord angle grows with the overhang; for a
    strongly softening law it can jump where that branch folds: the overhang returned is then the
    fold, where the strip snaps past 41.5° (as the real test would).
    """
    law = as_moment_law(moment_or_b)
    w = areal_mass * g

    def miss(L):
        return solve_cantilever(law, L, areal_mass, g, n=2, rtol=rtol, branch=branch)["chord_angle"] - angle

    # Start from the linear-law estimate with B_init (softening laws droop further: L smaller).
    L_guess = 2.0 * (law.b_init / w) ** (1.0 / 3.0)
    lo, hi = 0.5 * L_guess, 1.5 * L_guess
    while miss(lo) > 0:
        lo *= 0.5
    while miss(hi) < 0:
        hi *= 1.5
    return brentq(miss, lo, hi, xtol=1e-14 * L_guess, rtol=1e-13)


# ---------------------------------------------------------------------------------------------
# Picture frame and bias extension (pin-jointed net)
# ---------------------------------------------------------------------------------------------


def picture_frame_shear_angle(d, frame_side: float):
    """Shear angle (rad) of a picture frame of side ``L`` (pin to pin) pulled by ``d`` (m) along a diagonal.

    The frame is a rhombus of side ``L``; with ``phi`` the half-angle between two frame sides at the
    loaded corner (``phi = pi/4`` for the square) the loaded diagonal is ``2 L cos(phi)``, so
    ``2 L cos(phi) = sqrt(2) L + d`` and ``gamma = pi/2 - 2 phi``::

        gamma = pi/2 - 2 arccos(1/sqrt(2) + d / (2 L))

    (Equivalent to ``gamma = pi/2 - 2 arccos((sqrt(2) L + d) / (2 L))``.)
    """
    d = np.asarray(d, dtype=np.float64)
    return 0.5 * np.pi - 2.0 * np.arccos(np.sqrt(0.5) + d / (2.0 * frame_side))


def picture_frame_displacement(gamma, frame_side: float):
    """Inverse of :func:`picture_frame_shear_angle`: ``d = 2 L cos(pi/4 - gamma/2) - sqrt(2) L`` (m)."""
    gamma = np.asarray(gamma, dtype=np.float64)
    return 2.0 * frame_side * np.cos(0.25 * np.pi - 0.5 * gamma) - np.sqrt(2.0) * frame_side


def picture_frame_force(f_norm, gamma, frame_side: float):
    """Crosshead force (N) of a picture frame of side ``L`` at shear angle ``gamma``.

    Virtual work with the fabric filling the frame (area ``L^2`` initially, ``L^2 cos(gamma)``
    current): ``F dd = L^2 cos(gamma) F_norm(gamma) dgamma`` and ``dd/dgamma = L sin(phi)`` give::

        F = 2 L cos(phi) F_norm(gamma),   phi = pi/4 - gamma/2

    i.e. the classical normalisation ``F_norm = F / (2 L cos(phi))`` (force per unit frame length).

    Args:
        f_norm: normalised shear force, N/m — a callable of ``gamma`` or an array matching it.
        gamma: shear angle(s), rad.
        frame_side: ``L``, m.
    """
    gamma = np.asarray(gamma, dtype=np.float64)
    fn = f_norm(gamma) if callable(f_norm) else np.asarray(f_norm, dtype=np.float64)
    phi = 0.25 * np.pi - 0.5 * gamma
    return 2.0 * frame_side * np.cos(phi) * fn


def picture_frame_normalised_force(force, gamma, frame_side: float):
    """Inverse of :func:`picture_frame_force`: ``F_norm = F / (2 L cos(pi/4 - gamma/2))`` (N/m)."""
    gamma = np.asarray(gamma, dtype=np.float64)
    return np.asarray(force, dtype=np.float64) / (2.0 * frame_side * np.cos(0.25 * np.pi - 0.5 * gamma))


def bias_extension_shear_angle(d, length: float, width: float):
    """Shear angle (rad) of the central zone A of a bias-extension specimen (fibres at ±45°).

    Pin-jointed net, inextensible fibres, no slip. Between the clamps (free length ``H = length``,
    width ``W``, ``H >= 2 W``) three zones form: C (triangles at the clamps, undeformed), B
    (half-shear) and A (the central zone, pure shear). A fibre through a point of the centreline at
    height ``y`` reaches a free edge after an axial distance ``W/2``; the point is in A when neither
    fibre reaches a clamp, so on the centreline A spans ``W/2 <= y <= H - W/2``: its axial length is
    ``D = H - W``. The centreline crosses only C (rigid) and A, so the whole clamp displacement
    ``d`` stretches A's axial length from ``D`` to ``D + d``. In A the fibres form rhombi of fixed
    side whose axial diagonal is ``2 a cos(phi)`` (``phi``: half-angle between the fibres, about the
    loading axis; ``pi/4`` initially), hence ``(D + d)/D = sqrt(2) cos(phi)`` and::

        gamma_A = pi/2 - 2 arccos((D + d) / (sqrt(2) D)),   gamma_B = gamma_A / 2.
    """
    d = np.asarray(d, dtype=np.float64)
    D = length - width
    if not D > 0:
        raise ValueError(f"bias_extension_shear_angle: length {length} must exceed width {width}")
    return 0.5 * np.pi - 2.0 * np.arccos((D + d) / (np.sqrt(2.0) * D))


def bias_extension_displacement(gamma, length: float, width: float):
    """Inverse of :func:`bias_extension_shear_angle`: ``d = D (sqrt(2) cos(pi/4 - gamma/2) - 1)`` (m)."""
    gamma = np.asarray(gamma, dtype=np.float64)
    D = length - width
    return D * (np.sqrt(2.0) * np.cos(0.25 * np.pi - 0.5 * gamma) - 1.0)


def bias_extension_zone_areas(length: float, width: float):
    """Initial areas (m²) of zones A, B, C: ``W (H - 3W/2)``, ``W^2``, ``W^2 / 2`` (sum ``H W``)."""
    if length < 2.0 * width:
        raise ValueError(f"bias_extension_zone_areas: needs length >= 2 width (got {length}, {width})")
    return width * (length - 1.5 * width), width**2, 0.5 * width**2


def bias_extension_force(f_norm: Callable, gamma, length: float, width: float):
    """Clamp force (N) of a bias-extension test at central shear angle ``gamma`` for a law ``F_norm``.

    Virtual work (same convention as :func:`picture_frame_force`): zone A shears by ``gamma``,
    zone B by ``gamma/2``::

        F dd/dgamma = A_A cos(g) F_norm(g) + A_B cos(g/2) F_norm(g/2) / 2,
        dd/dgamma   = D sin(phi) / sqrt(2),   phi = pi/4 - g/2,  D = H - W.
    """
    gamma = np.asarray(gamma, dtype=np.float64)
    a_a, a_b, _ = bias_extension_zone_areas(length, width)
    D = length - width
    phi = 0.25 * np.pi - 0.5 * gamma
    power = a_a * np.cos(gamma) * f_norm(gamma) + a_b * np.cos(0.5 * gamma) * f_norm(0.5 * gamma) * 0.5
    return power / (D * np.sin(phi) / np.sqrt(2.0))


__all__ = [
    "GRAVITY", "PEIRCE_ANGLE", "MomentLaw", "linear_moment", "voce_moment", "as_moment_law",
    "invert_moment", "solve_cantilever", "small_deflection_tip", "standard_test_b", "peirce_overhang",
    "picture_frame_shear_angle", "picture_frame_displacement", "picture_frame_force",
    "picture_frame_normalised_force", "bias_extension_shear_angle", "bias_extension_displacement",
    "bias_extension_zone_areas", "bias_extension_force",
]
