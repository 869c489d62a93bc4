"""Helpers shared by the tests (not a test module): the one finite-difference derivative."""
import numpy as np


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
