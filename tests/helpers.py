"""Helpers shared by the tests (not a test module): the one finite-difference derivative, and
small stand-in cantilever models that the calibration scripts load with ``--simulate helpers:NAME``."""
import numpy as np

FAST = ("process.speed_mm_per_s=500", "numerics.fibre_mass_scaling=1", "contact.expected_pressure_Pa=1e5",
        "contact.self_contact=false", "contact.implicit_normal=false")
"""The former numerics of the presets (500 mm/s, no fibre mass, a contact stiff for 1e5 Pa and explicit), without
the self-contact of folds: tests of wiring, tool contact and gradients pin them (short, one program
each; flat 25 mm blanks that never fold). The automatic numerics and the self-contact have their own
tests (the self-contact's three rooms were 12 of the 20 s that a 25 mm forming program took to
compile, and half of such a test's time)."""
FAST_SET = tuple(x for kv in FAST for x in ("--set", kv))
""":data:`FAST` as ``jaxform`` command-line options."""


def central_difference(f, x, h, *, index=None, direction=None):
    """Central difference ``(f(x + h d) - f(x - h d)) / (2 h)`` as a float64 numpy array.

    ``d`` is the unit vector along ``index`` of ``x`` (an int or a tuple indexing ``x``), or
    ``direction`` (an array shaped like ``x``), or 1 for a scalar ``x``. ``f`` takes an array shaped
    like ``x`` (float64) and returns anything ``np.asarray`` reads. Use it in float64 (conftest.py
    turns x64 on for the test session).
    """
    x = np.asarray(x, dtype=np.float64)
    if direction is None:
        direction = np.zeros_like(x) if index is not None else np.ones_like(x)
        if index is not None:
            direction[index] = 1.0
    d = np.asarray(direction, dtype=np.float64)
    plus = np.asarray(f(x + h * d), dtype=np.float64)
    minus = np.asarray(f(x - h * d), dtype=np.float64)
    return (plus - minus) / (2.0 * h)


# ----- a small stand-in cantilever ------------------------------------------------------------
# ``simulate_standin(law, overhang=, areal_mass=)`` has the signature of
# ``jaxform.cantilever.simulate``: a discrete inextensible elastica (``n`` straight segments, angles
# as unknowns) whose bending + gravitational energy is minimised by Newton's method with load
# continuation, differentiable (forward and reverse mode) through the unrolled iterations. A test
# double, not physics the package relies on (test_calibration.test_standin_matches_reference checks
# it against the reference elastica). Command-line tests load it as
# ``--simulate helpers:simulate_small`` with tests/ on the PYTHONPATH.

import functools  # noqa: E402
from typing import NamedTuple  # noqa: E402

import jax  # noqa: E402
import jax.numpy as jnp  # noqa: E402

from jaxform.units import GRAVITY  # noqa: E402


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


SMALL = functools.partial(simulate_standin, n=16, steps=4, newton=5)
simulate_small = SMALL  # the command-line tests' MODULE:FUNCTION


def simulate_interrupted(law, **kwargs):
    """``simulate_small`` that first sends this process SIGINT, as Ctrl-C on a terminal does: the
    command-line test of an interrupted fit, without racing a real keyboard."""
    import os
    import signal

    # Python's own Ctrl-C handler, as in a terminal: a process started by a test worker can
    # inherit SIGINT *ignored* (seen once in the full suite: the signal did nothing, the fit ran on)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    os.kill(os.getpid(), signal.SIGINT)
    return SMALL(law, **kwargs)


def simulate_nan(law, *, overhang, areal_mass, **kwargs):
    """A forward model that never gives a finite profile (a fit that cannot start)."""
    out = SMALL(law, overhang=overhang, areal_mass=areal_mass)
    return out._replace(z=out.z * jnp.nan)


def run_calibration_script(name, argv, capsys):
    """Run ``calibration/<name>.py``'s ``main`` in-process -> (exit status, stdout, stderr)."""
    import importlib.util
    import pathlib

    path = pathlib.Path(__file__).resolve().parents[1] / "calibration" / f"{name}.py"
    spec = importlib.util.spec_from_file_location(f"{name}_script", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    try:
        rc = mod.main([str(a) for a in argv])
    except SystemExit as err:  # argparse's refusals
        rc = err.code
    out, err = capsys.readouterr()
    return rc, out, err
