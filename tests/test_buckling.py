"""Euler buckling of a strip on the shell: the critical load its bending stiffness predicts (float64).

A pinned–pinned strip of length ``L`` along the first fibre family, compressed along its axis by a
load ``p`` per unit width. The pre-buckling state is the uniformly shortened flat strip (fibre
stretch ``lambda = 1 - p/(E h)``, an exact equilibrium of the shell). Its stability is that of the
Hessian of the shell energy with respect to the out-of-plane dofs (the in-plane/out-of-plane
coupling vanishes at the flat state by the ``z -> -z`` symmetry), with ``z = 0`` at both ends:
the compressed fibres' tension term gives the geometric stiffness, the fibre bending the elastic
one. The critical load is where the smallest eigenvalue changes sign (bisection), compared with
``p_cr = pi^2 B / L^2`` (``B`` the tangent stiffness at zero curvature: ``B_init`` for Voce).
"""
import math

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxform.materials import Fabric
from jaxform.materials.bending import LinearBending, VoceBending
from jaxform.materials.fabric import WOVEN_38616
from jaxform.mesh import Mesh
from jaxform.shell import Shell, energy

L, W = 0.2, 0.02


def critical_load(bending_law, n_length=40, n_width=2, *, cylindrical=True, rtol=1e-4):
    """Critical load per unit width (N/m) by bisection on the sign of the lowest eigenvalue, and Euler's.

    ``cylindrical``: out-of-plane displacements uniform across the width (one dof per node column,
    the beam-like Euler mode); otherwise every node's ``z`` is free.
    """
    fab = Fabric(thickness=3e-4, areal_mass=0.21, fibre_modulus=3e9, shear=WOVEN_38616.shear,
                 bending=(bending_law, bending_law), fibre_angles=(0.0, 0.5 * math.pi))
    mesh = Mesh.strip(L, W, n_length, n_width)
    shell = Shell.build(mesh, fab)
    X = jnp.asarray(mesh.nodes)
    eh = float(fab.fibre_modulus * fab.thickness)
    inner = np.nonzero((np.asarray(X[:, 0]) > 1e-9) & (np.asarray(X[:, 0]) < L - 1e-9))[0]
    col = np.rint(np.asarray(X[:, 0]) / (L / n_length)).astype(int)  # node column 0..n_length
    P = np.zeros((X.shape[0], n_length - 1))
    P[inner, col[inner] - 1] = 1.0  # z of a node = its column's dof (ends pinned at z = 0)
    P = jnp.asarray(P if cylindrical else np.eye(X.shape[0])[:, inner])

    @jax.jit
    def lowest_eigenvalue(p):
        lam = 1.0 - p / eh
        base = X.at[:, 0].multiply(lam)

        def e(q):
            return energy(base.at[:, 2].set(P @ q), shell)

        H = jax.hessian(e)(jnp.zeros(P.shape[1]))
        return jnp.linalg.eigvalsh(H)[0]

    b0 = float(bending_law.b_init)
    p_euler = math.pi**2 * b0 / L**2
    lo, hi = 0.0, 2.0 * p_euler
    assert float(lowest_eigenvalue(lo)) > 0 and float(lowest_eigenvalue(hi)) < 0
    while hi - lo > rtol * p_euler:
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if float(lowest_eigenvalue(mid)) > 0 else (lo, mid)
    return 0.5 * (lo + hi), p_euler


@pytest.mark.parametrize("law", [LinearBending(2e-4), WOVEN_38616.bending[0]], ids=["linear", "voce"])
def test_strip_buckles_at_the_euler_load(law):
    p_cr, p_euler = critical_load(law, cylindrical=True)
    err = abs(p_cr / p_euler - 1.0)
    print(f"p_cr = {p_cr:.6g} N/m, Euler {p_euler:.6g} N/m, error {err:.2e}")
    assert err < 0.05, (p_cr, p_euler)
    if isinstance(law, VoceBending):  # the onset is governed by B_init, not B_inf
        assert p_cr > 5 * math.pi**2 * float(law.b_inf) / L**2


def test_unrestricted_lowest_mode_at_4_cells_across_is_euler():
    """All ``z`` free: the lowest mode is the antisymmetric ``z = y f(x)`` (no twist stiffness in the
    decoupled fibre bending; in the continuum its critical load equals Euler's), whose fibre
    curvature grows linearly towards the free edges. The free-edge curvature stencil reads it at
    the edge node (cubic terms in the patch fit, ``jaxform.mesh``): measured -0.05 % at 2, 4, 8
    and 16 cells across (the bisection's tolerance). With the quadratic fit alone it was read
    averaged over the edge row and the next two: -84 % (2 cells), -34 % (4), -9 % (8)."""
    p_cr, p_euler = critical_load(LinearBending(2e-4), n_width=4, cylindrical=False, rtol=1e-3)
    assert abs(p_cr / p_euler - 1.0) < 0.01, (p_cr, p_euler)


@pytest.mark.slow
@pytest.mark.parametrize("n_width", [2, 8, 16])
def test_unrestricted_lowest_mode_is_euler_at_any_width_resolution(n_width):
    p_cr, p_euler = critical_load(LinearBending(2e-4), n_width=n_width, cylindrical=False, rtol=1e-3)
    assert abs(p_cr / p_euler - 1.0) < 0.01, (n_width, p_cr, p_euler)
