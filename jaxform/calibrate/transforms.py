"""Parameters of the bending laws the fits vary, the similarity of hanging strips, and the laws a
wrinkle fit starts from and scales (:func:`voce_start`, :func:`scaled_shear`).

``q = (log B_init, log(b_inf / B_init), log kappa0)`` for the Voce law: ``B_init`` (what a profile
determines best), the softening ratio ``B_inf / B_init`` in (0, 1] and the curvature scale. Every
``q`` with ``q[1] <= 0`` is a physical law (``b_inf > 0``, ``m0 = (B_init - b_inf) kappa0 >= 0``,
``kappa0 > 0``); the fit bounds the coordinates (``scipy.optimize.least_squares`` bounds) instead
of letting ``b_inf`` run to zero in an unbounded log. ``q = (log B,)`` for the linear law.

Similarity: an inextensible strip of overhang ``L`` under ``w`` with the law ``M(kappa)`` has the
profile of a strip of overhang ``L' = s L`` under the same ``w`` with ``M'(kappa') = s^2 M(kappa'
s)``, scaled by ``1/s`` (moments ``w L^2``, curvatures ``1/L``). For the Voce law ``b_inf' = s^3
b_inf``, ``m0' = s^2 m0``, ``kappa0' = kappa0 / s``; :func:`law_from_q` with ``length_scale = s``
gives that law, so a fit solves every overhang on one strip (one compile).
"""
from __future__ import annotations

import dataclasses
import math

import jax
import jax.numpy as jnp
import numpy as np

from jaxform.materials import AsymmetricBending, LinearBending, VoceBending

LAW_KINDS = ("voce", "linear")


def law_from_q(q, law_kind: str, length_scale=1.0):
    """The bending law for parameters ``q`` (module docstring), for a strip scaled by ``length_scale``; jit-able."""
    s = length_scale
    if law_kind == "linear":
        return LinearBending(jnp.exp(q[0]) * s**3)
    b_init, r, kappa0 = jnp.exp(q[0]), jnp.exp(q[1]), jnp.exp(q[2])
    return VoceBending(b_inf=r * b_init * s**3, m0=(1.0 - r) * b_init * kappa0 * s**2, kappa0=kappa0 / s)


def q_from_law(law, law_kind: str) -> np.ndarray:
    """Inverse of :func:`law_from_q` at ``length_scale = 1`` (host)."""
    if law_kind == "linear":
        return np.array([math.log(float(law.b_init))])
    b_init = float(law.b_inf) + float(law.m0) / float(law.kappa0)
    r = min(max(float(law.b_inf) / b_init, 1e-12), 1.0)
    return np.array([math.log(b_init), math.log(r), math.log(float(law.kappa0))])


def _physical(q, law_kind: str):
    """(4,) ``(b_inf, m0, kappa0, b_init)`` (N·m, N, 1/m, N·m) from ``q``; jit-able (delta method)."""
    if law_kind == "linear":
        b = jnp.exp(q[0])
        return jnp.stack([b, 0.0 * b, jnp.inf * b, b])
    law = law_from_q(q, law_kind)
    return jnp.stack([law.b_inf, law.m0, law.kappa0, law.b_inf + law.m0 / law.kappa0])


def moment_band(q, cov, kappas) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The Voce moment ``M(kappa)`` (N·m/m, ``(n,)``) of ``q`` at ``kappas`` (1/m, ``(n,)``), its
    standard deviation under the covariance ``cov`` of ``q`` (its first three rows and columns)
    by the delta method, and the Jacobian ``dM/dq`` ``(n, 3)`` it used."""
    q = jnp.asarray(np.asarray(q, float)[:3])
    k = jnp.asarray(np.asarray(kappas, float), q.dtype)
    m = lambda v: law_from_q(v, "voce").moment(k)  # noqa: E731
    G = np.asarray(jax.jacfwd(m)(q), float)
    var = np.einsum("ij,jk,ik->i", G, np.asarray(cov, float)[:3, :3], G)
    return np.asarray(m(q), float), np.sqrt(np.clip(var, 0.0, None)), G


def voce_start(law) -> VoceBending:
    """The Voce law a fit starts from: the case's (positive side of an asymmetric law; a linear law
    ``B`` becomes ``B_init = B``, ``B_inf = B/2``, ``kappa0 = 20 1/m``)."""
    if isinstance(law, AsymmetricBending):
        law = law.pos
    if isinstance(law, LinearBending):
        b = float(law.b_init)
        return VoceBending(b_inf=0.5 * b, m0=0.5 * b * 20.0, kappa0=20.0)
    return law


def scaled_shear(shear, s):
    """The shear law with its force multiplied by ``s`` (the coefficient and force-knot leaves)."""
    if dataclasses.is_dataclass(shear):
        ch = {}
        for f in dataclasses.fields(shear):
            v = getattr(shear, f.name)
            if f.name in ("coeffs", "force_knots"):
                ch[f.name] = v * s
            elif dataclasses.is_dataclass(v) or isinstance(v, tuple):
                ch[f.name] = scaled_shear(v, s)
        return dataclasses.replace(shear, **ch) if ch else shear
    if isinstance(shear, tuple):
        return tuple(scaled_shear(v, s) for v in shear)
    return shear


__all__ = ["LAW_KINDS", "law_from_q", "q_from_law", "moment_band", "voce_start", "scaled_shear"]
