"""Unconstrained parameters of the bending laws a cantilever fit varies.

``q = (log B_init, log kappa0, logit(b_inf / B_init))`` for the Voce law, so that every ``q`` is a
physical law (``b_inf >= 0``, ``m0 = (B_init - b_inf) kappa0 >= 0``, ``kappa0 > 0``) and the
directions are well conditioned; ``q = (log B,)`` for the linear law.
"""
from __future__ import annotations

import math

import jax
import jax.numpy as jnp
import numpy as np

from jaxform.materials import LinearBending, VoceBending

LAW_KINDS = ("voce", "linear")


def law_from_q(q, law_kind: str):
    """The bending law for unconstrained parameters ``q`` (module docstring); jit-able."""
    if law_kind == "linear":
        return LinearBending(jnp.exp(q[0]))
    b_init, kappa0 = jnp.exp(q[0]), jnp.exp(q[1])
    r = jax.nn.sigmoid(q[2])
    return VoceBending(b_inf=r * b_init, m0=(1.0 - r) * b_init * kappa0, kappa0=kappa0)


def q_from_law(law, law_kind: str) -> np.ndarray:
    """Inverse of :func:`law_from_q` (host)."""
    if law_kind == "linear":
        return np.array([math.log(float(law.b_init))])
    b_init = float(law.b_inf) + float(law.m0) / float(law.kappa0)
    r = min(max(float(law.b_inf) / b_init, 1e-9), 1 - 1e-9)
    return np.array([math.log(b_init), math.log(float(law.kappa0)), math.log(r / (1 - r))])


def _physical(q, law_kind: str):
    """(4,) ``(b_inf, m0, kappa0, b_init)`` (N·m, N, 1/m, N·m) from ``q``; jit-able (delta method)."""
    if law_kind == "linear":
        b = jnp.exp(q[0])
        return jnp.stack([b, 0.0 * b, jnp.inf * b, b])
    law = law_from_q(q, law_kind)
    return jnp.stack([law.b_inf, law.m0, law.kappa0, law.b_inf + law.m0 / law.kappa0])


__all__ = ["LAW_KINDS", "law_from_q", "q_from_law"]
