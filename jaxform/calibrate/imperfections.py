"""Seeded out-of-plane imperfections of a blank (the wrinkle fit's averaging over imperfect blanks).
SI units; host-side numpy."""
from __future__ import annotations

import math

import numpy as np


def imperfections(x0: np.ndarray, seeds: int, amplitude: float, blank_size: float,
                  clearance: np.ndarray | None = None) -> np.ndarray:
    """(seeds, N, 3) out-of-plane blank imperfections: seed 0 none, the others a smooth random field
    (8 Fourier modes of wavelength 1/4 to 1 blank) scaled to ``amplitude`` (m) at its largest.

    ``clearance`` (N,), m, each node's gap to the nearest tool, tapers the field to 0 where it is under
    ``2 amplitude``: no node starts inside a tool (untapered, the 8 mm Case A blank started 0.1 h deep
    in holder and die, nodes flew off at 3-10 m/s and the run blew up at step 1,048)."""
    out = np.zeros((seeds,) + x0.shape)
    taper = 1.0 if clearance is None else np.clip(np.asarray(clearance, float) / max(amplitude, 1e-300) - 1.0, 0.0, 1.0)
    for k in range(1, seeds):
        rng = np.random.default_rng(k)
        z = np.zeros(len(x0))
        for _ in range(8):
            kx, ky = rng.uniform(-4.0, 4.0, 2) * 2.0 * math.pi / blank_size
            z += rng.normal() * np.cos(kx * x0[:, 0] + ky * x0[:, 1] + rng.uniform(0, 2 * math.pi))
        out[k, :, 2] = taper * amplitude * z / max(np.max(np.abs(z)), 1e-30)
    return out


__all__ = ["imperfections"]
