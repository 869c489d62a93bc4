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
from jaxform.mesh import Mesh, assemble_corners
from jaxform.shell_kinematics import (_angle, _angle_terms, _cross, _curvature_terms, _curvatures_soa, _derivs_soa,
                                      _derivs_transpose, _dot, _edges, _fibre_curvatures_np, _fibres_soa, _stretch,
                                      fibre_curvatures, fibre_curvatures_from_derivatives, fibre_vectors, node_derivatives,
                                      shear_angle)

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


def _with_derivative(f, x):
    """``(f(x), f'(x))`` of an elementwise function ``f`` (a law's energy), one forward-mode pass;
    the derivative in ``x``'s dtype, as reverse mode gives it (a law's parameters may be wider)."""
    w, dw = jax.jvp(f, (x,), (jnp.ones_like(x),))
    return w, dw.astype(x.dtype)


def _fibres_and_strains(e1, e2, coef, base=None):
    """``(g1, g2, lambda1, lambda2, lambda1 - 1, lambda2 - 1)`` of triangles: fibre vectors (3, T)
    and stretches and strains (T,), from their edges ``e1, e2`` (3, T) or, with ``base`` (the
    reference edges (2, 3, T)), from the edges' changes from the reference.

    From the fibre vectors alone (no ``base``) the strain ``|g| - 1`` keeps only the digits above
    ``|g|``'s rounding: about 6e-8 in float32, against fibre strains of 1e-5 to 1e-3, a noise that
    the stiff fibre tension turns into forces every step. That noise was what gave a float32 run
    more kinetic energy than float64 (woven Case A at 8 mm: peak KE/IE 0.10 against 0.058, and the
    same 0.10 in float64 with only ``|g|`` rounded to float32; README, issue 13). From the changes,
    the fibre vector's change ``dg`` is known apart from ``g = g0 + dg`` (``g0`` the unit reference
    fibre), and ``lambda**2 - 1 = 2 g0 . dg + dg . dg = (2 g - dg) . dg`` has no cancellation: the
    strain ``(lambda**2 - 1) / (lambda + 1)`` to the roundoff of itself."""
    if base is None:
        g1, g2 = _fibres_soa(e1, e2, coef)
        l1, l2 = _stretch(g1), _stretch(g2)
        return g1, g2, l1, l2, l1 - 1.0, l2 - 1.0
    d1, d2 = _fibres_soa(e1, e2, coef)
    r1, r2 = _fibres_soa(base[0].astype(e1.dtype), base[1].astype(e1.dtype), coef)
    g1, g2 = r1 + d1, r2 + d2
    l1, l2 = _stretch(g1), _stretch(g2)
    return g1, g2, l1, l2, _dot(2.0 * g1 - d1, d1) / (l1 + 1.0), _dot(2.0 * g2 - d2, d2) / (l2 + 1.0)


def _membrane_terms(e1, e2, shell: Shell, t0: int, t1: int, fab, base=None):
    """``(coef, g1, g2, lambda1, lambda2, strain1, strain2, (E h) per family, area, tension energy)``
    of ply triangles ``t0:t1`` (``base``: :func:`_fibres_and_strains`)."""
    ref = shell.ref
    dtype = e1.dtype
    coef = ref.tri_coef[t0:t1].astype(dtype)
    g1, g2, l1, l2, s1, s2 = _fibres_and_strains(e1, e2, coef, base)
    eh = jnp.broadcast_to(jnp.asarray(fab.fibre_modulus * fab.thickness, dtype), (2,))
    a = ref.tri_area[t0:t1].astype(dtype)
    return coef, g1, g2, l1, l2, s1, s2, eh, a, 0.5 * a * (eh[0] * s1 ** 2 + eh[1] * s2 ** 2)


def _membrane_density(e1, e2, shell: Shell, t0: int, t1: int, fab, base=None):
    """Membrane energy per triangle (J) of ply triangles ``t0:t1`` from SoA edges (3, T): (tension, shear)."""
    _, g1, g2, _, _, _, _, _, a, tension = _membrane_terms(e1, e2, shell, t0, t1, fab, base)
    gamma = shell.ref.theta0[t0:t1].astype(e1.dtype) - _angle(g1, g2)
    return tension, a * _shear_energy(fab.shear, gamma, shell.shear_reading)


def _membrane_gradient(e1, e2, shell: Shell, t0: int, t1: int, fab, wt, ws, base=None):
    """``(tension, shear, dE/de1, dE/de2)`` of ply triangles ``t0:t1``, ``E = wt tension + ws shear``:
    the closed form of ``jax.grad`` of :func:`_membrane_density` (tested against it; half its time).

    ``d lambda_f / d g_f = g_f / lambda_f``; ``theta = atan2(s, d)`` with ``s = |g1 x g2|``, ``d = g1 . g2``:
    ``d theta / d g1 = (d g2 x c - s g2) / (s² + d²)``, ``d theta / d g2 = (d c x g1 - s g1) / (s² + d²)``
    (``c`` the unit cross product; both vanish with ``s``, as autodiff's do); ``g_f = e1 coef[f, 0] + e2 coef[f, 1]``
    (with ``base``, the edges' changes: plus the reference's, :func:`_fibres_and_strains`; the derivatives are the same).
    """
    coef, g1, g2, l1, l2, s1, s2, eh, a, tension = _membrane_terms(e1, e2, shell, t0, t1, fab, base)
    theta, cr, s, d = _angle_terms(g1, g2)
    w, dw = _with_derivative(lambda g: _shear_energy(fab.shear, g, shell.shear_reading),
                             shell.ref.theta0[t0:t1].astype(e1.dtype) - theta)
    ch = cr / jnp.maximum(s, jnp.finfo(s.dtype).tiny)
    ts = -ws * a * dw / (s * s + d * d)  # dE/dtheta / (s² + d²): gamma = theta0 - theta
    G1 = (wt * a * eh[0] * s1 / l1) * g1 + ts * (d * _cross(g2, ch) - s * g2)
    G2 = (wt * a * eh[1] * s2 / l2) * g2 + ts * (d * _cross(ch, g1) - s * g1)
    dtype = e1.dtype  # the weights may be wider (cotangents of the energies): gradients in the edges' dtype, as autodiff's
    return (tension, a * w, (G1 * coef[:, 0, 0] + G2 * coef[:, 1, 0]).astype(dtype),
            (G1 * coef[:, 0, 1] + G2 * coef[:, 1, 1]).astype(dtype))


def _bending_density(D, shell: Shell, n0: int, n1: int, fab):
    """Bending energy per node (J) of ply nodes ``n0:n1`` from SoA node derivatives (5, 3, n)."""
    dtype = D.dtype
    k = _curvatures_soa(D, shell.ref.node_dir[n0:n1].astype(dtype))
    k = k - shell.ref.kappa0[n0:n1].T.astype(dtype)
    an = jnp.asarray(shell.mesh.node_area[n0:n1], dtype)
    return an * (fab.bending[0].energy(k[0]) + fab.bending[1].energy(k[1]))


def _bending_gradient(D, shell: Shell, n0: int, n1: int, fab, wb):
    """``(bending energy per node, dE/dD (5, 3, n))`` of ply nodes ``n0:n1``, ``E = wb`` times their energy:
    the closed form of ``jax.grad`` of :func:`_bending_density` (tested against it; 2.5x faster).

    ``kappa = -n . x_dd / q`` (``q = |x_d|²``): ``d kappa / d x_dd = -n / q``, ``d kappa / d x_d = -2 kappa
    x_d / q``, ``d kappa / d n = -x_dd / q``; through ``n = N / |N|`` that is ``(I - n n^T) / |N|``, and
    ``N = x_X x x_Y`` gives ``x_Y x g_N`` on ``x_X`` and ``g_N x x_X`` on ``x_Y``.
    """
    dtype = D.dtype
    nd = shell.ref.node_dir[n0:n1].astype(dtype)
    k0 = shell.ref.kappa0[n0:n1].T.astype(dtype)
    an = jnp.asarray(shell.mesh.node_area[n0:n1], dtype)
    n, ln, fams = _curvature_terms(D, nd)
    energy, gn, G = 0.0, 0.0, [0.0] * 5
    for f, (xd, xdd, q, k) in enumerate(fams):
        w, dw = _with_derivative(fab.bending[f].energy, k - k0[f])
        energy = energy + an * w
        mq = wb * an * dw / q
        c, s = nd[:, f, 0], nd[:, f, 1]
        gxd, gxdd = (-2.0 * mq * k) * xd, -mq * n
        gn = gn - mq * xdd
        G = [G[0] + c * gxd, G[1] + s * gxd, G[2] + (c * c) * gxdd, G[3] + (2 * c * s) * gxdd, G[4] + (s * s) * gxdd]
    gN = (gn - _dot(n, gn) * n) / ln
    G[0], G[1] = G[0] + _cross(D[1], gN), G[1] + _cross(gN, D[0])
    return energy, jnp.stack(G).astype(dtype)


def _ply_base(base, t0, t1):
    return None if base is None else base[:, :, t0:t1]


def _local_energy(e1, e2, D, shell: Shell, weights=None, base=None):
    """``(sum_k w_k E_k, parts)`` from the edges (with ``base``: their changes from it, :func:`_kinematics`)
    and node derivatives; ``weights`` (tension, shear, bending) default to 1 (the total energy)."""
    mesh = shell.mesh
    dtype = e1.dtype
    tension = jnp.zeros((), dtype)
    shear = jnp.zeros((), dtype)
    bending = jnp.zeros((), dtype)
    for (t0, t1), (n0, n1), fab in zip(mesh.ply_tris, mesh.ply_nodes, shell.fabrics):
        wt, ws = _membrane_density(e1[:, t0:t1], e2[:, t0:t1], shell, t0, t1, fab, _ply_base(base, t0, t1))
        tension = tension + jnp.sum(wt)
        shear = shear + jnp.sum(ws)
        if fab.bending is not None:
            bending = bending + jnp.sum(_bending_density(D[:, :, n0:n1], shell, n0, n1, fab))
    parts = {"tension": tension, "shear": shear, "bending": bending}
    if weights is None:
        return tension + shear + bending, parts
    wt, ws, wb = weights
    return wt * tension + ws * shear + wb * bending, parts


def _local_gradients(e1, e2, D, shell: Shell, weights=None, base=None):
    """``(parts, (dE/de1, dE/de2, dE/dD or None))`` of ``E = sum_k w_k E_k``: what ``jax.value_and_grad``
    of :func:`_local_energy` gives, in closed form (:func:`_membrane_gradient`, :func:`_bending_gradient`)."""
    mesh = shell.mesh
    wt, ws, wb = (1.0, 1.0, 1.0) if weights is None else weights
    parts = {k: jnp.zeros((), e1.dtype) for k in ("tension", "shear", "bending")}
    g1, g2, gD = [], [], []
    for (t0, t1), (n0, n1), fab in zip(mesh.ply_tris, mesh.ply_nodes, shell.fabrics):
        et, es, a, b = _membrane_gradient(e1[:, t0:t1], e2[:, t0:t1], shell, t0, t1, fab, wt, ws,
                                          _ply_base(base, t0, t1))
        parts["tension"], parts["shear"] = parts["tension"] + jnp.sum(et), parts["shear"] + jnp.sum(es)
        g1.append(a)
        g2.append(b)
        if D is not None:
            if fab.bending is None:
                gD.append(jnp.zeros_like(D[:, :, n0:n1]))
                continue
            eb, G = _bending_gradient(D[:, :, n0:n1], shell, n0, n1, fab, wb)
            parts["bending"] = parts["bending"] + jnp.sum(eb)
            gD.append(G)
    return parts, (jnp.concatenate(g1, axis=1), jnp.concatenate(g2, axis=1),
                   jnp.concatenate(gD, axis=2) if D is not None else None)


def _has_bending(shell: Shell) -> bool:
    return any(f.bending is not None for f in shell.fabrics)


def energy_parts(x, shell: Shell):
    """Elastic energies (J) of the deformed plies ``x`` (N, 3): dict(tension, shear, bending)."""
    return _parts_soa(x.T, shell)


def _kinematics(xs, shell: Shell, displacement: bool):
    """``(e1, e2, D, base)``: the triangles' edges and the node derivatives (``None`` without bending)
    from positions (``base`` None), or from displacements from the reference (``displacement``):
    then ``e1, e2`` are the edges' changes and ``base`` the reference edges (2, 3, T), from which the
    fibre strains are exact to their own roundoff (:func:`_fibres_and_strains`)."""
    ref, mesh = shell.ref, shell.mesh
    e1, e2 = _edges(xs, mesh)
    D = _derivs_soa(xs, mesh, ref.deriv0 if displacement else None) if _has_bending(shell) else None
    return e1, e2, D, (ref.edge0 if displacement else None)


def _parts_soa(xs, shell: Shell, displacement: bool = False):
    e1, e2, D, base = _kinematics(xs, shell, displacement)
    return _local_energy(e1, e2, D, shell, base=base)[1]


def energy(x, shell: Shell):
    """Total elastic energy, J."""
    p = energy_parts(x, shell)
    return p["tension"] + p["shear"] + p["bending"]


def forces_and_energy(x, shell: Shell):
    """``(forces (N, 3), parts dict)``: internal forces ``-dE/dx`` (N) and the energies (J).

    Each element's (node's) energy depends only on its own edge vectors (derivative stencil), so
    the local gradients are taken element-wise, in closed form (:func:`_local_gradients`: 2-2.5x
    faster than ``jax.grad`` of the densities on CPU), and assembled once: triangle corners by gathers
    (:func:`~jaxform.mesh.assemble_corners`), the bending stencil by the transpose of its gather. The
    result equals ``-jax.grad(energy)`` (tested).
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
    e1, e2, D, base = _kinematics(xs, shell, displacement)
    parts, (g1, g2, gD) = _local_gradients(e1, e2, D, shell, weights, base)
    grad_s = assemble_corners(jnp.concatenate([-(g1 + g2), g1, g2], axis=1), mesh)  # dE/dx of the corners
    if has_b:
        H = _derivs_transpose(gD, mesh)  # (3, K, N) dE/d(x_nbr_k - x_i)
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
    "fibre_curvatures_from_derivatives",
    "node_derivatives",
    "shear_resultant",
    "SHEAR_READINGS",
]
