"""Frozen dataclasses registered as JAX pytrees.

Array-valued fields are pytree leaves (so ``jax.grad`` reaches material parameters); fields declared
with ``static_field()`` are metadata (sizes, names, kinds) that become part of the compiled
program's identity, as in MJX ``dataclasses.py``.
"""
from __future__ import annotations

import dataclasses
from typing import Any

import jax
import numpy as np


def static_field(**kwargs: Any) -> Any:
    """A dataclass field that is static metadata, not a pytree leaf."""
    metadata = dict(kwargs.pop("metadata", {}))
    metadata["static"] = True
    return dataclasses.field(metadata=metadata, **kwargs)


def pytree_dataclass(cls: type) -> type:
    """Make ``cls`` a frozen dataclass and register it with ``jax.tree_util``.

    JAX rebuilds the object (after ``jit``, ``vmap``, ``grad``, ``tree_map``) without calling
    ``__init__``: ``__post_init__`` validation runs only when a user constructs the object, never
    on tracers, cotangents (which may be negative) or pytree sentinels.
    """
    cls = dataclasses.dataclass(frozen=True)(cls)
    data, meta = [], []
    for f in dataclasses.fields(cls):
        (meta if f.metadata.get("static", False) else data).append(f.name)
    data, meta = tuple(data), tuple(meta)
    keys = tuple(jax.tree_util.GetAttrKey(n) for n in data)

    def flatten_with_keys(obj):
        children = tuple((k, getattr(obj, n)) for k, n in zip(keys, data))
        return children, tuple(getattr(obj, n) for n in meta)

    def flatten(obj):
        return tuple(getattr(obj, n) for n in data), tuple(getattr(obj, n) for n in meta)

    def unflatten(aux, children):
        obj = object.__new__(cls)
        for n, v in zip(data, children):
            object.__setattr__(obj, n, v)
        for n, v in zip(meta, aux):
            object.__setattr__(obj, n, v)
        return obj

    jax.tree_util.register_pytree_with_keys(cls, flatten_with_keys, unflatten, flatten)
    return cls


def is_concrete(*values: Any) -> bool:
    """True when every value is a concrete number or array (not a tracer, not a pytree sentinel).

    Constructors validate user values only when this holds, so that validation happens where
    a law is built from user input and never while JAX rebuilds the object during tracing.
    """
    for v in values:
        if isinstance(v, (list, tuple)):
            if not is_concrete(*v):
                return False
            continue
        if isinstance(v, jax.core.Tracer):
            return False
        if not isinstance(v, (int, float, np.ndarray, np.generic, jax.Array)) or isinstance(v, bool):
            return False
    return True


def as_leaf(value: Any) -> Any:
    """Normalise a user-given value: Python numbers become float, sequences become arrays
    (numpy when concrete, JAX when they hold tracers), arrays are kept as they are."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value)
    if isinstance(value, (list, tuple)):
        if is_concrete(*value):
            return np.asarray(value, dtype=np.float64)
        import jax.numpy as jnp

        return jnp.stack([jnp.asarray(v) for v in value])
    return value
