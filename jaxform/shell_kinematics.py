"""The shell's kinematics on structure-of-arrays positions (3, N): triangle edges and fibre vectors,
the angle between the fibre families, the curvature stencil's node derivatives and the fibres'
normal curvatures (the definitions are :mod:`jaxform.shell`'s docstring's). The energies, their
closed-form gradients and the forces are :mod:`jaxform.shell`'s; this module holds only geometry,
shared with the fibre mass (:mod:`jaxform.fibre_mass`).
"""
from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np

from jaxform.geometry import safe_sqrt, tiny_sqrt
from jaxform.mesh import Mesh


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


def _edges(xs, mesh: Mesh):
    """Triangle edge vectors ``x1 - x0``, ``x2 - x0`` (3, T) each (of displacements: the edges' changes)."""
    t = mesh.tris
    x0 = xs[:, t[:, 0]]
    return xs[:, t[:, 1]] - x0, xs[:, t[:, 2]] - x0


def _fibres_soa(e1, e2, coef):
    g1 = e1 * coef[:, 0, 0] + e2 * coef[:, 0, 1]
    g2 = e1 * coef[:, 1, 0] + e2 * coef[:, 1, 1]
    return g1, g2


def _angle_terms(g1, g2):
    """``(theta, c, |c|, d)``: the angle between SoA vectors (3, ...), their cross product and dot."""
    cr = _cross(g1, g2)
    s, d = _norm(cr), _dot(g1, g2)
    return jnp.arctan2(s, d), cr, s, d


def _angle(g1, g2):
    return _angle_terms(g1, g2)[0]


def fibre_vectors(x, mesh: Mesh, ref):  # ref: jaxform.shell.ShellRef
    """Current fibre vectors ``g_f = F e0_f`` per triangle: (T, 2, 3) (stretch = norm)."""
    e1, e2 = _edges(x.T, mesh)
    g1, g2 = _fibres_soa(e1, e2, ref.tri_coef.astype(x.dtype))
    return jnp.stack([g1.T, g2.T], axis=1)


def shear_angle(g, ref):
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


def _curvature_terms(D, node_dir):
    """``(n, |N|, [(x_d, x_dd, |x_d|², kappa)] per family)`` from SoA derivatives (5, 3, N) and fibre
    dirs (N, 2, 2): the unit normal ``n = N / |N|``, ``N = x_X x x_Y``, and each family's curvature."""
    xX, xY, xXX, xXY, xYY = D[0], D[1], D[2], D[3], D[4]
    nrm = _cross(xX, xY)
    ln = _norm(nrm)
    n = nrm / ln
    out = []
    for f in range(2):
        c, s = node_dir[:, f, 0], node_dir[:, f, 1]
        xd = c * xX + s * xY
        xdd = c * c * xXX + 2 * c * s * xXY + s * s * xYY
        q = _dot(xd, xd)
        out.append((xd, xdd, q, -_dot(n, xdd) / q))
    return n, ln, out


def _curvatures_soa(D, node_dir):
    """Fibre curvatures (2, N) from SoA derivatives (5, 3, N) and fibre dirs (N, 2, 2)."""
    return jnp.stack([k for *_, k in _curvature_terms(D, node_dir)[2]])


def fibre_curvatures_from_derivatives(D, node_dir):
    """Fibre curvatures (N, 2), 1/m, from node derivatives (N, 5, 3) and fibre dirs (N, 2, 2)."""
    return _curvatures_soa(jnp.transpose(D, (1, 2, 0)), node_dir).T


def fibre_curvatures(x, mesh: Mesh, ref):  # ref: jaxform.shell.ShellRef
    """Current curvature of each fibre family at each node (N, 2), 1/m (SPEC sign)."""
    return _curvatures_soa(_derivs_soa(x.T, mesh), ref.node_dir.astype(x.dtype)).T


__all__ = ["fibre_vectors", "shear_angle", "node_derivatives", "fibre_curvatures", "fibre_curvatures_from_derivatives"]
