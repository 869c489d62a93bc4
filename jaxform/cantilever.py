"""The cantilever bending test, solved with the fabric shell (the same element as every other run).

A strip of arc length ``overhang`` (m), width ``width`` and areal mass ``areal_mass`` (kg/m²) is
clamped horizontally at ``x = 0`` (ply normal up) and hangs under gravity (9.81 m/s²). The static
equilibrium minimises ``E_shell(x) - sum_i m_i g . x_i`` over the free nodes. It is found by Newton's
method on that energy (dense Hessian: the strip has a few hundred unknowns), with the gravity
applied in ``load_steps`` increments, each followed by ``newton_iters`` Newton iterations
(Levenberg-regularised by a tiny multiple of the Hessian's diagonal to pass the zero shear
stiffness of the flat fabric). The clamp holds the first two rows of nodes (``x = -h`` and
``x = 0``): zero slope at the clamp edge.

Gradients (``jax.grad`` w.r.t. the law's parameters, the fibre modulus, ...) use the implicit
function theorem at the converged equilibrium ``g(u*, p) = 0``: the returned positions are
``u* - H^-1 g(u*, p)`` with ``u*`` and ``H`` held constant, whose value is ``u*`` and whose
derivative is ``-H^-1 dg/dp``, exactly the IFT, without differentiating through the iterations.

:func:`standard_test` reproduces BS EN ISO 9073-7 (Peirce): the overhang at which the chord from
the clamp edge to the tip is 41.5° below the horizontal, the bending length ``c = L/2`` and
``B = w c^3`` with ``w = areal_mass * g`` (N/m²).
"""
from __future__ import annotations

import math
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from jaxform._pytree import pytree_dataclass, static_field
from jaxform.materials import Fabric, PolynomialShear
from jaxform.mesh import Mesh
from jaxform.shell import Shell, energy_parts

GRAVITY = 9.81
PEIRCE_ANGLE = math.radians(41.5)


@pytree_dataclass
class CantileverResult:
    """Side profile of the hanging strip (centre line, clamp edge to tip).

    Attributes:
        x: (n+1,) horizontal positions, m (0 at the clamp edge).
        z: (n+1,) vertical positions, m (negative downwards).
        tip_angle: angle of the tip tangent below the horizontal, rad.
        tip_deflection: ``-z`` at the tip, m.
        residual: relative norm of the out-of-balance force at the solution (host check).
        nodes: (N, 3) all node positions, m.
    """

    x: Any
    z: Any
    tip_angle: Any
    tip_deflection: Any
    residual: Any
    nodes: Any


def _strip(overhang, width, n_elements, n_width):
    """Strip mesh with node rows at x = (i - 1/2) h, i = 0..n+1, h = overhang / (n + 1/2).

    The two clamped rows (x = -h/2 and +h/2) make the discrete slope zero exactly at the clamp
    edge x = 0 (their midpoint), and the last row is the tip at x = overhang. Lumped areas (weights
    of mass and bending) cover the overhang 0 <= x <= overhang only.
    """
    h = overhang / (n_elements + 0.5)
    xs = -0.5 * h + h * np.arange(n_elements + 2)
    xs[-1] = overhang
    ys = np.linspace(-0.5 * width, 0.5 * width, n_width + 1)
    mesh = Mesh.grid(xs, ys)
    X = np.asarray(mesh.nodes)
    # trapezoid weights along x over [0, L]: node at h/2 covers [0, h], interior nodes h, tip h/2
    wx = np.full(len(xs), h)
    wx[0] = 0.0
    wx[-1] = 0.5 * h
    wy = np.full(len(ys), width / n_width)
    wy[0] = wy[-1] = 0.5 * width / n_width
    node_area = (wy[:, None] * wx[None, :]).ravel()  # grid node order: y-major rows of x
    mesh = mesh.replace(node_area=node_area)
    free = X[:, 0] > 0.75 * h  # rows at -h/2 and +h/2 are clamped
    centre = np.abs(X[:, 1]) < 1e-12 * width + 1e-15
    line = np.nonzero(centre & (X[:, 0] > 0.0))[0]
    line = line[np.argsort(X[line, 0])]
    return mesh, free, line


def _fabric(bending, cross, areal_mass, thickness, fibre_modulus, shear):
    return Fabric(thickness=thickness, areal_mass=areal_mass, fibre_modulus=fibre_modulus, shear=shear,
                  bending=(bending, cross), name="cantilever-strip", fibre_angles=(0.0, 0.5 * math.pi))


def _energy_fn(shell, X, free_idx, g, alpha=1.0):
    """Total potential energy of the free dofs ``u``; ``alpha`` scales the fibre tension (continuation)."""
    mass = shell.node_masses()

    def total(u):
        x = jnp.asarray(X, u.dtype).at[free_idx].set(u.reshape(-1, 3))
        p = energy_parts(x, shell)
        return alpha * p["tension"] + p["shear"] + p["bending"] + g * jnp.sum(mass * x[:, 2])

    return total


@jax.jit
def _solve(shell, X, free_idx, gs, alphas, iters_arr, step_max):
    """Levenberg-Marquardt Newton (energy-decrease acceptance, trust region) along a continuation path.

    The path (``gs``, ``alphas``) first applies gravity with a softened fibre tension (``alpha`` << 1:
    a well-conditioned problem whose Newton predictor does not fight near-inextensible fibres),
    then stiffens the fibres to their true modulus (``alpha = 1``).
    """
    n_it = iters_arr.shape[0]
    dtype = shell.mesh.gfd.dtype
    u0 = jnp.asarray(X, dtype)[free_idx].reshape(-1)

    def newton(carry, ga):
        u, mu = carry
        E = _energy_fn(shell, X, free_idx, ga[0], ga[1])
        vg = jax.value_and_grad(E)
        hess = jax.jacfwd(jax.grad(E))

        def it(c, _):
            u, mu = c
            e, gr = vg(u)
            H = hess(u)
            d = jnp.abs(jnp.diag(H)) + 1e-12 * jnp.max(jnp.abs(jnp.diag(H)))
            du = jnp.linalg.solve(H + mu * jnp.diag(d), gr)
            du = du * jnp.minimum(1.0, step_max / (jnp.max(jnp.abs(du)) + 1e-30))
            e_new = E(u - du)
            ok = jnp.isfinite(e_new) & (e_new <= e)
            u = jnp.where(ok, u - du, u)
            mu = jnp.where(ok, jnp.maximum(mu * 0.1, 1e-14), jnp.minimum(mu * 10.0, 1e12))
            return (u, mu), None

        (u, mu), _ = jax.lax.scan(it, (u, mu), None, length=n_it)
        return (u, mu), None

    (u, _), _ = jax.lax.scan(newton, (u0, jnp.asarray(1e-6, dtype)), jnp.stack([gs, alphas], axis=1))
    return u


def _path(g, load_steps, alpha0=1e-4, stiffen_steps=4):
    gs = [g * (k + 1) / load_steps for k in range(load_steps)] + [g] * stiffen_steps
    al = [alpha0] * load_steps + [alpha0 ** (1.0 - (k + 1) / stiffen_steps) for k in range(stiffen_steps)]
    return np.asarray(gs), np.asarray(al)


def simulate(bending, *, overhang: float, areal_mass, width: float | None = None, n_elements: int = 20,
             n_width: int = 2, cross_bending=None, thickness=3e-4, fibre_modulus=3.0e9, shear=None,
             g: float = GRAVITY, load_steps: int = 16, newton_iters: int = 25) -> CantileverResult:
    """Solve the hanging strip to rest with the shell; return its side profile and tip angle.

    Args:
        bending: bending law along the strip (``LinearBending``, ``VoceBending``, ``AsymmetricBending``).
        overhang: arc length of the overhanging strip, m.
        areal_mass: kg/m² (may be traced).
        width: strip width, m (default ``overhang / 8``; the profile does not depend on it).
        n_elements: elements along the overhang; ``n_width`` across.
        cross_bending: law of the transverse family (default: the same as ``bending``).
        thickness, fibre_modulus, shear: membrane data (default: 0.3 mm, 3 GPa, a weak linear shear law).
        g: gravity, m/s². load_steps, newton_iters: the Newton continuation.
    """
    overhang = float(overhang)
    if not overhang > 0:
        raise ValueError(f"cantilever.simulate: overhang = {overhang!r} m: must be > 0")
    width = overhang / 8 if width is None else float(width)
    mesh, free, line = _strip(overhang, width, n_elements, n_width)
    shear_default = shear is None
    shear = PolynomialShear([1.0]) if shear is None else shear
    fabric = _fabric(bending, bending if cross_bending is None else cross_bending, areal_mass, thickness,
                     fibre_modulus, shear)
    # the strip's in-plane shear plays no part; a weak linear conjugate shear keeps the flat
    # strip's Hessian regular (the A.14 reading has zero shear stiffness at zero shear)
    shell = Shell.build(mesh, fabric, shear_reading="conjugate" if shear_default else "a14")
    dtype = jnp.float64 if jax.config.jax_enable_x64 else jnp.float32
    shell = jax.tree_util.tree_map(lambda a: jnp.asarray(a, dtype) if jnp.issubdtype(jnp.asarray(a).dtype, jnp.floating) else a, shell)
    X = jnp.asarray(mesh.nodes, dtype)
    free_idx = jnp.asarray(np.nonzero(free)[0])
    gs, alphas = _path(g, load_steps)
    u_star = jax.lax.stop_gradient(
        _solve(jax.lax.stop_gradient(shell), X, free_idx, jnp.asarray(gs, dtype), jnp.asarray(alphas, dtype),
               jnp.zeros(newton_iters), 0.3 * overhang / n_elements)
    )
    return _finish(shell, u_star, X, free_idx, g, jnp.asarray(line))


@jax.jit
def _finish(shell, u_star, X, free_idx, g, line):
    # implicit-function-theorem correction: value u*, derivative -H^-1 dg/dp
    E = _energy_fn(shell, X, free_idx, g)
    E_const = _energy_fn(jax.lax.stop_gradient(shell), X, free_idx, g)
    H = jax.lax.stop_gradient(jax.hessian(E_const)(u_star))
    mu = 1e-9 * jnp.max(jnp.abs(jnp.diag(H)))
    gr = jax.grad(E)(u_star)
    u = u_star - jnp.linalg.solve(H + mu * jnp.eye(H.shape[0], dtype=H.dtype), gr)
    x = X.at[free_idx].set(u.reshape(-1, 3))
    weight = jnp.sum(jax.lax.stop_gradient(shell.node_masses())) * g
    residual = jnp.linalg.norm(jax.lax.stop_gradient(gr)) / weight
    zero = jnp.zeros((1,), x.dtype)  # the clamp edge (0, 0)
    px = jnp.concatenate([zero, x[line, 0]])
    pz = jnp.concatenate([zero, x[line, 2]])
    tip = line[-1]
    # tip tangent from the node's finite-difference stencil (same weights as the bending)
    from jaxform.shell import node_derivatives

    t = node_derivatives(x, shell.mesh)[tip, 0]
    tip_angle = jnp.arctan2(-t[2], t[0])
    return CantileverResult(x=px, z=pz, tip_angle=tip_angle, tip_deflection=-pz[-1], residual=residual, nodes=x)


@pytree_dataclass
class StandardTestResult:
    """BS EN ISO 9073-7 (Peirce 41.5°) result.

    Attributes:
        overhang_41_5: overhang at which the clamp-to-tip chord is 41.5° below horizontal, m.
        bending_length: ``c = overhang_41_5 / 2``, m.
        b_41_5: ``B = w c^3`` with ``w = areal_mass * g``, N·m.
    """

    overhang_41_5: Any
    bending_length: Any
    b_41_5: Any


def chord_angle(result: CantileverResult):
    """Angle of the clamp-edge-to-tip chord below the horizontal, rad."""
    return jnp.arctan2(-result.z[-1], result.x[-1] - result.x[0])


def standard_test(bending, *, areal_mass: float, g: float = GRAVITY, tol: float = 1e-5, max_iter: int = 30,
                  **kwargs) -> StandardTestResult:
    """Find the 41.5° overhang with the shell (secant iterations on the overhang; host loop)."""
    from jaxform.materials import max_stiffness

    w = float(areal_mass) * g
    b0 = float(np.max(np.asarray(max_stiffness(bending))))

    def f(L):
        r = simulate(bending, overhang=L, areal_mass=areal_mass, g=g, **kwargs)
        return float(chord_angle(r)) - PEIRCE_ANGLE

    # bracket: start from Peirce with the initial stiffness (a softening law sags more: shorter)
    L1 = 2.0 * (b0 / w) ** (1.0 / 3.0)
    f1 = f(L1)
    L0 = L1 * (0.8 if f1 > 0 else 1.25)
    f0 = f(L0)
    for _ in range(max_iter):
        L2 = L1 - f1 * (L1 - L0) / (f1 - f0)
        L2 = min(max(L2, 0.5 * L1), 2.0 * L1)
        L0, f0, L1 = L1, f1, L2
        f1 = f(L1)
        if abs(L1 - L0) <= tol * L1:
            break
    c = 0.5 * L1
    return StandardTestResult(overhang_41_5=L1, bending_length=c, b_41_5=w * c**3)


__all__ = ["simulate", "standard_test", "chord_angle", "CantileverResult", "StandardTestResult", "GRAVITY",
           "PEIRCE_ANGLE"]
_ = static_field
