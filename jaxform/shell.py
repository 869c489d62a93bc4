"""The fabric shell: fibre tension, non-orthogonal in-plane shear and decoupled fibre bending.

One kernel serves every use (forming, cantilever, picture frame, bias extension): the elastic
energy of the deformed plies, written per element (membrane, per triangle) and per node (bending),
vmapped by array broadcasting, with forces ``-grad`` of it. It is *rotation free*: positions are
the only unknowns, bending curvatures come from neighbouring nodes.

Membrane (per triangle, constant strain; source paper appendix A, the non-orthogonal model):
    the fibre families are material lines. With ``F`` the deformation gradient of the triangle and
    ``e0_f`` the reference direction of family ``f``, the current fibre vector is ``g_f = F e0_f``
    (A.5), its stretch ``lambda_f = |g_f|``. Energy per reference area
    ``W_t = sum_f 1/2 (E h)_f (lambda_f - 1)^2``  (fibre tension, E the fibre modulus, SPEC 3).
    Shear angle ``gamma = theta0 - theta`` with ``theta = atan2(|g_1 x g_2|, g_1 . g_2)`` the current
    angle between the families (no ``arccos``: finite gradients at zero shear).

Shear, the reading of ``F_norm`` (SPEC section 3). Default ``shear_reading="a14"``: the paper
(eq. A.14) feeds ``F_norm`` as a tangent shear modulus ``G12 = F_norm / h`` into a rate update of
the shear stress, ``d sigma_12 = G12(gamma) d gamma``. Integrated over the thickness, the shear
stress resultant is ``T(gamma) = h sigma_12 = int_0^gamma F_norm dg`` (``law.integral``, odd) and
the hyperelastic energy whose derivative is that resultant is
``W_s = int_0^gamma T dg = law.integral2(gamma)`` per unit reference area. The energy form is used
(so forces are exact gradients and energy is conserved); the resultant conjugate to ``gamma`` is
``dW_s/dgamma = T(gamma)``, exactly the rate form's stress integrated along a monotone path. The
option ``shear_reading="conjugate"`` reads ``F_norm`` itself as the force conjugate to ``gamma``
(``W_s = law.integral(gamma)``, the picture-frame normalisation of e.g. Harrison et al.). The frame
rig (:mod:`jaxform.frame_tests`) checks the simulated frame force against each reading's closed form.

Bending (per node; decoupled from the membrane): with the node's generalised finite-difference
weights (:mod:`jaxform.mesh`), ``x_X, x_Y, x_XX, x_XY, x_YY`` at the node, the reference fibre
direction ``d = (c, s)`` in the node frame, ``x_d = c x_X + s x_Y``, ``x_dd = c^2 x_XX + 2cs x_XY +
s^2 x_YY``, the unit normal ``n = x_X x x_Y / |.|`` and the fibre's normal curvature ``kappa_f = -n
. x_dd / |x_d|^2`` (positive when the fibre bends away from ``n``, SPEC section 2). Energy
``sum_nodes A_node sum_f W_f(kappa_f - kappa0_f)`` with ``W_f`` the law's ``energy`` (derivative:
the moment ``M(kappa)``; asymmetric laws too), ``kappa0`` the reference curvature (zero for flat
blanks). ``d`` is a material direction: the bending follows the sheared fibres.
"""
from __future__ import annotations

from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from jaxform._pytree import pytree_dataclass, static_field
from jaxform.geometry import safe_sqrt, tiny_sqrt
from jaxform.mesh import Mesh, assemble_corners

SHEAR_READINGS = ("a14", "conjugate")


@pytree_dataclass
class ShellRef:
    """Reference quantities of the shell that depend on the fibre angles (host precomputed).

    Attributes:
        tri_area: (T,) reference area of each triangle, m².
        tri_dm_inv: (T, 2, 2) inverse of the reference edge matrix in the triangle frame, 1/m.
        tri_coef: (T, 2, 2) ``coef[t, f] = Dm^-1 e0_f``: ``g_f = (x1 - x0) coef[t,f,0] + (x2 - x0) coef[t,f,1]``.
        theta0: (T,) reference angle between the families, rad.
        node_dir: (N, 2, 2) reference fibre direction ``(c, s)`` of each family in the node frame.
        kappa0: (N, 2) reference fibre curvature, 1/m (zero for a flat blank).
        edge0: (2, 3, T) reference edge vectors ``x1 - x0``, ``x2 - x0`` of every triangle, m.
        deriv0: (5, 3, N) reference node derivatives ``X_X .. X_YY`` (the stencil on the mesh).
            With these, the kernel can take displacements (``displacement=True``): the edges and
            derivatives are then ``reference + linear(u)``, free of the rounding of absolute
            positions (in float32 a 0.1 m coordinate is rounded to 7e-9 m, a strain noise of
            1e-6 on 8 mm edges every step, which heats the stiff fibre modes of a long explicit
            run).
    """

    tri_area: Any
    tri_dm_inv: Any
    tri_coef: Any
    theta0: Any
    node_dir: Any
    kappa0: Any
    edge0: Any
    deriv0: Any


def shell_reference(mesh: Mesh, fibre_angles) -> ShellRef:
    """Precompute the reference quantities for ``fibre_angles``: one ``(a1, a2)`` pair (rad) per ply."""
    fibre_angles = [tuple(map(float, a)) for a in fibre_angles]
    if len(fibre_angles) != mesh.n_plies:
        raise ValueError(f"shell_reference: {len(fibre_angles)} fibre-angle pairs for {mesh.n_plies} plies")
    nodes = np.asarray(mesh.nodes, np.float64)
    tris = np.asarray(mesh.tris)
    tf = np.asarray(mesh.tri_frame)
    e1 = nodes[tris[:, 1]] - nodes[tris[:, 0]]
    e2 = nodes[tris[:, 2]] - nodes[tris[:, 0]]
    dm = np.stack([np.einsum("tc,tac->ta", e1, tf[:, :2]), np.einsum("tc,tac->ta", e2, tf[:, :2])], axis=2)  # (T,2,2)
    area = 0.5 * np.abs(np.linalg.det(dm))
    dm_inv = np.linalg.inv(dm)
    tri_ang = np.zeros((len(tris), 2))
    node_ang = np.zeros((len(nodes), 2))
    for (t0, t1), (n0, n1), ang in zip(mesh.ply_tris, mesh.ply_nodes, fibre_angles):
        tri_ang[t0:t1] = ang
        node_ang[n0:n1] = ang
    e0 = np.stack([np.cos(tri_ang), np.sin(tri_ang)], axis=-1)  # (T, 2 fam, 2)
    coef = np.einsum("tab,tfb->tfa", dm_inv, e0)
    c1, c2 = e0[:, 0], e0[:, 1]
    theta0 = np.arctan2(np.abs(c1[:, 0] * c2[:, 1] - c1[:, 1] * c2[:, 0]), np.sum(c1 * c2, -1))
    node_dir = np.stack([np.cos(node_ang), np.sin(node_ang)], axis=-1)  # (N, 2, 2)
    k0 = _fibre_curvatures_np(nodes, mesh, node_dir)
    deriv0 = np.einsum("nmk,nkc->mcn", np.asarray(mesh.gfd), nodes[np.asarray(mesh.nbr)] - nodes[:, None, :])
    return ShellRef(tri_area=area, tri_dm_inv=dm_inv, tri_coef=coef, theta0=theta0, node_dir=node_dir, kappa0=k0,
                    edge0=np.stack([e1.T, e2.T]), deriv0=deriv0)


def _fibre_curvatures_np(x, mesh: Mesh, node_dir):
    """Host (float64) twin of :func:`fibre_curvatures`, for the reference curvature."""
    D = np.einsum("nmk,nkc->nmc", np.asarray(mesh.gfd), x[np.asarray(mesh.nbr)] - x[:, None, :])
    xX, xY, xXX, xXY, xYY = (D[:, k] for k in range(5))
    n = np.cross(xX, xY)
    n = n / np.linalg.norm(n, axis=-1, keepdims=True)
    c, s = node_dir[..., 0][..., None], node_dir[..., 1][..., None]
    xd = c * xX[:, None] + s * xY[:, None]
    xdd = c * c * xXX[:, None] + 2 * c * s * xXY[:, None] + s * s * xYY[:, None]
    return -np.sum(n[:, None, :] * xdd, -1) / np.sum(xd * xd, -1)


# ------------------------------------------------------------------------------------------- kinematics


def _dot(a, b):
    """Dot product over the leading axis of structure-of-arrays vectors (3, ...)."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def _cross(a, b):
    return jnp.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


def _norm(v):
    """Norm of SoA vectors (3, ...) that may vanish: safe_sqrt (finite derivatives for Newton at 0)."""
    return safe_sqrt(_dot(v, v))


def _stretch(g):
    """Length of SoA fibre vectors (3, ...), ~1: tiny_sqrt, one fused op (safe_sqrt costs the step 30%)."""
    return tiny_sqrt(_dot(g, g))


# Kernels work on structure-of-arrays vectors (3, n): long contiguous rows vectorise and fuse on
# CPU, where (n, 3) layouts with tiny trailing axes do not (measured: 5-10x).


def _edges(xs, mesh: Mesh, base=None):
    """Triangle edge vectors ``x1 - x0``, ``x2 - x0`` (3, T) each; plus ``base`` (2, 3, T) if given."""
    t = mesh.tris
    x0 = xs[:, t[:, 0]]
    e1, e2 = xs[:, t[:, 1]] - x0, xs[:, t[:, 2]] - x0
    if base is None:
        return e1, e2
    return e1 + base[0].astype(xs.dtype), e2 + base[1].astype(xs.dtype)


def _fibres_soa(e1, e2, coef):
    g1 = e1 * coef[:, 0, 0] + e2 * coef[:, 0, 1]
    g2 = e1 * coef[:, 1, 0] + e2 * coef[:, 1, 1]
    return g1, g2


def _angle(g1, g2):
    cr = _cross(g1, g2)
    return jnp.arctan2(_norm(cr), _dot(g1, g2))


def fibre_vectors(x, mesh: Mesh, ref: ShellRef):
    """Current fibre vectors ``g_f = F e0_f`` per triangle: (T, 2, 3) (stretch = norm)."""
    e1, e2 = _edges(x.T, mesh)
    g1, g2 = _fibres_soa(e1, e2, ref.tri_coef.astype(x.dtype))
    return jnp.stack([g1.T, g2.T], axis=1)


def shear_angle(g, ref: ShellRef):
    """Shear angle ``gamma = theta0 - theta`` per triangle (rad) from fibre vectors (T, 2, 3)."""
    return ref.theta0.astype(g.dtype) - _angle(g[:, 0].T, g[:, 1].T)


def _derivs_soa(xs, mesh: Mesh, base=None):
    """(5, 3, N): x_X, x_Y, x_XX, x_XY, x_YY at every node, from SoA positions (3, N) (plus
    ``base`` (5, 3, N) if given).

    One gather of all neighbour slots; the derivatives are materialised
    (``optimization_barrier``): left fusible, XLA re-gathers the neighbours inside every consumer
    of the derivatives (measured 3-4x slower bending; a barrier on the gather itself costs more
    than it saves).
    """
    d = xs[:, mesh.nbr_k] - xs[:, None, :]  # (3, K, N)
    w = mesh.gfd_k.astype(xs.dtype)  # (K, 5, N)
    K = w.shape[0]
    # slice once per operand: each slice's transpose (reverse mode) is a full-size pad
    ds = [d[:, k] for k in range(K)]
    D = jnp.stack([sum(w[k, m][None] * ds[k] for k in range(K)) for m in range(5)])
    if base is not None:
        D = D + base.astype(xs.dtype)
    return jax.lax.optimization_barrier(D)


def _derivs_transpose(G, mesh: Mesh):
    """(3, K, N): the transpose of :func:`_derivs_soa`: ``dE/d(x[nbr_k] - x)`` from ``G = dE/dD`` (5, 3, N)."""
    w = mesh.gfd_k.astype(G.dtype)
    K = w.shape[0]
    Gs = [G[m] for m in range(5)]  # sliced once (see _derivs_soa)
    return jnp.stack([sum(w[k, m][None] * Gs[m] for m in range(5)) for k in range(K)], axis=1)


def node_derivatives(x, mesh: Mesh):
    """(N, 5, 3): x_X, x_Y, x_XX, x_XY, x_YY at every node (node-frame reference coordinates)."""
    return jnp.transpose(_derivs_soa(x.T, mesh), (2, 0, 1))


def _curvatures_soa(D, node_dir):
    """Fibre curvatures (2, N) from SoA derivatives (5, 3, N) and fibre dirs (N, 2, 2)."""
    xX, xY, xXX, xXY, xYY = D[0], D[1], D[2], D[3], D[4]
    nrm = _cross(xX, xY)
    n = nrm / _norm(nrm)
    out = []
    for f in range(2):
        c, s = node_dir[:, f, 0], node_dir[:, f, 1]
        xd = c * xX + s * xY
        xdd = c * c * xXX + 2 * c * s * xXY + s * s * xYY
        out.append(-_dot(n, xdd) / _dot(xd, xd))
    return jnp.stack(out)


def fibre_curvatures_from_derivatives(D, node_dir):
    """Fibre curvatures (N, 2), 1/m, from node derivatives (N, 5, 3) and fibre dirs (N, 2, 2)."""
    return _curvatures_soa(jnp.transpose(D, (1, 2, 0)), node_dir).T


def fibre_curvatures(x, mesh: Mesh, ref: ShellRef):
    """Current curvature of each fibre family at each node (N, 2), 1/m (SPEC sign)."""
    return _curvatures_soa(_derivs_soa(x.T, mesh), ref.node_dir.astype(x.dtype)).T


# ------------------------------------------------------------------------------------------- the shell


@pytree_dataclass
class Shell:
    """Mesh, reference quantities and one :class:`~jaxform.materials.Fabric` per ply.

    Attributes:
        mesh: the reference mesh.
        ref: reference fibre quantities (:func:`shell_reference`).
        fabrics: tuple of fabrics, one per ply (their laws are pytree leaves: ``grad`` reaches them).
        shear_reading: static, ``"a14"`` (default, the paper's eq. A.14) or ``"conjugate"``.
    """

    mesh: Mesh
    ref: ShellRef
    fabrics: tuple
    shear_reading: str = static_field(default="a14")

    @staticmethod
    def build(mesh: Mesh, fabrics, *, shear_reading: str = "a14") -> "Shell":
        """A shell on ``mesh`` with one fabric per ply (a single fabric is used for every ply)."""
        if not isinstance(fabrics, (tuple, list)):
            fabrics = (fabrics,) * mesh.n_plies
        fabrics = tuple(fabrics)
        if len(fabrics) != mesh.n_plies:
            raise ValueError(f"Shell.build: {len(fabrics)} fabrics for a mesh of {mesh.n_plies} plies")
        if shear_reading not in SHEAR_READINGS:
            raise ValueError(f"Shell.build: shear_reading = {shear_reading!r}: must be one of {SHEAR_READINGS}")
        ref = shell_reference(mesh, [f.fibre_angles for f in fabrics])
        return Shell(mesh=mesh, ref=ref, fabrics=fabrics, shear_reading=shear_reading)

    def replace(self, **changes) -> "Shell":
        import dataclasses

        return dataclasses.replace(self, **changes)

    def node_masses(self, mass_scale=1.0):
        """(N,) lumped masses, kg: areal mass times lumped area (times ``mass_scale``)."""
        out = []
        for (n0, n1), fab in zip(self.mesh.ply_nodes, self.fabrics):
            out.append(fab.areal_mass * jnp.asarray(self.mesh.node_area[n0:n1]))
        return jnp.concatenate(out) * mass_scale


def _shear_energy(law, gamma, reading: str):
    """Shear energy per reference area, J/m², of a reading (the laws evaluate by Horner's rule)."""
    return law.integral2(gamma) if reading == "a14" else law.integral(gamma)


def shear_resultant(law, gamma, reading: str = "a14"):
    """Shear stress resultant conjugate to ``gamma`` implied by a reading, N/m: ``dW_s/dgamma``."""
    if reading == "a14":
        gamma = jnp.asarray(gamma)
        # d/dgamma integral2(gamma): integral(gamma) with the sign of gamma (odd laws).
        return jnp.where(gamma >= 0, 1.0, -1.0) * law.integral(gamma)
    return law.force(gamma)


def _membrane_density(e1, e2, shell: Shell, t0: int, t1: int, fab):
    """Membrane energy per triangle (J) of ply triangles ``t0:t1`` from SoA edges (3, T): (tension, shear)."""
    ref = shell.ref
    dtype = e1.dtype
    g1, g2 = _fibres_soa(e1, e2, ref.tri_coef[t0:t1].astype(dtype))
    l1 = _stretch(g1)
    l2 = _stretch(g2)
    eh = jnp.broadcast_to(jnp.asarray(fab.fibre_modulus * fab.thickness, dtype), (2,))
    a = ref.tri_area[t0:t1].astype(dtype)
    tension = 0.5 * a * (eh[0] * (l1 - 1.0) ** 2 + eh[1] * (l2 - 1.0) ** 2)
    gamma = ref.theta0[t0:t1].astype(dtype) - _angle(g1, g2)
    shear = a * _shear_energy(fab.shear, gamma, shell.shear_reading)
    return tension, shear


def _bending_density(D, shell: Shell, n0: int, n1: int, fab):
    """Bending energy per node (J) of ply nodes ``n0:n1`` from SoA node derivatives (5, 3, n)."""
    dtype = D.dtype
    k = _curvatures_soa(D, shell.ref.node_dir[n0:n1].astype(dtype))
    k = k - shell.ref.kappa0[n0:n1].T.astype(dtype)
    an = jnp.asarray(shell.mesh.node_area[n0:n1], dtype)
    return an * (fab.bending[0].energy(k[0]) + fab.bending[1].energy(k[1]))


def _local_energy(e1, e2, D, shell: Shell, weights=None):
    """``(sum_k w_k E_k, parts)`` from the edges and node derivatives; ``weights`` (tension, shear,
    bending) default to 1 (the total energy)."""
    mesh = shell.mesh
    dtype = e1.dtype
    tension = jnp.zeros((), dtype)
    shear = jnp.zeros((), dtype)
    bending = jnp.zeros((), dtype)
    for (t0, t1), (n0, n1), fab in zip(mesh.ply_tris, mesh.ply_nodes, shell.fabrics):
        wt, ws = _membrane_density(e1[:, t0:t1], e2[:, t0:t1], shell, t0, t1, fab)
        tension = tension + jnp.sum(wt)
        shear = shear + jnp.sum(ws)
        if fab.bending is not None:
            bending = bending + jnp.sum(_bending_density(D[:, :, n0:n1], shell, n0, n1, fab))
    parts = {"tension": tension, "shear": shear, "bending": bending}
    if weights is None:
        return tension + shear + bending, parts
    wt, ws, wb = weights
    return wt * tension + ws * shear + wb * bending, parts


def _has_bending(shell: Shell) -> bool:
    return any(f.bending is not None for f in shell.fabrics)


def energy_parts(x, shell: Shell):
    """Elastic energies (J) of the deformed plies ``x`` (N, 3): dict(tension, shear, bending)."""
    return _parts_soa(x.T, shell)


def _kinematics(xs, shell: Shell, displacement: bool):
    """Edges and node derivatives (``None`` without bending) from positions, or from
    displacements from the reference (``displacement``)."""
    ref, mesh = shell.ref, shell.mesh
    e1, e2 = _edges(xs, mesh, ref.edge0 if displacement else None)
    D = _derivs_soa(xs, mesh, ref.deriv0 if displacement else None) if _has_bending(shell) else None
    return e1, e2, D


def _parts_soa(xs, shell: Shell, displacement: bool = False):
    return _local_energy(*_kinematics(xs, shell, displacement), shell)[1]


def energy(x, shell: Shell):
    """Total elastic energy, J."""
    p = energy_parts(x, shell)
    return p["tension"] + p["shear"] + p["bending"]


def forces_and_energy(x, shell: Shell):
    """``(forces (N, 3), parts dict)``: internal forces ``-dE/dx`` (N) and the energies (J).

    Each element's (node's) energy depends only on its own edge vectors (derivative stencil), so
    the local gradients are taken element-wise (``grad`` of a sum of independent terms, no
    scatter) and assembled once: triangle corners by gathers (:func:`~jaxform.mesh.assemble_corners`),
    the bending stencil by the transpose of its gather. The result equals ``-jax.grad(energy)`` (tested).
    """
    f, parts = forces_and_energy_soa(x.T, shell)
    return f.T, parts


def forces_and_energy_soa(xs, shell: Shell, weights=None, displacement: bool = False):
    """:func:`forces_and_energy` on structure-of-arrays positions (3, N): forces (3, N), parts.

    ``weights`` (tension, shear, bending): the forces of the weighted energy ``sum_k w_k E_k``
    instead of the total (the parts returned are unweighted). ``displacement``: ``xs`` are the
    displacements ``x - X`` from the mesh nodes (same forces, without the rounding of absolute
    positions; see :class:`ShellRef`).
    """
    mesh = shell.mesh
    has_b = _has_bending(shell)
    e1, e2, D = _kinematics(xs, shell, displacement)
    argnums = (0, 1, 2) if has_b else (0, 1)
    (_, parts), grads = jax.value_and_grad(_local_energy, argnums=argnums, has_aux=True)(e1, e2, D, shell, weights)
    g1, g2 = grads[0], grads[1]
    grad_s = assemble_corners(jnp.concatenate([-(g1 + g2), g1, g2], axis=1), mesh)  # dE/dx of the corners
    if has_b:
        H = _derivs_transpose(grads[2], mesh)  # (3, K, N) dE/d(x_nbr_k - x_i)
        grad_s = grad_s + jnp.zeros_like(xs).at[:, mesh.nbr_k.reshape(-1)].add(H.reshape(3, -1)) - jnp.sum(H, axis=1)
    return -grad_s, parts


@jax.custom_vjp
def forces_and_energy_sym(us, shell: Shell):
    """:func:`forces_and_energy_soa` on displacements ``us = x - X`` (3, N) whose reverse mode
    uses the symmetry of the Hessian.

    Same values as ``forces_and_energy_soa(us, shell, displacement=True)``. Cotangents ``(r, c)``
    of the forces (3, N) and of the energy parts give ``u_bar = -H r + grad(sum_k c_k E_k)`` with
    ``-H r`` taken as the *forward* derivative of the forces along ``r`` (``-H`` is symmetric),
    and ``shell_bar = d/dshell(-grad E . r + sum_k c_k E_k)``.
    Plain reverse mode would transpose every gather of the kernel into a scatter (slow on CPU);
    this way the backward pass has the forward pass's structure. Reverse mode only (no ``jvp``):
    the integrator uses it, :func:`forces_and_energy` stays plain.
    """
    return forces_and_energy_soa(us, shell, displacement=True)


def _sym_fwd(us, shell):
    return forces_and_energy_soa(us, shell, displacement=True), (us, shell)


def _sym_bwd(res, ct):
    (us, shell), (r, c) = res, ct
    c = (c["tension"], c["shear"], c["bending"])
    # -H r: the forward derivative of the forces along r; sum_k c_k grad E_k: the forces of the
    # c-weighted energy (same kernel and assembly as the forward pass, no transposed gathers)
    _, f_r = jax.jvp(lambda y: forces_and_energy_soa(y, shell, displacement=True)[0], (us,), (r,))
    f_c = forces_and_energy_soa(us, shell, weights=c, displacement=True)[0]

    def phi(sh):
        parts, dparts = jax.jvp(lambda z: _parts_soa(z, sh, displacement=True), (us,), (r,))
        return sum(ck * parts[k] - dparts[k] for ck, k in zip(c, ("tension", "shear", "bending")))

    val, pull = jax.vjp(phi, shell)  # the cotangent in phi's own dtype (float64 under x64 with a float32 rig)
    (shell_bar,) = pull(jnp.ones_like(val))
    return f_r - f_c, shell_bar


forces_and_energy_sym.defvjp(_sym_fwd, _sym_bwd)


def forces(x, shell: Shell):
    """Internal nodal forces ``-dE/dx`` (N, 3), N."""
    return forces_and_energy(x, shell)[0]


__all__ = [
    "Shell",
    "ShellRef",
    "shell_reference",
    "energy",
    "energy_parts",
    "forces",
    "forces_and_energy",
    "forces_and_energy_soa",
    "fibre_vectors",
    "shear_angle",
    "fibre_curvatures",
    "shear_resultant",
    "SHEAR_READINGS",
]
