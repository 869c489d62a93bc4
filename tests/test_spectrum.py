"""The shell's highest frequencies on the host (jaxform.spectrum) against the assembled shell's own
spectrum: power iteration through the shell's forces (autodiff), an operator built independently
of the host's sparse assembly."""

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from jaxform.materials import NCF_FCIM359, WOVEN_38616
from jaxform.mesh import Mesh
from jaxform.shell import Shell, forces
from jaxform.spectrum import ply_frequencies, stable_time_step


def _largest(shell, mask, iters):
    """Largest eigenvalue of ``M^-1 K`` at the flat blank over the displacements ``mask`` allows
    ((3,): which components), by power iteration (float64: the suite runs with x64, tests/conftest.py)."""
    x0 = jnp.asarray(shell.mesh.nodes, jnp.float64)
    m = jnp.asarray(shell.node_masses(), jnp.float64)[:, None]
    mask = jnp.asarray(mask, jnp.float64)
    kv = jax.jit(lambda u: -jax.jvp(lambda x: forces(x, shell), (x0,), (u,))[1] / m * mask)
    u = jnp.asarray(np.random.default_rng(0).normal(size=x0.shape)) * mask
    lam = 0.0
    for _ in range(iters):
        w = kv(u)
        lam = float(jnp.vdot(u, w) / jnp.vdot(u, u))
        u = w / jnp.linalg.norm(w)
    return lam


@pytest.mark.parametrize("fabric", [WOVEN_38616, NCF_FCIM359])
def test_bending_frequency_is_the_shells_and_the_step_holds(fabric):
    """The bending term is the largest eigenvalue of the shell's own bending (normal displacements
    of the flat blank carry bending alone): within 0.1 %, from above (Lanczos' margin). The former
    closed form ``8 sqrt(B / rho_A) / l^2`` was 3.2-3.8x this. With the lumped mass the whole step
    (fibre tension's bound, bending) stays within the assembled shell's linear limit."""
    shell = Shell.build(Mesh.rectangle(0.04, 0.03, 0.005), fabric)
    (wm, wb), = ply_frequencies(shell)
    w_shell = np.sqrt(_largest(shell, (0.0, 0.0, 1.0), 1500))
    assert w_shell <= wb <= 1.001 * w_shell
    closed_form = 8.0 * np.sqrt(float(np.max(fabric.bending[0].b_init)) / float(fabric.areal_mass)) / (0.005 / np.sqrt(2)) ** 2
    assert closed_form > 3.0 * wb
    limit = 2.0 / np.sqrt(_largest(shell, (1.0, 1.0, 1.0), 400))
    assert stable_time_step(shell, safety=1.0) <= limit
