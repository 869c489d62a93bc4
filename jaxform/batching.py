"""Members of a batch (``jax.vmap`` with :data:`BATCH_AXIS`) that take one branch together.

Under ``jax.vmap`` a ``lax.cond`` on a per-member predicate runs both branches for every member
and selects: the contact search (seconds per call on a fine mesh) would then run every step. The
contact loads ask :func:`any_member` instead: when one member needs a branch, every member of the
batch takes it (a search refreshed early, or every node evaluated, is still exact), and the
``cond`` stays a branch. Outside a vmap named :data:`BATCH_AXIS` the predicate is returned as is.
"""
from __future__ import annotations

import os

import jax
import jax.numpy as jnp

BATCH_AXIS = "member"
"""The axis name of a batch of forming runs (``jax.vmap(..., axis_name=BATCH_AXIS)``; the device
mesh they are sharded over has its own axis, ``"batch"``: :mod:`jaxform.forming.batch`)."""


def any_member(pred):
    """``pred`` (a boolean scalar) or-ed over the members of the enclosing :data:`BATCH_AXIS` vmap
    (the same value for all of them), or ``pred`` itself outside such a vmap."""
    try:
        return jax.lax.psum(jnp.asarray(pred, jnp.int32), BATCH_AXIS) > 0
    except NameError:  # not inside a vmap over BATCH_AXIS: an unbatched run
        return pred


__all__ = ["BATCH_AXIS", "any_member", "cores"]


def cores() -> int:
    """The CPU cores this process may use (its affinity where the system tells it)."""
    return len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
