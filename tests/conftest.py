"""Test configuration: verification tests run in float64 (STYLE habit 8).

x64 is switched on here, for the test session only; the library itself never changes global JAX
configuration. Tests that check float32 behaviour cast their inputs explicitly.
"""
import os

os.environ.setdefault("MPLBACKEND", "Agg")

import jax  # noqa: E402
import pytest  # noqa: E402

jax.config.update("jax_enable_x64", True)


def rtol_for(dtype) -> float:
    """A relative tolerance suited to the floating dtype of a computation."""
    import numpy as np

    return 1e-10 if np.dtype(dtype) == np.float64 else 1e-4


@pytest.fixture
def tmp_out(tmp_path):
    """An empty output directory for command-line and file-writing tests."""
    out = tmp_path / "out"
    return out
