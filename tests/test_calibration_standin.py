"""A small JAX stand-in for the shell cantilever, used to test the calibration machinery alone.

``simulate_standin(law, overhang=, areal_mass=)`` has the signature of
``jaxform.cantilever.simulate``: a discrete inextensible elastica (``n`` straight segments, angles
as unknowns) whose bending + gravitational energy is minimised by Newton's method with load
continuation, differentiable (forward and reverse mode) through the unrolled iterations. It is a
test double, not physics the package relies on; the real fits go through ``jaxform.cantilever``.
The test below checks it against the independent reference elastica (second-order convergence).
"""
import functools
from typing import NamedTuple

import jax
import jax.numpy as jnp
import numpy as np
import pytest

from reference import elastica as E

GRAVITY = 9.81


class StandinResult(NamedTuple):
    x: jax.Array  # (n+1,) m, clamp to tip
    z: jax.Array  # (n+1,) m, negative downwards
    tip_angle: jax.Array  # rad


@functools.partial(jax.jit, static_argnames=("overhang", "n", "steps", "newton"))
def simulate_standin(law, *, overhang, areal_mass, n: int = 48, steps: int = 8, newton: int = 6):
    h = overhang / n
    w = areal_mass * GRAVITY

    def energy(theta, lam):
        # curvature at interior nodes (between segment midpoints, weight h) and at the clamp
        # (from the clamped direction to the first midpoint, weight h/2): second order
        kappa = jnp.diff(theta) / h
        kappa_c = theta[0] / (0.5 * h)
        z = jnp.concatenate([jnp.zeros(1, theta.dtype), -h * jnp.cumsum(jnp.sin(theta))])
        bend = h * jnp.sum(law.energy(kappa)) + 0.5 * h * law.energy(kappa_c)
        return bend + lam * w * h * jnp.sum(0.5 * (z[:-1] + z[1:]))

    grad = jax.grad(energy)
    hess = jax.hessian(energy)

    def newton_step(theta, lam):
        return theta - jnp.linalg.solve(hess(theta, lam), grad(theta, lam))

    theta = jnp.zeros(n, jnp.result_type(float)) * law.b_init
    for k in range(1, steps + 1):
        lam = k / steps
        theta = jax.lax.fori_loop(0, newton, lambda i, t: newton_step(t, lam), theta)
    x = jnp.concatenate([jnp.zeros(1, theta.dtype), h * jnp.cumsum(jnp.cos(theta))])
    z = jnp.concatenate([jnp.zeros(1, theta.dtype), -h * jnp.cumsum(jnp.sin(theta))])
    return StandinResult(x=x, z=z, tip_angle=theta[-1])


@pytest.mark.parametrize("L", [0.1])
def test_standin_matches_reference(L):
    from jaxform.materials import VoceBending

    law = VoceBending(b_inf=3e-5, m0=5e-3, kappa0=25.0)
    ref = E.solve_cantilever(E.voce_moment(3e-5, 5e-3, 25.0), L, 0.21, n=3)
    errs = []
    for n in (24, 48):
        out = simulate_standin(law, overhang=L, areal_mass=0.21, n=n)
        errs.append(abs(float(out.z[-1]) - ref["z"][-1]))
    assert errs[1] < 0.02 * abs(ref["z"][-1])
    assert errs[1] < 0.35 * errs[0]  # ~second order
