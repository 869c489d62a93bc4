"""Virtual material tests on the shell: picture frame (pure shear) and bias extension.

Both rigs use the SAME shell kernel as forming (:mod:`jaxform.shell`): its energy, with forces
and stiffness taken by ``jax.grad`` / ``jax.hessian``. They are quasi-static: the driven nodes are
prescribed, the free in-plane dofs are brought to equilibrium by the damped Newton solver of
:mod:`jaxform.statics` (the one the cantilever uses; dense Hessian, small meshes), and reaction
forces are ``grad E`` at the driven nodes.
Out-of-plane dofs stay at ``z = 0`` (the flat state is an equilibrium; wrinkling is not studied).

Picture frame (:func:`picture_frame`)
    A square of fabric of side ``L`` (pin to pin), fibres along the frame arms (0°/90°), corner
    ``(0, 0)`` pinned, corner ``(L, L)`` pulled along the diagonal. The rigid arms carry all
    boundary nodes: ``x = F(gamma) X`` on the boundary with the fibre vectors
    ``F e_1 = (cos g/2, sin g/2)``, ``F e_2 = (sin g/2, cos g/2)``; the interior is solved for.
    Crosshead displacement ``d = 2 L cos(pi/4 - g/2) - sqrt(2) L`` (so
    ``gamma = pi/2 - 2 arccos(1/sqrt2 + d/(2L))``). The frame force ``F`` is the reaction by
    virtual work: ``F dd/dgamma = sum_b R_b . dx_b/dgamma`` over the driven nodes ``b``.

    Normalisation. Virtual work on the fabric of reference area ``L^2`` gives
    ``F dd/dgamma = L^2 dW/dgamma`` with ``dd/dgamma = L sin(phi)``, ``phi = pi/4 - gamma/2``; the
    rig reports

    * ``resultant = F sin(phi) / L`` (N/m): the shear resultant conjugate to ``gamma`` per unit
      *reference* area, ``dW/dgamma``;
    * ``f_norm`` (N/m): the ``F_norm`` the shell's reading implies from the measured response:
      ``resultant`` itself for ``shear_reading="conjugate"`` (``dW/dgamma = F_norm``), its
      derivative ``d resultant/dgamma`` for ``"a14"`` (``dW/dgamma = int_0^gamma F_norm``; the
      derivative is the exact tangent of the equilibrium path, by :func:`jaxform.statics.implicit`);
    * ``f_norm_classical = F / (2 L cos(phi))`` (N/m), the experimentalists' normalisation (force
      per unit frame length, power-conjugate to ``gamma`` per unit *current* area);
      ``f_norm_classical = resultant / cos(gamma)``.

Bias extension (:func:`bias_extension`)
    A rectangle ``H x W`` (``H = 2 W`` by default) with fibres at ±45° to the pull, clamped ends
    (all nodes of each end prescribed, one end moved by ``d`` along the axis). The mesh is the
    fibre lattice (nodes ``(i a, j a)`` with ``i + j`` even), each lattice cell split along its
    axial diagonal, so every triangle has two fibre-aligned edges and the pin-jointed net is
    representable without locking. Extension is applied in increments, each solved to rest.
    The central zone's shear angle is the area-weighted mean over the triangles whose reference
    centroid lies in the inner half of zone A (``|x - H/2| + |y - W/2| < W/4``).
"""
from __future__ import annotations

import dataclasses
import math
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from jaxform import statics
from jaxform._pytree import pytree_dataclass
from jaxform.mesh import Mesh
from jaxform.shell import Shell, energy, shear_angle, fibre_vectors


def _as_fabric(fabric_or_law, fibre_angles, thickness=1e-3, fibre_modulus=3e9):
    """A membrane-only fabric from a shear law, or the fabric itself (its fibre angles replaced)."""
    from jaxform.materials import Fabric

    if isinstance(fabric_or_law, Fabric):
        return fabric_or_law.replace(fibre_angles=fibre_angles, bending=None)
    return Fabric(thickness=thickness, areal_mass=0.2, fibre_modulus=fibre_modulus, shear=fabric_or_law,
                  bending=None, name="frame-test", fibre_angles=fibre_angles)


def _energy2(xy, shell: Shell):
    """Shell energy (J) of the flat configuration with in-plane positions ``xy`` (2N,), m."""
    n = shell.mesh.n_nodes
    x = jnp.concatenate([xy.reshape(n, 2), jnp.zeros((n, 1), xy.dtype)], axis=1)
    return energy(x, shell)


@pytree_dataclass
class _InPlane:
    """The flat rig as a :mod:`jaxform.statics` problem: the free in-plane dofs of ``xy``.

    Attributes:
        shell: the specimen's shell.
        xy: (2N,) in-plane node positions, m, the driven ones prescribed (the free ones are the unknowns).
        free_idx: (n,) int indices of the free dofs in ``xy``.
    """

    shell: Any
    xy: Any
    free_idx: Any

    def full(self, u):
        """(2N,) positions with the free dofs ``u``."""
        return self.xy.at[self.free_idx].set(u)

    def energy(self, u, load):
        return _energy2(self.full(u), self.shell)

    def hessian(self, u, load):
        return statics.dense_hessian(self, u, load)

    def lift(self, du):
        return du


_reactions = jax.jit(jax.grad(_energy2))  # (2N,) out-of-balance forces grad E, N
_NO_LOAD = jnp.zeros((1, 1))  # the flat rigs have no load path: each state is solved on its own


@jax.jit
def _grad_norm(problem, u):
    return jnp.linalg.norm(jax.grad(problem.energy)(u, _NO_LOAD[0]))


def _equilibrium(shell: Shell, xy, free, *, tol=1e-10, max_iter=60):
    """Free dofs (bool mask over the flat (2N,) vector) brought to rest from ``xy`` by
    :func:`jaxform.statics.solve`, to ``|grad E| <= tol max(|grad E(xy)|, 1 N)``.

    Returns ``(problem, equilibrium)``; ``problem.full(equilibrium.u)`` is the (2N,) solution.
    """
    problem = _InPlane(shell, jnp.asarray(np.asarray(xy, np.float64)), jnp.asarray(np.nonzero(free)[0]))
    u0 = problem.xy[problem.free_idx]
    atol = tol * max(float(_grad_norm(problem, u0)), 1.0)
    eq = statics.solve(problem, u0, _NO_LOAD.astype(u0.dtype), jnp.asarray([atol], u0.dtype), max_iter, jnp.inf, 0.0)
    return problem, eq


# ------------------------------------------------------------------------------------ picture frame


@pytree_dataclass
class PictureFrameResult:
    """Picture-frame response (host arrays), one entry per load point.

    Attributes:
        gamma: (P,) frame shear angle, rad.
        displacement: (P,) crosshead displacement along the diagonal, m.
        force: (P,) frame (crosshead) force, N.
        resultant: (P,) ``F sin(phi) / L``, the shear resultant per reference area ``dW/dgamma``, N/m.
        f_norm: (P,) ``F_norm`` implied by the shell's reading (module docstring), N/m.
        f_norm_classical: (P,) ``F / (2 L cos(phi))``, N/m.
        gamma_mesh: (P,) mean shear angle of the triangles (shell kinematics), rad.
        residual: (P,) largest out-of-balance force on the free nodes after the solve, N.
        side: frame side ``L``, m.
        shear_reading: the shell's reading.
    """

    gamma: Any
    displacement: Any
    force: Any
    resultant: Any
    f_norm: Any
    f_norm_classical: Any
    gamma_mesh: Any
    residual: Any
    side: Any
    shear_reading: Any


def picture_frame_displacement(gamma, side):
    """Crosshead displacement (m) of a frame of side ``side`` at shear angle ``gamma`` (rad)."""
    return 2.0 * side * np.cos(0.25 * np.pi - 0.5 * np.asarray(gamma, float)) - math.sqrt(2.0) * side


def _frame_xy(X, g):
    """(2N,) positions ``x = F(g) X`` of the frame's kinematics, ``F e_1 = (cos g/2, sin g/2)``,
    ``F e_2 = (sin g/2, cos g/2)``; ``X`` (N, 2) reference positions, m, ``g`` the shear angle, rad."""
    c, s = jnp.cos(0.5 * g), jnp.sin(0.5 * g)
    return (X @ jnp.stack([jnp.stack([c, s]), jnp.stack([s, c])]).T).ravel()


@jax.jit
def _frame_work(problem, X, driven, u_star, hessian, g):
    """Virtual work of the reactions on the driven nodes per unit ``gamma`` (``F dd/dgamma``, N·m),
    its derivative along the equilibrium path (the free nodes follow by the implicit function
    theorem, :func:`jaxform.statics.implicit`), and the (2N,) out-of-balance forces ``grad E``, N."""

    def work(gam):
        p = dataclasses.replace(problem, xy=_frame_xy(X, gam))
        R = jax.grad(_energy2)(p.full(statics.implicit(p, u_star, hessian, _NO_LOAD[0])), p.shell)
        v = jax.jvp(lambda t: _frame_xy(X, t), (gam,), (jnp.ones_like(gam),))[1]  # dx/dgamma
        return R[driven] @ v[driven], R

    (w, R), (dw, _) = jax.jvp(work, (g,), (jnp.ones_like(g),))
    return w, dw, R


def picture_frame(fabric_or_law, *, side: float = 0.1, gamma_max: float = math.radians(60.0), n: int = 6,
                  n_points: int = 13, gamma_min: float | None = None, shear_reading: str = "a14") -> PictureFrameResult:
    """Quasi-static picture frame on the shell (module docstring).

    Args:
        fabric_or_law: a :class:`~jaxform.materials.Fabric` (its shear law and tension stiffness
            are used, fibres set to 0°/90°, bending dropped: in-plane test) or a shear law alone
            (then a 1 mm, 3 GPa fabric).
        side: frame side ``L`` pin to pin, m.
        gamma_max: largest shear angle, rad (< pi/2).
        n: elements per side (n x n quads, 2 n^2 triangles; >= 2, so that there are interior nodes).
        n_points: load points, equally spaced in ``gamma`` from ``gamma_min`` (default
            ``gamma_max / n_points``) to ``gamma_max``.
        shear_reading: the shell's reading of ``F_norm`` (``"a14"`` or ``"conjugate"``).
    """
    if not (0.0 < gamma_max < 0.5 * math.pi):
        raise ValueError(f"picture_frame: gamma_max = {gamma_max!r} rad: must lie in (0, pi/2)")
    if not side > 0:
        raise ValueError(f"picture_frame: side = {side!r}: must be a positive length in m")
    if int(n) < 2:
        raise ValueError(f"picture_frame: n = {n!r}: must be >= 2 elements per side (the interior is solved for)")
    fab = _as_fabric(fabric_or_law, (0.0, 0.5 * math.pi))
    mesh = Mesh.rectangle(side, side, side / n)
    shell = Shell.build(mesh, fab, shear_reading=shear_reading)
    X = np.asarray(mesh.nodes)[:, :2]
    N = len(X)
    tol = 1e-9 * side
    bnd = (X[:, 0] < tol) | (X[:, 0] > side - tol) | (X[:, 1] < tol) | (X[:, 1] > side - tol)
    free = np.repeat(~bnd, 2)
    driven = jnp.asarray(np.nonzero(~free)[0])
    g0 = gamma_max / n_points if gamma_min is None else gamma_min
    gammas = np.linspace(g0, gamma_max, n_points)
    out = {k: [] for k in ("force", "resultant", "dres", "gmesh", "res")}
    for g in gammas:
        problem, eq = _equilibrium(shell, _frame_xy(jnp.asarray(X), g), free)
        work, dwork, R = _frame_work(problem, jnp.asarray(X), driven, eq.u, eq.hessian, jnp.asarray(g))
        dd = side * math.sin(0.25 * math.pi - 0.5 * g)
        out["force"].append(float(work) / dd)
        out["resultant"].append(float(work) / side**2)
        out["dres"].append(float(dwork) / side**2)
        x3 = jnp.concatenate([problem.full(eq.u).reshape(N, 2), jnp.zeros((N, 1))], axis=1)
        out["gmesh"].append(float(jnp.mean(shear_angle(fibre_vectors(x3, mesh, shell.ref), shell.ref))))
        out["res"].append(float(jnp.max(jnp.abs(R[problem.free_idx]))))
    force = np.asarray(out["force"])
    resultant = np.asarray(out["resultant"])
    f_norm = resultant if shear_reading == "conjugate" else np.asarray(out["dres"])
    phi = 0.25 * np.pi - 0.5 * gammas
    return PictureFrameResult(
        gamma=gammas, displacement=picture_frame_displacement(gammas, side), force=force, resultant=resultant,
        f_norm=f_norm, f_norm_classical=force / (2.0 * side * np.cos(phi)), gamma_mesh=np.asarray(out["gmesh"]),
        residual=np.asarray(out["res"]), side=side, shear_reading=shear_reading)


# ------------------------------------------------------------------------------------ bias extension


def bias_mesh(width: float, length: float, cells_across: int) -> Mesh:
    """Fibre-lattice mesh of an ``length`` x ``width`` rectangle (x along the pull), fibres at ±45°.

    ``cells_across`` (even) lattice spacings across the width; ``length / width`` must make the
    number of spacings along the length an even integer.
    """
    ny = int(cells_across)
    if ny < 2 or ny % 2:
        raise ValueError(f"bias_mesh: cells_across = {cells_across}: must be an even integer >= 2")
    a = width / ny
    nx = int(round(length / a))
    if nx % 2 or abs(nx * a - length) > 1e-9 * length:
        raise ValueError(f"bias_mesh: length {length} m is not an even multiple of the lattice step {a} m")
    ids = {}
    nodes = []
    for j in range(ny + 1):
        for i in range(nx + 1):
            if (i + j) % 2 == 0:
                ids[(i, j)] = len(nodes)
                nodes.append((i * a, j * a, 0.0))
    tris = []
    for j in range(ny + 1):
        for i in range(nx + 1):
            if (i + j) % 2 == 0:
                continue
            L, R, T, B = (i - 1, j), (i + 1, j), (i, j + 1), (i, j - 1)
            if i == 0:
                tris.append((B, R, T))
            elif i == nx:
                tris.append((B, T, L))
            else:
                if j < ny:
                    tris.append((L, R, T))
                if j > 0:
                    tris.append((L, B, R))
    tri = np.array([[ids[p] for p in t] for t in tris], np.int64)
    return Mesh.from_arrays(np.array(nodes), tri)


@pytree_dataclass
class BiasExtensionResult:
    """Bias-extension response (host arrays), one entry per load increment.

    Attributes:
        extension: (P,) clamp displacement over the free length ``d / H``.
        displacement: (P,) clamp displacement ``d``, m.
        force: (P,) axial clamp force (reaction on the moving clamp), N.
        gamma_centre: (P,) area-weighted mean shear angle in the centre of zone A, rad.
        gamma_max: (P,) largest triangle shear angle, rad.
        length: free length ``H`` between the clamps, m.
        width: specimen width ``W``, m.
    """

    extension: Any
    displacement: Any
    force: Any
    gamma_centre: Any
    gamma_max: Any
    length: Any
    width: Any


def bias_extension(fabric_or_law, *, width: float = 0.05, length: float | None = None, cells_across: int = 8,
                   extension: float = 0.2, n_steps: int = 20, shear_reading: str = "a14") -> BiasExtensionResult:
    """Quasi-static bias extension on the shell (module docstring): ``n_steps`` equal increments up to ``extension``.

    Args:
        fabric_or_law: a fabric (its shear law and tension stiffness; fibres set to ±45°, bending
            dropped) or a shear law alone (then a 1 mm, 3 GPa fabric).
        width: ``W``, m. length: free length ``H`` between the clamps, m (default ``2 W``).
        cells_across: lattice spacings across the width (even).
    """
    length = 2.0 * width if length is None else length
    fab = _as_fabric(fabric_or_law, (0.25 * math.pi, -0.25 * math.pi))
    mesh = bias_mesh(width, length, cells_across)
    shell = Shell.build(mesh, fab, shear_reading=shear_reading)
    X = np.asarray(mesh.nodes)[:, :2]
    N = len(X)
    tol = 1e-9 * length
    left, right = X[:, 0] < tol, X[:, 0] > length - tol
    free = np.repeat(~(left | right), 2)
    rx = np.nonzero(right)[0] * 2  # x dofs of the moving clamp
    tris = np.asarray(mesh.tris)
    cen = X[tris].mean(axis=1)
    area = np.asarray(shell.ref.tri_area)
    centre = np.abs(cen[:, 0] - 0.5 * length) + np.abs(cen[:, 1] - 0.5 * width) < 0.25 * width
    xy = X.ravel().copy()
    prev = xy.copy()
    res = {k: [] for k in ("d", "f", "gc", "gm")}
    for k in range(1, n_steps + 1):
        d = extension * length * k / n_steps
        guess = xy + (xy - prev) if k > 1 else xy.copy()  # linear predictor
        guess[rx] = X[right, 0] + d
        prev = xy
        problem, eq = _equilibrium(shell, guess, free, tol=1e-11, max_iter=100)
        xy = np.asarray(problem.full(eq.u))
        R = np.asarray(_reactions(xy, shell))
        x3 = jnp.concatenate([jnp.asarray(xy).reshape(N, 2), jnp.zeros((N, 1))], axis=1)
        g = np.asarray(shear_angle(fibre_vectors(x3, mesh, shell.ref), shell.ref))
        res["d"].append(d)
        res["f"].append(float(R[rx].sum()))
        res["gc"].append(float(np.sum(g[centre] * area[centre]) / np.sum(area[centre])))
        res["gm"].append(float(np.abs(g).max()))
    d = np.asarray(res["d"])
    return BiasExtensionResult(extension=d / length, displacement=d, force=np.asarray(res["f"]),
                               gamma_centre=np.asarray(res["gc"]), gamma_max=np.asarray(res["gm"]),
                               length=length, width=width)


__all__ = ["PictureFrameResult", "picture_frame", "picture_frame_displacement", "BiasExtensionResult",
           "bias_extension", "bias_mesh"]
