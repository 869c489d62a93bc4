"""The cantilever bending test, solved with the fabric shell (the same element as every other run).

A strip of arc length ``overhang`` (m), width ``width`` and areal mass ``areal_mass`` (kg/m²) is
clamped horizontally at ``x = 0`` (ply normal up) and hangs under gravity (``jaxform.units.GRAVITY``). The static
equilibrium minimises ``E_shell(x) - sum_i m_i g . x_i`` over the free nodes. It is found by the
damped Newton solver of :mod:`jaxform.statics` (dense Hessian: the strip has a few hundred
unknowns) along a load path: gravity applied in ``load_steps`` increments with softened fibres,
then ``stiffen_steps`` increments that restore the fibre modulus, all in one jitted
``lax.while_loop``; the Hessian is assembled from a few gradient JVPs by a distance-2 colouring of
the strip. The clamp holds the first two rows (``x = -e_0/2``
and ``x = +e_0/2``): zero slope at the clamp edge ``x = 0``. The unknowns are the configurations
mirror-symmetric about the strip's centre plane (the planar profile the test measures; the
antisymmetric twist and sway modes have almost no stiffness in this shell, see :func:`_symmetry_basis`).

Mesh: ``n_elements`` along the strip, element lengths growing geometrically from the clamp to the
tip by the factor ``grading`` (default 20). A softening (Voce) law concentrates the curvature at the
clamp: past ``kappa0`` the stiffness drops by ``B_init / B_inf`` (13-40x for the presets), so the
strip turns through most of its angle in the first few millimetres. A uniform mesh under-resolves
that region and the error it makes there rotates the whole tail (measured, Voce ``B_inf`` 2e-5 N·m,
``M0`` 1.5e-3 N, ``kappa0`` 6 /m, 300 g/m², 75 mm, tip 72.5°, clamp curvature 22 ``kappa0``; z-error
at 60 points against the reference elastica, RMS):

    n elements      20        40        80        160
    uniform       2.76 mm   0.83 mm   0.22 mm   0.056 mm   (tip angle -0.82 .. -0.015 deg)
    grading 20    0.18 mm   0.049 mm  0.012 mm  0.0028 mm  (tip angle -0.068 .. -0.001 deg)

Both converge at second order; the graded mesh is about 17x more accurate at equal cost.

Gradients (``jax.grad`` w.r.t. the law's parameters, the fibre modulus, ...) use the implicit
function theorem at the converged equilibrium (:func:`jaxform.statics.implicit`), without
differentiating through the iterations.

:func:`standard_test` reproduces BS EN ISO 9073-7 (Peirce): the overhang at which the chord from
the clamp edge to the tip is 41.5° below the horizontal, the bending length ``c = L/2`` and
``B = w c^3`` with ``w = areal_mass * g`` (N/m²).
"""
from __future__ import annotations

import functools
import math
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from jaxform import statics
from jaxform._pytree import pytree_dataclass
from jaxform.materials import Fabric, PolynomialShear
from jaxform.mesh import Mesh
from jaxform.shell import Shell, energy_parts
from jaxform.units import GRAVITY

PEIRCE_ANGLE = math.radians(41.5)
_DEFAULT_SHEAR = 1.0  # N/m, the strip's in-plane shear (conjugate reading; plays no part in a planar profile)


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
        iterations: Newton iterations the solve took (host check).
    """

    x: Any
    z: Any
    tip_angle: Any
    tip_deflection: Any
    residual: Any
    nodes: Any
    iterations: Any = None

    def __repr__(self) -> str:
        try:
            return (f"CantileverResult(points={len(self.x)}, tip_angle={float(self.tip_angle):.4g} rad, "
                    f"tip_deflection={float(self.tip_deflection):.4g} m)")
        except TypeError:  # traced values inside jit/grad
            return "CantileverResult(traced)"


def _row_positions(overhang, n_elements, grading):
    """Node rows along the strip: ``x_0 = -e_0/2`` (ghost, clamped), ``x_1 = +e_0/2`` (clamped),
    ``x_{k+1} = x_k + e_k`` with geometric element lengths ``e_k = e_0 r^k``, ``r^n = grading``,
    and ``x_{n+1} = overhang`` (the tip). ``grading = 1``: the uniform mesh ``h = overhang/(n + 1/2)``.
    """
    n = int(n_elements)
    q = float(grading)
    if not q > 0:
        raise ValueError(f"cantilever: grading = {grading!r}: must be > 0 (last / first element length)")
    r = q ** (1.0 / n)
    e = r ** np.arange(n + 1)  # e_0 .. e_n (relative)
    e0 = overhang / (0.5 * e[0] + np.sum(e[1:]))
    xs = np.concatenate([[-0.5 * e0, 0.5 * e0], 0.5 * e0 + e0 * np.cumsum(e[1:])])
    xs[-1] = overhang
    return xs


def _strip(overhang, width, n_elements, n_width, grading=1.0):
    """Strip mesh with node rows ``xs`` from :func:`_row_positions` (graded toward the clamp).

    The two clamped rows (x = -e_0/2 and +e_0/2) make the discrete slope zero exactly at the clamp
    edge x = 0 (their midpoint), and the last row is the tip at x = overhang. Lumped areas (weights
    of mass and bending) are the rows' cells (midpoint to midpoint) over the overhang
    0 <= x <= overhang only: the row at +e_0/2 covers [0, (x_1 + x_2)/2], the tip [(x_n + x_{n+1})/2, L].
    """
    xs = _row_positions(overhang, n_elements, grading)
    ys = np.linspace(-0.5 * width, 0.5 * width, n_width + 1)
    mesh = Mesh.grid(xs, ys)
    X = np.asarray(mesh.nodes)
    mid = np.concatenate([[0.0], 0.5 * (xs[1:-1] + xs[2:]), [overhang]])  # cell edges of rows 1..n+1
    wx = np.concatenate([[0.0], np.diff(mid)])
    wy = np.full(len(ys), width / n_width)
    wy[0] = wy[-1] = 0.5 * width / n_width
    node_area = (wy[:, None] * wx[None, :]).ravel()  # grid node order: y-major rows of x
    mesh = mesh.replace(node_area=node_area)
    free = X[:, 0] > 0.5 * (xs[1] + xs[2])  # rows at -e_0/2 and +e_0/2 are clamped
    centre = np.abs(X[:, 1]) < 1e-12 * width + 1e-15
    line = np.nonzero(centre & (X[:, 0] > 0.0))[0]
    line = line[np.argsort(X[line, 0])]
    return mesh, free, line


def _fabric(bending, cross, areal_mass, thickness, fibre_modulus, shear):
    return Fabric(thickness=thickness, areal_mass=areal_mass, fibre_modulus=fibre_modulus, shear=shear,
                  bending=(bending, cross), name="cantilever-strip", fibre_angles=(0.0, 0.5 * math.pi))


def _hessian_colouring(mesh: Mesh, free_idx: np.ndarray):
    """Host: a distance-2 colouring of the free nodes for a compressed Hessian (few ``jvp`` s).

    Two nodes are coupled when they share a triangle or a bending stencil; the Hessian's column of
    a dof is non-zero only at the rows of nodes coupled to its node. Nodes whose coupled sets are
    disjoint get the same colour, so one ``jvp`` of the gradient per (colour, x/y/z) recovers every
    entry exactly. The count does not grow with the strip's length (about 3 x 27 for a 3-node wide
    strip, whatever ``n_elements``).

    Returns:
        seeds: (C, n_dof) 0/1 seed directions.
        rows, cols: (P,) int dof indices of the structurally non-zero Hessian entries.
        colour: (P,) the seed whose product holds entry (rows, cols).
    """
    n = mesh.n_nodes
    # A node's bending energy depends on its whole stencil AND on the node itself (u[nbr] - u[i]).
    groups = [list(t) for t in np.asarray(mesh.tris)] + [sorted(set(s) | {i}) for i, s in enumerate(np.asarray(mesh.nbr))]
    adj = [set() for _ in range(n)]
    for grp in groups:
        for a in grp:
            adj[a].update(grp)
    pos = -np.ones(n, int)
    pos[free_idx] = np.arange(len(free_idx))
    colour = -np.ones(n, int)
    for a in free_idx:  # greedy: avoid colours of nodes within distance 2
        banned = {colour[c] for b in adj[a] for c in adj[b] if colour[c] >= 0}
        c = 0
        while c in banned:
            c += 1
        colour[a] = c
    n_col = int(colour[free_idx].max()) + 1
    n_dof = 3 * len(free_idx)
    seeds = np.zeros((3 * n_col, n_dof))
    rows, cols = [], []
    for a in free_idx:
        for b in adj[a]:
            if pos[b] >= 0:
                for i in range(3):
                    for j in range(3):
                        rows.append(3 * pos[b] + i)
                        cols.append(3 * pos[a] + j)
        for j in range(3):
            seeds[3 * colour[a] + j, 3 * pos[a] + j] = 1.0
    rows, cols = np.asarray(rows), np.asarray(cols)
    node_of_col = free_idx[cols // 3]
    return seeds, rows, cols, 3 * colour[node_of_col] + cols % 3


def _energy(u, shell, X, free_idx, g, alpha):
    """Total potential energy (J) of the free dofs ``u`` (3 n_free,): shell + gravity.

    ``alpha`` scales the fibre tension (continuation; 1 = the true modulus), ``g`` is the gravity (m/s²).
    """
    x = X.at[free_idx].set(u.reshape(-1, 3))
    p = energy_parts(x, shell)
    return alpha * p["tension"] + p["shear"] + p["bending"] + g * jnp.sum(shell.node_masses() * x[:, 2])


@pytree_dataclass
class _Strip:
    """The hanging strip as a :mod:`jaxform.statics` problem.

    The unknowns are the mirror-symmetric coordinates ``v`` (``u = sym @ v``, ``sym`` with
    orthonormal columns, see :func:`_symmetry_basis`); the load is ``(g, alpha)`` (gravity m/s²,
    fibre-tension factor). The Hessian ``sym^T H sym`` is assembled from one ``jvp`` of the full
    gradient per seed of the colouring (:func:`_hessian_colouring`).

    Attributes:
        shell: the strip's shell. X: (N, 3) reference node positions, m. free_idx: (n_free,) int.
        sym: (3 n_free, n_sym) symmetric basis. seeds: (C, 3 n_free). rows, cols, colour: (P,) int.
    """

    shell: Any
    X: Any
    free_idx: Any
    sym: Any
    seeds: Any
    rows: Any
    cols: Any
    colour: Any

    def energy(self, v, load):
        return _energy(self.sym @ v, self.shell, self.X, self.free_idx, load[0], load[1])

    def hessian(self, v, load):
        n_full = self.seeds.shape[1]
        gr = lambda w: jax.grad(_energy)(w, self.shell, self.X, self.free_idx, load[0], load[1])
        hs = jax.vmap(lambda s: jax.jvp(gr, (self.sym @ v,), (s,))[1])(self.seeds)  # (C, n_full)
        H = jnp.zeros((n_full, n_full), v.dtype).at[self.rows, self.cols].set(hs[self.colour, self.rows])
        H = self.sym.T @ H @ self.sym
        return 0.5 * (H + H.T)

    def lift(self, dv):
        return self.sym @ dv


def _path(g, load_steps, stiffen_steps, alpha0, tol, tol_path):
    gs = [g * (k + 1) / load_steps for k in range(load_steps)] + [g] * stiffen_steps
    al = [alpha0] * load_steps + [alpha0 ** (1.0 - (k + 1) / stiffen_steps) for k in range(stiffen_steps)]
    tols = [tol_path] * (len(gs) - 1) + [tol]
    return np.asarray(gs), np.asarray(al), np.asarray(tols)


@functools.lru_cache(maxsize=64)
def _strip_data(overhang, width, n_elements, n_width, grading=1.0):
    """Host tables of a strip (mesh, free dofs, profile line, symmetry basis, Hessian colouring),
    built once per strip geometry (plain numbers as the key: a fit solves the same strip many times)."""
    mesh, free, line = _strip(overhang, width, n_elements, n_width, grading)
    free_idx = np.nonzero(free)[0]
    return mesh, free_idx, line, _symmetry_basis(mesh, free_idx, n_width), _hessian_colouring(mesh, free_idx)


def _symmetry_basis(mesh: Mesh, free_idx: np.ndarray, n_width: int) -> np.ndarray:
    """(3 n_free, n_sym) orthonormal basis of the free dofs mirror-symmetric about the plane y = 0.

    The strip, its clamp, the load and the laws (fibres along and across it) are symmetric about
    its centre plane, and so is the planar profile the test measures (and the elastica describes).
    The shell's twist about the strip's axis costs no bending energy (decoupled fibre bending) and
    its in-plane shear is weak, so in the full dofs the symmetric equilibrium sits next to
    near-zero-stiffness antisymmetric modes (sway and twist) that a Newton iteration can fall into
    (seen: a strip twisting 1 mm sideways, or stalling at residual 1e-2). Solving in the symmetric
    subspace removes them: a node ``(x, y, z)`` of row ``j`` moves with its mirror in row
    ``n_width - j`` as ``(x, -y, z)``; centre-row nodes keep ``y = 0``.
    """
    X = np.asarray(mesh.nodes)
    ys = np.unique(X[:, 1])
    if len(ys) != n_width + 1:
        raise ValueError(f"cantilever: expected {n_width + 1} node rows across the strip, found {len(ys)}")
    pos = -np.ones(len(X), int)
    pos[free_idx] = np.arange(len(free_idx))
    key = {(round(X[i, 0] * 1e12), round(X[i, 1] * 1e12)): i for i in free_idx}
    cols = []
    s = np.sqrt(0.5)
    for i in free_idx:
        if X[i, 1] > 1e-12 * (ys[-1] - ys[0]):
            continue  # handled with its mirror
        if abs(X[i, 1]) <= 1e-12 * (ys[-1] - ys[0]):  # centre row: x and z
            for c in (0, 2):
                col = np.zeros(3 * len(free_idx))
                col[3 * pos[i] + c] = 1.0
                cols.append(col)
            continue
        m = key[(round(X[i, 0] * 1e12), round(-X[i, 1] * 1e12))]
        for c, sign in ((0, 1.0), (1, -1.0), (2, 1.0)):
            col = np.zeros(3 * len(free_idx))
            col[3 * pos[i] + c] = s
            col[3 * pos[m] + c] = sign * s
            cols.append(col)
    return np.stack(cols, 1)


def _is_traced(tree) -> bool:
    return any(isinstance(leaf, jax.core.Tracer) for leaf in jax.tree_util.tree_leaves(tree))


FIBRE_SOFTENING = 1e-2
"""The fibre modulus's factor while :func:`simulate` applies gravity (restored over
``stiffen_steps``). At 1e-4 (before 2026-12-06) the NCF's negative Voce law (``b_inf`` 1.03e-4
N·m, ``B_init`` 5.7e-3 N·m, a hinge at the clamp) did not solve near its 41.5° overhang (159 mm)
on any mesh with clamp elements shorter than about 1 mm (grading 20 at 40 and 160 elements, 5 at
80; 8 or 16 stiffening steps did not help): the soft-fibre strip sagged to a chord of 54-83° and
the damped Newton ended there, 1e2-1e5 times the weight out of balance. At 1e-2 the ones retried
solve (grading 20 at 40 elements and 5 at 80, at 159 and 200 mm; 41.59° at 159 mm and grading 20,
58 iterations, where gradings 10 and 5 at 40 took 48 at 1e-4), and the strips that solved before
give the same result (B_41.5 of the woven law to 1e-15, of the NCF's positive law to 2e-8); at 1
(no softening) they solve in 2.2-3.7x the iterations."""


def simulate(bending, *, overhang: float, areal_mass, width: float | None = None, n_elements: int = 40,
             n_width: int = 2, grading: float = 20.0, cross_bending=None, thickness=3e-4, fibre_modulus=3.0e9, shear=None,
             g: float = GRAVITY, load_steps: int = 8, stiffen_steps: int = 3, max_iter: int = 40,
             tol: float | None = None) -> CantileverResult:
    """Solve the hanging strip to rest with the shell; return its side profile and tip angle.

    Args:
        bending: bending law along the strip (``LinearBending``, ``VoceBending``, ``AsymmetricBending``).
        overhang: arc length of the overhanging strip, m (a host float: it sets the mesh).
        areal_mass: kg/m² (may be traced).
        width: strip width, m (default ``overhang / 8``; the profile does not depend on it).
        n_elements: elements along the overhang (40: tip deflection within ~0.05% of the elastica,
            see ``tests/test_cantilever.py``); ``n_width`` across (even: the profile is the centre row).
        grading: last / first element length along the strip (geometric growth away from the
            clamp, where a softening law's curvature concentrates; 1 = uniform; see the module
            docstring for the convergence table).
        cross_bending: law of the transverse family (default: the same as ``bending``).
        thickness, fibre_modulus, shear: membrane data (default: 0.3 mm, 3 GPa, a weak linear shear law).
        g: gravity, m/s². load_steps, stiffen_steps, max_iter: the Newton continuation (gravity
            increments with softened fibres, fibre-stiffening increments, iteration cap per increment).
        tol: final out-of-balance force relative to the strip's weight (default 1e-7 in float64,
            1e-4 in float32; round-off in the stiff fibre forces floors it near 1e-9).

    The laws, ``areal_mass``, ``thickness`` and ``fibre_modulus`` may be traced (``jax.grad``,
    ``jit``); derivatives come from the implicit function theorem at the converged equilibrium.
    """
    overhang = float(overhang)
    if not overhang > 0:
        raise ValueError(f"cantilever.simulate: overhang = {overhang!r} m: must be > 0")
    width = overhang / 8 if width is None else float(width)
    if int(n_width) < 2 or int(n_width) % 2:
        raise ValueError(f"cantilever.simulate: n_width = {n_width!r}: must be even and >= 2 (the profile is the centre row)")
    mesh, free_idx, line, sym, (seeds, rows, cols, colour) = _strip_data(overhang, width, int(n_elements), int(n_width), float(grading))
    shear_default = shear is None
    shear = PolynomialShear([_DEFAULT_SHEAR]) if shear is None else shear
    fabric = _fabric(bending, bending if cross_bending is None else cross_bending, areal_mass, thickness,
                     fibre_modulus, shear)
    # the strip's in-plane shear plays no part; a weak linear conjugate shear keeps the flat
    # strip's Hessian regular (the A.14 reading has zero shear stiffness at zero shear)
    shell = Shell.build(mesh, fabric, shear_reading="conjugate" if shear_default else "a14")
    dtype = jnp.float64 if jax.config.jax_enable_x64 else jnp.float32
    shell = jax.tree_util.tree_map(
        lambda a: jnp.asarray(a, dtype) if jnp.issubdtype(jnp.asarray(a).dtype, jnp.floating) else jnp.asarray(a), shell)
    if tol is None:
        tol = 1e-7 if dtype == jnp.float64 else 1e-4
    X = jnp.asarray(mesh.nodes, dtype)
    fi = jnp.asarray(free_idx)
    gs, alphas, tols = _path(g, load_steps, stiffen_steps, FIBRE_SOFTENING, tol, max(1e3 * tol, 1e-4))
    loads = jnp.asarray(np.stack([gs, alphas], 1), dtype)
    sym = jnp.asarray(sym, dtype)
    strip = _Strip(shell, X, fi, sym, jnp.asarray(seeds, dtype), jnp.asarray(rows), jnp.asarray(cols), jnp.asarray(colour))
    strip_c = jax.lax.stop_gradient(strip)
    weight = jnp.sum(strip_c.shell.node_masses()) * float(np.max(gs))  # N: the tolerances are relative to it
    # the predictor follows the gravity increments only: predicting the fibre stiffening overshoots
    # (measured: 20-50 % more Newton iterations)
    # small-step stop at 1e-13 of the overhang in float64, about an ulp in float32. At 1e-3 tol
    # overhang (8e-12 m) the Voce strip of tests/test_cantilever.py stopped at 1.1e-5 to 1.3e-5 of
    # its weight (one thread; 1e-13 m steps still lowered |grad E|), now 3e-8 to 4e-6: where in that
    # range depends on rounding (thread count, XLA's emitters), the floor of the stiff fibre modes
    xtol = max(1e-6 * tol, float(jnp.finfo(dtype).eps)) * overhang
    eq = statics.solve(strip_c, sym.T @ X[fi].reshape(-1), loads, jnp.asarray(tols, dtype) * weight, int(max_iter),
                       0.1 * overhang, xtol, jnp.asarray([1.0, 0.0], dtype))
    if _is_traced((bending, cross_bending, areal_mass, thickness, fibre_modulus, shear)):
        v = statics.implicit(strip, eq.u, eq.hessian, loads[-1])  # derivatives by the IFT
    else:
        v = eq.u
    return _profile(strip_c.shell.mesh, sym @ v, X, fi, jnp.asarray(line), eq.grad_norm / weight, eq.iterations)


@jax.jit
def _profile(mesh, u, X, free_idx, line, residual, iterations):
    """Side profile and tip angle from the free dofs ``u``; ``residual`` from the solver (relative
    out-of-balance force at its last iterate, relative to the strip's weight)."""
    from jaxform.shell import node_derivatives

    x = X.at[free_idx].set(u.reshape(-1, 3))
    zero = jnp.zeros((1,), x.dtype)  # the clamp edge (0, 0)
    px = jnp.concatenate([zero, x[line, 0]])
    pz = jnp.concatenate([zero, x[line, 2]])
    # tip tangent from the node's finite-difference stencil (same weights as the bending)
    t = node_derivatives(x, mesh)[line[-1], 0]
    tip_angle = jnp.arctan2(-t[2], t[0])
    return CantileverResult(x=px, z=pz, tip_angle=tip_angle, tip_deflection=-pz[-1], residual=residual, nodes=x,
                            iterations=iterations)


@pytree_dataclass
class StandardTestResult:
    """BS EN ISO 9073-7 (Peirce 41.5°) result.

    Attributes:
        overhang_41_5: overhang at which the clamp-to-tip chord is 41.5° below horizontal, m.
        bending_length: ``c = overhang_41_5 / 2``, m.
        b_41_5: ``B = w c^3`` with ``w = areal_mass * g``, N·m.
        residual: the cantilever solver's relative out-of-balance force at ``overhang_41_5``.
        max_residual: the largest such residual over every strip the search solved.
        n_simulations: strips solved by the search.
    """

    overhang_41_5: Any
    bending_length: Any
    b_41_5: Any
    residual: Any = None
    max_residual: Any = None
    n_simulations: Any = None


class CantileverNotConverged(RuntimeError):
    """The cantilever solve (or the standard test's search) stopped short of equilibrium."""


def chord_angle(profile):
    """Angle of the chord from the clamp edge (the origin) to the tip below the horizontal, rad.

    ``profile``: anything with ``x``, ``z`` (m, clamp to tip, z negative downwards): a
    :class:`CantileverResult` or a measured profile.
    """
    return jnp.arctan2(-profile.z[-1], profile.x[-1])


MAX_RETREATS = 6
"""Times :func:`standard_test` shortens a strip that does not solve before it gives up."""


def standard_test(bending, *, areal_mass: float, g: float = GRAVITY, tol: float = 1e-5, max_iter: int = 30,
                  max_residual: float = 1e-5, model=None, **kwargs) -> StandardTestResult:
    """Find the 41.5° overhang (secant iterations on the overhang; host loop), ``B_41.5 = w (L/2)^3``.

    Every strip the result rests on must reach equilibrium (a solver ``residual``, relative
    out-of-balance force, at most ``max_residual``). A strip that does not is one the search went
    too far with: the search starts from Peirce's overhang for the initial stiffness, which for a
    strongly softening law (the NCF's Voce laws: about 245 mm) hangs almost vertically where the
    solver cannot follow it; a longer strip always sags more, so the search shortens it (by 0.7
    when bracketing, halfway back to the last solved overhang in the secant steps, at most
    ``MAX_RETREATS`` times) instead of failing. :class:`CantileverNotConverged` names the
    overhang when that does not help, or when the secant search has not met ``tol`` (relative,
    on the overhang) after ``max_iter`` steps. ``model``: the forward model
    (default the shell, :func:`simulate` with gravity ``g``; another model with the same signature
    keeps its own gravity and may report no ``residual``). ``kwargs`` go to the model.
    """
    from jaxform.materials import max_stiffness

    model = functools.partial(simulate, g=g) if model is None else model
    w = float(areal_mass) * g
    b0 = float(np.max(np.asarray(max_stiffness(bending))))
    log = []  # (L, chord angle - 41.5 deg, residual) of the strips that reached equilibrium

    def f(L):
        r = model(bending, overhang=L, areal_mass=areal_mass, **kwargs)
        res = float(getattr(r, "residual", 0.0))
        if not res <= max_residual:
            raise CantileverNotConverged(
                f"standard_test: the cantilever of overhang {1e3 * L:.3f} mm did not converge (residual "
                f"{res:.2e} > max_residual {max_residual:.1e} after {int(getattr(r, 'iterations', -1))} Newton iterations); "
                "try more load_steps or max_iter")
        log.append((L, float(chord_angle(r)) - PEIRCE_ANGLE, res))
        return log[-1][1]

    def solved(L, shorter):
        """``(L, f(L))``, moving to ``shorter(L)`` while the strip of overhang L does not solve."""
        for attempt in range(MAX_RETREATS + 1):
            try:
                return L, f(L)
            except CantileverNotConverged:
                if attempt == MAX_RETREATS:
                    raise
                L = shorter(L)

    # bracket: start from Peirce with the initial stiffness (a softening law sags more: shorter)
    L1, f1 = solved(2.0 * (b0 / w) ** (1.0 / 3.0), lambda L: 0.7 * L)
    L0, f0 = solved(L1 * (0.8 if f1 > 0 else 1.25), lambda L: 0.5 * (L + L1))
    for _ in range(max_iter):
        L2 = L1 - f1 * (L1 - L0) / (f1 - f0)
        L2 = min(max(L2, 0.5 * L1), 2.0 * L1)
        L0, f0 = L1, f1
        L1, f1 = solved(L2, lambda L, last=L0: 0.5 * (L + last))
        if abs(L1 - L0) <= tol * L1:
            break
    else:
        raise CantileverNotConverged(
            f"standard_test: the 41.5 deg overhang search did not converge in {max_iter} secant steps "
            f"(last overhangs {1e3 * L0:.4f}, {1e3 * L1:.4f} mm, chord angle off by {math.degrees(f1):+.3g} deg)")
    c = 0.5 * L1
    return StandardTestResult(overhang_41_5=L1, bending_length=c, b_41_5=w * c**3, residual=log[-1][2],
                              max_residual=max(e[2] for e in log), n_simulations=len(log))


__all__ = ["simulate", "standard_test", "MAX_RETREATS", "FIBRE_SOFTENING", "chord_angle", "CantileverResult",
           "StandardTestResult", "CantileverNotConverged", "GRAVITY", "PEIRCE_ANGLE"]
