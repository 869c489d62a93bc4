"""The highest frequencies of a shell and its stable explicit step (host, float64, no physics of
its own: the operators are the shell's, linearised at the flat reference).

* Fibre tension: ``omega_m = 2 c / l`` with ``c = sqrt(E h / rho_A)`` and ``l`` the smallest
  triangle altitude, the wave-speed estimate, which the fibre mass's degree is chosen to hold
  (:mod:`jaxform.fibre_mass`; within 2-7 % of the measured spectrum on the Case A blanks under it:
  ``benchmarks/results/step-spectrum-20261205``); with the lumped mass alone the bound ``X`` of
  :func:`spectral_bound` (every state).
* Bending: the largest eigenvalue of ``M^-1 K_b``, ``K_b = sum_nodes A_node sum_f B_f g_f g_f^T``
  with ``g_f`` the node's fibre-curvature stencil (``kappa_f = -g_f . z`` for normal
  displacements ``z`` of the flat blank: :mod:`jaxform.shell`'s ``x_dd`` weights along the fibre)
  and ``B_f`` the law's largest tangent stiffness (:func:`jaxform.materials.max_stiffness`). The
  former closed form ``8 sqrt(B / rho_A) / l^2`` read the Case A blanks' bending frequency 3.2x too
  high, which at 2 mm cost a fifth of the step (a third of its ``omega^2`` was that term).

Both operators' largest eigenvalues by :func:`top_eigenvalue`.
"""
from __future__ import annotations

import numpy as np

from jaxform.shell import Shell

BOUND_MARGIN = 1e-3
""":func:`top_eigenvalue` raises Lanczos' value by this fraction (it converges from below; at tol
1e-4 it read the 1 mm woven blank's fibre operator 2.7e-6 below its value at tol 1e-10, which the
dense solver agrees with on small meshes)."""
DENSE_NODES = 500
""":func:`top_eigenvalue`: a dense eigensolver up to this many rows, Lanczos above."""


def top_eigenvalue(a) -> float:
    """An upper bound of the largest eigenvalue of the symmetric positive semi-definite sparse
    matrix ``a`` (host): Lanczos (``scipy.sparse.linalg.eigsh``; dense up to :data:`DENSE_NODES`
    rows; from a seeded start vector, so that every build of a case chooses the same step) raised
    by :data:`BOUND_MARGIN`, at most Gershgorin's bound (the largest absolute row
    sum), which is also the fallback where Lanczos does not converge."""
    import scipy.sparse.linalg as sla

    gershgorin = float(np.max(np.asarray(abs(a).sum(axis=1)).ravel()))
    try:
        lam = (float(np.linalg.eigvalsh(a.toarray())[-1]) if a.shape[0] <= DENSE_NODES else
               float(sla.eigsh(a, k=1, which="LA", tol=1e-4, return_eigenvectors=False,
                               v0=np.random.default_rng(0).uniform(0.5, 1.5, a.shape[0]))[0]))
    except sla.ArpackNoConvergence:
        lam = gershgorin
    return min(gershgorin, lam * (1.0 + BOUND_MARGIN))


def tension_stiffness(fab):
    """``(E h)_f`` (2,) of a ply's two fibre families, N/m (host, float64)."""
    return np.broadcast_to(np.asarray(fab.fibre_modulus, np.float64) * float(np.asarray(fab.thickness)), (2,))


def spectral_bound(shell: Shell, mass_scale=1.0) -> list:
    """Per ply, an upper bound ``X`` of the eigenvalues of ``M^-1 K_t``, 1/s² (host, float64), that
    holds whatever the current fibre directions.

    With ``d_f = sum_a c_a v_a`` (``c`` the triangle's corner coefficients of ``b_f``), ``v^T K_t v
    = sum A (E h)_f (u_f . d_f)^2 <= sum A (E h)_f |d_f|^2`` for unit ``u_f`` (Cauchy-Schwarz), which
    is ``sum_k v_k^T L v_k`` over the three components, ``L = sum A (E h)_f c c^T`` the scalar
    operator of the reference mesh. So the largest eigenvalue of ``M^-1/2 L M^-1/2`` bounds
    ``M^-1 K_t`` in every deformed state (fibre strains enter only through the small geometric
    stiffness, left out of ``K_t``). It is reached where both families run in one direction (the
    limit of shear: ``v`` the top eigenvector of ``L`` along it); sheared 50 degrees, ``M^-1 K_t``
    reaches 0.885 of it (tests/test_fibre_mass.py). It is found by
    :func:`top_eigenvalue` (Lanczos raised by a margin; Gershgorin's bound of the
    same operator, its largest absolute row sum, where Lanczos does not converge: 1.19x this on
    Case A, woven and NCF alike). The block Gershgorin bound
    used before (every triangle's blocks summed in absolute value) was 1.19x on the woven and 1.39x
    on the NCF, and gave the woven's factor-12 mass degree 14 where this gives 13 (``n ~ sqrt(X)``).
    """
    import scipy.sparse as sp

    mesh = shell.mesh
    m = np.asarray(shell.node_masses(mass_scale), np.float64)
    s = 1.0 / np.sqrt(m)
    tris = np.asarray(mesh.tris)
    coef = np.asarray(shell.ref.tri_coef, np.float64)
    area = np.asarray(shell.ref.tri_area, np.float64)
    out = []
    for (t0, t1), fab in zip(mesh.ply_tris, shell.fabrics):
        eh = tension_stiffness(fab)
        nodes, t = np.unique(tris[t0:t1], return_inverse=True)  # the ply's own nodes
        t, sn = t.reshape(-1, 3), s[nodes]
        rows, cols, vals = [], [], []
        for f in range(2):
            c = np.stack([-(coef[t0:t1, f, 0] + coef[t0:t1, f, 1]), coef[t0:t1, f, 0], coef[t0:t1, f, 1]], 1)
            for i in range(3):
                for j in range(3):
                    rows.append(t[:, i])
                    cols.append(t[:, j])
                    vals.append(area[t0:t1] * eh[f] * c[:, i] * c[:, j] * sn[t[:, i]] * sn[t[:, j]])
        out.append(top_eigenvalue(sp.csr_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                                                shape=(len(nodes),) * 2)))
    return out


def bending_operator(shell: Shell, n0: int, n1: int, stiffness):
    """``K_b`` (n, n), a scipy sparse matrix, N/m, of ply nodes ``n0:n1`` for normal displacements of
    the flat blank: ``sum_i A_i sum_f stiffness[f] g_if g_if^T`` (``stiffness`` (2,) N·m, one per
    fibre family)."""
    import scipy.sparse as sp

    mesh = shell.mesh
    idx = np.arange(n0, n1)
    n = n1 - n0
    nbr = np.asarray(mesh.nbr_k)[:, idx] - n0  # (K, n)
    w = np.asarray(mesh.gfd_k, np.float64)[:, :, idx]  # (K, 5, n)
    nd = np.asarray(shell.ref.node_dir, np.float64)[idx]  # (n, 2, 2)
    area = np.asarray(mesh.node_area, np.float64)[idx]
    rows = np.concatenate([np.broadcast_to(np.arange(n), nbr.shape).ravel(), np.arange(n)])
    k = sp.csr_matrix((n, n))
    for f in range(2):
        c, s = nd[:, f, 0], nd[:, f, 1]
        a = c * c * w[:, 2] + 2 * c * s * w[:, 3] + s * s * w[:, 4]  # (K, n): x_dd along the fibre
        g = sp.csr_matrix((np.concatenate([a.ravel(), -a.sum(0)]), (rows, np.concatenate([nbr.ravel(), np.arange(n)]))),
                          shape=(n, n))
        k = k + g.T @ sp.diags(area * float(stiffness[f])) @ g
    return k


def membrane_frequency(shell: Shell, mass_scale=1.0) -> list:
    """Per ply, the highest fibre-stretch frequency estimate ``omega_m = 2 c / l``, rad/s (host)."""
    nodes = np.asarray(shell.mesh.nodes)
    tris = np.asarray(shell.mesh.tris)
    out = []
    for (t0, t1), fab in zip(shell.mesh.ply_tris, shell.fabrics):
        p = nodes[tris[t0:t1]]
        el = np.linalg.norm(np.stack([p[:, 1] - p[:, 0], p[:, 2] - p[:, 1], p[:, 0] - p[:, 2]], 1), axis=-1)
        alt = (2 * np.asarray(shell.ref.tri_area[t0:t1]) / el.max(axis=1)).min()
        rho = float(np.max(np.asarray(fab.areal_mass))) * float(np.min(np.asarray(mass_scale)))
        eh = float(np.max(np.asarray(fab.fibre_modulus))) * float(np.max(np.asarray(fab.thickness)))
        out.append(2.0 * np.sqrt(eh / rho) / alt)
    return out


def bending_frequency(shell: Shell, mass_scale=1.0) -> list:
    """Per ply, the largest bending frequency of the flat blank, rad/s (host; 0 without bending):
    ``sqrt`` of the largest eigenvalue of ``M^-1 K_b`` (:func:`bending_operator` with the laws'
    largest tangent stiffness, :func:`jaxform.materials.max_stiffness`; the lumped masses)."""
    import scipy.sparse as sp

    from jaxform.materials import max_stiffness

    m = np.asarray(shell.node_masses(mass_scale), np.float64)
    out = []
    for (n0, n1), fab in zip(shell.mesh.ply_nodes, shell.fabrics):
        if fab.bending is None:
            out.append(0.0)
            continue
        b = [float(np.max(np.asarray(max_stiffness(law)))) for law in fab.bending]
        s = sp.diags(1.0 / np.sqrt(m[n0:n1]))
        out.append(float(np.sqrt(top_eigenvalue(s @ bending_operator(shell, n0, n1, b) @ s))))
    return out


def ply_frequencies(shell: Shell, mass_scale=1.0) -> list:
    """Per ply ``(omega_m, omega_b)``, rad/s: :func:`membrane_frequency` and :func:`bending_frequency`."""
    return list(zip(membrane_frequency(shell, mass_scale), bending_frequency(shell, mass_scale)))


def stable_time_step(shell: Shell, mass_scale=1.0, safety: float = 0.8, fibre_mass_factor: float = 1.0,
                     frequencies: list | None = None) -> float:
    """Largest stable central-difference time step of the shell, s (host):
    ``dt = safety * 2 / sqrt(omega_t^2 + omega_b^2)`` over the plies, ``omega_b`` the bending
    eigenvalue of :func:`ply_frequencies` and ``omega_t`` the fibre tension's (the two add as a
    bound: the largest eigenvalue of a sum is at most the sum of the largest). With a fibre mass
    (``fibre_mass_factor`` ``s > 1``, :mod:`jaxform.fibre_mass`) ``omega_t = omega_m / s``, which
    the fibre mass's degree is chosen to hold in every state; with the lumped mass alone
    ``omega_t = sqrt(X)`` (:func:`spectral_bound`, every state; 1.02-1.06x ``omega_m``). The test
    suite checks it against the largest eigenfrequency of the assembled shell (power iteration
    through the shell's forces). ``frequencies``: :func:`ply_frequencies` of ``shell`` at
    ``mass_scale`` where the caller has them (the bending eigenvalue takes about 1 s on Case B's
    1 mm stack)."""
    s = float(fibre_mass_factor)
    bounds = spectral_bound(shell, mass_scale) if s <= 1.0 else [None] * len(shell.fabrics)
    dt = np.inf
    for (wm, wb), x in zip(ply_frequencies(shell, mass_scale) if frequencies is None else frequencies, bounds):
        wt = wm / s if x is None else max(wm, float(np.sqrt(x)))
        dt = min(dt, safety * 2.0 / np.sqrt(wt**2 + wb**2))
    return float(dt)


__all__ = ["BOUND_MARGIN", "DENSE_NODES", "top_eigenvalue", "tension_stiffness", "spectral_bound", "bending_operator",
           "membrane_frequency", "bending_frequency", "ply_frequencies", "stable_time_step"]
