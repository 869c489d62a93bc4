"""Wrinkle-amplitude sections of a formed part: the measured data, their check against a case,
the simulated section at the measured points, and the position-tolerant residual.

A section is a straight line in the top view of the formed part (m, punch axis at the origin, as
``jaxform run`` writes it) with the wrinkle amplitude measured along it: the distance from the ply
mid-surface to the tool it conforms to (``d_P``, SPEC §5), at positions ``s`` from the line's start.

The residual tolerates small shifts of a wrinkle (documented in the README's modelling choices):
the simulated and measured amplitudes are compared after the same Gaussian smoothing along the
section, of width ``w`` (:func:`smoothing_matrix`, rows normalised over the measured points). A
wrinkle whose crest moves by ``delta`` changes the smoothed profile by a fraction of about
``delta / w`` of its height instead of the whole crest; the smoothed amplitude still carries the
wrinkle's height and extent (a smoothed crest of height ``a`` and width ``b`` keeps about
``a b / (b + 2.5 w)``), which is what the bending law sets. Each row is divided by the standard
deviation that measurement noise ``sigma`` has after smoothing (``sigma * sqrt(sum_j W_ij^2)``), so
rows are in units of the noise, comparable with a cantilever profile's.
"""
from __future__ import annotations

import dataclasses
import math

import jax.numpy as jnp
import numpy as np
from scipy.linalg import block_diag

from jaxform.metrics.wrinkles import section_profile

NOISE = 5e-5  # m, a scanner's noise on the amplitude (the wrinkle fit's default)
MIN_LINE = 5e-3  # m: a shorter section line is a line given in metres where millimetres were asked for
MIN_POINTS = 5
MAX_OFF_PART = 0.1  # the largest fraction of a section's points that may lie off the simulated part
SAMPLES_PER_ELEMENT = 4  # simulated samples along a section per element length


@dataclasses.dataclass(frozen=True)
class Section:
    """One measured section (SI).

    Attributes:
        s: (m,) position along the line from ``start``, m, increasing.
        amplitude: (m,) wrinkle amplitude ``d_P`` there, m.
        start, end: (2,) the line's end points in the top view, m.
        name: a label (the file name).
    """

    s: np.ndarray
    amplitude: np.ndarray
    start: np.ndarray
    end: np.ndarray
    name: str = ""

    @property
    def length(self) -> float:
        return float(np.hypot(*(np.asarray(self.end, float) - np.asarray(self.start, float))))

    def points(self) -> np.ndarray:
        """(m, 2) the measured points in the top view, m."""
        a, b = np.asarray(self.start, float), np.asarray(self.end, float)
        return a[None] + (np.asarray(self.s, float) / self.length)[:, None] * (b - a)[None]


def check_section(sec: Section, case) -> None:
    """Refuse a section no forming run of ``case`` can produce: ``ValueError`` saying what is wrong.

    The line must be at least :data:`MIN_LINE` long (a line in metres given as millimetres is
    1000x too short), the positions must lie on it, the amplitudes be finite and below the blank
    size, and every measured point lie on the undeformed blank (the formed part only draws in).
    """
    who = f"section {sec.name or '?'}"
    s, a = np.asarray(sec.s, float), np.asarray(sec.amplitude, float)
    if s.ndim != 1 or s.shape != a.shape or s.size < MIN_POINTS:
        raise ValueError(f"{who}: {s.size} points with {a.size} amplitudes; need at least {MIN_POINTS} (s, amplitude) pairs")
    if not (np.all(np.isfinite(s)) and np.all(np.isfinite(a))):
        raise ValueError(f"{who}: non-finite positions or amplitudes")
    L = sec.length
    if not L >= MIN_LINE:
        raise ValueError(f"{who}: the line is {L * 1e3:.3g} mm long (from {np.asarray(sec.start) * 1e3} to "
                         f"{np.asarray(sec.end) * 1e3} mm); a section line is at least {MIN_LINE * 1e3:g} mm — "
                         "are its coordinates in metres? The line is given in mm (X0,Y0,X1,Y1)")
    if np.any(np.diff(s) <= 0):
        raise ValueError(f"{who}: positions s must be strictly increasing along the line")
    tol = 1e-3 + 0.01 * L
    if s[0] < -tol or s[-1] > L + tol:
        raise ValueError(f"{who}: positions run from {s[0] * 1e3:.4g} to {s[-1] * 1e3:.4g} mm, off the "
                         f"{L * 1e3:.4g} mm line; s is measured from the line's start (X0, Y0), in mm")
    half = 0.5 * float(case.blank_size)
    if np.max(np.abs(a)) > 2 * half:
        raise ValueError(f"{who}: amplitudes up to {np.max(np.abs(a)) * 1e3:.4g} mm, more than the "
                         f"{2 * half * 1e3:.4g} mm blank; amplitude_mm is in millimetres")
    p = sec.points()
    off = np.max(np.abs(p), axis=1) > half * (1 + 1e-6)
    if np.any(off):
        raise ValueError(f"{who}: {int(off.sum())} of {len(p)} measured points lie outside the "
                         f"{2 * half * 1e3:.4g} mm square blank of case {case.name!r} (the formed part "
                         "only draws in): the line is not on this part, or its coordinates are not in mm "
                         "with the punch axis at the origin")


def smoothing_matrix(s, width: float) -> np.ndarray:
    """(m, m) Gaussian smoothing of width ``width`` (m, standard deviation) over the points ``s``
    (m), rows normalised; the identity for ``width == 0``."""
    s = np.asarray(s, float)
    if width <= 0:
        return np.eye(s.size)
    W = np.exp(-0.5 * ((s[:, None] - s[None]) / width) ** 2)
    return W / W.sum(axis=1, keepdims=True)


def row_scale(W: np.ndarray, noise: float) -> np.ndarray:
    """(m,) standard deviation of each smoothed row under measurement noise ``noise`` (m)."""
    return noise * np.sqrt(np.sum(W * W, axis=1))


def weights(sections, noise: float, width: float) -> np.ndarray:
    """(rows, M) the residual's map from the stacked section values (m) to smoothed rows in noise sds."""
    Ws = [smoothing_matrix(s.s, width) for s in sections]
    return block_diag(*[W / row_scale(W, noise)[:, None] for W in Ws])


def chi_square_moments(R: np.ndarray, noise: float) -> tuple[float, float]:
    """Mean and variance of ``|R e|^2`` for measurement noise ``e ~ N(0, noise^2 I)``: the section
    rows' chi-square at the true law (``R`` of :func:`weights`; rows correlated by the smoothing)."""
    C = noise * noise * (R @ R.T)
    return float(np.trace(C)), float(2.0 * np.sum(C * C))


def independent_points(sec: Section, width: float) -> float:
    """About how many independent residuals the smoothed section holds (``length / (2 sqrt(pi) w)``, at most m)."""
    if width <= 0:
        return float(len(sec.s))
    return float(min(len(sec.s), max(1.0, sec.length / (2.0 * math.sqrt(math.pi) * width))))


def n_samples(sec: Section, element_size: float) -> int:
    """Simulated samples along the line (static): :data:`SAMPLES_PER_ELEMENT` per element, at least 32."""
    return max(32, int(math.ceil(SAMPLES_PER_ELEMENT * sec.length / element_size)) + 1)


def simulated(nodes, faces, deviation, start, end, s, n: int):
    """The simulated amplitude at the measured points of a section (pure JAX).

    Args:
        nodes: (N, 3) positions, m; faces: (F, 3|4) of one ply; deviation: (N,) ``d_P``, m.
        start, end: (2,) the line's end points, m; s: (m,) the measured positions along it, m.
        n: samples along the line (static, :func:`n_samples`), linearly interpolated at ``s``.
    Returns:
        ``(values (m,), valid (m,) bool)``: 0 and ``False`` where a point is off the formed part.
    """
    dtype = nodes.dtype
    s_grid, v, valid, _ = section_profile(nodes, faces, deviation, start, end, n)
    val = jnp.interp(s, s_grid, v)
    ok = jnp.interp(s, s_grid, valid.astype(dtype)) > 1.0 - 1e-6  # both neighbouring samples on the part
    return jnp.where(ok, val, 0.0), ok


__all__ = ["Section", "check_section", "smoothing_matrix", "row_scale", "weights", "independent_points", "n_samples",
           "simulated", "MIN_LINE", "MAX_OFF_PART"]
