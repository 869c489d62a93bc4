"""A simulated strip's profile where the measurement has its points: cubic Hermite interpolation
and the discrete curvature of a polyline (pure JAX: jit- and grad-able; m, 1/m)."""
from __future__ import annotations

import jax.numpy as jnp

__all__ = ["interp_profile", "discrete_curvature"]


def interp_profile(xq, xs, zs):
    """Cubic Hermite interpolation of a simulated profile ``zs(xs)`` at ``xq``; jit/grad-able.

    Args:
        xq: (m,) query abscissae, m.
        xs: (n,) simulated x, m, increasing (n >= 3); outside ``[xs[0], xs[-1]]`` the end cubic
            is extrapolated (a measured tip beyond the simulated tip still gives a residual that
            pulls the fit the right way).
        zs: (n,) simulated z, m.
    Returns:
        (m,) z at xq, m. Slopes are second-order three-point estimates (interpolation error O(h^3)).
    """
    h = jnp.diff(xs)
    sl = jnp.diff(zs) / h
    d_in = (h[1:] * sl[:-1] + h[:-1] * sl[1:]) / (h[:-1] + h[1:])
    d0 = ((2 * h[0] + h[1]) * sl[0] - h[0] * sl[1]) / (h[0] + h[1])
    dn = ((2 * h[-1] + h[-2]) * sl[-1] - h[-1] * sl[-2]) / (h[-1] + h[-2])
    d = jnp.concatenate([d0[None], d_in, dn[None]])
    i = jnp.clip(jnp.searchsorted(xs, xq, side="right") - 1, 0, xs.shape[0] - 2)
    x0, hh = xs[i], h[i]
    t = (xq - x0) / hh
    h00 = 2 * t**3 - 3 * t**2 + 1
    h10 = t**3 - 2 * t**2 + t
    h01 = -2 * t**3 + 3 * t**2
    h11 = t**3 - t**2
    return h00 * zs[i] + h10 * hh * d[i] + h01 * zs[i + 1] + h11 * hh * d[i + 1]


def discrete_curvature(xs, zs):
    """(n-2,) curvature at interior nodes of a polyline (turning angle over mean segment length), 1/m."""
    ang = jnp.arctan2(-jnp.diff(zs), jnp.diff(xs))
    seg = jnp.hypot(jnp.diff(xs), jnp.diff(zs))
    return jnp.diff(ang) / (0.5 * (seg[:-1] + seg[1:]))
