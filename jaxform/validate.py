"""Validation of user-given values at the edge (STYLE habit 11).

Every check raises ``ValueError`` with the owner and field, the offending value and what is
allowed, e.g. ``VoceBending.kappa0 = -2.0: must be > 0 (1/m)``. Kernels never call these: they
assume valid input. Values that are not concrete (tracers during ``jit``) are not checked here;
constructors call these only on user values (see ``jaxform._pytree.is_concrete``).
"""
from __future__ import annotations

import numpy as np


def _fmt(value) -> str:
    arr = np.asarray(value)
    if arr.ndim == 0:
        return repr(float(arr)) if np.issubdtype(arr.dtype, np.number) else repr(value)
    return np.array2string(arr, precision=6, threshold=8)


def _array(owner: str, name: str, value) -> np.ndarray:
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{owner}.{name} = {value!r}: must be a number (or an array of numbers)") from None
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{owner}.{name} = {_fmt(value)}: must be finite (no NaN or inf)")
    return arr


def finite(owner: str, name: str, value, unit: str = "") -> None:
    """Require a finite number or array."""
    _array(owner, name, value)


def positive(owner: str, name: str, value, unit: str = "") -> None:
    """Require finite values > 0."""
    arr = _array(owner, name, value)
    if np.any(arr <= 0):
        raise ValueError(f"{owner}.{name} = {_fmt(value)}: must be > 0{_unit(unit)}")


def nonnegative(owner: str, name: str, value, unit: str = "") -> None:
    """Require finite values >= 0."""
    arr = _array(owner, name, value)
    if np.any(arr < 0):
        raise ValueError(f"{owner}.{name} = {_fmt(value)}: must be >= 0{_unit(unit)}")


def in_range(owner: str, name: str, value, low: float, high: float, unit: str = "", *, closed: bool = False) -> None:
    """Require low < value < high (or low <= value <= high when ``closed``)."""
    arr = _array(owner, name, value)
    bad = np.any(arr < low) or np.any(arr > high) if closed else np.any(arr <= low) or np.any(arr >= high)
    if bad:
        lo, hi = ("[", "]") if closed else ("(", ")")
        raise ValueError(f"{owner}.{name} = {_fmt(value)}: must lie in {lo}{low}, {high}{hi}{_unit(unit)}")


def _unit(unit: str) -> str:
    return f" ({unit})" if unit else ""
