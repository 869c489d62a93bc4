"""Fibre-selective mass: a larger stable time step without slowing the forming physics.

The explicit step of a fabric is limited by the fibre-stretch waves (``c = sqrt(E h / rho_A)``,
about 3 km/s for carbon), yet fibres barely stretch during forming: the motion that matters
(draw-in, trellis shear, bending, wrinkling) leaves the fibre lengths unchanged. Uniform mass
scaling slows all of it alike (it is exactly a faster punch). This module gives inertia to fibre
*stretching* only (a selective mass scaling in the sense of Olovsson et al., IJNME 2005, built
from the fibre-tension stiffness)::

    K_t = sum_tri sum_f  A (E h)_f  b_f b_f^T,   b_f = d lambda_f / d x

with ``lambda_f = |g_f|`` the fibre stretch of triangle ``tri`` (:mod:`jaxform.shell`). Motion
that stretches no fibre (rigid motion, trellis shear, inextensible bending: ``K_t v = 0``) is left
with its true lumped mass ``M``.

The mass is defined through its inverse, a polynomial (no linear solve)::

    a = C f,   C = q(G) M^-1,   G = M^-1 K_t / X

``X`` bounds the spectrum of ``M^-1 K_t`` from above in every deformed state (:func:`spectral_bound`:
the largest eigenvalue of the reference mesh's scalar operator, which ``K_t`` cannot exceed whatever
its fibre directions), so ``G``'s spectrum lies in ``[0, 1]``. ``q`` is the damped Chebyshev
polynomial of degree ``n - 1`` with
``1 - y q(y) / q(0)`` proportional to ``T_n(w0 - w1 y)`` (``w0 = 1 + eta / n^2``, ``w1 = 1 + w0``,
``eta = 0.05``: the residual polynomial of ``n`` steps of a Chebyshev semi-iteration, the same
construction as Runge-Kutta-Chebyshev stability polynomials), normalised to ``q(0) = 1``:

* ``q(0) = 1``: motion with ``K_t v = 0`` keeps the mass ``M`` exactly (``C M v = v``);
* ``0 < q(y) <= 1`` on ``[0, 1]``: ``C`` is symmetric positive definite and no motion is lighter
  than with ``M`` (the bending and shear limits of the step are unchanged);
* ``y q(y) <= peak(n) / n^2`` (``peak`` about 1.008): the fibre-stretch frequencies
  ``omega^2 = X y q(y)`` are bounded by ``X peak / n^2``. :func:`fibre_mass` takes the smallest
  ``n`` with ``sqrt(X peak(n)) / n <= omega_m / s`` (``omega_m`` the membrane estimate of
  :func:`jaxform.spectrum.stable_time_step`), so that the membrane limit grows by the factor ``s``;
* long fibre-stretch waves (small ``y``) get the mass ``M / q ~ M (1 + (n^2 - 1) y / 3)``:
  the added inertia is smallest where the waves are slow anyway.

Cost: ``n - 1`` products with ``K_t`` per step (gathers, a few multiply-adds, a scatter), no
reductions, no convergence test, fixed shapes; differentiable as any other loop of ``jit`` code.
Where the fibres run along the mesh's grid lines (woven 0/90 on the square blank) ``K_t`` is a set
of springs between nodes a fixed index apart (:func:`grid_springs`), and a product is a few
differences of shifted arrays: 0.14 against 0.42 ms at 2 mm (woven Case A, 15,625 nodes, two
cores), a step at factor 12 10.8 against 14.8 ms; written as padded copies rather than indexed
adds, the 12 products and their recurrence fuse into one pass each, 1.7 -> 1.1 ms at 2 mm.
(A Jacobi-preconditioned conjugate-gradient solve with ``M + alpha K_t`` needed about ``2 s``
iterations of a dearer kind, warm starts did not help: 28 ms/step at ``s = 10`` against 19 ms
with this polynomial, 2 mm hemisphere, two cores.)

The integrator carries the momentum ``p = C^-1 v`` of the free dofs: ``p += dt f``, ``v = C p``,
so the kinetic energy ``1/2 v . p`` needs no inverse of ``C``. ``C`` follows the fibre
directions at the step's positions, so the mass depends on the positions, and the momentum
equation has the term such a mass adds (Hamilton, ``H = 1/2 p^T C(x) p + V(x)``)::

    dp/dt = f - 1/2 d(p^T C(x) p)/dx          (:func:`geometric_force`, reverse mode)

Without it a triangle that turns (a free corner whipping in-plane, a spinning sheet) carries the
momentum of its heavy fibre-stretch directions into light ones and gains energy from nothing: a
free NCF sheet spun at 200 rad/s with ``s = 12`` blows up within half a turn without the term
and keeps its energy within 0.6 % with it (tests/test_fibre_mass.py). It costs about one more
polynomial per step, more on a fine mesh (woven Case A, ``s = 12``, degree 14: 5.2 -> 8.8 ms per
step at 4 mm, 20.1 -> 46.0 ms at 2 mm), so it is asked for (``momentum_term``; the forming case
key ``numerics.fibre_mass_momentum_term``), and without it the automatic factor stays where runs
were measured to complete (:mod:`jaxform.forming.numerics`).
"""
from __future__ import annotations

import functools
import math
from typing import Any

import jax
import jax.numpy as jnp
import numpy as np

from jaxform._pytree import pytree_dataclass, static_field
from jaxform.mesh import assemble_corners
from jaxform.shell import Shell
from jaxform.shell_kinematics import _dot, _edges, _fibres_soa, _stretch
from jaxform.spectrum import membrane_frequency, spectral_bound, tension_stiffness
ETA = 0.05  # Chebyshev damping: keeps q > 0 (undamped, q has zeros: modes of infinite mass)


@pytree_dataclass
class FibreMass:
    """The fibre-selective mass.

    Attributes:
        weight: (2, T) ``A (E h)_f / X`` per fibre family and triangle (``X`` of the triangle's
            ply), kg·m²: ``K_t / X``, see :func:`stiffness_times`; ``None`` where ``springs`` hold it.
        springs: ``K_t / X`` of a mesh whose fibres run along its edges (:func:`grid_springs`), a
            tuple of (N - stride,) spring weights, kg, one per entry of ``strides``; else ``None``.
        strides: static, the node-index distances of the springs' two ends (a grid's 1 and row
            length); empty for the triangle form.
        degree: static, the Chebyshev degree ``n`` (``n - 1`` products with ``K_t`` per step).
        factor: static, the factor ``s`` the membrane step limit grows by (for reports).
        geometric: static, the momentum equation has the term a position-dependent mass adds,
            ``-1/2 d(p^T C(x) p)/dx`` (:func:`geometric_force`; exact, at about twice the step's
            cost on a fine mesh).
    """

    weight: Any
    degree: int = static_field()
    factor: float = static_field(default=1.0)
    geometric: bool = static_field(default=False)
    springs: Any = None
    strides: tuple = static_field(default=())


@functools.lru_cache(maxsize=None)
def chebyshev(n: int):
    """Host constants of the degree-``n`` inverse mass: ``(theta, a, b, q0)`` of the recurrence
    ``z_0 = 0, d_0 = r_0 / theta``; ``z_{k+1} = z_k + d_k``, ``r_{k+1} = r_k - G d_k``,
    ``d_{k+1} = a_k d_k + b_k r_{k+1}`` (``k < n - 1``), after which ``z_n = q0 q(G) r_0``."""
    w0 = 1.0 + ETA / n**2
    delta = 1.0 / (1.0 + w0)
    theta = w0 * delta
    sigma = theta / delta
    rho = 1.0 / sigma
    a, b = [], []
    for _ in range(n - 1):
        rho_new = 1.0 / (2.0 * sigma - rho)
        a.append(rho_new * rho)
        b.append(2.0 * rho_new / delta)
        rho = rho_new
    return theta, tuple(a), tuple(b), float(_q(np.zeros(1), n, theta, a, b)[0])


def _q(y, n, theta, a, b):
    """The unnormalised polynomial on scalars ``y`` (host, float64)."""
    z, r, d = np.zeros_like(y), np.ones_like(y), np.ones_like(y) / theta
    for k in range(n - 1):
        z, r = z + d, r - y * d
        d = a[k] * d + b[k] * r
    return z + d


@functools.lru_cache(maxsize=None)
def peak(n: int) -> float:
    """``n^2 max_{0<=y<=1} y q(y)`` of the normalised degree-``n`` polynomial (host; a fine grid
    plus 0.1% for what falls between its points)."""
    theta, a, b, q0 = chebyshev(n)
    y = np.linspace(0.0, 1.0, 40001)
    return 1.001 * n**2 * float(np.max(y * _q(y, n, theta, a, b))) / q0


def degree_for(factor: float, bound: float, omega_m: float) -> int:
    """The smallest Chebyshev degree ``n`` with ``sqrt(bound peak(n)) / n <= omega_m / factor``."""
    n = max(1, math.ceil(factor * math.sqrt(bound) / omega_m) - 1)
    while math.sqrt(bound * peak(n)) / n > omega_m / factor:
        n += 1
    return n


def fibre_mass(shell: Shell, factor: float, *, mass_scale=1.0, dtype=jnp.float32,
               momentum_term: bool = False, springs: bool = True) -> FibreMass | None:
    """The :class:`FibreMass` that grows the membrane step limit of ``shell`` by ``factor`` (>= 1;
    1 gives ``None``: the lumped mass alone). Host-side; one degree for all plies (the largest
    any ply needs), each ply's stiffness scaled by its own bound; ``momentum_term``: see
    :attr:`FibreMass.geometric`; ``springs``: the springs' form where the mesh allows
    (:func:`grid_springs`; the same operator, faster), else the triangles'."""
    factor = float(factor)
    if not np.isfinite(factor) or factor < 1.0:
        raise ValueError(f"fibre_mass: factor = {factor!r}: must be a finite number >= 1 (1 = off)")
    if factor == 1.0:
        return None
    bounds = spectral_bound(shell, mass_scale)
    n = max(degree_for(factor, x, wm) for x, wm in zip(bounds, membrane_frequency(shell, mass_scale)))
    area = np.asarray(shell.ref.tri_area, np.float64)
    w = np.zeros((2, len(area)))
    for (t0, t1), fab, x in zip(shell.mesh.ply_tris, shell.fabrics, bounds):
        eh = tension_stiffness(fab)
        w[:, t0:t1] = area[None, t0:t1] * eh[:, None] / x
    springs = grid_springs(shell, w) if springs else None
    if springs is None:
        return FibreMass(weight=jnp.asarray(w, dtype), degree=n, factor=factor, geometric=bool(momentum_term))
    return FibreMass(weight=None, degree=n, factor=factor, geometric=bool(momentum_term),
                     springs=tuple(jnp.asarray(k, dtype) for k in springs.values()), strides=tuple(springs))


MAX_STRIDES = 4
""":func:`grid_springs` gives up beyond this many strides (each costs a pass over the nodes)."""


def grid_springs(shell: Shell, weight) -> dict | None:
    """``K_t`` as springs between node pairs, where the mesh allows: ``{stride: (N - stride,)
    weights}``, the spring from node ``k`` to ``k + stride`` weighing ``weight[k]`` (0: none), or
    ``None`` (host, float64; ``weight`` (2, T) the triangle form's weights).

    Where a triangle has a leg along a fibre (a grid whose lines are the fibres: woven 0/90 on the
    blank's grid), the fibre's gradient ``g_f = sum_a c_a x_a`` is that leg's vector over its
    reference length (``c = -c_j, c_j, 0``), so its term of ``K_t`` is a spring along the current
    leg, ``w c_j^2 (d d^T)`` on the leg's two nodes, and the two triangles that share the leg add
    their weights on the same spring. ``K_t p`` is then two differences of shifted arrays per
    stride (about 3x faster than the triangles' gathers at 2 mm). ``None`` where a triangle's
    fibre spans all three corners (fibres off the grid lines: the +-45 deg NCF) or the pairs' node
    distances take more than :data:`MAX_STRIDES` values."""
    tris = np.asarray(shell.mesh.tris)
    coef = np.asarray(shell.ref.tri_coef, np.float64)
    out: dict = {}
    for f in range(2):
        c = np.stack([-(coef[:, f, 0] + coef[:, f, 1]), coef[:, f, 0], coef[:, f, 1]], 1)
        scale = np.abs(c).max(axis=1)
        leg = np.abs(c) > 1e-9 * scale[:, None]
        if not np.all(leg.sum(axis=1) == 2):
            return None
        k = np.argsort(~leg, axis=1, kind="stable")[:, :2]
        ends, cs = np.take_along_axis(tris, k, 1), np.take_along_axis(c, k, 1)
        if np.any(np.abs(cs.sum(axis=1)) > 1e-9 * scale):
            return None
        a, stride = ends.min(axis=1), np.abs(ends[:, 1] - ends[:, 0])
        for d in np.unique(stride):
            if d not in out:
                if len(out) == MAX_STRIDES:
                    return None
                out[int(d)] = np.zeros(shell.mesh.nodes.shape[0] - int(d))
            on = stride == d
            np.add.at(out[int(d)], a[on], weight[f, on] * cs[on, 0] ** 2)
    return dict(sorted(out.items()))


def fibre_units(xs, fm: FibreMass | None, shell: Shell):
    """Unit current fibre directions at positions ``xs`` (3, N): per triangle, two (3, T) arrays;
    in ``fm``'s spring form (:func:`grid_springs`) per spring, one (3, N - stride) array per stride
    (0 where no spring)."""
    if fm is not None and fm.strides:
        out = []
        for d, w in zip(fm.strides, fm.springs):
            g = xs[:, d:] - xs[:, :-d]
            out.append(jnp.where(w > 0, g / jnp.where(w > 0, _stretch(g), 1.0), 0.0))
        return tuple(out)
    e1, e2 = _edges(xs, shell.mesh)
    g1, g2 = _fibres_soa(e1, e2, shell.ref.tri_coef.astype(xs.dtype))
    return g1 / _stretch(g1), g2 / _stretch(g2)


def stretch_rates(vs, units, shell: Shell):
    """Fibre stretch rates ``d lambda_f / dt`` (2, T) of velocities ``vs`` (3, N), 1/s."""
    e1, e2 = _edges(vs, shell.mesh)
    u1, u2 = _fibres_soa(e1, e2, shell.ref.tri_coef.astype(vs.dtype))
    return jnp.stack([_dot(units[0], u1), _dot(units[1], u2)])


def stiffness_times(ps, units, fm: FibreMass, shell: Shell):
    """``K_t p / X`` (3, N), kg times the units of ``p``, for structure-of-arrays vectors ``ps``
    (3, N) with the fibre directions ``units`` (:func:`fibre_units`)."""
    if fm.strides:  # springs from node k to k + d: -q on k, +q on k + d
        # padded copies, not `.at[].add` (see the module's note on cost); the same sums, bit for bit
        out = jnp.zeros_like(ps)
        for d, w, u in zip(fm.strides, fm.springs, units):
            q = (w.astype(ps.dtype) * _dot(u, ps[:, d:] - ps[:, :-d])) * u
            out = out + jnp.pad(q, ((0, 0), (d, 0))) - jnp.pad(q, ((0, 0), (0, d)))
        return out
    s = stretch_rates(ps, units, shell) * fm.weight.astype(ps.dtype)
    coef = shell.ref.tri_coef.astype(ps.dtype)
    q1, q2 = s[0] * units[0], s[1] * units[1]
    c1 = q1 * coef[:, 0, 0] + q2 * coef[:, 1, 0]
    c2 = q1 * coef[:, 0, 1] + q2 * coef[:, 1, 1]
    return assemble_corners(jnp.concatenate([-(c1 + c2), c1, c2], axis=1), shell.mesh)


def inverse_mass_times(fs, units, mass, free, fm: FibreMass, shell: Shell):
    """``C f`` (3, N) for forces (or momenta) ``fs`` (3, N) on the free dofs (``free`` (3, N) 0/1;
    the others get 0); ``mass`` (N,) lumped, kg; ``units`` from :func:`fibre_units` at the
    step's positions."""
    n = fm.degree
    theta, a, b, q0 = chebyshev(n)
    m = mass[None, :].astype(fs.dtype)
    r = free * fs / m
    if n == 1:
        return r
    a, b = jnp.asarray(a, fs.dtype), jnp.asarray(b, fs.dtype)

    def iteration(k, c):
        z, r, d = c
        r = r - free * stiffness_times(d, units, fm, shell) / m
        return z + d, r, a[k] * d + b[k] * r

    # a loop, not unrolled: the same speed per iteration and a compile time that does not grow with n
    z, _, d = jax.lax.fori_loop(0, n - 1, iteration, (jnp.zeros_like(r), r, r / theta))
    return (z + d) / q0


def geometric_force(xs, ps, mass, free, fm: FibreMass, shell: Shell):
    """``-1/2 d(p^T C(x) p)/dx`` (3, N) at positions ``xs`` (3, N) for momenta ``ps`` (3, N): the
    force a position-dependent mass adds to the momentum equation (Hamilton: ``dp/dt = -dH/dx``
    with ``H = 1/2 p^T C(x) p + V(x)``). ``C`` follows the fibre directions; without this term a
    rotating triangle turns momentum stored in a heavy fibre-stretch direction into a light one,
    and its kinetic energy grows from nothing. Reverse mode through :func:`inverse_mass_times`."""
    ps = jax.lax.stop_gradient(ps)

    def kinetic(x):
        return 0.5 * jnp.sum(ps * inverse_mass_times(ps, fibre_units(x, fm, shell), mass, free, fm, shell))

    return -jax.grad(kinetic)(xs)


__all__ = ["FibreMass", "MAX_STRIDES", "geometric_force", "fibre_mass", "grid_springs", "degree_for",
           "chebyshev", "peak", "fibre_units", "stretch_rates", "stiffness_times", "inverse_mass_times"]
