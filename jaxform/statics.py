"""Static equilibrium ``grad E(u) = 0`` of the shell lab rigs (cantilever, picture frame, bias extension).

One solver and one gradient serve every rig. A rig states its problem as a pytree (arrays are
leaves, so one compile serves every law and load of a given mesh) with three methods:

* ``energy(u, load) -> scalar``: total potential energy (J) of the unknowns ``u`` (n,) under the
  load parameters ``load`` (m,) (gravity, a continuation factor, ...; unused by a rig without a
  load path);
* ``hessian(u, load) -> (n, n)``: its Hessian (dense ``jax.hessian``, or one assembled from a few
  coloured gradient JVPs);
* ``lift(du) -> array``: the node displacements (m) a step ``du`` makes, for the step cap and the
  small-step test.

:func:`solve` is a damped (Levenberg–Marquardt) Newton method along a load path in one
``lax.while_loop``: at each path point it iterates ``(H + mu diag|H|) du = grad E`` with the step
capped at ``step_max`` (m), tried at a few lengths at once and accepted where the energy does not
rise (``mu`` falls tenfold on success, rises tenfold on failure); it moves to the next path point
when ``|grad E| <= tol_k``, when an accepted step is below ``xtol * tol_k / tol_K`` (m; the
force residual's floor is round-off in stiff fibre forces), or after ``max_iter`` iterations there,
with a first-order load predictor ``du = -H^-1 (d grad E / d load) d load`` (over the load
components the caller asks it to predict).

:func:`implicit` gives the equilibrium its derivative by the implicit function theorem: the value
``u* - H^-1 grad E(u*, p)`` with ``u*`` and ``H`` held constant is ``u*``, and its derivative with
respect to anything ``E`` depends on (law parameters, masses, moduli, prescribed positions) is
``-H^-1 d(grad E)/dp``, in forward and reverse mode, without differentiating the iterations.

Why not ``optimistix.root_find`` (Newton) with ``ImplicitAdjoint``: the rigs need what a plain
root find does not give, an energy merit function (a Newton step on a nearly inextensible strip
must not be taken unless the energy drops), a load path with a predictor, and a Hessian assembled
by colouring; the adjoint is the same implicit-function theorem, written in four lines above.
"""
from __future__ import annotations

from typing import Any, NamedTuple

import jax
import jax.numpy as jnp

_TRIAL_STEPS = (1.0, 0.5, 0.25, 0.1, 0.03)  # step lengths tried at once (energies are cheap next to H)


class Equilibrium(NamedTuple):
    """Result of :func:`solve`.

    Attributes:
        u: (n,) unknowns at equilibrium.
        hessian: (n, n) Hessian of the energy at the last iterate (for :func:`implicit`).
        iterations: Newton iterations along the whole path.
        grad_norm: ``|grad E|`` at the last iterate (N for displacement unknowns).
    """

    u: Any
    hessian: Any
    iterations: Any
    grad_norm: Any


@jax.jit
def solve(problem, u0, loads, tols, max_iter, step_max, xtol, predict=None) -> Equilibrium:
    """Damped Newton on ``grad E = 0`` along the load path (module docstring); jitted.

    Args:
        problem: the rig's problem pytree (``energy``, ``hessian``, ``lift``).
        u0: (n,) starting unknowns.
        loads: (K, m) load parameters of the path points (K = 1: no path).
        tols: (K,) gradient-norm tolerance at each path point (N).
        max_iter: iteration cap per path point.
        step_max: largest node displacement of one step, m.
        xtol: small-step convergence at the last path point, m.
        predict: (m,) weights of the load components in the predictor (default all 1; 0 leaves a
            component out, e.g. a continuation factor whose first-order prediction overshoots).
    """
    K = loads.shape[0]
    predict = jnp.ones(loads.shape[1], loads.dtype) if predict is None else predict
    steps = jnp.asarray(_TRIAL_STEPS, u0.dtype)
    grad = jax.grad(problem.energy)

    def cap(du):
        return du * jnp.minimum(1.0, step_max / (jnp.max(jnp.abs(problem.lift(du))) + 1e-30))

    def body(s):
        k, u, mu, it, it_k, H, _, small = s
        load = loads[k]
        e, gr = jax.value_and_grad(problem.energy)(u, load)
        H = problem.hessian(u, load)
        done = (jnp.linalg.norm(gr) <= tols[k]) | small | (it_k >= max_iter)
        d = jnp.abs(jnp.diag(H))
        d = d + 1e-12 * jnp.max(d)
        dload = jnp.where(done, predict * (loads[jnp.minimum(k + 1, K - 1)] - load), 0.0)
        dgrad = jax.jvp(lambda lo: grad(u, lo), (load,), (dload,))[1]
        sol = jnp.linalg.solve(H + mu * jnp.diag(d), jnp.stack([gr, dgrad], 1))
        du = cap(sol[:, 0])
        e_try = jax.vmap(lambda t: problem.energy(u - t * du, load))(steps)
        e_try = jnp.where(jnp.isfinite(e_try), e_try, jnp.inf)
        best = jnp.argmin(e_try)
        du = steps[best] * du
        ok = (e_try[best] <= e) & ~done
        u = jnp.where(done, u - cap(sol[:, 1]), jnp.where(ok, u - du, u))
        mu = jnp.where(done, mu, jnp.where(ok, jnp.maximum(mu * 0.1, 1e-14), jnp.minimum(mu * 10.0, 1e12)))
        small = ok & (jnp.max(jnp.abs(problem.lift(du))) <= xtol * tols[k] / tols[K - 1])
        return (k + done, u, mu, it + 1, jnp.where(done, 0, it_k + 1), H, jnp.linalg.norm(gr), small)

    n = u0.shape[0]
    s0 = (jnp.asarray(0), u0, jnp.asarray(1e-6, u0.dtype), jnp.asarray(0), jnp.asarray(0),
          jnp.zeros((n, n), u0.dtype), jnp.asarray(jnp.inf, u0.dtype), jnp.asarray(False))
    _, u, _, it, _, H, gn, _ = jax.lax.while_loop(lambda s: s[0] < K, body, s0)
    return Equilibrium(u, H, it, gn)


@jax.jit
def implicit(problem, u_star, hessian, load):
    """``u* - H^-1 grad E(u*, load)``: value ``u*``, derivative ``-H^-1 d(grad E)/dp`` (the IFT).

    ``u_star`` and ``hessian`` come from :func:`solve` (held constant); ``problem`` carries the
    parameters to differentiate. No regularisation: a rig's softest mode (a strip's global sag) is
    ~1e-9 of the fibre stiffness on the diagonal, and a Levenberg shift biases the derivative
    (measured on the cantilever: 0.3 % at 1e-12).
    """
    u_star, hessian = jax.lax.stop_gradient(u_star), jax.lax.stop_gradient(hessian)
    return u_star - jnp.linalg.solve(hessian, jax.grad(problem.energy)(u_star, load))


def dense_hessian(problem, u, load):
    """(n, n) Hessian of ``problem.energy`` by ``jax.hessian`` (small problems)."""
    return jax.hessian(problem.energy)(u, load)


__all__ = ["Equilibrium", "solve", "implicit", "dense_hessian"]
